//! Whether a dynamic scene's time step is stable on its mesh
//! (`palpate::session::stability`): an unstable `dt_s` refused at load with
//! the limit and a `dt_s` that works, the estimated limit against the
//! bisection and against the modal update matrices, and the refusals'
//! messages.

use std::time::Instant;

use palpate::fem::material::Material;
use palpate::mesh::generate::{box_mesh, cylinder_mesh};
use palpate::mesh::{MeshReport, TetMesh};
use palpate::scene::{ModelSpec, Scene};
use palpate::session::stability::{STABLE_STEP_SAFETY, check_stable_step};
use palpate::table::build::BuildOptions;
use palpate::table::file::Precision;
use palpate::tensor_mass::stability::{critical_dt_of_mesh, integrator_limit, stable_step_limit};
use palpate_kernel::tensor_mass::Integrator;
use palpate_tests::scene;

/// A dynamic scene on the mesh the test passes (the `mesh` file is not read), its base
/// `z = 0` fixed, E = 3 kPa, ν = 0.45, 1000 kg/m³, with `model` keys added.
fn dynamic_scene(model: &str) -> Scene {
    scene(&format!(
        "mesh = \"given.msh\"\nfix = [\"z<1e-9\"]\n[material]\nyoung_pa = 3000\n\
         poisson = 0.45\ndensity_kg_m3 = 1000\n[model]\nkind = \"dynamic\"\n{model}"
    ))
}

fn with_dt(scene: &Scene, dt_s: f64) -> Scene {
    let mut scene = scene.clone();
    if let ModelSpec::Dynamic(d) = &mut scene.model {
        d.dt_s = dt_s;
    }
    scene.validate().expect("a valid dt_s");
    scene
}

fn refusal(scene: &Scene, mesh: &TetMesh) -> String {
    match check_stable_step(scene, mesh, &MeshReport::default()) {
        Ok(step) => panic!("expected a refusal, got {step:?}"),
        Err(e) => {
            let msg = format!("{e:#}");
            assert!(!msg.contains('\n'), "one line: {msg}");
            msg
        }
    }
}

/// A user's case: a finely meshed cylinder (6144 tets, 7.6 cm high, radius 1.52 cm, E =
/// 3 kPa, ν = 0.45, symplectic Euler) at dt_s = 0.5 ms faulted on the first press; its limit
/// is 0.458 ms. Refused at load, with the limit and a dt_s that validates and passes.
#[test]
fn unstable_dt_on_a_fine_cylinder_is_refused_at_load() {
    let mesh = cylinder_mesh(0.076, 4, 16);
    assert_eq!(mesh.tets.len(), 6144);
    let scene = dynamic_scene("integrator = \"symplectic\"\ndt_s = 0.0005\ndamping_per_s = 2\n");
    let started = Instant::now();
    let msg = refusal(&scene, &mesh);
    println!("check on {} tets: {:?}", mesh.tets.len(), started.elapsed());
    println!("{msg}");
    assert_eq!(
        msg,
        "scene.toml: [model] dt_s = 0.0005: above the largest stable step of symplectic Euler \
         on this mesh, 0.000458 s (4/(c + sqrt(c^2 + 4 omega_max^2)), symplectic Euler's \
         bound with damping c (2/omega_max undamped); omega_max = 4365 rad/s, c = 2 1/s); use \
         dt_s <= 0.000435 (e.g. physics_every = 1 at 1000 Hz with dt_s = 0.000333333333333, \
         3 steps per physics update) or a coarser mesh"
    );

    // The suggested step validates and passes; so does any step well below the limit.
    let suggested = with_dt(&scene, 0.000333333333333);
    let step = check_stable_step(&suggested, &mesh, &MeshReport::default())
        .unwrap()
        .unwrap();
    assert!((step.limit_dt_s - 0.000458).abs() < 0.0000005, "{step:?}");
    assert!(step.rule.contains("symplectic Euler"));
    let quarter = with_dt(&scene, 0.00025);
    assert!(
        check_stable_step(&quarter, &mesh, &MeshReport::default())
            .unwrap()
            .is_some()
    );
    // Between the margin and the limit: refused, saying so.
    let mut close = scene.clone();
    close.rates.physics_every = 4;
    let close = with_dt(&close, 0.004 / 9.0);
    let msg = refusal(&close, &mesh);
    assert!(
        msg.starts_with(
            "scene.toml: [model] dt_s = 0.00044444444444444447: above 0.95 of the largest \
             stable step (STABLE_STEP_SAFETY) of symplectic Euler on this mesh, 0.000458 s"
        ) && msg.ends_with(
            "use dt_s <= 0.000435 (e.g. physics_every = 4 at 1000 Hz with dt_s = 0.0004, 10 \
             steps per physics update) or a coarser mesh"
        ),
        "{msg}"
    );
}

