//! The compressible neo-Hookean tetrahedron (Bonet & Wood, *Nonlinear
//! Continuum Mechanics for Finite Element Analysis*, 2nd ed., §6.4.3): the
//! law of the speed/accuracy study's truth, solved by the Newton solver
//! ([`super::newton::solve_neo_hookean`]; the 10-node element of the same
//! law: [`super::neo_hookean_p2`]). Strain energy density, Pa:
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

/// The law's constants, Lamé λ, μ (Pa), and its functions of `F`, shared by
/// the P1 tet ([`NeoHookeanTet`]) and the P2 tet
/// ([`super::neo_hookean_p2`]).
#[derive(Clone, Copy, Debug)]
pub struct NeoHookeanLaw {
    /// Lamé λ, μ, Pa.
    lambda_pa: f64,
    mu_pa: f64,
}

impl NeoHookeanLaw {
    /// The law with `material`'s Lamé constants.
    pub fn new(material: &Material) -> Self {
        let (lambda_pa, mu_pa) = material.lame();
        Self { lambda_pa, mu_pa }
    }

    /// `J = det F` and `F⁻ᵀ` (`None` where `J ≤ 0` or `F` is not finite).
    pub fn invert(f: &Matrix3<f64>) -> Option<(f64, Matrix3<f64>)> {
        let j = f.determinant();
        if !(j > 0.0 && j.is_finite()) {
            return None;
        }
        Some((j, f.try_inverse()?.transpose()))
    }

    /// `ψ(F)`, Pa (J/m³); `+∞` where `J ≤ 0`.
    pub fn density_pa(&self, f: &Matrix3<f64>) -> f64 {
        let Some((j, _)) = Self::invert(f) else {
            return f64::INFINITY;
        };
        let ln_j = j.ln();
        let i1 = (f.transpose() * f).trace();
        0.5 * self.mu_pa * (i1 - 3.0) - self.mu_pa * ln_j + 0.5 * self.lambda_pa * ln_j * ln_j
    }

    /// `P(F)`, Pa (non-finite where `J ≤ 0`).
    pub fn pk1(&self, f: &Matrix3<f64>) -> Matrix3<f64> {
        match Self::invert(f) {
            Some((j, f_inv_t)) => (f - f_inv_t) * self.mu_pa + f_inv_t * (self.lambda_pa * j.ln()),
            None => Matrix3::from_element(f64::NAN),
        }
    }

    /// The differential `dF ↦ dP` at `F` (`J`, `F⁻ᵀ` from
    /// [`Self::invert`]), Pa.
    pub fn differential(
        &self,
        j: f64,
        f_inv_t: Matrix3<f64>,
    ) -> impl Fn(&Matrix3<f64>) -> Matrix3<f64> {
        let (lambda, mu) = (self.lambda_pa, self.mu_pa);
        let ln_j = j.ln();
        move |df| {
            df * mu
                + f_inv_t * df.transpose() * f_inv_t * (mu - lambda * ln_j)
                + f_inv_t * (lambda * (f_inv_t.transpose() * df).trace())
        }
    }
}

/// One P1 tet's rest shape and law.
#[derive(Clone, Copy, Debug)]
pub struct NeoHookeanTet {
    /// Rest shape.
    rest: RestTet,
    /// The law.
    law: NeoHookeanLaw,
}

impl NeoHookeanTet {
    /// `P` at `x`, Pa (non-finite where `J ≤ 0`).
    pub fn pk1(&self, x: &[[f64; 3]; 4]) -> Matrix3<f64> {
        self.law.pk1(&self.rest.deformation_gradient(x))
    }
}

impl HyperelasticTet for NeoHookeanTet {
    fn at_rest(rest: &[[f64; 3]; 4], material: &Material) -> Self {
        Self {
            rest: RestTet::new(rest),
            law: NeoHookeanLaw::new(material),
        }
    }

    fn energy_j(&self, x: &[[f64; 3]; 4]) -> f64 {
        self.rest.volume_m3() * self.law.density_pa(&self.rest.deformation_gradient(x))
    }

    /// Non-finite where `J ≤ 0`.
    fn forces_n(&self, x: &[[f64; 3]; 4]) -> [Vector3<f64>; 4] {
        self.rest.forces_n(&self.pk1(x))
    }

    /// Non-finite where `J ≤ 0`.
    fn tangent(&self, x: &[[f64; 3]; 4]) -> TetTangent {
        match NeoHookeanLaw::invert(&self.rest.deformation_gradient(x)) {
            Some((j, f_inv_t)) => self.rest.tangent(self.law.differential(j, f_inv_t)),
            None => [[[[f64::NAN; 3]; 3]; 4]; 4],
        }
    }

    fn admissible(&self, x: &[[f64; 3]; 4]) -> bool {
        NeoHookeanLaw::invert(&self.rest.deformation_gradient(x)).is_some()
    }
}
