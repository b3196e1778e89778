//! The generators of the tool columns (`palpate::scene::generate`): the
//! probe generators unchanged by them, grasp-and-pull and cut-line keyframes
//! and trajectories, the jaw and cut of sampled keyframes, and every bad
//! grasp or cut parameter (the probe generators themselves are tested in
//! `host::session`).

use palpate::scene::{
    CutLine, Generator, GraspPull, Keyframe, MAX_TOOL_POINTS, Pinch, Poke, Press, PressHold, Slide,
    Strike, Trajectory, sample_keyframes, sample_keyframes_with_tool_columns,
};
use palpate_tests::{csv, keyframe, tool_state};

/// Tool point 0's keyframe `label` is at time `t_s` and position `position_m` (within 1e-12)
/// with this jaw opening and cut.
fn assert_key(
    keys: &[Keyframe],
    label: &str,
    t_s: f64,
    position_m: [f64; 3],
    jaw_m: f64,
    cut: bool,
) {
    let k = keyframe(keys, 0, label);
    assert!((k.t_s - t_s).abs() < 1e-12, "{label}: {k:?}");
    for (a, b) in k.position_m.iter().zip(&position_m) {
        assert!((a - b).abs() < 1e-12, "{label}: {k:?}");
    }
    assert!((k.jaw_m - jaw_m).abs() < 1e-15, "{label}: {k:?}");
    assert_eq!(k.cut, cut, "{label}: {k:?}");
}

/// 64-bit FNV-1a.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// The probe generators write exactly what they wrote before the tool columns existed (the
/// length, hash and first lines of `palpate session generate KIND` then).
#[test]
fn probe_generators_are_unchanged() {
    let cases: [(&str, Trajectory, usize, u64, &str); 5] = [
        (
            "poke",
            Poke::default().trajectory().unwrap(),
            27593,
            0x2896_391a_54eb_7515,
            "t,tool,x,y,z\n0,0,0.06,0.06,0.065\n0.001,0,0.06,0.06,0.06498\n",
        ),
        (
            "press-hold",
            PressHold::default().trajectory().unwrap(),
            51714,
            0x3cda_84a1_40e3_0e7c,
            "t,tool,x,y,z\n0,0,0.06,0.06,0.065\n0.001,0,0.06,0.06,0.06498\n",
        ),
        (
            "slide",
            Slide::default().trajectory().unwrap(),
            72574,
            0xc367_8e59_387e_1841,
            "t,tool,x,y,z\n0,0,0.06,0.06,0.065\n0.001,0,0.06,0.06,0.06498\n",
        ),
        (
            "pinch",
            Pinch::default().trajectory().unwrap(),
            171_626,
            0xfce8_f25c_6315_0ceb,
            "t,tool,x,y,z\n0,0,0.039999999999999994,0.06,0.065\n0,1,0.08,0.06,0.065\n",
        ),
        (
            "strike",
            Strike::default().trajectory().unwrap(),
            26795,
            0x7932_8067_f2ff_6617,
            "t,tool,x,y,z\n0,0,0.06,0.06,0.06999999999999999\n0.001,0,0.06,0.06,0.06949999999999999\n",
        ),
    ];
    for (name, trajectory, len, hash, head) in cases {
        assert!(!trajectory.has_tool_columns(), "{name}");
        let text = csv(&trajectory);
        assert!(text.starts_with(head), "{name}: {}", &text[..200]);
        assert_eq!((text.len(), fnv1a(text.as_bytes())), (len, hash), "{name}");
    }
}

