//! `palpate::session::run` (`palpate session run`): the haptic loop driven
//! by generated trajectories on the built-in scene. Deterministic output,
//! bounded force changes, and non-finite input turned into a latched fault
//! with zero force.

use palpate::session::run::run_session;
use palpate::session::{Generator, Poke, Scene, Strike, Trajectory};

fn run(scene: &Scene, trajectory: &Trajectory) -> (String, palpate::session::run::SessionSummary) {
    let mut out = Vec::new();
    let summary = run_session(scene, trajectory, &mut out, None).expect("session");
    (String::from_utf8(out).expect("utf-8"), summary)
}

/// A poke on the built-in block: the probe is in contact for part of the
/// run, the force is never clamped, every tick's change is below the slew
/// limit times the tick (2 N), in fact below 1 mN (measured 0.91 mN against
/// a peak of 0.32 N: the force follows the probe smoothly), and two runs
/// give byte-identical CSV.
#[test]
fn poke_is_deterministic_and_smooth() {
    let scene = Scene::built_in();
    let trajectory = Poke::default().trajectory().expect("poke");
    let (a, summary) = run(&scene, &trajectory);
    let (b, _) = run(&scene, &trajectory);
    assert_eq!(a, b, "bit-identical runs");
    println!("{summary:?}");
    assert!(summary.ticks_in_contact > 100);
    assert_eq!((summary.clamped, summary.faulted), (0, 0));
    assert!(summary.max_force_n > 0.1);
    assert!(summary.max_jump_n <= 1e-3, "{}", summary.max_jump_n);
    assert_eq!(a.lines().next(), Some("t,fx,fy,fz,contacts,status"));
    assert_eq!(a.lines().count(), summary.ticks + 1);
}

/// The strike with a slew limit of 5 N/s (5 mN per tick): the unlimited
/// run's largest jump (measured 22.7 mN, at contact) is above it, the
/// limited run's jumps all stay at or below it, and the limited ticks are
/// reported as clamped.
#[test]
fn strike_jumps_are_slew_limited() {
    let mut scene = Scene::built_in();
    let trajectory = Strike::default().trajectory().expect("strike");
    let (_, free) = run(&scene, &trajectory);
    scene.safety.max_slew_n_per_s = 5.0;
    let (_, limited) = run(&scene, &trajectory);
    println!(
        "strike: largest jump {:.4} N unlimited, {:.4} N limited",
        free.max_jump_n, limited.max_jump_n
    );
    assert!(free.max_jump_n > 0.005);
    assert!(limited.max_jump_n <= 0.005 * (1.0 + 1e-5));
    assert!(limited.clamped > 0);
}

/// A NaN in the trajectory (read leniently) reaches the kernel: that tick
/// and every later one are faulted with zero force (latched until reset).
#[test]
fn non_finite_input_faults_with_zero_force() {
    let scene = Scene::built_in();
    let text = "t,tool,x,y,z\n0,0,0.06,0.06,0.07\n0.002,0,0.06,0.06,0.059\n0.004,0,NaN,0.06,0.059\n0.006,0,0.06,0.06,0.058\n";
    let (trajectory, findings) =
        Trajectory::from_csv_str_unchecked(text, "nan.csv", 1).expect("lenient read");
    assert_eq!(findings.len(), 1, "{findings:?}");
    let (csv, summary) = run(&scene, &trajectory);
    let rows: Vec<Vec<&str>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    let faulted: Vec<usize> = (0..rows.len())
        .filter(|&k| rows[k][5].starts_with("faulted"))
        .collect();
    println!("{csv}");
    assert!(!faulted.is_empty());
    let first = faulted[0];
    assert!(faulted.iter().copied().eq(first..rows.len()), "latched");
    for row in &rows[first..] {
        assert_eq!(&row[1..4], &["0", "0", "0"]);
    }
    assert_eq!(summary.faulted, rows.len() - first);
}
