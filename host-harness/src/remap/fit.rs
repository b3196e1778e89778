//! Least-squares fits of the remaps (Cotin 1999 TVCG §3: "least squares
//! minimization to find the polynomial function approximating" each curve).

use anyhow::{Context, ensure};
use nalgebra::{DMatrix, DVector};
use palpate_kernel::precomputed::{QuasiNonLinear, REMAP_DEGREE, Remap};
use serde::Serialize;

use super::curves::CurvePoint;
use super::sample::LinearResponse;

/// A fitted remap and how well it fits.
#[derive(Clone, Debug, Serialize)]
pub struct FittedRemap {
    /// `c_1..c_D` of `φ(x) = Σ c_k x^k` (zeros above the fitted degree).
    pub coefficients: [f64; REMAP_DEGREE],
    /// End of the fitted range: the largest input of the data.
    pub x_max: f64,
    /// Largest `|φ(x_i) − y_i|` over the data, output units.
    pub max_residual: f64,
}

impl FittedRemap {
    /// The kernel's remap (monotonicity checked there).
    pub fn remap<T: palpate_kernel::Real>(&self) -> anyhow::Result<Remap<T>> {
        Remap::new(self.coefficients.map(T::of_f64), T::of_f64(self.x_max))
            .context("fitted remap refused")
    }
}

/// The least-squares polynomial `φ(x) = Σ_{k=1..degree} c_k x^k` (no
/// constant term: zero stays zero) through `(x_i, y_i)`. Solved on the
/// scaled input `x/x_max` (a Vandermonde matrix of entries in `[0, 1]`) by
/// SVD, then unscaled: `c_k = ĉ_k / x_max^k`.
pub fn fit_polynomial(points: &[(f64, f64)], degree: usize) -> anyhow::Result<FittedRemap> {
    ensure!(
        (1..=REMAP_DEGREE).contains(&degree),
        "degree {degree} outside 1..={REMAP_DEGREE}"
    );
    ensure!(
        points.len() >= degree,
        "{} points cannot fix a degree-{degree} polynomial",
        points.len()
    );
    let x_max = points.iter().map(|p| p.0.abs()).fold(0.0, f64::max);
    ensure!(x_max > 0.0 && x_max.is_finite(), "no positive input to fit");
    let a = DMatrix::from_fn(points.len(), degree, |i, k| {
        (points[i].0 / x_max).powi(k as i32 + 1)
    });
    let b = DVector::from_iterator(points.len(), points.iter().map(|p| p.1));
    let scaled = a
        .svd(true, true)
        .solve(&b, 1e-12)
        .map_err(|e| anyhow::anyhow!("least squares: {e}"))?;
    let mut coefficients = [0.0; REMAP_DEGREE];
    for (k, c) in scaled.iter().enumerate() {
        coefficients[k] = c / x_max.powi(k as i32 + 1);
    }
    let evaluate = |x: f64| coefficients.iter().rev().fold(0.0, |acc, &c| acc * x + c) * x;
    let max_residual = points
        .iter()
        .map(|&(x, y)| (evaluate(x) - y).abs())
        .fold(0.0, f64::max);
    Ok(FittedRemap {
        coefficients,
        x_max,
        max_residual,
    })
}

/// Both remaps of a compression test.
#[derive(Clone, Debug, Serialize)]
pub struct FittedModel {
    /// `φ`: measured radial displacement as a function of the linear one, m → m.
    pub radial: FittedRemap,
    /// `ψ`: measured force as a function of the linear one, N → N.
    pub force: FittedRemap,
    /// The linear sample's response the inputs come from.
    pub linear: LinearResponse,
}

impl FittedModel {
    /// The kernel's [`QuasiNonLinear`].
    pub fn kernel<T: palpate_kernel::Real>(&self) -> anyhow::Result<QuasiNonLinear<T>> {
        Ok(QuasiNonLinear {
            radial: self.radial.remap()?,
            force: self.force.remap()?,
        })
    }
}

/// Fits `φ` and `ψ` of degree `degree` to `curves`: each measured value
/// against the linear sample's value at the same compression (Cotin: the
/// curves "expressed as functions of the linear displacement (resp. linear
/// force)").
pub fn fit_curves(
    curves: &[CurvePoint],
    linear: &LinearResponse,
    degree: usize,
) -> anyhow::Result<FittedModel> {
    let radial: Vec<(f64, f64)> = curves
        .iter()
        .map(|p| (linear.radial_per_axial * p.axial_m, p.radial_m))
        .collect();
    let force: Vec<(f64, f64)> = curves
        .iter()
        .map(|p| (linear.force_n_per_m * p.axial_m, p.force_n))
        .collect();
    Ok(FittedModel {
        radial: fit_polynomial(&radial, degree).context("radial curve")?,
        force: fit_polynomial(&force, degree).context("force curve")?,
        linear: linear.clone(),
    })
}