#[test]
fn grasp_pull_keyframes() {
    let g = GraspPull::default();
    let keys = g.keyframes().unwrap();
    let labels: Vec<_> = keys.iter().map(|k| k.label).collect();
    assert_eq!(
        labels,
        [
            "start", "contact", "deepest", "closed", "gripped", "pulled", "held", "opened", "end"
        ]
    );
    let (open, closed) = (0.012, 0.0045);
    let at = |z| [0.06, 0.06, z];
    assert_key(&keys, "start", 0.0, at(0.07), open, false);
    // The jaw spheres (radius 2 mm) touch the top face, then are 1 mm into it.
    assert_key(&keys, "contact", 0.4, at(0.062), open, false);
    assert_key(
        &keys,
        "deepest",
        0.45,
        at(0.06 + 0.002 - 0.001),
        open,
        false,
    );
    assert_key(&keys, "closed", 0.75, at(0.061), closed, false);
    assert_key(&keys, "gripped", 0.95, at(0.061), closed, false);
    assert_key(&keys, "pulled", 1.75, at(0.069), closed, false);
    assert_key(&keys, "held", 2.25, at(0.069), closed, false);
    assert_key(&keys, "opened", 2.45, at(0.069), open, false);
    assert_key(&keys, "end", 2.95, at(0.079), open, false);
    // The jaw spheres at the start: x = 0.054 and 0.066.
    let start = keyframe(&keys, 0, "start");
    let jaws = [-0.5, 0.5].map(|s| start.position_m[0] + s * start.jaw_m);
    assert!((jaws[0] - 0.054).abs() < 1e-15 && (jaws[1] - 0.066).abs() < 1e-15);

    let t = g.trajectory().unwrap();
    assert!(t.has_tool_columns());
    assert_eq!(t.tool_count(), 1);
    assert_eq!(t.samples().len(), 2951);
    assert!(t.samples().iter().all(|s| !s.cut));
    // At the keyframes exactly their state; between them, the jaw linear.
    for k in &keys {
        assert_eq!(
            t.tools_at(k.t_s),
            [tool_state(k.position_m, k.jaw_m, k.cut)],
            "{}",
            k.label
        );
    }
    let mid_close = t.tools_at(0.6)[0];
    assert!((mid_close.jaw_m - 0.008_25).abs() < 1e-12, "{mid_close:?}");
    let mid_open = t.tools_at(2.35)[0];
    assert!((mid_open.jaw_m - 0.008_25).abs() < 1e-12, "{mid_open:?}");
    let mid_pull = t.tools_at(1.35)[0];
    assert!((mid_pull.position_m[2] - 0.065).abs() < 1e-12 && mid_pull.jaw_m == closed);
    let text = csv(&t);
    assert!(
        text.starts_with("t,tool,x,y,z,jaw_m,cut\n0,0,0.06,0.06,0.06999999999999999,0.012,0\n"),
        "{}",
        &text[..100]
    );
    // Read back: the same trajectory.
    assert_eq!(Trajectory::from_csv_str(&text, "g", 1).unwrap(), t);
}

#[test]
fn cut_line_keyframes_and_blade() {
    let c = CutLine::default();
    let keys = c.keyframes().unwrap();
    let labels: Vec<_> = keys.iter().map(|k| k.label).collect();
    assert_eq!(
        labels,
        ["start", "contact", "deepest", "cut", "release", "end"]
    );
    // The tool point is the blade's upper end, 10 mm above the tip.
    assert_key(&keys, "start", 0.0, [0.03, 0.06, 0.075], 0.0, false);
    assert_key(&keys, "contact", 0.25, [0.03, 0.06, 0.07], 0.0, true);
    assert_key(&keys, "deepest", 0.45, [0.03, 0.06, 0.066], 0.0, true);
    assert_key(&keys, "cut", 6.45, [0.09, 0.06, 0.066], 0.0, false);
    assert_key(&keys, "release", 6.65, [0.09, 0.06, 0.07], 0.0, false);
    assert_key(&keys, "end", 7.2, [0.09, 0.06, 0.081], 0.0, false);

    let t = c.trajectory().unwrap();
    assert!(t.has_tool_columns());
    assert_eq!(t.samples().len(), 7201);
    let (on, off) = (
        keyframe(&keys, 0, "contact").t_s,
        keyframe(&keys, 0, "cut").t_s,
    );
    // Enabled from the tip reaching the surface to the end of the line.
    for s in t.samples() {
        assert_eq!(s.cut, s.t_s >= on && s.t_s < off, "{s:?}");
        assert_eq!(s.jaw_m, 0.0);
    }
    let cases = [
        (0.1, false),
        (on, true),
        (0.3, true),
        (3.0, true),
        (6.449_5, true),
        (off, false),
        (7.0, false),
        (100.0, false),
    ];
    for (time, cut) in cases {
        assert_eq!(t.tools_at(time)[0].cut, cut, "t = {time}");
    }
    let middle = t.tools_at(3.0)[0].position_m;
    assert!((middle[0] - 0.0555).abs() < 1e-12 && (middle[2] - 0.066).abs() < 1e-12);
    let text = csv(&t);
    assert!(
        text.starts_with("t,tool,x,y,z,jaw_m,cut\n0,0,0.03,0.06,0.075,0,0\n"),
        "{}",
        &text[..100]
    );
    assert_eq!(Trajectory::from_csv_str(&text, "c", 1).unwrap(), t);
}

