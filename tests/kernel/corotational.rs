//! The co-rotational linear force of the tensor-mass model
//! (`palpate_kernel::tensor_mass`, `ElasticLaw::Corotational`) against
//! independent truth: the linear model (the tensor pass, `f = −K u`) for a
//! pure strain and under any rigid rotation of it, zero under a rigid
//! motion, rotation of the forces with the deformed state, the linear limit
//! of a small general deformation, and central finite differences of the
//! co-rotated energy.

use nalgebra::{Matrix3, Rotation3, Vector3};
use palpate::fem::material::Material;
use palpate::mesh::{MeshReport, TetMesh, read_mesh};
use palpate::tensor_mass::evaluate::forces_and_energy;
use palpate_kernel::tensor_mass::ElasticLaw;
use palpate_tests::{Lcg, reference_dir};

fn material() -> Material {
    Material::new(5000.0, 0.45).expect("material")
}

fn cube() -> TetMesh {
    read_mesh(&reference_dir().join("meshes/cube.msh"))
        .expect("cube.msh")
        .0
}

/// Forces (N) and energy (J) of `mesh` deformed to `x` (m).
fn evaluate(mesh: &TetMesh, law: ElasticLaw, x: &[[f64; 3]]) -> (Vec<[f64; 3]>, f64) {
    forces_and_energy(mesh, &MeshReport::default(), material(), law, None, x).expect("forces")
}

/// `x ↦ Q x + t` applied to every point.
fn moved(points: &[[f64; 3]], q: &Matrix3<f64>, t: Vector3<f64>) -> Vec<[f64; 3]> {
    points
        .iter()
        .map(|p| (q * Vector3::from(*p) + t).into())
        .collect()
}

/// Largest entry of `a − b` and of `b`.
fn max_diff(a: &[[f64; 3]], b: &[[f64; 3]]) -> (f64, f64) {
    let diff = a
        .iter()
        .flatten()
        .zip(b.iter().flatten())
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    let scale = b.iter().flatten().fold(0.0f64, |m, f| m.max(f.abs()));
    (diff, scale)
}

/// Rotations tested: small, large, near a half turn, about skew axes.
fn rotations() -> Vec<Matrix3<f64>> {
    [
        (Vector3::new(0.0, 0.0, 1.0), 0.01),
        (Vector3::new(1.0, 2.0, 3.0), 0.7),
        (Vector3::new(-1.0, 0.5, 0.2), 2.0),
        (Vector3::new(0.3, -1.0, 0.4), 3.1),
        (Vector3::new(1.0, 1.0, 0.0), core::f64::consts::PI),
    ]
    .into_iter()
    .map(|(axis, angle)| *Rotation3::new(axis.normalize() * angle).matrix())
    .collect()
}

/// The cube under a symmetric strain `x = (I + E) X` (`E` symmetric,
/// entries up to 1e-3): `R = I`, so the co-rotational force is the linear
/// force `−K u` of the tensor pass; and rotating the strained cube by any
/// `Q` (plus a translation) gives `Q` times that force. Bound 1e-10 of the
/// largest force: the two passes are different arithmetic of the same
/// `K` (measured about 1e-13).
#[test]
fn rotated_pure_strain_gives_the_rotated_linear_force() {
    let mesh = cube();
    let e = Matrix3::new(1e-3, 4e-4, -2e-4, 4e-4, -6e-4, 3e-4, -2e-4, 3e-4, 5e-4);
    let strained = moved(
        &mesh.positions,
        &(Matrix3::identity() + e),
        Vector3::zeros(),
    );
    let (linear, _) = evaluate(&mesh, ElasticLaw::Linear, &strained);
    for q in rotations() {
        let x = moved(&strained, &q, Vector3::new(0.3, -0.2, 0.1));
        let (corotational, _) = evaluate(&mesh, ElasticLaw::Corotational, &x);
        let expected = moved(&linear, &q, Vector3::zeros());
        let (diff, scale) = max_diff(&corotational, &expected);
        assert!(diff <= 1e-10 * scale, "{q}: {diff:e} vs {scale:e}");
    }
}

