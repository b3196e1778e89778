//! The St Venant-Kirchhoff tetrahedron of the host's Newton reference
//! ([`super::newton`]), written from the continuum definitions and not from
//! the kernel's tensor-mass forms, so that the reference is independent of
//! the code it checks (Picinbono 2001 §2; MODELS.md §4):
//!
//! `E = ½(FᵀF − I)`, `S = λ tr(E) I + 2μE`, `P = FS`,
//! `W = V₀ (λ/2 (tr E)² + μ tr(E²))`, and the stress differential
//! `dE = sym(Fᵀ dF)`, `dS = λ tr(dE) I + 2μ dE`, `dP = dF S + F dS`
//! (the forces and the tangent from `P` and `dP`: [`RestTet`]).

use nalgebra::{Matrix3, Vector3};

use super::hyperelastic::{HyperelasticTet, RestTet, TetTangent};
use super::material::Material;

/// One tet's rest shape and material.
#[derive(Clone, Copy, Debug)]
pub struct StvkTet {
    /// Rest shape.
    rest: RestTet,
    /// Lamé λ, μ, Pa.
    lambda_pa: f64,
    mu_pa: f64,
}

impl StvkTet {
    /// The tet with rest positions `rest` (m, positively oriented) of `material`.
    pub fn new(rest: &[[f64; 3]; 4], material: &Material) -> Self {
        let (lambda_pa, mu_pa) = material.lame();
        Self {
            rest: RestTet::new(rest),
            lambda_pa,
            mu_pa,
        }
    }

    /// `F` at current positions `x` (m).
    pub fn deformation_gradient(&self, x: &[[f64; 3]; 4]) -> Matrix3<f64> {
        self.rest.deformation_gradient(x)
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
        self.rest.volume_m3()
            * (0.5 * self.lambda_pa * e.trace().powi(2) + self.mu_pa * (e * e).trace())
    }

    /// The force on each vertex at `x`, N.
    pub fn forces_n(&self, x: &[[f64; 3]; 4]) -> [Vector3<f64>; 4] {
        let f = self.deformation_gradient(x);
        self.rest.forces_n(&(f * self.pk2(&Self::green(&f))))
    }

    /// The tangent stiffness at `x` as 4×4 blocks of 3×3, N/m:
    /// `K[j][k][a][c] = −∂f_{j,a}/∂x_{k,c}` (symmetric; at rest the linear
    /// element stiffness).
    pub fn tangent(&self, x: &[[f64; 3]; 4]) -> TetTangent {
        let f = self.deformation_gradient(x);
        let s = self.pk2(&Self::green(&f));
        self.rest.tangent(|df| {
            let ftdf = f.transpose() * df;
            let de = (ftdf + ftdf.transpose()) * 0.5;
            df * s + f * self.pk2(&de)
        })
    }
}

impl HyperelasticTet for StvkTet {
    fn at_rest(rest: &[[f64; 3]; 4], material: &Material) -> Self {
        Self::new(rest, material)
    }
    fn energy_j(&self, x: &[[f64; 3]; 4]) -> f64 {
        StvkTet::energy_j(self, x)
    }
    fn forces_n(&self, x: &[[f64; 3]; 4]) -> [Vector3<f64>; 4] {
        StvkTet::forces_n(self, x)
    }
    fn tangent(&self, x: &[[f64; 3]; 4]) -> TetTangent {
        StvkTet::tangent(self, x)
    }
}
