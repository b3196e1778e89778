//! The host's compressible neo-Hookean element and its Newton solve
//! (`palpate::fem::{neo_hookean, newton::solve_neo_hookean}`), the truth of
//! the speed/accuracy study: forces against central differences of the
//! energy, the tangent against central differences of the forces, rigid
//! motions, the rejected inversion, and the small-strain limit (the linear
//! FEM direct solve). The comparison with an independent implementation
//! (scikit-fem) is `neo_hookean_reference`.

use nalgebra::{Matrix3, Rotation3, Vector3};
use palpate::experiment::scenes::cylinder;
use palpate::fem::hyperelastic::HyperelasticTet;
use palpate::fem::material::{Material, TetMaterials};
use palpate::fem::neo_hookean::NeoHookeanTet;
use palpate::fem::newton::{NewtonOptions, StaticProblem, solve_neo_hookean};
use palpate::fem::static_solve::solve_loaded;

/// An irregular tet about 5 cm across (positively oriented), m.
const REST: [[f64; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [0.05, 0.004, -0.003],
    [0.012, 0.043, 0.006],
    [-0.004, 0.009, 0.047],
];

fn material() -> Material {
    Material::new(5000.0, 0.45).expect("material")
}

/// `REST` deformed by `F = I + g` then moved by `t`, m.
fn deformed(g: Matrix3<f64>, t: Vector3<f64>) -> [[f64; 3]; 4] {
    let f = Matrix3::identity() + g;
    REST.map(|p| (f * Vector3::from(p) + t).into())
}

/// Large deformations: a stretch, a compression to `J ≈ 0.33`, a shear with
/// rotation (each `J > 0`).
fn configurations() -> Vec<(&'static str, [[f64; 3]; 4])> {
    let t = Vector3::new(0.01, -0.02, 0.005);
    vec![
        (
            "stretch 1.4",
            deformed(Matrix3::from_diagonal(&Vector3::new(0.4, -0.1, -0.1)), t),
        ),
        (
            "compression J 0.33",
            deformed(Matrix3::from_diagonal(&Vector3::new(-0.5, -0.2, -0.15)), t),
        ),
        (
            "shear and rotation",
            deformed(
                Matrix3::new(0.1, 0.35, -0.2, -0.3, 0.15, 0.1, 0.25, -0.1, -0.2),
                t,
            ),
        ),
    ]
}

/// The forces equal minus the central difference of the energy (step 1e-8
/// m, about 1e-6 of the tet's size) within 1e-6 of the largest force: the
/// difference's truncation error is `h²·W'''/6`, about 1e-10 relative, its
/// rounding `ε·W/h` about 1e-8 relative (W ~ 1e-2 J, f ~ 1 N).
#[test]
fn forces_are_minus_the_energy_gradient() {
    let e = NeoHookeanTet::at_rest(&REST, &material());
    for (name, x) in configurations() {
        let f = e.forces_n(&x);
        let scale = f.iter().map(|v| v.amax()).fold(0.0, f64::max);
        let h = 1e-8;
        let mut worst = 0.0f64;
        for v in 0..4 {
            for c in 0..3 {
                let (mut plus, mut minus) = (x, x);
                plus[v][c] += h;
                minus[v][c] -= h;
                let fd = -(e.energy_j(&plus) - e.energy_j(&minus)) / (2.0 * h);
                worst = worst.max((fd - f[v][c]).abs());
            }
        }
        println!("{name}: |f + ∇W| ≤ {worst:.2e} of {scale:.2e} N");
        assert!(scale > 1e-3, "{name}: a loaded configuration");
        assert!(worst <= 1e-6 * scale, "{name}");
    }
}

/// The tangent equals minus the central difference of the forces (step
/// 1e-7 m) within 1e-6 of its largest entry (truncation about 1e-9
/// relative, rounding `ε·|f|/h` about 1e-8 relative), and is symmetric to
/// rounding (1e-12 of its largest entry).
#[test]
fn tangent_is_minus_the_force_derivative() {
    let e = NeoHookeanTet::at_rest(&REST, &material());
    for (name, x) in configurations() {
        let k = e.tangent(&x);
        let h = 1e-7;
        let (mut worst, mut scale, mut asymmetry) = (0.0f64, 0.0f64, 0.0f64);
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
                        asymmetry = asymmetry.max((k[j][kv][a][c] - k[kv][j][c][a]).abs());
                    }
                }
            }
        }
        println!("{name}: |K − FD| ≤ {worst:.2e}, asymmetry {asymmetry:.1e} of {scale:.2e} N/m");
        assert!(worst <= 1e-6 * scale, "{name}");
        assert!(asymmetry <= 1e-12 * scale, "{name}");
    }
}

