//! Isotropic linear elastic material (Young's modulus, Poisson ratio).

/// Why a [`Material`] was rejected.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum MaterialError {
    /// Young's modulus must be finite and strictly positive (Pa).
    #[error("Young's modulus must be finite and > 0 Pa, got {0}")]
    YoungModulus(f64),
    /// Poisson ratio must satisfy `0 <= nu < 0.5`.
    #[error("Poisson ratio must satisfy 0 <= nu < 0.5, got {0}")]
    PoissonRatio(f64),
}

/// Isotropic linear elastic material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Young's modulus `E`, Pa.
    pub young_pa: f64,
    /// Poisson ratio `nu`, dimensionless, `0 <= nu < 0.5`.
    pub poisson: f64,
}

impl Material {
    /// A material with Young's modulus `young_pa` (Pa, finite, `> 0`) and Poisson
    /// ratio `poisson` (`0 <= nu < 0.5`, incompressible `0.5` excluded).
    pub fn new(young_pa: f64, poisson: f64) -> Result<Self, MaterialError> {
        if !(young_pa.is_finite() && young_pa > 0.0) {
            return Err(MaterialError::YoungModulus(young_pa));
        }
        if !(poisson.is_finite() && (0.0..0.5).contains(&poisson)) {
            return Err(MaterialError::PoissonRatio(poisson));
        }
        Ok(Self { young_pa, poisson })
    }

    /// Lamé coefficients `(lambda, mu)` in Pa (`MODELS.md` §1):
    /// `lambda = E nu / ((1 + nu)(1 - 2 nu))`, `mu = E / (2 (1 + nu))`.
    pub fn lame(&self) -> (f64, f64) {
        palpate_kernel::math::element::lame(self.young_pa, self.poisson)
    }
}
