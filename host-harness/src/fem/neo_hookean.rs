//! The compressible neo-Hookean tetrahedron (Bonet & Wood, *Nonlinear
//! Continuum Mechanics for Finite Element Analysis*, 2nd ed., §6.4.3): the
//! law of the speed/accuracy study's truth, solved by the Newton solver
//! ([`super::newton::solve_neo_hookean`]). Strain energy density, Pa:
//!
//! `ψ(F) = μ/2 (I₁ − 3) − μ ln J + λ/2 (ln J)²`, `I₁ = tr(FᵀF)`, `J = det F`,
//!
//! `+∞` for `J ≤ 0` (an inverted tet has no energy: the solver rejects a
//! step that inverts one). First Piola-Kirchhoff stress
//! `P = μ (F − F⁻ᵀ) + λ ln J F⁻ᵀ` and its differential
//! `dP = μ dF + (μ − λ ln J) F⁻ᵀ dFᵀ F⁻ᵀ + λ tr(F⁻¹ dF) F⁻ᵀ`
//! (from `d(F⁻ᵀ) = −F⁻ᵀ dFᵀ F⁻ᵀ`, `d ln J = tr(F⁻¹ dF)`); at `F = I` it
//! is the linear elastic `μ (dF + dFᵀ) + λ tr(dF) I`, so the small-strain
//! limit is linear elasticity with the same Lamé λ, μ. Forces and tangent
//! from `P` and `dP`: [`RestTet`].

use nalgebra::{Matrix3, Vector3};

use super::hyperelastic::{HyperelasticTet, RestTet, TetTangent};
use super::material::Material;

/// One tet's rest shape and material.
#[derive(Clone, Copy, Debug)]
pub struct NeoHookeanTet {
    /// Rest shape.
    rest: RestTet,
    /// Lamé λ, μ, Pa.
    lambda_pa: f64,
    mu_pa: f64,
}

impl NeoHookeanTet {
    /// `F` at `x`, `J = det F` and `F⁻ᵀ` (`None` where `J ≤ 0` or `F` is
    /// not finite).
    fn kinematics(&self, x: &[[f64; 3]; 4]) -> Option<(Matrix3<f64>, f64, Matrix3<f64>)> {
        let f = self.rest.deformation_gradient(x);
        let j = f.determinant();
        if !(j > 0.0 && j.is_finite()) {
            return None;
        }
        let f_inv_t = f.try_inverse()?.transpose();
        Some((f, j, f_inv_t))
    }

    /// `P` at `x`, Pa (non-finite where `J ≤ 0`).
    pub fn pk1(&self, x: &[[f64; 3]; 4]) -> Matrix3<f64> {
        match self.kinematics(x) {
            Some((f, j, f_inv_t)) => {
                (f - f_inv_t) * self.mu_pa + f_inv_t * (self.lambda_pa * j.ln())
            }
            None => Matrix3::from_element(f64::NAN),
        }
    }
}

impl HyperelasticTet for NeoHookeanTet {
    fn at_rest(rest: &[[f64; 3]; 4], material: &Material) -> Self {
        let (lambda_pa, mu_pa) = material.lame();
        Self {
            rest: RestTet::new(rest),
            lambda_pa,
            mu_pa,
        }
    }

    fn energy_j(&self, x: &[[f64; 3]; 4]) -> f64 {
        let Some((f, j, _)) = self.kinematics(x) else {
            return f64::INFINITY;
        };
        let ln_j = j.ln();
        let i1 = (f.transpose() * f).trace();
        self.rest.volume_m3()
            * (0.5 * self.mu_pa * (i1 - 3.0) - self.mu_pa * ln_j
                + 0.5 * self.lambda_pa * ln_j * ln_j)
    }

    /// Non-finite where `J ≤ 0`.
    fn forces_n(&self, x: &[[f64; 3]; 4]) -> [Vector3<f64>; 4] {
        self.rest.forces_n(&self.pk1(x))
    }

    /// Non-finite where `J ≤ 0`.
    fn tangent(&self, x: &[[f64; 3]; 4]) -> TetTangent {
        let Some((_, j, f_inv_t)) = self.kinematics(x) else {
            return [[[[f64::NAN; 3]; 3]; 4]; 4];
        };
        let (lambda, mu) = (self.lambda_pa, self.mu_pa);
        let ln_j = j.ln();
        self.rest.tangent(|df| {
            df * mu
                + f_inv_t * df.transpose() * f_inv_t * (mu - lambda * ln_j)
                + f_inv_t * (lambda * (f_inv_t.transpose() * df).trace())
        })
    }

    fn admissible(&self, x: &[[f64; 3]; 4]) -> bool {
        self.kinematics(x).is_some()
    }
}
