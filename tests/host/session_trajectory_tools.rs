//! Trajectory files' tool columns `jaw_m,cut` (`palpate::scene::trajectory`):
//! the 5-column format read as no jaw and no cut, the jaw interpolated and the
//! cut held, the round trip bit for bit, when the columns are written, every
//! error and the lenient reader (the 5-column format itself is tested in
//! `host::session`).

use palpate::scene::{Sample, ToolState, Trajectory};
use palpate_tests::{csv, tool_state, traj, traj_err};

/// Two tool points with the tool columns; tool 0 jumps at t = 3 (jaw and cut too).
const TOOLS: &str = "\
t,tool,x,y,z,jaw_m,cut
0,0,0,0,0,0.012,0
0,1,1,1,1,0,1
1,0,0.5,0,-0.25,0.004,1
2,1,1,1,3,0,0
3,0,1.5,0,-1.25,0.008,1
3,0,1.5,0,-2.25,0.01,0
";

#[test]
fn five_columns_read_as_no_jaw_and_no_cut_and_write_back_unchanged() {
    let text = "t,tool,x,y,z\n0,0,0.06,0.06,0.07\n0.5,0,0.06,0.06,0.055\n";
    let t = traj(text, 1);
    assert!(!t.has_tool_columns());
    assert!(t.samples().iter().all(|s| s.jaw_m == 0.0 && !s.cut));
    assert_eq!(csv(&t), text);
    assert_eq!(
        t.tools_at(0.25),
        [tool_state([0.06, 0.06, 0.0625], 0.0, false)]
    );
}

#[test]
fn tool_columns_interpolate_the_jaw_and_hold_the_cut() {
    let t = traj(TOOLS, 2);
    assert!(t.has_tool_columns());
    assert_eq!(
        t.samples()[2],
        Sample {
            t_s: 1.0,
            tool: 0,
            position_m: [0.5, 0.0, -0.25],
            jaw_m: 0.004,
            cut: true,
        }
    );
    let cases: [(f64, [ToolState; 2]); 10] = [
        // Before the first sample: the first sample, its cut included.
        (
            -1.0,
            [
                tool_state([0.0; 3], 0.012, false),
                tool_state([1.0; 3], 0.0, true),
            ],
        ),
        (
            0.0,
            [
                tool_state([0.0; 3], 0.012, false),
                tool_state([1.0; 3], 0.0, true),
            ],
        ),
        // Between samples: the jaw linear, the cut of the sample before.
        (
            0.5,
            [
                tool_state([0.25, 0.0, -0.125], 0.008, false),
                tool_state([1.0, 1.0, 1.5], 0.0, true),
            ],
        ),
        // At a sample: exactly the sample, its cut from then on.
        (
            1.0,
            [
                tool_state([0.5, 0.0, -0.25], 0.004, true),
                tool_state([1.0, 1.0, 2.0], 0.0, true),
            ],
        ),
        (
            1.5,
            [
                tool_state([0.75, 0.0, -0.5], 0.005, true),
                tool_state([1.0, 1.0, 2.5], 0.0, true),
            ],
        ),
        (
            2.0,
            [
                tool_state([1.0, 0.0, -0.75], 0.006, true),
                tool_state([1.0, 1.0, 3.0], 0.0, false),
            ],
        ),
        // After tool 1's last sample: held.
        (
            2.5,
            [
                tool_state([1.25, 0.0, -1.0], 0.007, true),
                tool_state([1.0, 1.0, 3.0], 0.0, false),
            ],
        ),
        // The jump: from t = 3 on, the later sample (jaw and cut too).
        (
            3.0,
            [
                tool_state([1.5, 0.0, -2.25], 0.01, false),
                tool_state([1.0, 1.0, 3.0], 0.0, false),
            ],
        ),
        (
            10.0,
            [
                tool_state([1.5, 0.0, -2.25], 0.01, false),
                tool_state([1.0, 1.0, 3.0], 0.0, false),
            ],
        ),
        (
            f64::NAN,
            [
                tool_state([0.0; 3], 0.012, false),
                tool_state([1.0; 3], 0.0, true),
            ],
        ),
    ];
    for (time, expected) in cases {
        let got = t.tools_at(time);
        for (g, e) in got.iter().zip(&expected) {
            assert_eq!(g.cut, e.cut, "t = {time}: {g:?}");
            assert!((g.jaw_m - e.jaw_m).abs() < 1e-15, "t = {time}: {g:?}");
        }
        let mut out = [tool_state([9.0; 3], 9.0, true); 3];
        t.tools_at_into(time, &mut out);
        assert_eq!(&out[..2], got.as_slice(), "t = {time}");
        assert_eq!(out[2], tool_state([9.0; 3], 9.0, true), "t = {time}");
        // The positions are those of positions_at, and as expected.
        let positions = t.positions_at(time);
        assert_eq!(
            positions,
            got.iter().map(|s| s.position_m).collect::<Vec<_>>()
        );
        let expected_positions: Vec<_> = expected.iter().map(|s| s.position_m).collect();
        assert_eq!(positions, expected_positions, "t = {time}");
    }
    // At a sample's own time, exactly the sample's jaw.
    assert_eq!(t.tools_at(1.0)[0].jaw_m, 0.004);
    // Just before the jump: on the way to the first of the two samples, cut still held.
    let before = t.tools_at(2.999_999)[0];
    assert!(
        (before.jaw_m - 0.008).abs() < 1e-8 && before.cut,
        "{before:?}"
    );
}

