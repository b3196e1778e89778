//! The kernel's neo-Hookean tensor-mass model (`ElasticLaw::NeoHookean`,
//! f64) brought to static equilibrium (dynamic relaxation,
//! `palpate::experiment::relax`) against the host's Newton neo-Hookean
//! (`palpate::fem::newton::solve_neo_hookean`) on the same mesh under the
//! same loads, past the buckling load of the chart's cylinder: two codes of
//! one law (the kernel's per-tet pass, the host's element), so the
//! equilibria agree to the relaxation's residual. This is what separates a
//! defect of the kernel's law from the discretization when the kernel's
//! neo-Hookean model is compared with a refined or P2 truth.

use nalgebra::{Matrix3, Vector3};
use palpate::experiment::relax::{Relaxation, relax};
use palpate::experiment::scenes::cylinder;
use palpate::experiment::volume_bend::Scene;
use palpate::fem::hyperelastic::HyperelasticTet;
use palpate::fem::material::TetMaterials;
use palpate::fem::neo_hookean::NeoHookeanTet;
use palpate::fem::newton::{NewtonOptions, StaticProblem, solve_neo_hookean};
use palpate::fem::static_solve::solve_loaded;
use palpate::table::tensor_mass::static_study_table;
use palpate::tensor_mass::OwnedState;
use palpate::tensor_mass::stability::omega_max;
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::tensor_mass::{
    DynamicParams, ElasticLaw, NEO_HOOKEAN_J_FLOOR, TensorMassModel,
};

use super::neo_hookean::relative;

/// The press's lateral imperfection along x, of the axial force (the
/// chart's, `palpate::chart::PRESS_IMPERFECTION`): it picks the buckling
/// direction for both solvers.
const IMPERFECTION: f64 = 1e-3;

/// Relaxation step over `1/ω_max` (of the tangent at rest). Below the
/// chart's 0.5: the suddenly applied press overshoots its equilibrium and
/// the neo-Hookean volume term stiffens in compression, so at 0.5 the
/// relaxation of the 1×5 cylinder under this file's press diverged (the
/// kernel's displacement bound faulted), as it did on 2×10 at the chart's
/// 20 % press; at 0.3 both settled (measured; at equilibrium `ω_max` is
/// 1.5× its rest value).
const DT_FACTOR: f64 = 0.3;

/// The top face of `scene` pressed down by `force_n` (equal shares, with
/// the [`IMPERFECTION`]), N per vertex.
fn press(scene: &Scene, force_n: f64) -> Vec<[f64; 3]> {
    let share = force_n / scene.loaded.len() as f64;
    let mut loads = vec![[0.0; 3]; scene.mesh.positions.len()];
    for &v in &scene.loaded {
        loads[v as usize] = [IMPERFECTION * share, 0.0, -share];
    }
    loads
}

/// The kernel's neo-Hookean model of `scene` relaxed under `loads` until
/// the largest residual force is `tolerance_n`: the displacements (m).
fn kernel_equilibrium(
    scene: &Scene,
    loads: &[[f64; 3]],
    tolerance_n: f64,
) -> (Vec<[f64; 3]>, Relaxation) {
    let materials = TetMaterials::uniform(scene.material, scene.mesh.tets.len());
    let file = static_study_table(&scene.mesh, &materials, scene.fixed.clone());
    let table = TensorMassTable::<f64>::load(file.bytes()).expect("table");
    let mut state = OwnedState::for_table(&table);
    let params = DynamicParams::linear(0.0, 1.0).with_law(ElasticLaw::NeoHookean);
    let mut model = TensorMassModel::new(table, state.buffers(), params).expect("model");
    let dt_s = DT_FACTOR / omega_max(&mut model);
    model.reset();
    for (v, f) in loads.iter().enumerate() {
        if f.iter().any(|&c| c != 0.0) {
            model
                .set_external_force(v as u32, Vector3::from(*f))
                .expect("load");
        }
    }
    let mut u = vec![[0.0; 3]; loads.len()];
    let relaxation = relax(&mut model, loads, dt_s, tolerance_n, 100_000, &mut u).expect("relax");
    (u, relaxation)
}

/// The host's neo-Hookean internal forces of `scene` at displacement `u`,
/// summed per vertex, N.
fn host_forces(scene: &Scene, u: &[[f64; 3]]) -> Vec<Vector3<f64>> {
    let p = &scene.mesh.positions;
    let mut f = vec![Vector3::zeros(); p.len()];
    for t in &scene.mesh.tets {
        let rest = t.map(|v| p[v as usize]);
        let x = t.map(|v| {
            let (p, d) = (p[v as usize], u[v as usize]);
            [p[0] + d[0], p[1] + d[1], p[2] + d[2]]
        });
        let element = NeoHookeanTet::at_rest(&rest, &scene.material);
        for (v, fv) in t.iter().zip(element.forces_n(&x)) {
            f[*v as usize] += fv;
        }
    }
    f
}

