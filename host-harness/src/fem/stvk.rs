//! The St Venant-Kirchhoff tetrahedron of the host's Newton reference
//! ([`super::newton`]), written from the continuum definitions and not from
//! the kernel's tensor-mass forms, so that the reference is independent of
//! the code it checks (Picinbono 2001 §2; MODELS.md §4):
//!
//! `F = Σ_j x_j a_jᵀ` (`a_j = ∇Λ_j` at rest), `E = ½(FᵀF − I)`,
//! `S = λ tr(E) I + 2μE`, `P = FS`, `W = V₀ (λ/2 (tr E)² + μ tr(E²))`,
//! force on vertex `j` `f_j = −∂W/∂x_j = −V₀ P a_j`, and the tangent
//! stiffness `K_jk = −∂f_j/∂x_k`: for `dx_k = e_c`, `dF = e_c a_kᵀ`,
//! `dE = sym(Fᵀ dF)`, `dS = λ tr(dE) I + 2μ dE`, `dP = dF S + F dS`, column
//! `c` of `K_jk` is `V₀ dP a_j`.

use nalgebra::{Matrix3, Vector3};

use super::element::shape_gradients;
use super::material::Material;

/// One tet's rest shape and material.
#[derive(Clone, Copy, Debug)]
pub struct StvkTet {
    /// `a_j = ∇Λ_j` at rest, 1/m.
    gradients: [Vector3<f64>; 4],
    /// Rest volume `V₀`, m³.
    volume_m3: f64,
    /// Lamé λ, μ, Pa.
    lambda_pa: f64,
    mu_pa: f64,
}

impl StvkTet {
    /// The tet with rest positions `rest` (m, positively oriented) of `material`.
    pub fn new(rest: &[[f64; 3]; 4], material: &Material) -> Self {
        let (a, volume) = shape_gradients(rest);
        let (lambda_pa, mu_pa) = material.lame();
        Self {
            gradients: a.map(Vector3::from),
            volume_m3: volume.abs(),
            lambda_pa,
            mu_pa,
        }
    }

    /// `F` at current positions `x` (m).
    pub fn deformation_gradient(&self, x: &[[f64; 3]; 4]) -> Matrix3<f64> {
        x.iter()
            .zip(&self.gradients)
            .map(|(xj, aj)| Vector3::from(*xj) * aj.transpose())
            .sum()
    }

    /// `S` of the Green strain `e`, Pa.
    fn pk2(&self, e: &Matrix3<f64>) -> Matrix3<f64> {
        Matrix3::identity() * (self.lambda_pa * e.trace()) + e * (2.0 * self.mu_pa)
    }

    /// Green strain of `F`.
    fn green(f: &Matrix3<f64>) -> Matrix3<f64> {
        (f.transpose() * f - Matrix3::identity()) * 0.5
    }

    /// Elastic energy `W` at `x`, J.
    pub fn energy_j(&self, x: &[[f64; 3]; 4]) -> f64 {
        let e = Self::green(&self.deformation_gradient(x));
        self.volume_m3 * (0.5 * self.lambda_pa * e.trace().powi(2) + self.mu_pa * (e * e).trace())
    }

    /// The force on each vertex at `x`, N.
    pub fn forces_n(&self, x: &[[f64; 3]; 4]) -> [Vector3<f64>; 4] {
        let f = self.deformation_gradient(x);
        let p = f * self.pk2(&Self::green(&f));
        self.gradients.map(|a| -(p * a) * self.volume_m3)
    }

    /// The tangent stiffness at `x` as 4×4 blocks of 3×3, N/m:
    /// `K[j][k][a][c] = −∂f_{j,a}/∂x_{k,c}` (symmetric; at rest the linear
    /// element stiffness).
    pub fn tangent(&self, x: &[[f64; 3]; 4]) -> [[[[f64; 3]; 3]; 4]; 4] {
        let f = self.deformation_gradient(x);
        let s = self.pk2(&Self::green(&f));
        let mut k = [[[[0.0; 3]; 3]; 4]; 4];
        for (kk, ak) in self.gradients.iter().enumerate() {
            for c in 0..3 {
                let df = Vector3::ith(c, 1.0) * ak.transpose();
                let ftdf = f.transpose() * df;
                let de = (ftdf + ftdf.transpose()) * 0.5;
                let dp = df * s + f * self.pk2(&de);
                for (row, aj) in k.iter_mut().zip(&self.gradients) {
                    let column = dp * aj * self.volume_m3;
                    for (entry, value) in row[kk].iter_mut().zip(column.iter()) {
                        entry[c] = *value;
                    }
                }
            }
        }
        k
    }
}
