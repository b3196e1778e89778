//! The haptic loop over the dynamic tensor-mass model
//! (`palpate_kernel::tensor_mass::{DeformingSurface, DynamicTissue}`): the re-binned
//! surface against moved geometry, the extrapolated force against the
//! model's own force pass, the held force at rest against the pre-computed
//! model's static solve, continuity across physics updates, the
//! divergence fault, and robustness to any tool input (proptest).

use nalgebra::Vector3;
use palpate::fem::material::Material;
use palpate::mesh::MeshReport;
use palpate::mesh::generate::box_mesh;
use palpate::table::build::{BuildOptions, build};
use palpate::table::file::Precision;
use palpate::table::load::TableFile;
use palpate::tensor_mass::run::f64_table;
use palpate::tensor_mass::{OwnedState, OwnedSurface};
use palpate_kernel::contact::{ContactWork, Supports};
use palpate_kernel::haptic::{DynamicLoop, LoopConfig};
use palpate_kernel::haptic::{OutputStatus, SafetyFault, SafetyLimits};
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::tensor_mass::DeformingSurface;
use palpate_kernel::tensor_mass::{DynamicParams, Integrator, TensorMassModel};
use palpate_kernel::tensor_mass::{DynamicTissue, Extrapolation, PhysicsConfig};
use proptest::prelude::*;

/// A 6 × 6 × 3 cm block of 648 tets (1 cm cells), bottom fixed, E = 3 kPa,
/// ν = 0.45, ρ = 1000 kg/m³ (soft tissue).
const SIZE_M: [f64; 3] = [0.06, 0.06, 0.03];
const RADIUS_M: f64 = 0.002;
const TICK_S: f64 = 1e-3;

fn block_table() -> TableFile {
    let mesh = box_mesh([6, 6, 3], SIZE_M);
    let options = BuildOptions::tensor_mass(
        Material::new(3000.0, 0.45).expect("material"),
        1000.0,
        vec!["z<0.001".parse().expect("predicate")],
        Precision::F64,
    );
    f64_table(&mesh, &MeshReport::default(), &options).expect("table")
}

fn params(max_displacement_m: f64) -> DynamicParams<f64> {
    DynamicParams::linear(30.0, max_displacement_m)
}

fn loop_config() -> LoopConfig<f64> {
    palpate_tests::unclamped_loop_config(RADIUS_M, TICK_S)
}

/// Symplectic Euler in steps of `dt_s`, `substeps` per physics update.
fn symplectic(extrapolation: Extrapolation, dt_s: f64, substeps: u32) -> PhysicsConfig<f64> {
    PhysicsConfig {
        extrapolation,
        ..PhysicsConfig::new(Integrator::SymplecticEuler, dt_s, substeps)
    }
}

/// Runs `body` on a one-point loop over the block (f64) with `physics`
/// and divergence beyond `max_displacement_m`.
fn with_loop<R>(
    physics: PhysicsConfig<f64>,
    max_displacement_m: f64,
    body: impl FnOnce(&mut DynamicLoop<'_, '_, f64, 1, 1>) -> R,
) -> R {
    let file = block_table();
    let table = TensorMassTable::<f64>::load(file.bytes()).expect("table");
    let mut state = OwnedState::for_table(&table);
    let params = params(max_displacement_m);
    let model = TensorMassModel::new(table, state.buffers(), params).expect("model");
    let mut owned = OwnedSurface::for_model(&model);
    let (buffers, forces) = owned.buffers();
    let tissue = DynamicTissue::<f64, 1>::new(model, buffers, forces, physics).expect("tissue");
    let mut haptic = DynamicLoop::<f64, 1, 1>::new(tissue, loop_config()).expect("loop");
    body(&mut haptic)
}

/// The tool above the block's top centre, `depth_m` below first touch.
fn tool_at(depth_m: f64) -> [Vector3<f64>; 1] {
    // Off the grid lines, so the contact is inside one triangle.
    [Vector3::new(0.0313, 0.0291, SIZE_M[2] + RADIUS_M - depth_m)]
}