/// The estimate against the bisection of `dynamic critical-dt` on a small box (64 vertices,
/// fast to bisect): at most the measured step, and within 10 % of it (the margin
/// [`STABLE_STEP_SAFETY`] is 5 %; an estimate 10 % off would make it meaningless).
///
/// "At most" to 1e-5: the estimate is the exact modal limit of an `ω_max` from below, so it
/// is the true limit to the Lanczos tolerance (1e-10), but the bisection's finite trial
/// (2000 steps, energy below 1e6 times its start) is itself off by about 1e-6 at the limit:
/// undamped, symplectic Euler's modified energy swings by `1/(1 − (ωΔt/2)²)`, which passes
/// 1e6 within a few 1e-7 below `2/ω` (measured 6.5e-7 below here); with damping, or for RK4,
/// an unstable mode grows slowly just past the limit and the trial passes it (ratio 0.9995
/// for RK4). The check's bound, 0.95 of the estimate, stays below the measured step.
#[test]
fn stable_step_limit_matches_the_bisection_on_a_small_box() {
    let mesh = box_mesh([3, 3, 3], [0.03; 3]);
    let options = BuildOptions::tensor_mass(
        Material::new(3000.0, 0.45).unwrap(),
        1000.0,
        vec!["z<1e-9".parse().unwrap()],
        Precision::F64,
    );
    let report = MeshReport::default();
    let tolerance = 1e-5;
    for (integrator, damping_per_s) in [
        (Integrator::SymplecticEuler, 0.0),
        (Integrator::SymplecticEuler, 30.0),
        (Integrator::CentralDifference, 30.0),
        (Integrator::Rk4, 30.0),
    ] {
        let estimate =
            stable_step_limit(&mesh, &report, &options, damping_per_s, integrator).unwrap();
        let measured =
            critical_dt_of_mesh(&mesh, &report, &options, damping_per_s, integrator).unwrap();
        let ratio = estimate.limit_dt_s / measured.critical_dt;
        println!(
            "{} c = {damping_per_s}: estimate {:.7e} s (omega_max {:.6} rad/s), bisection \
             {:.7e} s (omega_max {:.6} rad/s): ratio {ratio:.7}",
            integrator.name(),
            estimate.limit_dt_s,
            estimate.omega_max,
            measured.critical_dt,
            measured.omega_max
        );
        assert!(ratio <= 1.0 + tolerance, "{integrator:?}: {ratio}");
        assert!(ratio >= 0.9, "{integrator:?}: {ratio}");
        // Lanczos against the bisection's 500 power iterations (from the same start).
        let omega_error = (estimate.omega_max / measured.omega_max - 1.0).abs();
        assert!(omega_error <= 1e-6, "{omega_error}");
        assert!(STABLE_STEP_SAFETY * estimate.limit_dt_s < measured.critical_dt);
    }
    // Explicit Euler: the asymptotic limit min(c/ω², 2/c) is far below the finite trial's
    // (which passes steps on which the energy grows by under 1e6 in 2000 steps).
    let estimate =
        stable_step_limit(&mesh, &report, &options, 30.0, Integrator::ExplicitEuler).unwrap();
    let measured =
        critical_dt_of_mesh(&mesh, &report, &options, 30.0, Integrator::ExplicitEuler).unwrap();
    println!(
        "euler c = 30: estimate {:.7e} s, bisection {:.7e} s",
        estimate.limit_dt_s, measured.critical_dt
    );
    let omega = estimate.omega_max;
    assert_eq!(estimate.limit_dt_s, 30.0 / (omega * omega));
    assert!(estimate.limit_dt_s < measured.critical_dt);
}

