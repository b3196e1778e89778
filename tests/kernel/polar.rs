//! The closest rotation of a 3×3 matrix (`palpate_kernel::math::polar`,
//! the co-rotational law's `R`) on random matrices with known singular
//! values, including inverted, nearly singular, rank-one and zero ones:
//! orthonormal, `det R = +1`, `RᵀF` symmetric (the polar condition), and no
//! nearby rotation closer to `F` (`tr(QᵀF)` largest at `Q = R`).

use nalgebra::{Matrix3, Rotation3, Vector3};
use palpate_kernel::math::polar::closest_rotation;
use palpate_tests::Lcg;

fn rows(m: &Matrix3<f64>) -> [[f64; 3]; 3] {
    [
        [m[(0, 0)], m[(0, 1)], m[(0, 2)]],
        [m[(1, 0)], m[(1, 1)], m[(1, 2)]],
        [m[(2, 0)], m[(2, 1)], m[(2, 2)]],
    ]
}

fn matrix(r: &[[f64; 3]; 3]) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| r[i][j])
}

fn random_rotation(rng: &mut Lcg) -> Matrix3<f64> {
    let axis = Vector3::new(rng.signed(), rng.signed(), rng.signed());
    let angle = core::f64::consts::PI * rng.signed();
    *Rotation3::new(axis.normalize() * angle).matrix()
}

/// `Q₁ diag(s) Q₂` for random rotations: a matrix with singular values
/// `|s|` and determinant sign `sign(s₁s₂s₃)`.
fn with_singular_values(rng: &mut Lcg, s: [f64; 3]) -> Matrix3<f64> {
    random_rotation(rng) * Matrix3::from_diagonal(&Vector3::from(s)) * random_rotation(rng)
}

/// The singular-value triples tested: well conditioned, stretched,
/// inverted (one negative), nearly singular (1e-6, 1e-9), rank one, zero.
const CASES: [[f64; 3]; 9] = [
    [1.0, 1.0, 1.0],
    [1.3, 0.9, 0.7],
    [3.0, 1.0, 0.2],
    [1.2, 0.8, -0.5],
    [1.0, 1.0, -1.0],
    [2.0, 1.0, 1e-6],
    [1.0, 0.5, -1e-9],
    [1.0, 0.0, 0.0],
    [0.0, 0.0, 0.0],
];

/// f64, 100 random matrices per case. Orthonormality and `det R` within
/// 1e-13 (rounding of a product of 12 Givens rotations and a twice
/// orthogonalized frame; measured about 1e-15). `RᵀF − FᵀR` within 1e-11 |F|
/// (four Jacobi sweeps converge to rounding; measured about 1e-15) when
/// the two largest singular values are nonzero (otherwise the closest
/// rotation is not unique and only orthonormality is asked); no rotation
/// `R exp(±0.01 e_k)` has a larger `tr(QᵀF)` by more than 1e-12 |F|.
#[test]
fn closest_rotation_is_a_proper_rotation_satisfying_the_polar_condition() {
    let mut rng = Lcg(11);
    let mut worst_orthonormal: f64 = 0.0;
    let mut worst_symmetry: f64 = 0.0;
    for s in CASES {
        for _ in 0..100 {
            let f = with_singular_values(&mut rng, s);
            let r = matrix(&closest_rotation(&rows(&f)));
            let orthonormal = (r.transpose() * r - Matrix3::identity()).abs().max();
            let det = r.determinant();
            assert!(orthonormal <= 1e-13, "{s:?}: RᵀR − I = {orthonormal:e}");
            assert!((det - 1.0).abs() <= 1e-13, "{s:?}: det R = {det}");
            worst_orthonormal = worst_orthonormal.max(orthonormal);
            let norm = f.norm();
            if s[1] == 0.0 {
                continue;
            }
            let g = r.transpose() * f;
            let symmetry = (g - g.transpose()).abs().max() / norm;
            assert!(
                symmetry <= 1e-11,
                "{s:?}: RᵀF asymmetric by {symmetry:e} |F|"
            );
            worst_symmetry = worst_symmetry.max(symmetry);
            let trace = g.trace();
            for axis in [Vector3::x(), Vector3::y(), Vector3::z()] {
                for angle in [0.01, -0.01] {
                    let q = r * Rotation3::new(axis * angle).matrix();
                    let other = (q.transpose() * f).trace();
                    assert!(
                        other <= trace + 1e-12 * norm,
                        "{s:?}: a rotation {angle} about {axis:?} is closer"
                    );
                }
            }
        }
    }
    println!("|RᵀR − I| ≤ {worst_orthonormal:.1e}, |RᵀF − FᵀR| ≤ {worst_symmetry:.1e} |F|");
}

/// The same in f32 (the firmware's and the bench's precision): orthonormal
/// and `det R = 1` within 1e-5 (a few f32 roundings, 1.2e-7 each, through
/// the 12 rotations); `RᵀF` symmetric within 1e-4 |F| for singular-value
/// ratios up to 15 (eigenvectors of `FᵀF` lose accuracy with the ratio
/// squared).
#[test]
fn closest_rotation_in_f32_is_orthonormal() {
    let mut rng = Lcg(12);
    for s in CASES {
        for _ in 0..100 {
            let f = with_singular_values(&mut rng, s);
            let f32_rows = rows(&f).map(|row| row.map(|x| x as f32));
            let r = closest_rotation(&f32_rows).map(|row| row.map(f64::from));
            let r = matrix(&r);
            let orthonormal = (r.transpose() * r - Matrix3::identity()).abs().max();
            assert!(orthonormal <= 1e-5, "{s:?}: RᵀR − I = {orthonormal:e}");
            assert!((r.determinant() - 1.0).abs() <= 1e-5, "{s:?}");
            if s[0] > 0.0 && s[2].abs() * 15.0 >= s[0] {
                let f = Matrix3::from_fn(|i, j| f64::from(f32_rows[i][j]));
                let g = r.transpose() * f;
                let symmetry = (g - g.transpose()).abs().max() / f.norm();
                assert!(
                    symmetry <= 1e-4,
                    "{s:?}: RᵀF asymmetric by {symmetry:e} |F|"
                );
            }
        }
    }
}

/// A rotation is its own closest rotation, and a symmetric positive
/// definite matrix has `R = I`, both to 1e-14.
#[test]
fn rotations_and_pure_stretches_are_recovered() {
    let mut rng = Lcg(13);
    for _ in 0..100 {
        let q = random_rotation(&mut rng);
        let r = matrix(&closest_rotation(&rows(&q)));
        assert!((r - q).abs().max() <= 1e-14, "{q}");
        let a = random_rotation(&mut rng);
        let d = Matrix3::from_diagonal(&Vector3::new(1.2, 0.9, 0.95));
        let spd = a * d * a.transpose();
        let r = matrix(&closest_rotation(&rows(&spd)));
        assert!((r - Matrix3::identity()).abs().max() <= 1e-14, "{spd}");
    }
}