/// The smallest volume ratio `J` over the tets at displacement `u`.
fn min_volume_ratio(scene: &Scene, u: &[[f64; 3]]) -> f64 {
    let p = &scene.mesh.positions;
    let edges = |x: &dyn Fn(usize) -> Vector3<f64>, t: &[u32; 4]| {
        let o = x(t[0] as usize);
        Matrix3::from_columns(&[1, 2, 3].map(|i| x(t[i] as usize) - o)).determinant()
    };
    let rest = |v: usize| Vector3::from(p[v]);
    let deformed = |v: usize| Vector3::from(p[v]) + Vector3::from(u[v]);
    scene
        .mesh
        .tets
        .iter()
        .map(|t| edges(&deformed, t) / edges(&rest, t))
        .fold(f64::INFINITY, f64::min)
}

/// The chart's 1×5 cylinder (54 vertices, 120 tets) under 1.183 N, its
/// 20 % press (the linear tip at 20 % of the height; about 8 times the
/// free-top column's Euler load): it buckles along the imperfection, the
/// top sinks 0.17 m (further than the 0.1 m height: the column folds over)
/// and a tet is compressed to `J ≈ 0.52`, above the kernel's `J` floor (so
/// both solve the same law, no continuation). The kernel's equilibrium
/// (relaxed to 1e-8 of the per-vertex load) equals Newton's within 1e-6
/// relative (L2): they solve the same equations, so they differ by the
/// residual over the stiffness (measured 7.0e-10 in 2 900 steps). The
/// linear solution is more than 50 % away (measured 90 %): the comparison
/// tells the laws apart.
#[test]
fn kernel_equilibrium_is_newtons_under_large_compression() {
    let scene = cylinder(1, 5);
    let force_n = 1.183;
    let loads = press(&scene, force_n);
    let share = force_n / scene.loaded.len() as f64;
    let materials = TetMaterials::uniform(scene.material, scene.mesh.tets.len());
    let problem = StaticProblem {
        positions: &scene.mesh.positions,
        tets: &scene.mesh.tets,
        materials: &materials,
        fixed: &scene.fixed,
        prescribed: &[],
        loads_n: &loads,
    };
    let options = NewtonOptions {
        load_steps: 10,
        max_iterations: 400,
        ..NewtonOptions::default()
    };
    let newton = solve_neo_hookean(&problem, &options).expect("newton");
    let (kernel, relaxation) = kernel_equilibrium(&scene, &loads, 1e-8 * share);
    let (linear, _) = solve_loaded(
        &scene.mesh.positions,
        &scene.mesh.tets,
        &materials,
        &scene.fixed,
        &[],
        &loads,
    )
    .expect("linear");
    let difference = relative(&kernel, &newton.u);
    let sink = -scene
        .loaded
        .iter()
        .map(|&v| newton.u[v as usize][2])
        .sum::<f64>()
        / scene.loaded.len() as f64;
    let j = min_volume_ratio(&scene, &newton.u);
    println!(
        "top sinks {sink:.4} m, min J {j:.3}: kernel ({} steps) vs Newton ({} iterations) \
         {difference:.2e}, linear vs Newton {:.2e}",
        relaxation.steps,
        newton.iterations,
        relative(&linear, &newton.u)
    );
    assert!(relaxation.converged && newton.tolerance_met);
    assert!(sink > 0.15, "not the folded column: {sink} m");
    assert!((NEO_HOOKEAN_J_FLOOR..0.6).contains(&j), "min J {j}");
    assert!(difference <= 1e-6, "{difference:e}");
    assert!(relative(&linear, &newton.u) > 0.5);
}

/// The chart's 2×10 cylinder under its 5 % press (0.319 N, about twice the
/// free-top column's Euler load), where the chart scored the kernel's
/// neo-Hookean model far from a P2 truth: the kernel's relaxed equilibrium
/// (1e-8 of the per-vertex load) is an equilibrium of the host's element,
/// the host's forces there balance the loads within 1e-7 of the per-vertex
/// load (measured 8.9e-9: the relaxation's residual; the two force codes agree
/// to rounding), and it is the buckled column (the top 80 mm aside, the
/// smallest `J` 0.64, above the floor). Newton from rest may buckle along a
/// diagonal of this mesh instead (the bifurcation is nearly symmetric; its
/// direction follows the load steps' rounding): another stable equilibrium
/// of the same equations, not compared here.
#[test]
fn kernel_equilibrium_under_the_charts_press_is_a_host_equilibrium() {
    let scene = cylinder(2, 10);
    let force_n = 0.319;
    let loads = press(&scene, force_n);
    let share = force_n / scene.loaded.len() as f64;
    let (u, relaxation) = kernel_equilibrium(&scene, &loads, 1e-8 * share);
    let f = host_forces(&scene, &u);
    let residual = (0..u.len())
        .filter(|&v| !scene.fixed[v])
        .map(|v| (f[v] + Vector3::from(loads[v])).norm())
        .fold(0.0, f64::max);
    let aside =
        scene.loaded.iter().map(|&v| u[v as usize][0]).sum::<f64>() / scene.loaded.len() as f64;
    let j = min_volume_ratio(&scene, &u);
    println!(
        "{} steps: host residual {:.2e} of the share, top {aside:.4} m aside, min J {j:.3}",
        relaxation.steps,
        residual / share
    );
    assert!(relaxation.converged);
    assert!(residual <= 1e-7 * share, "{residual:e} N");
    assert!(aside > 0.05, "not buckled: {aside} m");
    assert!(j > NEO_HOOKEAN_J_FLOOR, "min J {j}");
}
