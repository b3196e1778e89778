//! The host's St Venant-Kirchhoff element and Newton static reference
//! (`palpate::fem::{stvk, newton}`), the truth of the speed/accuracy study,
//! against independent truth: the JAX St Venant-Kirchhoff forces
//! (`tests/reference/svk`), central differences of its own forces, the
//! linear FEM direct solve at small strain, and the kernel's dynamic model
//! settled at rest.

use nalgebra::Vector3;
use palpate::experiment::relax::relax;
use palpate::experiment::scenes::cylinder;
use palpate::fem::material::{Material, TetMaterials};
use palpate::fem::newton::{NewtonOptions, StaticProblem, solve_stvk};
use palpate::fem::static_solve::solve_loaded;
use palpate::fem::stvk::StvkTet;
use palpate::mesh::read_mesh;
use palpate::table::tensor_mass::static_study_table;
use palpate::tensor_mass::OwnedState;
use palpate::tensor_mass::stability::omega_max;
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::tensor_mass::{DynamicParams, ElasticLaw, StvkForm, TensorMassModel};
use palpate_tests::{json_rows, read_reference_json, reference_dir};

/// Forces of every tet of `tets` at `x`, summed per vertex.
fn forces(
    positions: &[[f64; 3]],
    tets: &[[u32; 4]],
    m: &Material,
    x: &[[f64; 3]],
) -> Vec<Vector3<f64>> {
    let mut f = vec![Vector3::zeros(); positions.len()];
    for t in tets {
        let e = StvkTet::new(&t.map(|v| positions[v as usize]), m);
        for (v, fv) in t.iter().zip(e.forces_n(&t.map(|v| x[v as usize]))) {
            f[*v as usize] += fv;
        }
    }
    f
}

/// Every configuration of the JAX references (single tet and cube, E =
/// 5 kPa, ν = 0.45): forces within 1e-10 of the largest reference force
/// (at least 1 N: the rigid configurations' reference forces are rounding
/// noise) and, for the single tet, energy within 1e-10 relative (at least
/// 1e-6 J). Both are exact f64 evaluations of the same formula: rounding.
#[test]
fn element_matches_the_jax_reference() {
    let single = read_reference_json("svk/svk_single_tet.json");
    let m = Material::new(5000.0, 0.45).expect("material");
    let tet = (json_rows(&single["X"]), vec![[0u32, 1, 2, 3]]);
    let (cube, _) = read_mesh(&reference_dir().join("meshes/cube.msh")).expect("cube");
    for (file, (positions, tets)) in [
        (single, tet),
        (
            read_reference_json("svk/svk_cube.json"),
            (cube.positions, cube.tets),
        ),
    ] {
        for config in file["configs"].as_array().expect("configs") {
            let x = json_rows(&config["x"]);
            let reference = json_rows(&config["forces"]);
            let f = forces(&positions, &tets, &m, &x);
            let scale = reference
                .iter()
                .flatten()
                .fold(1.0f64, |a, b| a.max(b.abs()));
            let diff = f
                .iter()
                .zip(&reference)
                .map(|(a, b)| (a - Vector3::from(*b)).amax())
                .fold(0.0, f64::max);
            println!("{}: {diff:.2e} of {scale:.2e} N", config["name"]);
            assert!(diff <= 1e-10 * scale, "{}", config["name"]);
            if tets.len() == 1 {
                let e = StvkTet::new(&tets[0].map(|v| positions[v as usize]), &m);
                let w = e.energy_j(&[x[0], x[1], x[2], x[3]]);
                let energy = config["energy"].as_f64().expect("energy");
                assert!((w - energy).abs() <= 1e-10 * energy.abs().max(1e-6));
            }
        }
    }
}