#[test]
fn sampled_keyframes_interpolate_the_jaw_and_hold_the_cut() {
    let k = |t_s, z, jaw_m, cut, label| Keyframe {
        tool: 0,
        t_s,
        position_m: [0.0, 0.0, z],
        jaw_m,
        cut,
        label,
    };
    let keys = [
        k(0.0, 0.01, 0.01, false, "start"),
        k(0.01, 0.0, 0.0, true, "contact"),
        // The same place and time, the blade switched off: a jump.
        k(0.02, 0.0, 0.0, true, "held"),
        k(0.02, 0.0, 0.0, false, "cut"),
        k(0.03, 0.0, 0.0, false, "end"),
    ];
    let t = sample_keyframes(&keys, 1000.0).unwrap();
    assert!(t.has_tool_columns());
    // 31 grid times, plus the jump's second sample.
    assert_eq!(t.samples().len(), 32);
    for s in t.samples() {
        let expected_jaw = (0.01 - s.t_s).max(0.0);
        assert!((s.jaw_m - expected_jaw).abs() < 1e-15, "{s:?}");
        assert!((s.position_m[2] - expected_jaw).abs() < 1e-15, "{s:?}");
    }
    let cuts: Vec<(f64, bool)> = t.samples().iter().map(|s| (s.t_s, s.cut)).collect();
    assert_eq!(cuts[9], (0.009, false));
    assert_eq!(cuts[10], (0.01, true));
    assert_eq!(cuts[19], (0.019, true));
    assert_eq!(cuts[20], (0.02, true));
    assert_eq!(cuts[21], (0.02, false));
    assert_eq!(cuts[22], (0.021, false));
    assert!(!t.tools_at(0.02)[0].cut && t.tools_at(0.0195)[0].cut);
    assert!((t.tools_at(0.0025)[0].jaw_m - 0.0075).abs() < 1e-15);

    // No jaw and no cut: the 5-column format, unless asked for.
    let plain = [
        k(0.0, 0.01, 0.0, false, "start"),
        k(0.01, 0.0, 0.0, false, "end"),
    ];
    assert!(!sample_keyframes(&plain, 1000.0).unwrap().has_tool_columns());
    let with = sample_keyframes_with_tool_columns(&plain, 1000.0, true).unwrap();
    assert!(with.has_tool_columns());
    assert_eq!(
        with.samples(),
        sample_keyframes(&plain, 1000.0).unwrap().samples()
    );

    // A jaw opening below 0 or not finite is refused.
    for jaw in [-0.001, f64::NAN, f64::INFINITY] {
        let bad = [
            k(0.0, 0.0, 0.0, false, "start"),
            k(1.0, 0.0, jaw, false, "closed"),
        ];
        assert_eq!(
            sample_keyframes(&bad, 10.0).unwrap_err().to_string(),
            "keyframes: closed of tool point 0: non-finite value, negative time or negative jaw_m"
        );
    }
}

