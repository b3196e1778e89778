//! Trajectory CSV parser, `Trajectory::from_csv_str` (checked) and `from_csv_str_unchecked`
//! (lenient). The first input byte modulo 6 is the scene's tool point count (0 and 5 are out
//! of range), the rest is the file (invalid UTF-8 replaced), with or without the tool columns
//! `jaw_m,cut`. No input panics; a parsed trajectory keeps its invariants, `positions_at` returns
//! one position per tool point and `tools_at` one state per tool point at any time (NaN and
//! infinities included), the two agreeing on positions, every data line gives exactly one sample
//! and holds one CSV record (no carriage return outside quotes between other characters: it would
//! end the record and the rest of the line would be lost), a checked trajectory's jaw openings
//! are finite and ≥ 0 and its `cut` is sample-and-hold, a trajectory without the tool columns has
//! no jaw and no cut, and writing it out (in the format it was read in) and reading it back gives
//! the same samples, jaw openings and cuts included, bit for bit.
#![no_main]

use libfuzzer_sys::fuzz_target;
use palpate::scene::{Sample, ToolState, Trajectory, TrajectoryError};

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

/// Both readers: the structural invariants, `positions_at` and `tools_at` everywhere, NaN gives
/// the first samples, and the CSV round trip.
fn check_common(trajectory: &Trajectory, tool_count: usize) -> Vec<u8> {
    assert!((1..=4).contains(&tool_count));
    assert_eq!(trajectory.tool_count(), tool_count);
    let samples = trajectory.samples();
    assert!(!samples.is_empty());
    assert!(samples.iter().all(|s| s.tool < tool_count));
    assert!((0..tool_count).all(|i| samples.iter().any(|s| s.tool == i)));
    if !trajectory.has_tool_columns() {
        // Only the 7-column header gives jaw openings and cuts (+0 exactly, no cut).
        assert!(samples.iter().all(|s| s.jaw_m.to_bits() == 0 && !s.cut));
    }
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
        // One state per tool point, at the positions of positions_at.
        let tools = trajectory.tools_at(t);
        assert_eq!(tools.len(), tool_count, "tools_at({t})");
        let tool_positions: Vec<[f64; 3]> = tools.iter().map(|s| s.position_m).collect();
        assert!(same_positions(&tool_positions, &positions), "tools_at({t})");
        let untouched = ToolState {
            position_m: [0.0; 3],
            jaw_m: 0.0,
            cut: true,
        };
        let mut into = vec![untouched; tool_count + 1];
        trajectory.tools_at_into(t, &mut into);
        assert!(same_states(&into[..tool_count], &tools));
        assert_eq!(into[tool_count], untouched);
        // No cut without the tool columns (the jaw openings are +0 only on a checked
        // trajectory: on an unchecked one, times out of order or infinite make NaN).
        assert!(trajectory.has_tool_columns() || tools.iter().all(|s| !s.cut));
    }
    // A NaN time gives every tool point's first sample.
    let first: Vec<ToolState> = (0..tool_count)
        .map(|i| first_sample(samples, i).tool_state())
        .collect();
    let first_positions: Vec<[f64; 3]> = first.iter().map(|s| s.position_m).collect();
    assert!(same_positions(
        &trajectory.positions_at(f64::NAN),
        &first_positions
    ));
    assert!(same_states(&trajectory.tools_at(f64::NAN), &first));

    let mut csv = Vec::new();
    trajectory.write_csv(&mut csv).expect("write to a Vec");
    // The format it has: the 7-column header if and only if it has the tool columns.
    assert_eq!(
        csv.starts_with(b"t,tool,x,y,z,jaw_m,cut\n"),
        trajectory.has_tool_columns()
    );
    assert!(csv.starts_with(b"t,tool,x,y,z\n") || trajectory.has_tool_columns());
    csv
}

