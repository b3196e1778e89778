//! The surgeon's tools in the live haptic loop over the dynamic model
//! (`palpate_kernel::haptic::{ToolAction, ToolInput}`, the tissue's cuts,
//! grips and tearing, the deforming surface's exposed faces): contact
//! found again when the surface moves onto a resting tool, grasping,
//! cutting during the loop, touching the faces a cut exposes, tearing off a
//! grasped flap.

use nalgebra::Vector3;
use palpate::fem::material::Material;
use palpate::mesh::generate::box_mesh;
use palpate::mesh::{MeshReport, TetMesh};
use palpate::table::build::BuildOptions;
use palpate::table::file::Precision;
use palpate::table::load::TableFile;
use palpate::tensor_mass::run::f64_table;
use palpate::tensor_mass::{OwnedState, OwnedSurface};
use palpate_kernel::haptic::{DynamicLoop, LoopConfig, SafetyLimits};
use palpate_kernel::haptic::{ToolAction, ToolInput};
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::tensor_mass::TensorMassModel;
use palpate_kernel::tensor_mass::{DynamicParams, DynamicTissue, Integrator, PhysicsConfig};

const RADIUS_M: f64 = 0.002;
const TICK_S: f64 = 1e-3;

/// The f64 tensor-mass table of `mesh`, E = 3 kPa, ν = 0.45, ρ = 1000
/// kg/m³, vertices matching `fix` fixed.
fn table_of(mesh: &TetMesh, fix: &str) -> TableFile {
    let options = BuildOptions::tensor_mass(
        Material::new(3000.0, 0.45).expect("material"),
        1000.0,
        vec![fix.parse().expect("predicate")],
        Precision::F64,
    );
    f64_table(mesh, &MeshReport::default(), &options).expect("table")
}

fn loop_config() -> LoopConfig<f64> {
    LoopConfig {
        radius_m: RADIUS_M,
        dt_s: TICK_S,
        limits: SafetyLimits {
            max_force_n: 1e3,
            max_slew_n_per_s: 1e9,
        },
    }
}

/// Runs `body` on a `P`-point loop over `file`'s table: damping 30/s,
/// symplectic Euler, `physics` (a physics update every tick unless the body
/// says otherwise).
fn with_loop<const P: usize, R>(
    file: &TableFile,
    physics: PhysicsConfig<f64>,
    body: impl FnOnce(&mut DynamicLoop<'_, '_, f64, P, P>) -> R,
) -> R {
    let table = TensorMassTable::<f64>::load(file.bytes()).expect("table");
    let mut state = OwnedState::for_table(&table).without_split_terms();
    let params = DynamicParams::linear(30.0, 0.5);
    let model = TensorMassModel::new(table, state.buffers(), params).expect("model");
    let mut owned = OwnedSurface::for_model(&model);
    let (buffers, forces) = owned.buffers();
    let tissue = DynamicTissue::<f64, P>::new(model, buffers, forces, physics).expect("tissue");
    let mut haptic = DynamicLoop::<f64, P, P>::new(tissue, loop_config()).expect("loop");
    body(&mut haptic)
}

/// The cantilever: 0.1 × 0.02 × 0.02 m, fixed at x = 0, 1 cm cells.
fn cantilever() -> TableFile {
    table_of(&box_mesh([10, 2, 2], [0.1, 0.02, 0.02]), "x<0.001")
}

