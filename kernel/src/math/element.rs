//! The linear P1 tetrahedron (MODELS.md §1; Cotin RR-3510 §4): the one
//! stiffness-block formula shared by the host's assembly and the tensor-mass
//! table builder, and the one a local tet removal must subtract (each tet's
//! rest gradients and volume are in the table for that).

use nalgebra::{Matrix3, Vector3};

use crate::Real;

/// Lamé coefficients `(λ, μ)` in Pa from Young's modulus `young_pa` (Pa) and
/// Poisson ratio `poisson` (MODELS.md §1):
/// `λ = Eν/((1+ν)(1−2ν))`, `μ = E/(2(1+ν))`.
pub fn lame(young_pa: f64, poisson: f64) -> (f64, f64) {
    let lambda = young_pa * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson));
    let mu = young_pa / (2.0 * (1.0 + poisson));
    (lambda, mu)
}

/// The 3×3 stiffness block `K_jk` (N/m) of a tet with volume `volume_m3`
/// (m³, positive) coupling its local vertices `j` and `k`, whose
/// shape-function gradients are `a_j`, `a_k` (1/m), for Lamé coefficients
/// `lambda`, `mu` (Pa):
///
/// `K_jk = V (λ a_j a_kᵀ + μ a_k a_jᵀ + μ (a_j·a_k) I)` (MODELS.md §1), with
/// the sign convention `f_j = −Σ_k K_jk u_k`; `K_kj = K_jkᵀ`.
pub fn stiffness_block<T: Real>(
    a_j: &Vector3<T>,
    a_k: &Vector3<T>,
    volume_m3: T,
    lambda: T,
    mu: T,
) -> Matrix3<T> {
    let diagonal = Matrix3::from_diagonal_element(mu * a_j.dot(a_k));
    (a_j * a_k.transpose() * lambda + a_k * a_j.transpose() * mu + diagonal) * volume_m3
}
