//! Trajectory CSV parser, `Trajectory::from_csv_str` (checked) and `from_csv_str_unchecked`
//! (lenient). The first input byte modulo 6 is the scene's tool point count (0 and 5 are out
//! of range), the rest is the file (invalid UTF-8 replaced). No input panics; a parsed
//! trajectory keeps its invariants, `positions_at` returns one position per tool point at any
//! time (NaN and infinities included), every data line gives exactly one sample and holds one
//! CSV record (no carriage return outside quotes between other characters: it would end the
//! record and the rest of the line would be lost), and writing it out and reading it back gives
//! the same samples, bit for bit.
#![no_main]

use libfuzzer_sys::fuzz_target;
use palpate::session::{Sample, Trajectory, TrajectoryError};

const SOURCE: &str = "fuzz-input";

fuzz_target!(|data: &[u8]| {
    let Some((&first, rest)) = data.split_first() else {
        return;
    };
    let tool_count = usize::from(first % 6);
    let text = String::from_utf8_lossy(rest);
    let (lines, bare_cr) = data_lines(&text);
    match Trajectory::from_csv_str(&text, SOURCE, tool_count) {
        Ok(trajectory) => {
            assert_eq!(
                trajectory.samples().len(),
                lines,
                "one sample per data line"
            );
            assert!(!bare_cr, "accepted a line with a carriage return inside");
            check_checked(&trajectory, tool_count);
        }
        Err(err) => check_error(&err),
    }
    match Trajectory::from_csv_str_unchecked(&text, SOURCE, tool_count) {
        Ok((trajectory, findings)) => {
            assert_eq!(
                trajectory.samples().len(),
                lines,
                "one sample per data line"
            );
            assert!(!bare_cr, "accepted a line with a carriage return inside");
            findings.iter().for_each(check_error);
            check_unchecked(&trajectory, tool_count, findings.len());
        }
        Err(err) => check_error(&err),
    }
});

/// The number of lines after the header that are neither blank nor comments (the module doc's
/// rules: lines split on `\n`, a trailing `\r` dropped), and whether one of the lines read
/// (header included) holds a carriage return outside double quotes between other characters.
fn data_lines(text: &str) -> (usize, bool) {
    let mut count = 0usize;
    let mut bare_cr = false;
    let content = text
        .split('\n')
        .map(|line| line.strip_suffix('\r').unwrap_or(line))
        .filter(|line| {
            let line = line.trim_ascii();
            !line.is_empty() && !line.starts_with('#')
        });
    for line in content {
        count += 1;
        // A carriage return outside quotes with something else than carriage returns both
        // before and after it (leading ones only make empty records, which are skipped).
        let (mut quoted, mut content, mut cr) = (false, false, false);
        for c in line.chars() {
            match c {
                '\r' if !quoted => cr = content,
                _ if cr => bare_cr = true,
                '"' => (quoted, content) = (!quoted, true),
                _ => content = true,
            }
        }
    }
    (count.saturating_sub(1), bare_cr)
}

fn check_error(err: &TrajectoryError) {
    assert!(err.to_string().starts_with(SOURCE), "{err}");
}

