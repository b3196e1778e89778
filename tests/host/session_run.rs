//! `palpate::session::run` (`palpate session run`): the haptic loop driven
//! by generated trajectories on the built-in scene. Deterministic output,
//! bounded force changes, and non-finite input turned into a latched fault
//! with zero force.

use palpate::scene::{Generator, Poke, Scene, Slide, Strike, Trajectory};
use palpate::session::run::run_session;
use palpate_tests::traj;

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

/// The strike with a slew limit of 5 N/s (5 mN per tick), on both models:
/// the unlimited run's largest jump (measured at contact: 22.7 mN
/// pre-computed, 67 mN dynamic, whose first ticks in contact feel the
/// tissue's instantaneous stiffness) is above it, the limited run's jumps
/// all stay at or below it, and the limited ticks are reported as clamped.
#[test]
fn strike_jumps_are_slew_limited() {
    for mut scene in [Scene::built_in(), Scene::built_in_dynamic()] {
        let trajectory = Strike::default().trajectory().expect("strike");
        let (_, free) = run(&scene, &trajectory);
        scene.safety.max_slew_n_per_s = 5.0;
        let (_, limited) = run(&scene, &trajectory);
        println!(
            "{}: strike: largest jump {:.4} N unlimited, {:.4} N limited",
            scene.source, free.max_jump_n, limited.max_jump_n
        );
        assert!(free.max_jump_n > 0.005);
        assert!(limited.max_jump_n <= 0.005 * (1.0 + 1e-5));
        assert!(limited.clamped > 0);
    }
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

/// Largest tick-to-tick change of the force vector over the CSV rows
/// from `from` on, N.
fn max_jump_from(csv: &str, from: usize) -> f64 {
    let forces: Vec<[f64; 3]> = csv
        .lines()
        .skip(1)
        .map(|l| {
            let c: Vec<f64> = l
                .split(',')
                .skip(1)
                .take(3)
                .map(|x| x.parse().expect("force"))
                .collect();
            [c[0], c[1], c[2]]
        })
        .collect();
    forces
        .windows(2)
        .skip(from)
        .map(|w| {
            ((w[1][0] - w[0][0]).powi(2)
                + (w[1][1] - w[0][1]).powi(2)
                + (w[1][2] - w[0][2]).powi(2))
            .sqrt()
        })
        .fold(0.0, f64::max)
}

/// The built-in block on the dynamic model (100 Hz physics, force
/// extrapolated at 1 kHz) under the same poke as the pre-computed model:
/// bit-identical runs, no clamp or fault, a force that pushes the probe
/// out. Smoothness against the same poke with physics at 1 kHz (no
/// extrapolation): once the first physics period in contact has measured
/// the tissue's secant stiffness, the largest tick-to-tick change is no
/// larger than the 1 kHz run's over the same ticks (measured 2.6 mN vs
/// 4.7 mN). In that first period the force grows at the instantaneous
/// stiffness (α = 1, measured 2.7 mN per tick at 20 mm/s), bounded here by
/// 10 mN. The dynamic model holds the contact triangle's vertices while the
/// pre-computed solve constrains only the contact point (a smaller set of
/// constraints: less energy for the same displacement), so its peak is the
/// larger (measured 1.35×).
#[test]
fn dynamic_poke_is_deterministic_smooth_and_pushes_out() {
    let scene = Scene::built_in_dynamic();
    let trajectory = Poke::default().trajectory().expect("poke");
    let (a, summary) = run(&scene, &trajectory);
    let (b, _) = run(&scene, &trajectory);
    assert_eq!(a, b, "bit-identical runs");
    let mut every_tick = scene.clone();
    every_tick.rates.physics_every = 1;
    let (reference, _) = run(&every_tick, &trajectory);
    let (_, quasi_static) = run(&Scene::built_in(), &trajectory);
    let first_contact = a
        .lines()
        .skip(1)
        .position(|l| l.ends_with(",1,ok"))
        .expect("contact");
    let settled = first_contact + 2 * scene.rates.physics_every as usize;
    let (jump, reference_jump) = (
        max_jump_from(&a, settled),
        max_jump_from(&reference, settled),
    );
    println!(
        "dynamic {summary:?}\npre-computed {quasi_static:?}\n\
         after the first period: largest jump {jump:.3e} N, physics every tick {reference_jump:.3e} N; \
         peak ratio dynamic / pre-computed {:.3}",
        summary.max_force_n / quasi_static.max_force_n
    );
    assert_eq!((summary.clamped, summary.faulted), (0, 0));
    assert_eq!(summary.physics_error, None);
    assert!(summary.ticks_in_contact > 100);
    assert!(summary.max_jump_n <= 1e-2, "{}", summary.max_jump_n);
    assert!(
        jump <= 1.5 * reference_jump,
        "{jump:.3e} vs {reference_jump:.3e}"
    );
    assert!(summary.max_force_n > quasi_static.max_force_n);
    let up = a
        .lines()
        .skip(1)
        .filter(|l| l.ends_with(",1,ok"))
        .all(|l| l.split(',').nth(3).and_then(|z| z.parse::<f64>().ok()) >= Some(0.0));
    assert!(up, "the tissue pushes the probe up");
}

/// A NaN reaching the dynamic loop faults it with zero force, latched.
#[test]
fn dynamic_non_finite_input_faults_with_zero_force() {
    let scene = Scene::built_in_dynamic();
    let text = "t,tool,x,y,z\n0,0,0.06,0.06,0.07\n0.002,0,0.06,0.06,0.059\n0.004,0,NaN,0.06,0.059\n0.006,0,0.06,0.06,0.058\n";
    let (trajectory, _) =
        Trajectory::from_csv_str_unchecked(text, "nan.csv", 1).expect("lenient read");
    let (csv, summary) = run(&scene, &trajectory);
    let first = csv
        .lines()
        .skip(1)
        .position(|l| l.contains("faulted"))
        .expect("a fault");
    assert_eq!(summary.faulted, summary.ticks - first, "latched");
    assert!(csv.lines().skip(1 + first).all(|l| l.contains(",0,0,0,")));
}

/// A slide of 3 cm across the top of the dynamic block (the contact point
/// walks across triangles of the re-binned, deforming surface): contact
/// through the slide, no clamp or fault, and with `--vtk` one frame per
/// physics update (100 Hz) plus the `.pvd` collection, each frame a
/// deformed field. Sliding onto the next triangle changes the held set at
/// the next update, and that correction is spread over the following
/// period: the largest tick-to-tick change stays below 30 mN (measured
/// 22.4 mN) against a force of about 0.6 N.
#[test]
fn dynamic_slide_crosses_triangles_and_writes_frames() {
    let scene = Scene::built_in_dynamic();
    let trajectory = Slide::default().trajectory().expect("slide");
    let dir = std::env::temp_dir().join(format!("palpate-dynamic-slide-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("vtk dir");
    let mut out = Vec::new();
    let summary = run_session(&scene, &trajectory, &mut out, Some(&dir)).expect("session");
    println!("{summary:?}");
    assert_eq!((summary.clamped, summary.faulted), (0, 0));
    assert_eq!(summary.physics_error, None);
    assert!(summary.ticks_in_contact * 2 > summary.ticks, "{summary:?}");
    assert!(summary.max_jump_n < 0.03, "{}", summary.max_jump_n);
    assert_eq!(summary.frames, summary.ticks / 10);
    assert!(dir.join("session.pvd").is_file());
    let last = std::fs::read_to_string(dir.join(format!("frame_{:06}.vtk", summary.frames - 1)))
        .expect("frame");
    assert!(
        last.contains("displacement") || last.contains("POINT_DATA"),
        "a field"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// A dynamic scene runs with every elastic law the scene file offers
/// (linear, St Venant-Kirchhoff per tet and in Picinbono's tensor form,
/// with the incompressibility penalty, co-rotational, neo-Hookean), on a
/// coarse block: the poke makes
/// contact, pushes the probe out, and no physics update fails. The two St
/// Venant-Kirchhoff forms compute the same forces, so their peaks agree to
/// f32 rounding (measured 9e-8 relative; bound 1e-5).
#[test]
fn dynamic_sessions_run_with_every_law() {
    use palpate::scene::{DynamicSpec, MeshSource, ModelSpec};
    use palpate_kernel::tensor_mass::{ElasticLaw, StvkForm};
    let base = Scene::built_in_dynamic();
    let ModelSpec::Dynamic(spec) = base.model else {
        panic!("built-in-dynamic is dynamic");
    };
    let laws = [
        (ElasticLaw::Linear, None),
        (ElasticLaw::StVenantKirchhoff(StvkForm::PerTet), None),
        (ElasticLaw::StVenantKirchhoff(StvkForm::Tensors), None),
        (ElasticLaw::StVenantKirchhoff(StvkForm::PerTet), Some(0.05)),
        (ElasticLaw::Corotational, None),
        (ElasticLaw::NeoHookean, None),
    ];
    let trajectory = Poke::default().trajectory().expect("poke");
    let mut peaks = Vec::new();
    for (law, incompressibility_n) in laws {
        let mut scene = base.clone();
        scene.mesh = MeshSource::GeneratedBox {
            size_m: [0.12, 0.12, 0.06],
            cells: [6, 6, 3],
        };
        scene.model = ModelSpec::Dynamic(DynamicSpec {
            law,
            incompressibility_n,
            ..spec
        });
        let (_, summary) = run(&scene, &trajectory);
        println!("{law:?} {incompressibility_n:?}: {summary:?}");
        assert_eq!(summary.physics_error, None, "{law:?}");
        assert_eq!(summary.faulted, 0, "{law:?}");
        assert!(summary.ticks_in_contact > 100, "{law:?}");
        assert!(summary.max_force_n > 0.05, "{law:?}");
        peaks.push(summary.max_force_n);
    }
    let forms = (peaks[1] - peaks[2]).abs() / peaks[1];
    assert!(forms < 1e-5, "per tet {} vs tensors {}", peaks[1], peaks[2]);
}

/// Tool samples `(t, position)`, s and m.
type Samples = Vec<(f64, [f64; 3])>;

/// A tool deeper than the penetration test looks (its centre 5 mm below the
/// block's top, 2.5 radii), reached without the sweep seeing it cross the
/// surface, on the built-in block with both models: the first sample
/// there; a first sample far beside the block (at x = 1 m, beyond the
/// grid) then there; and a fast sideways entry (3 cm inside the side face x = 0 in
/// one tick, beyond a grid cell from the face). Each run's ticks with the
/// tool inside are reported `tool-inside` (never a silent `ok` with no
/// contact and zero force), with zero force, until the tool comes back up
/// to 1 mm below the top, where the penetration test finds it: a contact,
/// pushing the tool out (+z).
#[test]
fn a_tool_deeper_than_its_radius_is_reported_inside() {
    // (t, x, y, z) samples: sample-and-hold between them; the tool rises to
    // 1 mm below the top from t = 0.3 s to 0.35 s.
    let deep = [0.06, 0.06, 0.055];
    let cases: [(&str, Samples); 3] = [
        ("first sample inside", vec![(0.0, deep)]),
        (
            "after a far sample",
            vec![(0.0, [1.0, 0.06, 0.055]), (0.001, deep)],
        ),
        (
            "fast sideways entry",
            vec![(0.0, [-0.02, 0.06, 0.055]), (0.001, [0.03, 0.06, 0.055])],
        ),
    ];
    for scene in [Scene::built_in(), Scene::built_in_dynamic()] {
        for (name, samples) in &cases {
            let at = samples.last().map(|(_, p)| *p).expect("samples");
            let mut text = String::from("t,tool,x,y,z\n");
            for (t, [x, y, z]) in samples {
                text += &format!("{t},0,{x},{y},{z}\n");
            }
            text += &format!("0.3,0,{},{},{}\n", at[0], at[1], at[2]);
            text += &format!("0.35,0,{},{},0.059\n", at[0], at[1]);
            text += &format!("0.4,0,{},{},0.059\n", at[0], at[1]);
            let (csv, summary) = run(&scene, &traj(&text, 1));
            let rows: Vec<Vec<&str>> = csv
                .lines()
                .skip(1)
                .map(|l| l.split(',').collect())
                .collect();
            let label = format!("{}: {name}", scene.source);
            println!("{label}: {summary:?}");
            // Every tick from the one at the deep point to t = 0.3 s.
            let first = samples.len() - 1;
            for (k, r) in rows.iter().enumerate().take(300).skip(first) {
                assert_eq!(r[5], "tool-inside", "{label}: tick {k}: {r:?}");
                assert_eq!(r[4], "0", "{label}: tick {k}");
                let f: f64 = r[3].parse().expect("fz");
                assert_eq!(f, 0.0, "{label}: tick {k}");
            }
            assert!(summary.tool_inside >= 300 - first, "{label}");
            let last = rows.last().expect("rows");
            assert_eq!(last[4], "1", "{label}: found again near the top: {last:?}");
            assert_ne!(last[5], "tool-inside", "{label}");
            let fz: f64 = last[3].parse().expect("fz");
            assert!(fz > 0.0, "{label}: pushes out: {last:?}");
        }
    }
}
