//! The neo-Hookean force of the tensor-mass model
//! (`palpate_kernel::tensor_mass`, `ElasticLaw::NeoHookean`) against
//! independent truth: central finite differences of its energy (also
//! across the `J` floor and for inverted tets), the small-strain limit (the
//! linear model), the host's own element (`palpate::fem::neo_hookean`)
//! under strong compression, and the inverted-tet rule: finite and
//! restoring.

use nalgebra::{Matrix3, Vector3};
use palpate::fem::hyperelastic::HyperelasticTet;
use palpate::fem::material::Material;
use palpate::fem::neo_hookean::NeoHookeanTet;
use palpate::mesh::{MeshReport, TetMesh, read_mesh};
use palpate::tensor_mass::evaluate::forces_and_energy;
use palpate_kernel::tensor_mass::{ElasticLaw, NEO_HOOKEAN_J_FLOOR};
use palpate_tests::{Lcg, reference_dir};

fn material() -> Material {
    Material::new(5000.0, 0.45).expect("material")
}

/// Forces (N) and energy (J) of `mesh` deformed to `x` (m).
fn evaluate(mesh: &TetMesh, law: ElasticLaw, x: &[[f64; 3]]) -> (Vec<[f64; 3]>, f64) {
    forces_and_energy(mesh, &MeshReport::default(), material(), law, None, x).expect("forces")
}

/// The largest difference between the forces and the central difference
/// `−(W(x + h e) − W(x − h e))/2h` over every degree of freedom of the
/// vertices `vertices`, and the largest force.
fn gradient_error(
    mesh: &TetMesh,
    law: ElasticLaw,
    x: &[[f64; 3]],
    vertices: &[usize],
) -> (f64, f64) {
    let (forces, _) = evaluate(mesh, law, x);
    let h = 1e-7;
    let mut worst: f64 = 0.0;
    for &v in vertices {
        for axis in 0..3 {
            let mut plus = x.to_vec();
            plus[v][axis] += h;
            let mut minus = x.to_vec();
            minus[v][axis] -= h;
            let fd = -(evaluate(mesh, law, &plus).1 - evaluate(mesh, law, &minus).1) / (2.0 * h);
            worst = worst.max((fd - forces[v][axis]).abs());
        }
    }
    let scale = forces.iter().flatten().fold(0.0f64, |m, f| m.max(f.abs()));
    (worst, scale)
}

/// The unit corner tet with its apex at height `z` (m; 1 at rest, below 0
/// inverted).
fn corner_tet(z: f64) -> (TetMesh, Vec<[f64; 3]>) {
    let positions = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let mesh = TetMesh {
        positions,
        tets: vec![[0, 1, 2, 3]],
    };
    let mut x = mesh.positions.clone();
    x[3] = [0.1, 0.05, z];
    (mesh, x)
}

/// Forces are `−∂W/∂x` of the kernel's energy by central differences on 40
/// vertices of the cube (cells 0.2 m) jiggled by up to 0.04 m (strains of
/// 10–30 %, `J` from about 0.5 to 1.6). Step 1e-7 m: truncation (h² W''')
/// and rounding (1e-16 W / h with W ~ 1e3 J) each near 1e-6 N against
/// forces up to 1e3 N; bound 1e-6 relative to the largest force (the
/// requirement), measured well below it.
#[test]
fn forces_are_minus_the_energy_gradient() {
    let (mesh, _) = read_mesh(&reference_dir().join("meshes/cube.msh")).expect("cube.msh");
    let mut rng = Lcg(7);
    let x: Vec<[f64; 3]> = mesh
        .positions
        .iter()
        .map(|p| p.map(|c| c + 0.04 * rng.signed()))
        .collect();
    let vertices: Vec<usize> = (0..mesh.positions.len()).step_by(5).take(40).collect();
    let (worst, scale) = gradient_error(&mesh, ElasticLaw::NeoHookean, &x, &vertices);
    println!("|f − FD| ≤ {worst:.2e} N, forces up to {scale:.3e} N");
    assert!(worst <= 1e-6 * scale, "{worst:e} vs {scale:e}");
}

/// The same on one tet at apex heights above, at, below the `J` floor and
/// inverted (J from 1.2 to −2): the continued energy is C¹, so its
/// gradient is the force everywhere. Bound 1e-6 relative, as above.
#[test]
fn forces_are_the_energy_gradient_across_the_floor_and_inverted() {
    for z in [
        1.2,
        0.5,
        NEO_HOOKEAN_J_FLOOR + 1e-4,
        NEO_HOOKEAN_J_FLOOR - 1e-4,
        0.05,
        0.0,
        -0.3,
        -2.0,
    ] {
        let (mesh, x) = corner_tet(z);
        let (worst, scale) = gradient_error(&mesh, ElasticLaw::NeoHookean, &x, &[0, 1, 2, 3]);
        assert!(worst <= 1e-6 * scale, "z = {z}: {worst:e} vs {scale:e}");
    }
}