/// Both readers: the structural invariants, `positions_at` everywhere, NaN gives the first
/// samples, and the CSV round trip.
fn check_common(trajectory: &Trajectory, tool_count: usize) -> Vec<u8> {
    assert!((1..=4).contains(&tool_count));
    assert_eq!(trajectory.tool_count(), tool_count);
    let samples = trajectory.samples();
    assert!(!samples.is_empty());
    assert!(samples.iter().all(|s| s.tool < tool_count));
    assert!((0..tool_count).all(|i| samples.iter().any(|s| s.tool == i)));
    let (start, end) = (trajectory.start_s(), trajectory.end_s());
    assert!(start.is_finite() && end.is_finite() && start <= end);

    let mut times = vec![start, end, 0.5 * start + 0.5 * end, -1e300, 1e300];
    times.extend([f64::NAN, f64::INFINITY, f64::NEG_INFINITY]);
    times.extend(samples.iter().take(16).map(|s| s.t_s));
    for &t in &times {
        let positions = trajectory.positions_at(t);
        assert_eq!(positions.len(), tool_count, "positions_at({t})");
        let mut into = vec![[0.0; 3]; tool_count + 1];
        trajectory.positions_at_into(t, &mut into);
        assert!(same_positions(&into[..tool_count], &positions));
        assert_eq!(into[tool_count], [0.0; 3]);
    }
    // A NaN time gives every tool point's first sample.
    let first: Vec<[f64; 3]> = (0..tool_count)
        .map(|i| first_sample(samples, i).position_m)
        .collect();
    assert!(same_positions(&trajectory.positions_at(f64::NAN), &first));

    let mut csv = Vec::new();
    trajectory.write_csv(&mut csv).expect("write to a Vec");
    csv
}

fn check_checked(trajectory: &Trajectory, tool_count: usize) {
    let csv = check_common(trajectory, tool_count);
    let samples = trajectory.samples();
    assert!(samples.iter().all(finite));
    assert!(samples.windows(2).all(|w| w[0].t_s <= w[1].t_s));
    // At a sample's own time, a tool point is at its last sample of that time.
    for s in samples.iter().take(64) {
        let last = samples
            .iter()
            .rfind(|o| o.tool == s.tool && o.t_s == s.t_s)
            .expect("the sample itself");
        let at = trajectory.positions_at(s.t_s)[s.tool];
        assert!(same_position(&at, &last.position_m), "{s:?}: {at:?}");
    }
    // Moderate values: every interpolated position is finite.
    let moderate = |x: f64| x.abs() < 1e150;
    if samples
        .iter()
        .all(|s| moderate(s.t_s) && s.position_m.iter().all(|&x| moderate(x)))
    {
        let (start, end) = (trajectory.start_s(), trajectory.end_s());
        for k in 0..=8 {
            let t = start + (end - start) * f64::from(k) / 8.0;
            let positions = trajectory.positions_at(t);
            assert!(positions.iter().flatten().all(|x| x.is_finite()), "t = {t}");
        }
    }
    let again = Trajectory::from_csv_str(&String::from_utf8_lossy(&csv), SOURCE, tool_count)
        .expect("a written checked trajectory reads back");
    assert_eq!(&again, trajectory);
    let rebuilt = Trajectory::from_samples(samples.to_vec(), tool_count).expect("from samples");
    assert_eq!(&rebuilt, trajectory);
}

fn check_unchecked(trajectory: &Trajectory, tool_count: usize, findings: usize) {
    let csv = check_common(trajectory, tool_count);
    let (again, again_findings) =
        Trajectory::from_csv_str_unchecked(&String::from_utf8_lossy(&csv), SOURCE, tool_count)
            .expect("a written unchecked trajectory reads back");
    assert_eq!(again_findings.len(), findings);
    assert_eq!(again.samples().len(), trajectory.samples().len());
    for (a, b) in again.samples().iter().zip(trajectory.samples()) {
        assert!(a.tool == b.tool && same(a.t_s, b.t_s), "{a:?} != {b:?}");
        assert!(
            same_position(&a.position_m, &b.position_m),
            "{a:?} != {b:?}"
        );
    }
}

fn first_sample(samples: &[Sample], tool: usize) -> &Sample {
    samples.iter().find(|s| s.tool == tool).expect("a sample")
}

fn finite(s: &Sample) -> bool {
    s.t_s.is_finite() && s.position_m.iter().all(|x| x.is_finite())
}

/// Equal bits, or both NaN (NaN signs and payloads are not kept through text).
fn same(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

fn same_position(a: &[f64; 3], b: &[f64; 3]) -> bool {
    a.iter().zip(b).all(|(&x, &y)| same(x, y))
}

fn same_positions(a: &[[f64; 3]], b: &[[f64; 3]]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| same_position(x, y))
}
