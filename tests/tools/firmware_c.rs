//! The C example (`tools/firmware-c`): its scripted sequence,
//! `sequence.h`, is `tools/firmware-m4f/sequence.txt` as C data, generated
//! here from the values `palpate-script` parses (so the C firmware replays
//! exactly the floats the Rust replay does) and committed. The test fails
//! when the committed file differs; `PALPATE_BLESS=1` rewrites it.
//!
//! The floats are written as C99 hexadecimal literals, which a C compiler
//! converts exactly (an f32's 24-bit significand fits the 6 hex digits);
//! the formatter is checked against the bit patterns by decoding its output
//! independently.

use core::fmt::Write;
use std::path::PathBuf;

use palpate_kernel::precomputed::{AsConstraint, ContactPoint};
use palpate_script::steps;

fn repository() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// `x` as an exact C hexadecimal `float` literal.
fn c_float(x: f32) -> String {
    let bits = x.to_bits();
    let sign = if bits >> 31 == 1 { "-" } else { "" };
    let exponent = ((bits >> 23) & 0xff) as i32;
    let fraction = bits & 0x7f_ffff;
    match (exponent, fraction) {
        (0, 0) => format!("{sign}0x0p+0f"),
        (0, _) => format!("{sign}0x0.{:06x}p-126f", fraction << 1),
        (255, _) => panic!("non-finite value {x} in the sequence"),
        _ => format!("{sign}0x1.{:06x}p{:+}f", fraction << 1, exponent - 127),
    }
}

/// Decodes a literal of [`c_float`] (sign, `0x` lead digit `.` six hex
/// digits `p` exponent `f`) to its value, in f64 (exact for every f32).
fn decode(literal: &str) -> f64 {
    let (sign, rest) = match literal.strip_prefix('-') {
        Some(rest) => (-1.0, rest),
        None => (1.0, literal),
    };
    let rest = rest.strip_prefix("0x").unwrap().strip_suffix('f').unwrap();
    let (significand, exponent) = rest.split_once('p').unwrap();
    let exponent: i32 = exponent.parse().unwrap();
    let (lead, fraction) = significand.split_once('.').unwrap_or((significand, ""));
    let mut value = f64::from(u32::from_str_radix(lead, 16).unwrap());
    for (i, digit) in fraction.chars().enumerate() {
        value += f64::from(digit.to_digit(16).unwrap()) * 16f64.powi(-(i as i32) - 1);
    }
    sign * value * 2f64.powi(exponent)
}

#[test]
fn hexadecimal_literals_are_exact() {
    let cases = [
        0.0f32,
        -0.0,
        1.0,
        -0.0004,
        0.2,
        0.3,
        0.5,
        1.2e-7,
        f32::MIN_POSITIVE,
        f32::MIN_POSITIVE / 3.0,
        f32::MAX,
    ];
    for x in cases {
        let literal = c_float(x);
        let decoded = decode(&literal);
        assert_eq!(decoded, f64::from(x), "{literal}");
        assert_eq!((decoded as f32).to_bits(), x.to_bits(), "{literal}");
    }
}

/// `sequence.h` for the sequence text `sequence`.
fn sequence_header(sequence: &str) -> String {
    let lines: Vec<&str> = sequence.lines().collect();
    let vector = |v: [f32; 3]| {
        format!(
            "{{{}, {}, {}}}",
            c_float(v[0]),
            c_float(v[1]),
            c_float(v[2])
        )
    };
    let mut rows = String::new();
    let mut count = 0;
    for (line, step) in steps::<f32>(sequence) {
        let step = step.unwrap_or_else(|e| panic!("sequence.txt line {line}: {e}"));
        let text = lines[line - 1].split('#').next().unwrap().trim();
        let contacts: Vec<String> = step
            .iter()
            .map(|c| {
                let (kind, vertices, weights) = match c.point() {
                    ContactPoint::Vertex(v) => ("VERTEX", [v, 0, 0], [0.0; 3]),
                    ContactPoint::Triangle { vertices, weights } => ("TRIANGLE", vertices, weights),
                };
                let [a, b, d] = vertices;
                format!(
                    "{{PALPATE_CONTACT_KIND_{kind}, {{{a}, {b}, {d}}}, {}, {}}}",
                    vector(weights),
                    vector(c.displacement_m().into())
                )
            })
            .collect();
        let contacts = if contacts.is_empty() {
            "{{0}}".to_string()
        } else {
            format!("{{{}}}", contacts.join(",\n      "))
        };
        writeln!(
            rows,
            "    /* line {line}: {text} */\n    {{{}, {contacts}}},",
            step.len()
        )
        .unwrap();
        count += 1;
    }
    format!(
        r#"/*
 * Generated from tools/firmware-m4f/sequence.txt (the firmware's scripted
 * contact sequence) by tests/tools/firmware_c.rs; do not edit. Rewrite it
 * with `PALPATE_BLESS=1 cargo test -p palpate-tests --test integration
 * tools::firmware_c`. Each float is the f32 palpate-script parses from the
 * text (what `palpate precomputed replay` solves), as an exact hexadecimal
 * literal.
 */
#ifndef PALPATE_EXAMPLE_SEQUENCE_H
#define PALPATE_EXAMPLE_SEQUENCE_H

#include <stdint.h>

#include "palpate.h"

/* One step of the sequence: its contacts. */
struct sequence_step {{
    uint32_t count;
    palpate_contact contacts[PALPATE_MAX_CONTACTS];
}};

#define SEQUENCE_STEPS {count}u

static const struct sequence_step SEQUENCE[SEQUENCE_STEPS] = {{
{rows}}};

#endif /* PALPATE_EXAMPLE_SEQUENCE_H */
"#
    )
}

#[test]
fn sequence_header_is_the_firmware_sequence() {
    let root = repository();
    let sequence = std::fs::read_to_string(root.join("tools/firmware-m4f/sequence.txt")).unwrap();
    let generated = sequence_header(&sequence);
    let path = root.join("tools/firmware-c/sequence.h");
    if std::env::var_os("PALPATE_BLESS").is_some_and(|v| v == "1") {
        let tmp = path.with_extension("h.tmp");
        std::fs::write(&tmp, &generated).unwrap();
        std::fs::rename(&tmp, &path).unwrap();
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "tools/firmware-c/sequence.h is not tools/firmware-m4f/sequence.txt's: rewrite it with \
         PALPATE_BLESS=1 cargo test -p palpate-tests --test integration tools::firmware_c"
    );
    // 30 steps, as the Rust replay runs them (one `step` line each).
    assert_eq!(generated.matches("/* line ").count(), 30);
}