/// Re-binning follows the body: after a rigid lift of 5 cm the falling
/// sphere touches the top face at z = 8 cm (contact point to 1e-12 m), and
/// after a 3× stretch in x (longest edge now 3 cm, beyond the rest grid)
/// a sphere falling at x = 15 cm, far outside the rest box, still hits.
#[test]
fn rebinned_surface_follows_the_deformation() {
    let file = block_table();
    let table = TensorMassTable::<f64>::load(file.bytes()).expect("table");
    let mut state = OwnedState::for_table(&table);
    let model = TensorMassModel::new(table, state.buffers(), params(f64::INFINITY)).expect("model");
    let mut owned = OwnedSurface::for_model(&model);
    let (buffers, _) = owned.buffers();
    let mut surface = DeformingSurface::new(&model, buffers).expect("surface");
    let rest = table.rest_positions();
    let mut work = ContactWork::default();
    // One tick's motion, 1 mm each side of touching a top at `top_m`.
    let fall =
        |surface: &DeformingSurface<'_, '_, f64>, x: f64, top_m: f64, work: &mut ContactWork| {
            let geometry = surface.geometry(Supports::TensorMass(&table));
            let contact = geometry.detect(
                0,
                Some(&Vector3::new(x, 0.0291, top_m + RADIUS_M + 1e-3)),
                &Vector3::new(x, 0.0291, top_m + RADIUS_M - 1e-3),
                RADIUS_M,
                work,
            );
            contact.map(|c| c.point_m)
        };
    let lifted: Vec<[f64; 3]> = rest.iter().map(|_| [0.0, 0.0, 0.05]).collect();
    surface.rebin(&lifted).expect("finite");
    assert!(
        fall(&surface, 0.0313, SIZE_M[2], &mut work).is_none(),
        "rest top is gone"
    );
    let hit = fall(&surface, 0.0313, 0.08, &mut work).expect("hit on the lifted top");
    assert!((hit.z - 0.08).abs() < 1e-12, "lifted top at {}", hit.z);
    let stretched: Vec<[f64; 3]> = rest.iter().map(|p| [2.0 * p[0], 0.0, 0.0]).collect();
    surface.rebin(&stretched).expect("finite");
    let hit = fall(&surface, 0.15, SIZE_M[2], &mut work).expect("hit on the stretched top");
    assert!((hit.z - SIZE_M[2]).abs() < 1e-12 && (hit.x - 0.15).abs() < 1e-12);
    assert!(
        surface
            .geometry(Supports::TensorMass(&table))
            .index()
            .cell_m()
            >= 0.03 - 1e-12
    );
    assert!(
        fall(&surface, 0.25, SIZE_M[2], &mut work).is_none(),
        "beyond the stretched box"
    );
    let nan: Vec<[f64; 3]> = rest.iter().map(|_| [f64::NAN, 0.0, 0.0]).collect();
    assert!(surface.rebin(&nan).is_err());
}