/// A rigid motion (rotations of 90° about z and of 130° about (1, 2, 3),
/// with a translation) has zero energy and zero force: within 1e-12 of the
/// forces of a 10 % stretch (rounding of `F⁻ᵀ` and `ln J` at `J = 1`); and
/// rotating a deformed tet rotates its forces (frame invariance).
#[test]
fn rigid_motions_have_no_force() {
    let e = NeoHookeanTet::at_rest(&REST, &material());
    let stretch = deformed(
        Matrix3::from_diagonal(&Vector3::new(0.1, 0.0, 0.0)),
        Vector3::zeros(),
    );
    let scale = e
        .forces_n(&stretch)
        .iter()
        .map(|v| v.amax())
        .fold(0.0, f64::max);
    let rotations = [
        Rotation3::from_axis_angle(&Vector3::z_axis(), core::f64::consts::FRAC_PI_2),
        Rotation3::new(Vector3::new(1.0, 2.0, 3.0).normalize() * 130f64.to_radians()),
    ];
    for r in rotations {
        let moved = REST.map(|p| (r * Vector3::from(p) + Vector3::new(0.3, -0.1, 0.2)).into());
        let f = e.forces_n(&moved);
        let largest = f.iter().map(|v| v.amax()).fold(0.0, f64::max);
        println!(
            "rigid: |f| ≤ {largest:.2e} N, W = {:.2e} J (stretch: {scale:.2e} N)",
            e.energy_j(&moved)
        );
        assert!(largest <= 1e-12 * scale);
        assert!(e.energy_j(&moved).abs() <= 1e-12 * e.energy_j(&stretch));
        for (_, x) in configurations() {
            let turned = x.map(|p| (r * Vector3::from(p)).into());
            let (f, g) = (e.forces_n(&x), e.forces_n(&turned));
            for (a, b) in f.iter().zip(&g) {
                assert!((r * a - b).amax() <= 1e-12 * scale.max(a.amax()));
            }
        }
    }
}

/// An inverted or flat tet has infinite energy and is not admissible: the
/// Newton line search halves a step that reaches one.
#[test]
fn inversion_has_infinite_energy() {
    let e = NeoHookeanTet::at_rest(&REST, &material());
    let flat = deformed(
        Matrix3::from_diagonal(&Vector3::new(0.0, 0.0, -1.0)),
        Vector3::zeros(),
    );
    let inverted = deformed(
        Matrix3::from_diagonal(&Vector3::new(0.0, 0.0, -1.5)),
        Vector3::zeros(),
    );
    for x in [flat, inverted] {
        assert_eq!(e.energy_j(&x), f64::INFINITY);
        assert!(!e.admissible(&x));
    }
    assert!(e.admissible(&REST));
    assert!(e.energy_j(&REST).abs() <= 1e-20, "zero to rounding at rest");
}

/// The volume experiment's small cylinder (768 tets), base fixed, a lateral
/// load `force_n` on its top face: neo-Hookean Newton's field.
fn bend(force_n: f64) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let scene = cylinder(2, 8);
    let mut loads = vec![[0.0; 3]; scene.mesh.positions.len()];
    for &v in &scene.loaded {
        loads[v as usize] = [force_n / scene.loaded.len() as f64, 0.0, 0.0];
    }
    let materials = TetMaterials::uniform(scene.material, scene.mesh.tets.len());
    let problem = StaticProblem {
        positions: &scene.mesh.positions,
        tets: &scene.mesh.tets,
        materials: &materials,
        fixed: &scene.fixed,
        prescribed: &[],
        loads_n: &loads,
    };
    let newton = solve_neo_hookean(&problem, &NewtonOptions::default()).expect("newton");
    let (linear, _) = solve_loaded(
        &scene.mesh.positions,
        &scene.mesh.tets,
        &materials,
        &scene.fixed,
        &[],
        &loads,
    )
    .expect("linear");
    (newton.u, linear)
}

/// `‖a − b‖₂ / ‖b‖₂` over all vertices (also `host::neo_hookean_kernel`'s).
pub fn relative(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    let diff: f64 = a
        .iter()
        .zip(b)
        .map(|(x, y)| (Vector3::from(*x) - Vector3::from(*y)).norm_squared())
        .sum();
    let norm: f64 = b.iter().map(|y| Vector3::from(*y).norm_squared()).sum();
    (diff / norm).sqrt()
}

/// At small strain neo-Hookean is linear elasticity with the same Lamé
/// coefficients: under a load bending the cylinder by about 1e-5 of its
/// height, Newton's field equals the linear direct solve within 1e-4
/// relative (L2; the non-linear terms are of the order of the displacement
/// gradient, about 1e-5, times a factor of a few). At 100× the load the
/// difference grows about 100× (the first non-linear term is linear in the
/// load): the agreement is the limit, not a coincidence.
#[test]
fn small_strain_limit_is_linear_elasticity() {
    let (n1, l1) = bend(1e-6);
    let (n2, l2) = bend(1e-4);
    let (d1, d2) = (relative(&n1, &l1), relative(&n2, &l2));
    println!("neo-Hookean vs linear: {d1:.3e} at 1e-6 N, {d2:.3e} at 1e-4 N");
    assert!(d1 <= 1e-4);
    assert!((50.0..=200.0).contains(&(d2 / d1)), "growth {}", d2 / d1);
}
