//! `palpate demo` (`palpate::demo`): both parts run and report. The organ's
//! surgery is cut to its first second here (the CLI runs all of it); the
//! truth is the generated surgery's own timing (`session generate
//! hepatectomy`: the blade tip reaches the surface at 0.25 s, the jaws
//! close past the grip opening at 0.73 s) and the series the folder holds.

use std::path::PathBuf;

use palpate::demo::{block, organ, run_with};
use palpate::scene::Scene;

/// The first second of the surgery, at 1 kHz.
const ORGAN_S: f64 = 1.0;

/// A phase line of the organ's table: name, start (s), ticks, |F| peak (N)
/// and tets removed.
fn organ_phases(report: &str) -> Vec<(String, f64, usize, f64, usize)> {
    report
        .lines()
        .skip_while(|l| !l.starts_with("part two"))
        .filter(|l| l.starts_with("grasper "))
        .map(|l| {
            let (name, rest) = l.split_at(30);
            let fields: Vec<&str> = rest.split_whitespace().collect();
            let n = fields.len();
            (
                name.trim().to_string(),
                fields[0].parse().expect("from"),
                fields[1].parse().expect("ticks"),
                fields[n - 2].parse().expect("peak"),
                fields[n - 1].parse().expect("removed"),
            )
        })
        .collect()
}

/// The block's 100 steps and 25 frames; the organ's first second: 1001
/// ticks, 100 physics updates, 10 frames (one per 0.1 s), no fault, the
/// blade's cut removing tets; its phases start when the generator's tools
/// change state, to the tick (1 ms: the tick grid against the keyframe
/// times); every force within the scene's clamp; both collections in
/// place and nothing else left in the folder but their frames.
#[test]
fn the_demo_runs_the_block_and_the_organ_and_reports_both() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("host_demo");
    std::fs::create_dir_all(&dir).expect("tmp");
    let out_dir = dir.join("demo-out");
    let mut printed = Vec::new();
    let run = run_with(&out_dir, Some(ORGAN_S), &mut printed).expect("demo");
    let report = String::from_utf8(printed).expect("utf-8");
    println!("{report}");

    assert_eq!((run.block.ticks.len(), run.block.frames), (100, 25));
    assert_eq!(run.organ.costs.ticks.len(), 1001);
    assert_eq!(run.organ.costs.physics.len(), 100);
    assert_eq!(run.organ.costs.frames, 10);
    assert_eq!(run.organ.faulted, 0);
    assert!(run.organ.ticks_in_contact > 0);
    assert!(run.organ.removed_tets > 0, "{report}");

    let phases = organ_phases(&report);
    let names: Vec<&str> = phases.iter().map(|p| p.0.as_str()).collect();
    assert_eq!(
        names,
        [
            "grasper open, blade off",
            "grasper open, blade cutting",
            "grasper closed, blade cutting"
        ],
        "{report}"
    );
    for ((_, from_s, ..), expected_s) in phases.iter().zip([0.0, 0.25, 0.73]) {
        assert!((from_s - expected_s).abs() <= 0.0011, "{report}");
    }
    assert_eq!(phases.iter().map(|p| p.2).sum::<usize>(), 1001);
    assert_eq!(
        phases.iter().map(|p| p.4).sum::<usize>(),
        run.organ.removed_tets
    );
    // Nothing removed before the blade is enabled.
    assert_eq!(phases[0].4, 0);
    let max_force_n = Scene::built_in_hybrid().safety.max_force_n;
    assert!(phases.iter().all(|p| p.3 <= max_force_n), "{report}");
    assert!(report.contains(&format!("the cut removed {} tets", run.organ.removed_tets)));

    for (collection, frames) in [(block::COLLECTION, 25), (organ::COLLECTION, 10)] {
        let text = std::fs::read_to_string(out_dir.join(collection)).expect("collection");
        let listed: Vec<&str> = text
            .lines()
            .filter_map(|l| l.split("file=\"").nth(1))
            .map(|f| f.trim_end_matches("\"/>"))
            .collect();
        assert_eq!(listed.len(), frames, "{collection}");
        assert!(listed.iter().all(|f| out_dir.join(f).is_file()));
    }
    let entries = std::fs::read_dir(&out_dir).expect("folder").count();
    // The two collections, their frames and the folder's marker.
    assert_eq!(entries, 2 + 25 + 10 + 1);
    std::fs::remove_dir_all(&dir).ok();
}