/// Between physics updates the instantaneous extrapolation sends
/// `(n · F_update − k · gap) n` with `k = Σ s_i s_j n · K_ij n` from the
/// vertex and edge tensors and `gap` the tool's motion along the held
/// normal. For the linear law it must equal the normal part of `Σ s_i f_i`
/// from the model's own force pass (`elastic_forces_of`, assembled over
/// the CSR edges) with the held vertices moved by their shares `s_i` of
/// `gap · n`. Measured 2.6e-16 relative; bound 1e-10 (rounding).
#[test]
fn extrapolated_force_equals_the_model_force_between_updates() {
    let physics = symplectic(Extrapolation::Instantaneous, 5e-4, 2);
    with_loop(physics, 1.0, |haptic| {
        let mut last = None;
        for k in 0..=40 {
            let depth = (k as f64 - 5.0) * 1e-4; // 0.1 mm per tick, touching at k = 5
            let out = haptic.tick(&tool_at(depth));
            assert_eq!(out.status, OutputStatus::Ok, "tick {k}");
            haptic.physics_update().expect("stable");
            last = Some(out);
        }
        assert_eq!(last.expect("ran").contacts, 1);
        // The next tick presses 0.3 mm further without an update.
        let tool = tool_at(35.0e-4 + 3.0e-4);
        let out = haptic.tick(&tool);
        assert!(haptic.contacts()[0].is_some(), "in contact");
        let held = haptic.tissue().held()[0].expect("held");
        let model = haptic.tissue().model();
        // The top's rest normal, and shares solving Σ w_i u_i = d.
        assert!((held.contact.normal - Vector3::z()).norm() < 1e-12);
        let moved: f64 = held
            .shares
            .iter()
            .zip(&held.contact.weights)
            .map(|(s, w)| s * w)
            .sum();
        assert!((moved - 1.0).abs() < 1e-12, "Σ w_i s_i = {moved}");
        let normal = held.contact.normal;
        let gap = (tool[0] - held.contact.tip_m).dot(&normal);
        assert!(gap < -2e-4, "pressed further: gap {gap}");
        let mut u = model.displacements_m().expect("finite").to_vec();
        for (&v, &share) in held.contact.vertices.iter().zip(&held.shares) {
            for (a, d) in u[v.get()].iter_mut().zip((normal * (gap * share)).iter()) {
                *a += d;
            }
        }
        let mut f = vec![[0.0; 3]; u.len()];
        model.elastic_forces_of(&u, &mut f);
        let total: Vector3<f64> = held
            .contact
            .vertices
            .iter()
            .zip(&held.shares)
            .map(|(&v, &share)| Vector3::from(f[v.get()]) * share)
            .sum();
        let truth = normal * total.dot(&normal);
        let error = (out.force_n - truth).norm() / truth.norm();
        println!(
            "extrapolated {:?} N, model {:?} N, relative error {error:.2e}",
            out.force_n, truth
        );
        assert!(truth.z > 0.0, "the tissue pushes the tool up");
        assert!(error < 1e-10, "relative error {error:.3e}");
    })
}

/// Press 2 mm and hold until the damped tissue is at rest (1.5 s, physics
/// every tick): the force on the probe is then the static reaction of the
/// held vertices (weighted by their shares), which the pre-computed model (a different method: the
/// global compliance of a sparse Cholesky factorization, Cotin 1999 §3)
/// must reproduce when its three vertices are imposed at the dynamic
/// model's displacements. Measured 4e-14 relative; bound 1e-6 (the
/// slowest mode's residual after 1.5 s at 30/s damping is ~e^-22 of the
/// press, the rest is rounding).
#[test]
fn held_force_at_rest_matches_the_static_solve() {
    let physics = symplectic(Extrapolation::Secant, 5e-4, 2);
    with_loop(physics, 1.0, |haptic| {
        let mut force = Vector3::zeros();
        for k in 0..1600 {
            let depth = ((k as f64 - 5.0) * 2e-5).min(2e-3);
            let out = haptic.tick(&tool_at(depth));
            assert_eq!(out.status, OutputStatus::Ok);
            haptic.physics_update().expect("stable");
            force = out.force_n;
        }
        let held = haptic.tissue().held()[0].expect("held");
        let u = haptic.tissue().model().displacements_m().expect("finite");
        // The vertices with a share are the held ones.
        let vertices: Vec<(u32, Vector3<f64>, f64)> = held
            .contact
            .vertices
            .iter()
            .zip(&held.shares)
            .filter(|(_, s)| **s != 0.0)
            .map(|(&v, &s)| (v.as_u32(), Vector3::from(u[v.get()]), s))
            .collect();
        let mesh = box_mesh([6, 6, 3], SIZE_M);
        let reaction = palpate_tests::static_reaction(&mesh, "z<0.001", &vertices);
        let normal = held.contact.normal;
        let error = (force.norm() - reaction.dot(&normal)).abs() / force.norm();
        println!(
            "held 2 mm: dynamic {:.6e} N, static solve {:.6e} N along the normal, relative {error:.2e}",
            force.norm(),
            reaction.dot(&normal)
        );
        assert!(force.z > 0.1, "pressed: {force:?}");
        assert!(error < 1e-6, "relative error {error:.3e}");
    })
}