#[test]
fn bad_grasp_and_cut_parameters_name_the_field() {
    let grasp = |g: GraspPull| g.keyframes().unwrap_err().to_string();
    let d = GraspPull::default();
    let cases = [
        (
            grasp(GraspPull { open_m: 0.004, ..d }),
            "grasp_pull.open_m: must be finite and > closed_m = 0.0045 m, got 0.004",
        ),
        (
            grasp(GraspPull {
                closed_m: -0.001,
                ..d
            }),
            "grasp_pull.closed_m: must be finite and >= 0 m, got -0.001",
        ),
        (
            grasp(GraspPull {
                standoff_m: 0.001,
                ..d
            }),
            "grasp_pull.standoff_m: must be finite and >= 0.002 m (grasp_pull.radius_m), got 0.001",
        ),
        (
            grasp(GraspPull { radius_m: 0.0, ..d }),
            "grasp_pull.radius_m: must be finite and > 0 m, got 0",
        ),
        (
            grasp(GraspPull {
                normal: [0.0; 3],
                ..d
            }),
            "grasp_pull.normal: must be a finite non-zero vector, got [0.0, 0.0, 0.0]",
        ),
        (
            grasp(GraspPull {
                surface_m: [f64::NAN, 0.0, 0.0],
                ..d
            }),
            "grasp_pull.surface_m: must be finite, got [NaN, 0.0, 0.0]",
        ),
        (
            grasp(GraspPull {
                close_s: f64::NAN,
                ..d
            }),
            "grasp_pull.close_s: must be finite and >= 0 s, got NaN",
        ),
        (
            grasp(GraspPull {
                pull_speed_m_s: 0.0,
                ..d
            }),
            "grasp_pull.pull_speed_m_s: must be finite and > 0 m/s, got 0",
        ),
        (
            grasp(GraspPull {
                tool: MAX_TOOL_POINTS,
                ..d
            }),
            &format!(
                "grasp_pull.tool: tool point {MAX_TOOL_POINTS} out of range 0..{MAX_TOOL_POINTS}"
            ),
        ),
    ];
    let cut = |c: CutLine| c.keyframes().unwrap_err().to_string();
    let d = CutLine::default();
    let more = [
        (
            cut(CutLine {
                blade_m: [0.0, f64::INFINITY, 0.0],
                ..d
            }),
            "cut_line.blade_m: must be finite, got [0.0, inf, 0.0]",
        ),
        (
            cut(CutLine {
                direction: [0.0, 0.0, -2.0],
                ..d
            }),
            "cut_line.direction: [0.0, 0.0, -2.0] is along the surface normal",
        ),
        (
            cut(CutLine {
                withdraw_m: 0.003,
                ..d
            }),
            "cut_line.withdraw_m: must be finite and >= 0.004 m (press.depth_m), got 0.003",
        ),
        (
            cut(CutLine {
                cut_speed_m_s: -1.0,
                ..d
            }),
            "cut_line.cut_speed_m_s: must be finite and > 0 m/s, got -1",
        ),
        (
            cut(CutLine {
                distance_m: -0.01,
                ..d
            }),
            "cut_line.distance_m: must be finite and >= 0 m, got -0.01",
        ),
        (
            cut(CutLine {
                press: Press {
                    depth_m: -1.0,
                    ..d.press
                },
                ..d
            }),
            "press.depth_m: must be finite and >= 0 m, got -1",
        ),
    ];
    for (got, expected) in cases
        .iter()
        .map(|(g, e)| (g, *e))
        .chain(more.iter().map(|(g, e)| (g, *e)))
    {
        assert_eq!(got, expected);
    }
    assert_eq!(
        GraspPull {
            rate_hz: 0.0,
            ..GraspPull::default()
        }
        .trajectory()
        .unwrap_err()
        .to_string(),
        "rate_hz: must be finite and > 0 Hz, got 0"
    );
}