#[test]
fn tool_columns_round_trip_bit_for_bit() {
    let s = |t_s, tool, jaw_m, cut| Sample {
        t_s,
        tool,
        position_m: [0.1, -0.0, 1e-7],
        jaw_m,
        cut,
    };
    let samples = vec![
        s(0.0, 0, 1.0 / 3.0, false),
        s(0.0, 1, -0.0, true),
        s(0.001, 1, f64::MIN_POSITIVE, true),
        s(0.30000000000000004, 0, 5e-324, false),
        s(0.4, 0, 999.9999999999999, true),
    ];
    let t = Trajectory::from_samples(samples.clone(), 2).unwrap();
    assert!(t.has_tool_columns());
    let text = csv(&t);
    assert!(
        text.starts_with(
            "t,tool,x,y,z,jaw_m,cut\n0,0,0.1,-0,0.0000001,0.3333333333333333,0\n0,1,0.1,-0,0.0000001,-0,1\n"
        ),
        "{text}"
    );
    let back = traj(&text, 2);
    let bits = |t: &Trajectory| -> Vec<(u64, usize, [u64; 3], u64, bool)> {
        t.samples()
            .iter()
            .map(|s| {
                (
                    s.t_s.to_bits(),
                    s.tool,
                    s.position_m.map(f64::to_bits),
                    s.jaw_m.to_bits(),
                    s.cut,
                )
            })
            .collect()
    };
    assert_eq!(bits(&back), bits(&t));
    assert_eq!(back, t);
    assert_eq!(csv(&back), text);
    // The lenient reader reads the same.
    let (lenient, findings) = Trajectory::from_csv_str_unchecked(&text, "r", 2).unwrap();
    assert!(findings.is_empty());
    assert_eq!(lenient, t);
}

#[test]
fn tool_columns_are_kept_when_asked_for_or_needed() {
    let s = |t_s, jaw_m, cut| Sample {
        t_s,
        tool: 0,
        position_m: [0.0; 3],
        jaw_m,
        cut,
    };
    // Nothing needs them: 5 columns, unless asked for (or read from a 7-column file).
    let plain = vec![s(0.0, 0.0, false), s(1.0, 0.0, false)];
    let t = Trajectory::from_samples(plain.clone(), 1).unwrap();
    assert!(!t.has_tool_columns());
    assert_eq!(csv(&t), "t,tool,x,y,z\n0,0,0,0,0\n1,0,0,0,0\n");
    let t = Trajectory::from_samples_with_tool_columns(plain, 1, true).unwrap();
    assert!(t.has_tool_columns());
    let text = csv(&t);
    assert_eq!(
        text,
        "t,tool,x,y,z,jaw_m,cut\n0,0,0,0,0,0,0\n1,0,0,0,0,0,0\n"
    );
    let back = traj(&text, 1);
    assert!(back.has_tool_columns());
    assert_eq!(back, t);
    // A jaw opening, a cut, or a jaw of -0 needs them.
    for samples in [
        vec![s(0.0, 0.001, false)],
        vec![s(0.0, 0.0, true)],
        vec![s(0.0, -0.0, false)],
    ] {
        let t = Trajectory::from_samples_with_tool_columns(samples, 1, false).unwrap();
        assert!(t.has_tool_columns());
        assert_eq!(traj(&csv(&t), 1), t);
    }
    // from_samples refuses what the reader refuses, naming the would-be line.
    let msg = Trajectory::from_samples(vec![s(0.0, 0.0, false), s(1.0, -0.5, true)], 1)
        .unwrap_err()
        .to_string();
    assert_eq!(
        msg,
        "samples: line 3: jaw_m = -0.5 m is negative: a jaw opening is >= 0"
    );
}