/// Forces of a press at 20 mm/s with a physics update every `every` ticks
/// (1 kHz ticks, 1 ms of physics per tick in 0.5 ms steps).
fn press_forces(every: usize, extrapolation: Extrapolation) -> Vec<f64> {
    let physics = symplectic(extrapolation, 5e-4, 2 * every as u32);
    with_loop(physics, 1.0, |haptic| {
        (0..300)
            .map(|k| {
                let depth = (k as f64 - 10.0) * 2e-5;
                let out = haptic.tick(&tool_at(depth));
                assert_eq!(out.status, OutputStatus::Ok);
                if (k + 1) % every == 0 {
                    haptic.physics_update().expect("stable");
                }
                out.force_n.z
            })
            .collect()
    })
}

/// Physics updates back to back, with no tick in between (a late physics
/// thread catching up): the first moves the contact onto the tool, the
/// others hold it there. Pressed 2 mm, the tool goes 1 mm deeper in one
/// tick and 50 updates follow without a tick: the held vertices (those with
/// a share) end where the first update put them (to 1e-12 m: imposed, not
/// integrated), and the force at the next tick is finite and pushes out
/// (measured 0.25 N, against 0.35 N right after the first update: the free
/// tissue settles). Imposing the tick's gap again at every update instead
/// drove a held vertex a further 9.1 mm in (measured).
#[test]
fn back_to_back_physics_updates_hold_the_contact() {
    with_loop(symplectic(Extrapolation::Secant, 5e-4, 2), 1.0, |haptic| {
        for k in 0..=20 {
            haptic.tick(&tool_at(1e-4 * f64::from(k)));
            haptic.physics_update().expect("stable while pressing");
        }
        haptic.tick(&tool_at(3e-3));
        haptic.physics_update().expect("first update");
        let held_at = |haptic: &DynamicLoop<'_, '_, f64, 1, 1>| -> Vec<[f64; 3]> {
            let held = haptic.tissue().held()[0].expect("held");
            let u = haptic.tissue().model().displacements_m().expect("finite");
            let imposed = held.contact.vertices.iter().zip(&held.shares);
            imposed
                .filter(|(_, s)| **s != 0.0)
                .map(|(v, _)| u[v.get()])
                .collect()
        };
        let first = held_at(haptic);
        assert!(!first.is_empty(), "the contact holds a vertex");
        for update in 1..50 {
            let report = haptic.physics_update();
            assert!(report.is_ok(), "update {update}: {report:?}");
        }
        let last = held_at(haptic);
        for (a, b) in first.iter().zip(&last) {
            let moved = (Vector3::from(*a) - Vector3::from(*b)).norm();
            assert!(
                moved < 1e-12,
                "a held vertex moved {moved} m: {a:?} -> {b:?}"
            );
        }
        let out = haptic.tick(&tool_at(3e-3));
        println!("force at the next tick {:.4} N", out.force_n.z);
        assert_eq!(out.status, OutputStatus::Ok);
        assert!(out.force_n.z > 0.0 && out.force_n.z < 1.0, "{out:?}");
    });
}

/// The largest tick-to-tick force change at the first tick after a
/// physics update, and at every other tick, after the contact settled.
fn update_and_other_jumps(f: &[f64], every: usize) -> (f64, f64) {
    let settled = 60;
    let (mut at_update, mut between) = (0.0f64, 0.0f64);
    for (k, w) in f.windows(2).enumerate().skip(settled) {
        let jump = (w[1] - w[0]).abs();
        if (k + 1) % every == 0 {
            at_update = at_update.max(jump);
        } else {
            between = between.max(jump);
        }
    }
    (at_update, between)
}