/// Each rule against the update matrix of the modal equation `ü = −c u̇ − ω² u` in the
/// kernel's schemes (palpate_kernel::tensor_mass::Integrator), built by stepping the unit
/// states, over modes `ω' ∈ (0, ω]`: every mode stable at 0.999 of the limit, some mode
/// unstable at 1.001 of it, by the Jury conditions (a real 2×2 matrix has both eigenvalues
/// in the closed unit disk iff `|det| ≤ 1` and `|tr| ≤ 1 + det`; no square root, so no
/// rounding blow-up near critical damping).
#[test]
fn integrator_limits_bound_the_modal_update_matrices() {
    type State = [f64; 2];
    // One step of each scheme on (u, v), or (u, u⁻) for the central difference.
    let step = |integrator: Integrator, h: f64, w: f64, c: f64, y: State| -> State {
        let accel = |u: f64, v: f64| -c * v - w * w * u;
        match integrator {
            Integrator::ExplicitEuler => [y[0] + h * y[1], y[1] + h * accel(y[0], y[1])],
            Integrator::SymplecticEuler => {
                let v = y[1] + h * accel(y[0], y[1]);
                [y[0] + h * v, v]
            }
            Integrator::CentralDifference => {
                let a = 0.5 * c * h;
                let next = (h * h * (-w * w * y[0]) + 2.0 * y[0] - y[1] * (1.0 - a)) / (1.0 + a);
                [next, y[0]]
            }
            Integrator::Rk4 => {
                let f = |y: State| [y[1], accel(y[0], y[1])];
                let add = |y: State, k: State, s: f64| [y[0] + s * k[0], y[1] + s * k[1]];
                let k1 = f(y);
                let k2 = f(add(y, k1, h / 2.0));
                let k3 = f(add(y, k2, h / 2.0));
                let k4 = f(add(y, k3, h));
                let sum = |i: usize| k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i];
                [y[0] + h / 6.0 * sum(0), y[1] + h / 6.0 * sum(1)]
            }
        }
    };
    // How far the mode is from the Jury conditions (> 0: unstable).
    let excess = |integrator: Integrator, h: f64, w: f64, c: f64| -> f64 {
        let a = step(integrator, h, w, c, [1.0, 0.0]);
        let b = step(integrator, h, w, c, [0.0, 1.0]);
        let (trace, det) = (a[0] + b[1], a[0] * b[1] - b[0] * a[1]);
        (det.abs() - 1.0).max(trace.abs() - 1.0 - det)
    };
    let omega = 1000.0;
    for integrator in Integrator::ALL {
        for c in [0.0, 2.0, 30.0, 500.0, 1800.0, 5000.0] {
            let (limit, rule) = integrator_limit(integrator, omega, c);
            if limit == 0.0 {
                assert_eq!((integrator, c), (Integrator::ExplicitEuler, 0.0));
                assert!(excess(integrator, 1e-9, omega, c) > 0.0);
                continue;
            }
            let modes: Vec<f64> = (1..=4096)
                .map(|k| omega * k as f64 / 4096.0)
                .chain([omega * 1e-6])
                .collect();
            let worst = |h: f64| {
                modes
                    .iter()
                    .map(|&w| excess(integrator, h, w, c))
                    .fold(f64::NEG_INFINITY, f64::max)
            };
            let (below, above) = (worst(0.999 * limit), worst(1.001 * limit));
            println!(
                "{integrator:?} c = {c}: limit {limit:e} ({rule}); excess {below:e} / {above:e}"
            );
            assert!(below <= 1e-12, "{integrator:?} c = {c}: {below}");
            assert!(above > 0.0, "{integrator:?} c = {c}: {above}");
        }
    }
}

/// The built-in dynamic scene passes with room; the pre-computed model has no limit.
#[test]
fn built_in_scenes_pass() {
    let scene = Scene::built_in_dynamic();
    let (mesh, report) = scene.load_mesh().unwrap();
    let step = check_stable_step(&scene, &mesh, &report).unwrap().unwrap();
    println!("built-in dynamic: {step:?}");
    assert!(step.limit_dt_s > 2.0 * 0.0005, "{step:?}");
    let (mesh, report) = Scene::built_in().load_mesh().unwrap();
    assert!(
        check_stable_step(&Scene::built_in(), &mesh, &report)
            .unwrap()
            .is_none()
    );
}