/// Inverted and collapsed tets: the forces and energy are finite, and the
/// apex's force points up (`f_z > 0`, towards un-inverting) at every height
/// below rest, growing as the tet is pushed further through its base. An
/// analytic check of the sign: with the apex at `(0.1, 0.05, z)`,
/// `∂W/∂z = V (μ F₃₃ + g'(J) cof(F)₃₃) = V (μ z + g'(z))` is negative for
/// `z < 1` (`g' < 0` there and below the floor).
#[test]
fn inverted_tets_get_a_finite_restoring_force() {
    let mut previous = 0.0;
    for z in [0.9, 0.5, 0.2, 0.1, 0.0, -0.1, -0.5, -1.0, -3.0, -10.0] {
        let (mesh, x) = corner_tet(z);
        let (forces, energy) = evaluate(&mesh, ElasticLaw::NeoHookean, &x);
        assert!(energy.is_finite() && forces.iter().flatten().all(|f| f.is_finite()));
        let fz = forces[3][2];
        assert!(fz > 0.0, "z = {z}: apex force {fz} N does not restore");
        assert!(
            fz > previous,
            "z = {z}: {fz} N not above {previous} N higher up"
        );
        previous = fz;
    }
}

/// At small strain the law is linear elasticity with the same `λ, μ`: on
/// the jiggled cube at 1e-6 m (strains ~1e-5) the forces differ from the
/// linear model's by the first non-linear term, of relative size the
/// strain; bound 1e-4 of the largest force (measured about 1e-5).
#[test]
fn small_strain_is_the_linear_law() {
    let (mesh, _) = read_mesh(&reference_dir().join("meshes/cube.msh")).expect("cube.msh");
    let mut rng = Lcg(3);
    let x: Vec<[f64; 3]> = mesh
        .positions
        .iter()
        .map(|p| p.map(|c| c + 1e-6 * rng.signed()))
        .collect();
    let (nh, _) = evaluate(&mesh, ElasticLaw::NeoHookean, &x);
    let (linear, _) = evaluate(&mesh, ElasticLaw::Linear, &x);
    let diff = nh
        .iter()
        .flatten()
        .zip(linear.iter().flatten())
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    let scale = linear.iter().flatten().fold(0.0f64, |m, f| m.max(f.abs()));
    println!("|f_nh − f_lin| = {:.2e} of the largest force", diff / scale);
    assert!(diff <= 1e-4 * scale, "{diff:e} vs {scale:e}");
}

/// Under strong compression the kernel's forces and energy (what `palpate
/// forces --model neo-hookean` prints) are the host's neo-Hookean element's
/// (its own code of the same law, the Newton truth's): the cube squeezed to
/// 40 % of its height and widened by 10 % (`J = 0.48`) after a jiggle of up
/// to 0.015 m (cells 0.2 m), so the tets' `J` spread over about 0.3–0.7,
/// above the floor (the law proper). Bound 1e-10 of the largest force and
/// of the energy: two f64 codes of one formula differ by rounding (about
/// 1e-15 relative per tet; measured 2.1e-15 and 3.6e-16); a wrong term (a
/// `ln J` or a `μ` off by a factor, a missing `F⁻ᵀ`) would be of order one
/// at these strains.
#[test]
fn forces_and_energy_are_the_host_elements_under_strong_compression() {
    let (mesh, _) = read_mesh(&reference_dir().join("meshes/cube.msh")).expect("cube.msh");
    let squeeze = Matrix3::from_diagonal(&Vector3::new(1.1, 1.1, 0.4));
    let mut rng = Lcg(11);
    let x: Vec<[f64; 3]> = mesh
        .positions
        .iter()
        .map(|p| (squeeze * Vector3::from(p.map(|c| c + 0.015 * rng.signed()))).into())
        .collect();
    let (forces, energy) = evaluate(&mesh, ElasticLaw::NeoHookean, &x);
    let mut host = vec![Vector3::<f64>::zeros(); x.len()];
    let mut host_energy = 0.0;
    let (mut j_min, mut j_max) = (f64::INFINITY, 0.0f64);
    for t in &mesh.tets {
        let element = NeoHookeanTet::at_rest(&t.map(|v| mesh.positions[v as usize]), &material());
        let corners = t.map(|v| x[v as usize]);
        for (v, f) in t.iter().zip(element.forces_n(&corners)) {
            host[*v as usize] += f;
        }
        host_energy += element.energy_j(&corners);
        let edges = |p: &dyn Fn(usize) -> Vector3<f64>| {
            Matrix3::from_columns(&[1, 2, 3].map(|i| p(i) - p(0))).determinant()
        };
        let j = edges(&|i| Vector3::from(corners[i]))
            / edges(&|i| Vector3::from(mesh.positions[t[i] as usize]));
        (j_min, j_max) = (j_min.min(j), j_max.max(j));
    }
    let diff = forces
        .iter()
        .zip(&host)
        .fold(0.0f64, |m, (a, b)| m.max((Vector3::from(*a) - b).amax()));
    let scale = host.iter().fold(0.0f64, |m, f| m.max(f.amax()));
    let energy_diff = (energy - host_energy).abs() / host_energy;
    println!(
        "J in [{j_min:.3}, {j_max:.3}]: |f − f_host| = {:.2e} of the largest force, energy {energy_diff:.2e}",
        diff / scale
    );
    assert!(
        j_min > NEO_HOOKEAN_J_FLOOR && j_max < 0.8,
        "J in [{j_min}, {j_max}]"
    );
    assert!(diff <= 1e-10 * scale, "{diff:e} vs {scale:e}");
    assert!(energy_diff <= 1e-10, "{energy_diff:e}");
}