/// Continuity across physics updates (100 Hz physics, 1 kHz force, a press
/// at 20 mm/s). The reference is the same press with physics at 1 kHz (no
/// extrapolation at all). A zero-order hold of each update's force would
/// jump by the whole period's change at once; the instantaneous stiffness
/// overshoots between updates and drops at each (the free vertices relax);
/// the secant extrapolation's jump at an update must stay within 2× the
/// reference's largest tick-to-tick change, and below half the others'.
#[test]
fn force_is_continuous_across_physics_updates() {
    let every = 10;
    let secant = press_forces(every, Extrapolation::Secant);
    let instantaneous = press_forces(every, Extrapolation::Instantaneous);
    let reference = press_forces(1, Extrapolation::Secant);
    let (secant_jump, secant_between) = update_and_other_jumps(&secant, every);
    let (instant_jump, _) = update_and_other_jumps(&instantaneous, every);
    let (reference_jump, _) = update_and_other_jumps(&reference, 1);
    // The hold: the force just after each update, held for the period.
    let hold = (60..secant.len() - every)
        .filter(|k| (k + 1) % every == 0)
        .map(|k| (secant[k + every] - secant[k]).abs())
        .fold(0.0, f64::max);
    let end = |f: &[f64]| f[f.len() - 1];
    println!(
        "press 20 mm/s, final force: secant {:.4} N, instantaneous {:.4} N, 1 kHz physics {:.4} N\n\
         largest jump at an update: secant {secant_jump:.3e} N (between updates {secant_between:.3e} N), \
         instantaneous {instant_jump:.3e} N, zero-order hold {hold:.3e} N; \
         1 kHz physics, any tick: {reference_jump:.3e} N",
        end(&secant),
        end(&instantaneous),
        end(&reference),
    );
    assert!(end(&secant) > 0.01, "pressed");
    assert!((end(&secant) - end(&reference)).abs() < 0.1 * end(&reference));
    assert!(
        secant_jump <= 2.0 * reference_jump,
        "{secant_jump:.3e} vs {reference_jump:.3e}"
    );
    assert!(secant_jump <= 0.5 * hold.min(instant_jump));
}