/// A rigid motion of the rest shape gives zero force and energy: bound
/// 1e-9 of the force a 1e-3 strain gives (about 1e-12 N measured against
/// forces of about 1 N: rounding of `RᵀF − I`).
#[test]
fn rigid_motion_gives_no_force() {
    let mesh = cube();
    let strained = moved(
        &mesh.positions,
        &(Matrix3::identity() * 1.001),
        Vector3::zeros(),
    );
    let (reference, _) = evaluate(&mesh, ElasticLaw::Corotational, &strained);
    let scale = reference
        .iter()
        .flatten()
        .fold(0.0f64, |m, f| m.max(f.abs()));
    for q in rotations() {
        let x = moved(&mesh.positions, &q, Vector3::new(-1.0, 2.0, 0.5));
        let (forces, energy) = evaluate(&mesh, ElasticLaw::Corotational, &x);
        let largest = forces.iter().flatten().fold(0.0f64, |m, f| m.max(f.abs()));
        assert!(largest <= 1e-9 * scale, "{q}: {largest:e} N vs {scale:e} N");
        assert!(energy.abs() <= 1e-15, "{q}: energy {energy:e} J");
    }
}

/// A general deformation (every vertex jiggled by up to 0.04 m: strains and
/// local rotations of 10–30 %) rotated by `Q` gives `Q` times its forces
/// (the law is frame-indifferent): bound 1e-10 of the largest force.
#[test]
fn forces_rotate_with_the_deformed_state() {
    let mesh = cube();
    let mut rng = Lcg(5);
    let x: Vec<[f64; 3]> = mesh
        .positions
        .iter()
        .map(|p| p.map(|c| c + 0.04 * rng.signed()))
        .collect();
    let (forces, energy) = evaluate(&mesh, ElasticLaw::Corotational, &x);
    for q in rotations() {
        let (rotated, rotated_energy) = evaluate(
            &mesh,
            ElasticLaw::Corotational,
            &moved(&x, &q, Vector3::zeros()),
        );
        let (diff, scale) = max_diff(&rotated, &moved(&forces, &q, Vector3::zeros()));
        assert!(diff <= 1e-10 * scale, "{q}: {diff:e} vs {scale:e}");
        assert!((rotated_energy - energy).abs() <= 1e-10 * energy);
    }
}

/// A small general deformation (jiggle 1e-5 m on 0.2 m cells, strains and
/// rotations ~1e-4) under a large rotation `Q`: the forces are `Q` times
/// the linear forces of the unrotated deformation up to the first
/// non-linear term, of relative size the strain; bound 1e-3 of the largest
/// force.
#[test]
fn rotated_small_deformation_gives_the_rotated_linear_force() {
    let mesh = cube();
    let mut rng = Lcg(9);
    let x: Vec<[f64; 3]> = mesh
        .positions
        .iter()
        .map(|p| p.map(|c| c + 1e-5 * rng.signed()))
        .collect();
    let (linear, _) = evaluate(&mesh, ElasticLaw::Linear, &x);
    let mut worst: f64 = 0.0;
    for q in rotations() {
        let (corotational, _) = evaluate(
            &mesh,
            ElasticLaw::Corotational,
            &moved(&x, &q, Vector3::zeros()),
        );
        let (diff, scale) = max_diff(&corotational, &moved(&linear, &q, Vector3::zeros()));
        worst = worst.max(diff / scale);
    }
    println!("|f_corot − Q f_lin| ≤ {worst:.2e} of the largest force");
    assert!(worst <= 1e-3, "{worst:e}");
}

/// The co-rotational force is the gradient of the co-rotated energy
/// `V (μ |F − R|² + λ/2 (tr RᵀF − 3)²)` (McAdams et al. 2011 §4): central
/// differences on 40 vertices of the jiggled cube, step 1e-7 m, bound 1e-6
/// of the largest force (as for the neo-Hookean law).
#[test]
fn forces_are_minus_the_corotated_energy_gradient() {
    let mesh = cube();
    let mut rng = Lcg(7);
    let x: Vec<[f64; 3]> = mesh
        .positions
        .iter()
        .map(|p| p.map(|c| c + 0.04 * rng.signed()))
        .collect();
    let law = ElasticLaw::Corotational;
    let (forces, _) = evaluate(&mesh, law, &x);
    let h = 1e-7;
    let mut worst: f64 = 0.0;
    for v in (0..mesh.positions.len()).step_by(5).take(40) {
        for axis in 0..3 {
            let mut plus = x.clone();
            plus[v][axis] += h;
            let mut minus = x.clone();
            minus[v][axis] -= h;
            let fd = -(evaluate(&mesh, law, &plus).1 - evaluate(&mesh, law, &minus).1) / (2.0 * h);
            worst = worst.max((fd - forces[v][axis]).abs());
        }
    }
    let scale = forces.iter().flatten().fold(0.0f64, |m, f| m.max(f.abs()));
    println!("|f − FD| ≤ {worst:.2e} N, forces up to {scale:.3e} N");
    assert!(worst <= 1e-6 * scale, "{worst:e} vs {scale:e}");
}