/// The tangent against central differences of the element's own forces
/// (step 1e-7 m) on the single tet's large configurations: within 1e-6 of
/// the largest entry (the difference's truncation error is `h²·f'''`, about
/// 1e-9 relative here, and its rounding `ε·|f|/h` about 1e-8 relative).
#[test]
fn tangent_matches_central_differences() {
    let single = read_reference_json("svk/svk_single_tet.json");
    let m = Material::new(5000.0, 0.45).expect("material");
    let rest = json_rows(&single["X"]);
    let e = StvkTet::new(&[rest[0], rest[1], rest[2], rest[3]], &m);
    for config in single["configs"].as_array().expect("configs") {
        let x = json_rows(&config["x"]);
        let x = [x[0], x[1], x[2], x[3]];
        let k = e.tangent(&x);
        let h = 1e-7;
        let mut worst = 0.0f64;
        let mut scale = 0.0f64;
        for kv in 0..4 {
            for c in 0..3 {
                let (mut plus, mut minus) = (x, x);
                plus[kv][c] += h;
                minus[kv][c] -= h;
                let (fp, fm) = (e.forces_n(&plus), e.forces_n(&minus));
                for j in 0..4 {
                    for a in 0..3 {
                        let fd = -(fp[j][a] - fm[j][a]) / (2.0 * h);
                        worst = worst.max((fd - k[j][kv][a][c]).abs());
                        scale = scale.max(k[j][kv][a][c].abs());
                    }
                }
            }
        }
        println!(
            "{}: |K − FD| ≤ {worst:.2e} of {scale:.2e} N/m",
            config["name"]
        );
        assert!(worst <= 1e-6 * scale, "{}", config["name"]);
    }
}

/// The volume experiment's small cylinder (768 tets), base fixed, a lateral
/// load on its top face.
struct Bend {
    scene: palpate::experiment::volume_bend::Scene,
    loads: Vec<[f64; 3]>,
}

fn bend(force_n: f64) -> Bend {
    let scene = cylinder(2, 8);
    let mut loads = vec![[0.0; 3]; scene.mesh.positions.len()];
    for &v in &scene.loaded {
        loads[v as usize] = [force_n / scene.loaded.len() as f64, 0.0, 0.0];
    }
    Bend { scene, loads }
}

fn newton(b: &Bend, steps: usize) -> palpate::fem::newton::Equilibrium {
    let materials = TetMaterials::uniform(b.scene.material, b.scene.mesh.tets.len());
    solve_stvk(
        &StaticProblem {
            positions: &b.scene.mesh.positions,
            tets: &b.scene.mesh.tets,
            materials: &materials,
            fixed: &b.scene.fixed,
            prescribed: &[],
            loads_n: &b.loads,
        },
        &NewtonOptions {
            load_steps: steps,
            ..NewtonOptions::default()
        },
    )
    .expect("newton")
}

fn relative(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    let diff = a
        .iter()
        .zip(b)
        .map(|(x, y)| (Vector3::from(*x) - Vector3::from(*y)).norm_squared())
        .sum::<f64>();
    let norm = b
        .iter()
        .map(|y| Vector3::from(*y).norm_squared())
        .sum::<f64>();
    (diff / norm).sqrt()
}

/// At small strain St Venant-Kirchhoff is linear elasticity: under a load
/// that bends the cylinder by about 1e-5 of its height, Newton's field
/// equals the linear direct solve within 1e-4 relative (L2; the non-linear
/// terms are of the order of the displacement gradient, about 1e-5, times
/// a factor of a few). At 100× the load the difference grows about 100×
/// (the first non-linear term is linear in the load).
#[test]
fn newton_is_linear_fem_at_small_strain() {
    let mut previous = 0.0;
    for force_n in [1e-6, 1e-4] {
        let b = bend(force_n);
        let reference = newton(&b, 1);
        let materials = TetMaterials::uniform(b.scene.material, b.scene.mesh.tets.len());
        let (linear, _) = solve_loaded(
            &b.scene.mesh.positions,
            &b.scene.mesh.tets,
            &materials,
            &b.scene.fixed,
            &[],
            &b.loads,
        )
        .expect("linear");
        let difference = relative(&reference.u, &linear);
        let tip = reference.u.iter().map(|d| d[0].abs()).fold(0.0, f64::max);
        println!(
            "{force_n:e} N: tip {tip:.3e} m, Newton vs linear {difference:.3e} ({} iterations, residual {:.1e} N)",
            reference.iterations, reference.residual_n
        );
        if previous == 0.0 {
            assert!(difference <= 1e-4);
        } else {
            let growth = difference / previous;
            assert!((50.0..=200.0).contains(&growth), "growth {growth}");
        }
        previous = difference;
    }
}