/// A physics step far above the critical step diverges; the update reports
/// it, the next tick latches a model fault with zero force, and reset
/// brings the tissue back to rest with the force at zero.
#[test]
fn divergence_faults_the_loop_until_reset() {
    let physics = symplectic(Extrapolation::Secant, 0.05, 1);
    with_loop(physics, 0.01, |haptic| {
        let mut failed = None;
        for k in 0..200 {
            let out = haptic.tick(&tool_at((k as f64 - 2.0) * 1e-4));
            if let OutputStatus::Faulted(reason) = out.status {
                assert_eq!(reason, SafetyFault::ModelFault);
                assert_eq!(out.force_n, Vector3::zeros());
                failed = Some(k);
                break;
            }
            assert!(out.force_n.norm().is_finite());
            let _ = haptic.physics_update();
        }
        let k = failed.expect("diverged within 200 updates");
        assert!(haptic.tissue().fault().is_some(), "fault at tick {k}");
        haptic.reset();
        let out = haptic.tick(&tool_at(-1e-3));
        assert_eq!(
            (out.status, out.force_n),
            (OutputStatus::Ok, Vector3::zeros())
        );
        assert!(haptic.tissue().fault().is_none());
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]
    /// Any sequence of tool positions for two tool points, including NaN,
    /// infinities and huge jumps, with a physics update after each tick
    /// (f32, the firmware precision), anywhere around the block (top,
    /// sides, next to the clamped base): every force is finite and within
    /// the clamp, so is the force the tissue requests before the clamp, a
    /// non-finite input is a fault with zero force, and the model never
    /// diverges silently (a failed update faults the next tick).
    #[test]
    fn any_input_gives_a_bounded_finite_force(
        steps in prop::collection::vec(
            (
                prop_oneof![
                    // Over the whole block: top, sides, next to the clamped base.
                    8 => (-0.005..0.065f64, -0.005..0.065f64, 0.0..0.035f64).prop_map(|(x, y, z)| [x, y, z]),
                    1 => Just([f64::NAN, 0.03, 0.03]),
                    1 => Just([0.03, f64::INFINITY, 0.03]),
                    1 => (-1e9..1e9f64, -1e9..1e9f64, -1e9..1e9f64).prop_map(|(x, y, z)| [x, y, z]),
                ],
                (-0.005..0.065f64, -0.005..0.065f64, 0.0..0.035f64).prop_map(|(x, y, z)| [x, y, z]),
            ),
            1..40,
        )
    ) {
        let mesh = box_mesh([6, 6, 3], SIZE_M);
        let options = BuildOptions::tensor_mass(
            Material::new(3000.0, 0.45).expect("material"),
            1000.0,
            vec!["z<0.001".parse().expect("predicate")],
            Precision::F32,
        );
        let bytes = build(&mesh, &MeshReport::default(), &options).expect("table").bytes;
        let file = TableFile::from_bytes(&bytes);
        let table = TensorMassTable::<f32>::load(file.bytes()).expect("table");
        let mut state = OwnedState::for_table(&table).without_split_terms();
        let params = DynamicParams::linear(30.0f32, 0.1);
        let model = TensorMassModel::new(table, state.buffers(), params).expect("model");
        let mut owned = OwnedSurface::for_model(&model);
        let (buffers, forces) = owned.buffers();
        let physics = PhysicsConfig::new(Integrator::SymplecticEuler, 5e-4f32, 2);
        let tissue = DynamicTissue::<f32, 2>::new(model, buffers, forces, physics).expect("tissue");
        let limits = SafetyLimits { max_force_n: 4.0f32, max_slew_n_per_s: 2000.0 };
        let config = LoopConfig { radius_m: 0.002f32, dt_s: 1e-3, limits };
        let mut haptic = DynamicLoop::<f32, 2, 2>::new(tissue, config).expect("loop");
        for (a, b) in steps {
            let tool = [a, b].map(|p| Vector3::new(p[0] as f32, p[1] as f32, p[2] as f32));
            let out = haptic.tick(&tool);
            prop_assert!(out.force_n.iter().all(|x| x.is_finite()));
            prop_assert!(out.force_n.norm() <= 4.0 * (1.0 + 1e-6));
            // What the tissue itself requests, before the clamp: finite,
            // shares bounded, and below 100 N (the 2 mm press at rest gives
            // 0.19 N; scaled linearly to the block's whole 3.5 cm, 3.3 N).
            for h in haptic.tissue().held().iter().flatten() {
                prop_assert!(h.contact.force_n.iter().all(|x| x.is_finite()));
                prop_assert!(h.shares.iter().all(|s| s.abs() <= 3.0 + 1e-3));
                prop_assert!(h.contact.force_n.norm() < 100.0, "{:?}", h);
            }
            if !tool.iter().all(|p| p.iter().all(|x| x.is_finite())) {
                prop_assert_eq!(out.status, OutputStatus::Faulted(SafetyFault::NonFiniteInput));
                prop_assert_eq!(out.force_n, Vector3::zeros());
                haptic.reset();
            } else if haptic.physics_update().is_err() {
                let next = haptic.tick(&tool);
                prop_assert_eq!(next.status, OutputStatus::Faulted(SafetyFault::ModelFault));
                prop_assert_eq!(next.force_n, Vector3::zeros());
                haptic.reset();
            }
        }
    }
}

/// Near a fixed vertex the minimum-norm shares `w_i / Σ w²` would grow
/// without bound (the review that found it measured 208 N for a 0.74 mm
/// press 2 mm above the clamped base). Pressing the side face 0.5 mm above
/// the base must instead be refused (`Σ w² < 1/9` over the movable
/// vertices), with every requested force finite and small; 5 mm above the
/// base the contact is held and pushes the tool out.
#[test]
fn contact_next_to_the_support_is_refused_not_amplified() {
    let side =
        |z0_m: f64, depth_m: f64| [Vector3::new(SIZE_M[0] + RADIUS_M - depth_m, 0.0291, z0_m)];
    for (z0_m, held) in [(0.0005, false), (0.005, true)] {
        with_loop(symplectic(Extrapolation::Secant, 5e-4, 2), 1.0, |haptic| {
            let (mut refused, mut in_contact, mut peak) = (0u32, 0u32, 0.0f64);
            for k in 0..60 {
                let out = haptic.tick(&side(z0_m, (k as f64 - 5.0) * 2e-5));
                haptic.physics_update().expect("stable");
                assert!(out.force_n.iter().all(|x| x.is_finite()));
                refused += u32::from(out.refused);
                in_contact += u32::from(out.contacts);
                peak = peak.max(out.force_n.norm());
                if let Some(h) = haptic.tissue().held()[0] {
                    assert!(h.shares.iter().all(|s| s.abs() <= 3.0 + 1e-9), "{h:?}");
                }
            }
            println!(
                "side press at z = {z0_m} m: refused {refused}, in contact {in_contact}, peak {peak:.4} N"
            );
            if held {
                assert!(in_contact > 40 && refused == 0 && peak > 1e-3);
            } else {
                assert!(refused > 0 && in_contact == 0 && peak == 0.0);
            }
        });
    }
}

/// A 4 cm slide across the block's top at 20 mm/s (physics at 100 Hz): the
/// held triangle changes as the contact point crosses edges (1 cm cells:
/// at least 4 distinct triangles; measured 10), the force stays on (above
/// 20 mN; measured 63 mN at its lowest), and the largest tick-to-tick
/// change stays below 10 mN (measured 7.3 mN; the corrections of the
/// changes of held triangle are spread over a period).
#[test]
fn sliding_moves_the_held_triangle_smoothly() {
    with_loop(symplectic(Extrapolation::Secant, 5e-4, 20), 1.0, |haptic| {
        let mut triangles = Vec::new();
        let mut forces = Vec::new();
        for k in 0..2600 {
            let depth = ((k as f64 - 5.0) * 2e-5).clamp(-1e-3, 2e-3);
            let x = 0.0113 + (k as f64 - 300.0).max(0.0) * 2e-5;
            let tool = [Vector3::new(x, 0.0291, SIZE_M[2] + RADIUS_M - depth)];
            let out = haptic.tick(&tool);
            assert_eq!(out.status, OutputStatus::Ok);
            if (k + 1) % 10 == 0 {
                haptic.physics_update().expect("stable");
            }
            if let Some(h) = haptic.tissue().held()[0]
                && triangles.last() != Some(&h.contact.vertices)
            {
                triangles.push(h.contact.vertices);
            }
            if k >= 300 {
                assert_eq!(out.contacts, 1, "tick {k}");
                forces.push(out.force_n);
            }
        }
        let jump = forces
            .windows(2)
            .map(|w| (w[1] - w[0]).norm())
            .fold(0.0, f64::max);
        let low = forces
            .iter()
            .map(|f| f.norm())
            .fold(f64::INFINITY, f64::min);
        println!(
            "slide 4 cm: {} held triangles, largest change {jump:.3e} N, smallest force {low:.4} N",
            triangles.len()
        );
        assert!(triangles.len() >= 4, "{triangles:?}");
        assert!(low > 0.02, "{low}");
        assert!(jump < 0.01, "{jump:.3e}");
    });
}