#[test]
fn every_tool_column_error_names_the_file_and_line() {
    let h = "t,tool,x,y,z,jaw_m,cut\n";
    let cases: Vec<(String, &str)> = vec![
        // Bad cut values.
        (
            format!("{h}0,0,0,0,0,0,2\n"),
            "traj.csv: line 2: cut = `2` is not 0 or 1",
        ),
        (
            format!("{h}0,0,0,0,0,0,\n"),
            "traj.csv: line 2: cut = `` is not 0 or 1",
        ),
        (
            format!("{h}0,0,0,0,0,0,0\n1,0,0,0,0,0,true\n"),
            "traj.csv: line 3: cut = `true` is not 0 or 1",
        ),
        (
            format!("{h}0,0,0,0,0,0,1.0\n"),
            "traj.csv: line 2: cut = `1.0` is not 0 or 1",
        ),
        // Bad jaw openings.
        (
            format!("{h}0,0,0,0,0,abc,0\n"),
            "traj.csv: line 2: jaw_m = `abc` is not a number",
        ),
        (
            format!("{h}0,0,0,0,0,NaN,0\n"),
            "traj.csv: line 2: non-finite jaw_m = NaN",
        ),
        (
            format!("{h}0,0,0,0,0,inf,1\n"),
            "traj.csv: line 2: non-finite jaw_m = inf",
        ),
        (
            format!("{h}\n# c\n0,0,0,0,0,-0.001,0\n"),
            "traj.csv: line 4: jaw_m = -0.001 m is negative: a jaw opening is >= 0",
        ),
        // Mixed field counts: the header decides.
        (
            format!("{h}0,0,0,0,0,0,0\n1,0,0,0,0\n"),
            "traj.csv: line 3: expected 7 fields t,tool,x,y,z,jaw_m,cut as the header, found 5",
        ),
        (
            format!("{h}0,0,0,0,0,0\n"),
            "traj.csv: line 2: expected 7 fields t,tool,x,y,z,jaw_m,cut as the header, found 6",
        ),
        (
            "t,tool,x,y,z\n0,0,0,0,0\n1,0,0,0,0,0,0\n".into(),
            "traj.csv: line 3: expected 5 fields t,tool,x,y,z, found 7",
        ),
        // Headers.
        (
            "t,tool,x,y,z,jaw_m\n0,0,0,0,0,0\n".into(),
            "traj.csv: line 1: expected the header `t,tool,x,y,z` or `t,tool,x,y,z,jaw_m,cut`, found `t,tool,x,y,z,jaw_m`",
        ),
        (
            "t,tool,x,y,z,cut,jaw_m\n".into(),
            "traj.csv: line 1: expected the header `t,tool,x,y,z` or `t,tool,x,y,z,jaw_m,cut`, found `t,tool,x,y,z,cut,jaw_m`",
        ),
        (
            "".into(),
            "traj.csv: empty: expected the header line `t,tool,x,y,z` or `t,tool,x,y,z,jaw_m,cut`",
        ),
        (h.into(), "traj.csv: no samples after the header"),
    ];
    for (text, expected) in cases {
        assert_eq!(traj_err(&text, 1), expected, "\n{text}");
    }
    // Padded fields and a quoted cut are read as in any other column.
    let t = traj(&format!("{h} 0 , 0 , 0 , 0 , 0 , 0.002 ,\"1\"\n"), 1);
    assert_eq!(t.tools_at(0.0), [tool_state([0.0; 3], 0.002, true)]);
}

#[test]
fn the_lenient_reader_keeps_bad_jaws_but_not_bad_cuts() {
    let text = "t,tool,x,y,z,jaw_m,cut\n0,0,0,0,0,NaN,1\n1,0,0,0,0,-0.5,0\n0.5,0,0,0,0,0.001,0\n";
    let (t, findings) = Trajectory::from_csv_str_unchecked(text, "r", 1).unwrap();
    let findings: Vec<String> = findings.iter().map(ToString::to_string).collect();
    assert_eq!(
        findings,
        [
            "r: line 2: non-finite jaw_m = NaN",
            "r: line 3: jaw_m = -0.5 m is negative: a jaw opening is >= 0",
            "r: line 4: time 0.5 s goes backwards: line 3 is at 1 s",
        ]
    );
    assert!(t.has_tool_columns());
    assert!(t.samples()[0].jaw_m.is_nan() && t.samples()[0].cut);
    assert_eq!(t.samples()[1].jaw_m, -0.5);
    // Written and read back: the same values and findings.
    let (again, again_findings) = Trajectory::from_csv_str_unchecked(&csv(&t), "r", 1).unwrap();
    assert_eq!(again_findings.len(), 3);
    assert!(again.samples()[0].jaw_m.is_nan());
    assert_eq!(again.samples()[1..], t.samples()[1..]);
    // The checked reader refuses the first of them.
    assert_eq!(
        traj_err(text, 1),
        "traj.csv: line 2: non-finite jaw_m = NaN"
    );
    // A cut other than 0 or 1 has no value to keep.
    let msg =
        Trajectory::from_csv_str_unchecked("t,tool,x,y,z,jaw_m,cut\n0,0,0,0,0,0,-1\n", "r", 1)
            .unwrap_err()
            .to_string();
    assert_eq!(msg, "r: line 2: cut = `-1` is not 0 or 1");
}