/// Height of the deformed top face (rest height `top_m`) over `(x, y)`,
/// m: the current positions interpolated on the top triangle whose
/// projection contains the point.
fn top_height(
    haptic_positions: &[[f64; 3]],
    table: &TensorMassTable<'_, f64>,
    top_m: f64,
    x: f64,
    y: f64,
) -> f64 {
    let rest = table.rest_positions();
    for tri in table.surface_triangles() {
        if !tri
            .iter()
            .all(|&v| (rest[v as usize][2] - top_m).abs() < 1e-9)
        {
            continue;
        }
        let [a, b, c] = tri.map(|v| haptic_positions[v as usize]);
        let det = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
        let wb = ((x - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (y - a[1])) / det;
        let wc = ((b[0] - a[0]) * (y - a[1]) - (x - a[0]) * (b[1] - a[1])) / det;
        let wa = 1.0 - wb - wc;
        if [wa, wb, wc].iter().all(|&w| w >= -1e-12) {
            return wa * a[2] + wb * b[2] + wc * c[2];
        }
    }
    panic!("({x}, {y}) is not over the top face");
}

/// The defect (pop-through): the cantilever, E = 3 kPa, ν = 0.45,
/// damping 30/s, symplectic Euler (0.5 ms, a physics update every 10
/// ticks), pressed 0.5 mm deep near its free end within one physics period,
/// then held still for 3 s. The beam overshoots and the contact is let go
/// (the held vertices would pull); the beam then creeps back up onto the
/// resting probe. Checked against the deformed top face itself (its height
/// under the probe, from the surface positions): at every physics update
/// after which the probe's sphere reaches into the surface by more than
/// 1 µm, the next tick has the contact back, and from then on the force
/// is never zero and settles. Before the fix the contact never came back:
/// zero force for the remaining 2.5 s with the probe 0.5 mm inside.
#[test]
fn surface_moving_onto_a_resting_probe_is_felt() {
    let file = cantilever();
    let table = TensorMassTable::<f64>::load(file.bytes()).expect("table");
    let every = 10;
    let physics = PhysicsConfig::new(Integrator::SymplecticEuler, 5e-4, 2 * every as u32);
    let (x, y) = (0.0853, 0.0113);
    with_loop::<1, _>(&file, physics, |haptic| {
        let mut released = None;
        let mut inside_after_update = false;
        let mut forces = Vec::new();
        for k in 0..3000 {
            let depth = 0.0005 * (k as f64 / 10.0).min(1.0);
            let tip = Vector3::new(x, y, 0.02 + RADIUS_M - depth);
            let out = haptic.tick(&[tip]);
            if inside_after_update {
                assert_eq!(
                    out.contacts, 1,
                    "tick {k}: the probe is inside the surface, no contact"
                );
                assert!(
                    out.force_n.z > 0.0,
                    "tick {k}: inside with force {}",
                    out.force_n.z
                );
            }
            if k > 10 && out.contacts == 0 && released.is_none() {
                released = Some(k);
            }
            forces.push(out.force_n.z);
            if (k + 1) % every == 0 {
                haptic.physics_update().expect("stable");
                let top = top_height(haptic.tissue().surface().positions_m(), &table, 0.02, x, y);
                inside_after_update = top - (tip.z - RADIUS_M) > 1e-6;
            }
        }
        let released = released.expect("the case lets the contact go during the rebound");
        let back = (released..3000)
            .find(|&k| forces[k] > 0.0)
            .expect("contact found again");
        println!("released at tick {released}, felt again at tick {back}");
        assert!(
            forces[back..].iter().all(|&f| f > 0.0),
            "zero force after the contact came back"
        );
        // Settled: the last 0.5 s within 1e-9 N of each other.
        let tail = &forces[2500..];
        let (lo, hi) = tail
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), &f| (a.min(f), b.max(f)));
        assert!(hi - lo < 1e-9 && lo > 1e-4, "not settled: {lo}..{hi} N");
    });
}

/// Two probes, one pushing tissue into the other: the cantilever's free
/// end pressed 1.5 mm down from above (tool 0) onto a probe resting 0.2 mm
/// below its lower face (tool 1), which never moves. Tool 1's contact comes
/// from the surface moving onto it; at rest it pushes the beam up (its
/// force on the tissue along +z), the beam's lower face stays on it (its
/// height under the probe, from the surface positions, within 0.1 mm of the
/// sphere's top), and the static balance holds: the press is larger than
/// the support (the fixed end carries the rest).
#[test]
fn tissue_pushed_onto_a_second_probe_is_felt_by_it() {
    let file = cantilever();
    let table = TensorMassTable::<f64>::load(file.bytes()).expect("table");
    let every = 10;
    let physics = PhysicsConfig::new(Integrator::SymplecticEuler, 5e-4, 2 * every as u32);
    let (x, y) = (0.0853, 0.0113);
    let below = Vector3::new(x, y, -RADIUS_M - 0.0002);
    with_loop::<2, _>(&file, physics, |haptic| {
        let mut first_touch = None;
        for k in 0..4000 {
            let depth = 0.0015 * (k as f64 / 500.0).min(1.0);
            let above = Vector3::new(x, y, 0.02 + RADIUS_M - depth);
            haptic.tick(&[above, below]);
            if first_touch.is_none() && haptic.contacts()[1].is_some() {
                first_touch = Some(k);
            }
            if (k + 1) % every == 0 {
                haptic.physics_update().expect("stable");
            }
        }
        let [Some(press), Some(support)] = haptic.tissue().held().map(|h| h.map(|h| h.contact))
        else {
            panic!("both probes held at the end: {:?}", haptic.tissue().held());
        };
        println!(
            "support touched at tick {first_touch:?}; press {:.6} N, support {:.6} N",
            press.force_n.z, support.force_n.z
        );
        assert!(press.force_n.z < 0.0 && support.force_n.z > 0.0);
        assert!(-press.force_n.z > support.force_n.z);
        let bottom = top_height(haptic.tissue().surface().positions_m(), &table, 0.0, x, y);
        assert!(
            (bottom - (below.z + RADIUS_M)).abs() < 1e-4,
            "lower face at {bottom} m"
        );
    });
}
