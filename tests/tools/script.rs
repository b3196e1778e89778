//! The contact-script syntax and the replay runner (`tools/script`, crate
//! `palpate-script`) that the CLI and the firmware share: exact parsing,
//! every syntax error, and the replay output decoded back to numbers and
//! checked against the scikit-fem reference (`cube_contact.json`).
//!
//! Tolerance of the decoded forces: the replay runs f32 tables, so the bound
//! of the kernel's f32 reference test applies (1e-6 relative to the largest
//! force component; measured there ≤ 7.9e-8).

use nalgebra::Vector3;
use palpate::table::file::Precision;
use palpate::table::load::AnyModel;
use palpate_kernel::{Constraint, PrecomputedModel};
use palpate_script::{ParseError, ReplayError, parse_contact, parse_step, replay, steps};
use palpate_tests::{json_rows, read_reference_json, reference_cube_table};

const F32_TOL: f64 = 1e-6;

#[test]
fn contacts_parse_to_exact_values() {
    assert_eq!(
        parse_contact::<f64>("194:0,0,-0.01"),
        Ok(Constraint::at_vertex(194, Vector3::new(0.0, 0.0, -0.01)))
    );
    assert_eq!(
        parse_contact::<f32>(" 1, 2 ,3@0.2,0.5,0.3:1e-3, -2e-3,0 "),
        Ok(Constraint::on_triangle(
            [1, 2, 3],
            [0.2, 0.5, 0.3],
            Vector3::new(1e-3, -2e-3, 0.0)
        ))
    );
}

#[test]
fn every_syntax_error_is_named() {
    let cases = [
        ("194", ParseError::MissingColon),
        (
            "194:0,0",
            ParseError::NotThree {
                what: "displacement",
            },
        ),
        (
            "194:0,0,0,0",
            ParseError::NotThree {
                what: "displacement",
            },
        ),
        ("-1:0,0,0", ParseError::BadVertex),
        ("4294967296:0,0,0", ParseError::BadVertex),
        ("194:0,x,0", ParseError::BadNumber),
        (
            "1,2@0.5,0.5:0,0,0",
            ParseError::NotThree { what: "vertices" },
        ),
        (
            "1,2,3@0.5,0.5:0,0,0",
            ParseError::NotThree { what: "weights" },
        ),
        ("1,2,3@0.5,0.5,z:0,0,0", ParseError::BadNumber),
    ];
    for (text, want) in cases {
        assert_eq!(parse_contact::<f32>(text), Err(want), "{text}");
    }
    assert_eq!(
        parse_step::<f32>("1:0,0,0 2:0,0,0 3:0,0,0 4:0,0,0 5:0,0,0"),
        Err(ParseError::TooManyContacts)
    );
    assert!(
        ParseError::NotThree { what: "weights" }
            .to_string()
            .contains("weights")
    );
}

#[test]
fn sequences_skip_comments_and_blank_lines() {
    let text = "# header\n\n194:0,0,-0.001  # one contact\n-\n194:0,0,0 201:0,0,0\n";
    let parsed: Vec<(usize, usize)> = steps::<f32>(text)
        .map(|(line, step)| (line, step.expect("valid").len()))
        .collect();
    assert_eq!(parsed, [(3, 1), (4, 0), (5, 2)]);
}

/// Decodes the `0x…` f32 bit patterns of a replay line.
fn hex_values(line: &str) -> Vec<f64> {
    line.split_whitespace()
        .filter_map(|w| w.strip_prefix("0x"))
        .map(|h| f64::from(f32::from_bits(u32::from_str_radix(h, 16).expect("hex"))))
        .collect()
}

#[test]
fn replay_output_decodes_to_the_reference_forces() {
    let file = reference_cube_table(Precision::F32);
    let AnyModel::F32(model) = file.model().expect("valid table") else {
        panic!("f32 table expected")
    };
    let reference = read_reference_json("linear/cube_contact.json");
    let single = &reference["single_contact"];
    let two = &reference["two_contacts"];
    let sequence = "194:0,0,-0.01\n-\n0:0,0,-0.01\n194:0,0,-0.01 201:0.003,-0.002,-0.006\n";
    let mut u = vec![[0.0f32; 3]; model.table().vertex_count()];
    let mut out = String::new();
    replay(&model, sequence, &mut u, &mut out).expect("replay");
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines.len(), 4, "{out}");

    let check = |line: &str, forces: &[[f64; 3]], umax: f64| {
        let values = hex_values(line);
        assert_eq!(values.len(), 3 + 3 * forces.len() + 1, "{line}");
        let scale = forces.iter().flatten().fold(0.0f64, |m, g| m.max(g.abs()));
        for axis in 0..3 {
            let device: f64 = -forces.iter().map(|g| g[axis]).sum::<f64>();
            assert!((values[axis] - device).abs() <= F32_TOL * scale, "{line}");
        }
        for (got, want) in values[3..].iter().zip(forces.iter().flatten()) {
            assert!(
                (got - want).abs() <= F32_TOL * scale,
                "{line}: {got} vs {want}"
            );
        }
        let got_umax = values[values.len() - 1];
        assert!((got_umax - umax).abs() <= F32_TOL * umax, "{line}");
    };
    let max_abs = |rows: &[[f64; 3]]| rows.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    let single_u = json_rows(&single["displacements"]);
    let single_g = json_rows(&serde_json::json!([single["force"].clone()]));
    assert!(lines[0].starts_with("step 0 device "), "{}", lines[0]);
    check(lines[0], &single_g, max_abs(&single_u));
    assert_eq!(
        lines[1],
        "step 1 device 0x00000000 0x00000000 0x00000000 contacts umax 0x00000000"
    );
    assert!(
        lines[2].starts_with("step 2 error ") && lines[2].contains("vertex 0 is fixed"),
        "{}",
        lines[2]
    );
    let two_u = json_rows(&two["displacements"]);
    check(lines[3], &json_rows(&two["forces"]), max_abs(&two_u));
}

#[test]
fn replay_refuses_bad_lines_and_buffers_before_writing() {
    let file = reference_cube_table(Precision::F32);
    let AnyModel::F32(model) = file.model().expect("valid table") else {
        panic!("f32 table expected")
    };
    let model: &PrecomputedModel<'_, f32> = &model;
    let mut u = vec![[0.0f32; 3]; model.table().vertex_count()];
    let mut out = String::new();
    assert_eq!(
        replay(model, "194:0,0,-0.01\n# note\n194:0,0\n", &mut u, &mut out),
        Err(ReplayError::Parse {
            line: 3,
            error: ParseError::NotThree {
                what: "displacement"
            }
        })
    );
    assert!(out.is_empty());
    assert_eq!(
        replay(model, "194:0,0,-0.01\n", &mut u[1..], &mut out),
        Err(ReplayError::DisplacementBuffer {
            expected: 216,
            found: 215
        })
    );
    assert!(out.is_empty());
}