fn check_checked(trajectory: &Trajectory, tool_count: usize) {
    let csv = check_common(trajectory, tool_count);
    let samples = trajectory.samples();
    assert!(samples.iter().all(finite));
    assert!(
        samples.iter().all(|s| s.jaw_m >= 0.0),
        "a negative jaw opening"
    );
    assert!(samples.windows(2).all(|w| w[0].t_s <= w[1].t_s));
    // At a sample's own time, a tool point is at its last sample of that time (jaw and cut too).
    for s in samples.iter().take(64) {
        let last = samples
            .iter()
            .rfind(|o| o.tool == s.tool && o.t_s == s.t_s)
            .expect("the sample itself");
        let at = trajectory.positions_at(s.t_s)[s.tool];
        assert!(same_position(&at, &last.position_m), "{s:?}: {at:?}");
        let state = trajectory.tools_at(s.t_s)[s.tool];
        assert!(same_state(&state, &last.tool_state()), "{s:?}: {state:?}");
    }
    // The cut is sample-and-hold: the latest sample's at or before a time (the first's before
    // every sample).
    let mut times: Vec<f64> = samples.iter().take(16).map(|s| s.t_s).collect();
    times.extend(
        samples
            .windows(2)
            .take(16)
            .map(|w| 0.5 * w[0].t_s + 0.5 * w[1].t_s),
    );
    times.extend([trajectory.start_s() - 1.0, trajectory.end_s() + 1.0]);
    for t in times {
        let tools = trajectory.tools_at(t);
        for (tool, state) in tools.iter().enumerate() {
            let held = samples
                .iter()
                .rfind(|s| s.tool == tool && s.t_s <= t)
                .unwrap_or_else(|| first_sample(samples, tool));
            assert_eq!(state.cut, held.cut, "cut of tool point {tool} at {t}");
            if !trajectory.has_tool_columns() {
                assert_eq!(state.jaw_m.to_bits(), 0, "jaw of tool point {tool} at {t}");
            }
        }
    }
    // Moderate values: every interpolated position is finite.
    let moderate = |x: f64| x.abs() < 1e150;
    if samples
        .iter()
        .all(|s| moderate(s.t_s) && moderate(s.jaw_m) && s.position_m.iter().all(|&x| moderate(x)))
    {
        let (start, end) = (trajectory.start_s(), trajectory.end_s());
        for k in 0..=8 {
            let t = start + (end - start) * f64::from(k) / 8.0;
            let positions = trajectory.positions_at(t);
            assert!(positions.iter().flatten().all(|x| x.is_finite()), "t = {t}");
            let tools = trajectory.tools_at(t);
            assert!(tools.iter().all(|s| s.jaw_m.is_finite()), "t = {t}");
        }
    }
    let again = Trajectory::from_csv_str(&String::from_utf8_lossy(&csv), SOURCE, tool_count)
        .expect("a written checked trajectory reads back");
    assert_eq!(&again, trajectory);
    assert_same_samples(&again, trajectory);
    let rebuilt = Trajectory::from_samples_with_tool_columns(
        samples.to_vec(),
        tool_count,
        trajectory.has_tool_columns(),
    )
    .expect("from samples");
    assert_eq!(&rebuilt, trajectory);
    assert_same_samples(&rebuilt, trajectory);
}

fn check_unchecked(trajectory: &Trajectory, tool_count: usize, findings: usize) {
    let csv = check_common(trajectory, tool_count);
    let (again, again_findings) =
        Trajectory::from_csv_str_unchecked(&String::from_utf8_lossy(&csv), SOURCE, tool_count)
            .expect("a written unchecked trajectory reads back");
    assert_eq!(again_findings.len(), findings);
    assert_same_samples(&again, trajectory);
}

/// The same samples, bit for bit (NaN for NaN), and the same format.
fn assert_same_samples(a: &Trajectory, b: &Trajectory) {
    assert_eq!(a.has_tool_columns(), b.has_tool_columns());
    assert_eq!(a.samples().len(), b.samples().len());
    for (x, y) in a.samples().iter().zip(b.samples()) {
        assert!(x.tool == y.tool && same(x.t_s, y.t_s), "{x:?} != {y:?}");
        assert!(
            same_state(&x.tool_state(), &y.tool_state()),
            "{x:?} != {y:?}"
        );
    }
}

fn first_sample(samples: &[Sample], tool: usize) -> &Sample {
    samples.iter().find(|s| s.tool == tool).expect("a sample")
}

fn finite(s: &Sample) -> bool {
    s.t_s.is_finite() && s.jaw_m.is_finite() && s.position_m.iter().all(|x| x.is_finite())
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

fn same_state(a: &ToolState, b: &ToolState) -> bool {
    same_position(&a.position_m, &b.position_m) && same(a.jaw_m, b.jaw_m) && a.cut == b.cut
}

fn same_states(a: &[ToolState], b: &[ToolState]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| same_state(x, y))
}