/// Explicit Euler: no stable step undamped; with damping a limit so short that no whole
/// number of steps up to MAX_SUBSTEPS fits a long physics period.
#[test]
fn explicit_euler_refusals_say_what_to_change() {
    let mesh = box_mesh([3, 3, 3], [0.03; 3]);
    let undamped = dynamic_scene("integrator = \"euler\"\ndamping_per_s = 0\n");
    assert_eq!(
        refusal(&undamped, &mesh),
        "scene.toml: [model] dt_s = 0.001: explicit Euler is unstable at every step without \
         damping (it amplifies every mode by sqrt(1 + (omega dt)^2) per step; omega_max = \
         1050 rad/s); give damping_per_s > 0, or integrator = \"symplectic\" or \"central\""
    );
    let mut long = dynamic_scene("integrator = \"euler\"\ndamping_per_s = 2\ndt_s = 0.001\n");
    long.rates.physics_every = 100;
    long.validate().unwrap();
    let msg = refusal(&long, &mesh);
    assert!(
        msg.ends_with(
            "use dt_s <= 0.00000172, which needs more than 10000 steps per physics update of \
             0.1 s (MAX_SUBSTEPS): lower physics_every, or a coarser mesh"
        ),
        "{msg}"
    );
}

/// The steps in a refusal are decimals of a few significant digits, trailing zeros trimmed: the
/// limit rounded to 3 (0.0018771 s as 0.00188), the bound `dt_s <=` rounded down to 3 (never
/// above [`STABLE_STEP_SAFETY`] of the limit), the suggested `dt_s` rounded down to 12 (0.01/6 s
/// as 0.00166666666666), each checked against the limit that `check_stable_step` returns for a
/// stable step.
#[test]
fn refusals_print_steps_to_significant_digits() {
    let mesh = box_mesh([3, 3, 3], [0.03; 3]);
    // Model keys, physics_every, then the printed limit, bound and suggested dt_s.
    let cases = [
        (
            "integrator = \"symplectic\"\ndamping_per_s = 30\ndt_s = 0.01\n",
            10,
            ["0.00188", "0.00178", "0.00166666666666"],
        ),
        (
            "integrator = \"central\"\ndamping_per_s = 2\ndt_s = 0.003\n",
            3,
            ["0.0019", "0.0018", "0.0015"],
        ),
        (
            "integrator = \"rk4\"\ndamping_per_s = 2\ndt_s = 0.008\n",
            8,
            ["0.00269", "0.00256", "0.002"],
        ),
        (
            "integrator = \"euler\"\ndamping_per_s = 30\ndt_s = 0.001\n",
            1,
            ["0.0000272", "0.0000258", "0.000025641025641"],
        ),
    ];
    for (model, physics_every, expected) in cases {
        let scene = dynamic_scene(&format!(
            "{model}[rates]\nphysics_every = {physics_every}\n"
        ));
        let msg = refusal(&scene, &mesh);
        let field = |before: &str, after: &str| -> String {
            let (_, rest) = msg.split_once(before).expect(before);
            rest.split_once(after).expect(after).0.to_owned()
        };
        let printed = [
            field("on this mesh, ", " s ("),
            field("use dt_s <= ", " ("),
            field("with dt_s = ", ", "),
        ];
        assert_eq!(printed, expected, "{msg}");
        let [limit, bound, suggested] = printed.map(|text| text.parse::<f64>().expect("a number"));
        let stable = with_dt(&scene, scene.physics_period_s() / 1000.0);
        let step = check_stable_step(&stable, &mesh, &MeshReport::default())
            .unwrap()
            .unwrap();
        let digits = |x: f64, n: usize| format!("{x:.*e}", n - 1).parse::<f64>().unwrap();
        assert_eq!(limit, digits(step.limit_dt_s, 3), "{msg}");
        let max = STABLE_STEP_SAFETY * step.limit_dt_s;
        let unit = 10f64.powi(max.log10().floor() as i32 - 2);
        assert!(bound <= max && max - bound < unit, "{msg}");
        assert_eq!(bound, digits(bound, 3), "{msg}");
        assert!(suggested <= max, "{msg}");
        assert_eq!(suggested, digits(suggested, 12), "{msg}");
        let suggested = with_dt(&scene, suggested);
        assert!(
            check_stable_step(&suggested, &mesh, &MeshReport::default())
                .unwrap()
                .is_some()
        );
    }
}