/// The kernel's dynamic St Venant-Kirchhoff model (per-tet form, f64)
/// relaxed to rest under a load that bends the top 11 mm (a tenth of the
/// height: large rotation): its settled field equals Newton's within 1e-6
/// relative (L2). The relaxation stops at a residual of 1e-7 of the load
/// per loaded vertex; the two solve the same equations by different codes
/// (the kernel's per-tet forces, the host's element), so they agree to
/// about that residual over the stiffness (measured 3.4e-8 in 3900 steps;
/// 4.9e-11 at a residual of 1e-10, in 5200; the step is `0.5/ω_max` of the
/// tangent at rest).
#[test]
fn newton_equals_the_dynamic_model_settled_at_rest() {
    let b = bend(0.03);
    let reference = newton(&b, 4);
    let scene = &b.scene;
    let materials = TetMaterials::uniform(scene.material, scene.mesh.tets.len());
    let file = static_study_table(&scene.mesh, &materials, scene.fixed.clone());
    let table = TensorMassTable::<f64>::load(file.bytes()).expect("table");
    let mut state = OwnedState::for_table(&table);
    let params =
        DynamicParams::linear(0.0, 1.0).with_law(ElasticLaw::StVenantKirchhoff(StvkForm::PerTet));
    let mut model = TensorMassModel::new(table, state.buffers(), params).expect("model");
    let dt_s = 0.5 / omega_max(&mut model);
    model.reset();
    for &v in &scene.loaded {
        model
            .set_external_force(v, Vector3::from(b.loads[v as usize]))
            .expect("load");
    }
    let share = 0.03 / scene.loaded.len() as f64;
    let mut settled = vec![[0.0; 3]; scene.mesh.positions.len()];
    let relaxation = relax(
        &mut model,
        &b.loads,
        dt_s,
        1e-7 * share,
        2_000_000,
        &mut settled,
    )
    .expect("relax");
    let difference = relative(&settled, &reference.u);
    let tip = reference.u.iter().map(|d| d[0]).fold(0.0, f64::max);
    println!(
        "tip {tip:.3e} m: dynamic (relaxed, {} steps) vs Newton ({} iterations): {difference:.3e}",
        relaxation.steps, reference.iterations
    );
    assert!(relaxation.converged && reference.tolerance_met);
    assert!(difference <= 1e-6);
}

/// `NewtonOptions::descent` past the buckling load: the chart's 1×5
/// cylinder (`chart::Body`) under the press at 20 % of its height (eight
/// times the free-top column's Euler load, with the chart's lateral
/// imperfection; at 5 % this coarse, stiffer mesh still passes by plain
/// Newton).
/// Plain load-stepped Newton fails there (the path loses stability); the
/// descent returns a stable equilibrium, checked here independently of the
/// solver: the element forces (this file's `forces`, summed per vertex)
/// balance the loads on every free vertex to 1e-8 of the largest nodal load
/// (the solver's tolerance is 1e-10 of it; 1e-8 leaves room for the
/// rounding of the sums), and it is St Venant-Kirchhoff's collapse (tets
/// inverted). Below the buckling load (1 %) the descent is Newton: the same
/// equilibrium to 1e-9 (relative L2).
#[test]
fn descent_follows_the_stable_equilibrium_past_buckling() {
    use palpate::chart::{Body, HEIGHT_M, Load};
    let body = Body::cylinder((1, 5), palpate::experiment::scenes::tissue());
    let materials = body.materials();
    let per_newton = body.tip_per_newton_m(Load::Press).expect("linear solve");
    let solve = |level: f64, descent: bool| {
        let loads = body.loads(Load::Press, level * HEIGHT_M / per_newton);
        let result = solve_stvk(
            &body.static_problem(&materials, &loads),
            &NewtonOptions {
                load_steps: 3,
                max_iterations: 400,
                tolerance: 1e-10,
                descent,
            },
        );
        (loads, result)
    };
    let (_, plain) = solve(0.2, false);
    assert!(plain.is_err(), "plain Newton passed the buckling load");
    let (loads, collapse) = solve(0.2, true);
    let collapse = collapse.expect("descent");
    let x: Vec<[f64; 3]> = body
        .mesh
        .positions
        .iter()
        .zip(&collapse.u)
        .map(|(p, u)| [p[0] + u[0], p[1] + u[1], p[2] + u[2]])
        .collect();
    let f = forces(&body.mesh.positions, &body.mesh.tets, &body.material, &x);
    let largest = loads
        .iter()
        .map(|l| Vector3::from(*l).amax())
        .fold(0.0, f64::max);
    for v in (0..x.len()).filter(|&v| !body.fixed[v]) {
        let r = (f[v] + Vector3::from(loads[v])).amax();
        assert!(r <= 1e-8 * largest, "vertex {v}: residual {r:e} N");
    }
    let inverted = palpate::experiment::volume_bend::inverted_tets(&body.mesh, &collapse.u);
    assert!(inverted > 0, "no collapse");
    let (_, a) = solve(0.01, false);
    let (_, b) = solve(0.01, true);
    let gap = relative(&a.expect("newton").u, &b.expect("descent").u);
    assert!(gap < 1e-9, "{gap:e}");
}
