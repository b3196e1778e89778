//! The quasi-non-linear remap of the pre-computed model (Cotin 1999, TVCG
//! §3; MODELS.md §7).
//!
//! The linear pre-computed solution keeps its deformation law; only
//! amplitudes change, along the direction `d̂` of an imposed constraint
//! (a contact's imposed displacement, normalized):
//! - each contact force's colinear amplitude `g_p·d̂_p` becomes
//!   `ψ(g_p·d̂_p)` (sign kept) along its own contact's direction; its
//!   orthogonal part keeps its linear value;
//! - each vertex's linear displacement `u` is split into its colinear part
//!   `(u·d̂) d̂` and its orthogonal part `u⊥`, `d̂` the direction of the
//!   contact with the largest imposed displacement (Cotin's single tool
//!   point has one; a pinch's two opposed jaws give the same field, since
//!   the split does not depend on the sign of `d̂`); the colinear amplitude
//!   keeps its linear value (the compression test imposes it: the axial
//!   displacement is the test's independent variable) and the orthogonal
//!   amplitude `|u⊥|` becomes `φ(|u⊥|)`, the measured radial displacement as
//!   a function of the linear one.
//!
//! Both maps are odd, so a direction's sign never matters. A contact on a
//! triangle has its three vertices remapped, so the remapped surface no
//! longer passes exactly through the tool point (a rendering effect; the
//! force is the remapped contact force).
//!
//! `φ` and `ψ` are [`Remap`]s, polynomials fitted on the host to a
//! compression test's force/axial/radial curves. Cost: one polynomial per
//! vertex (Horner, [`REMAP_DEGREE`] multiply-adds) and one per contact.

use core::fmt;

use nalgebra::Vector3;

use crate::Real;

/// Highest polynomial degree of a [`Remap`]: Cotin fits degrees up to
/// about 5 depending on the precision needed.
pub const REMAP_DEGREE: usize = 5;

/// Why a [`Remap`] or [`QuasiNonLinear`] was refused.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RemapError {
    /// A coefficient or the fitted range is not finite.
    NonFinite,
    /// The fitted range's end is not positive.
    EmptyRange,
    /// The polynomial decreases inside its fitted range: an amplitude would
    /// shrink as the load grows. `at` is the first sample (input units)
    /// where its slope is negative.
    Decreasing {
        /// Input amplitude, m or N.
        at: f64,
    },
}

impl fmt::Display for RemapError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NonFinite => write!(f, "remap coefficient or range is not finite"),
            Self::EmptyRange => write!(f, "remap range end is not positive"),
            Self::Decreasing { at } => {
                write!(
                    f,
                    "remap polynomial decreases at input {at:e} inside its range"
                )
            }
        }
    }
}

impl core::error::Error for RemapError {}

/// A monotone amplitude map `x ↦ Σ_{k=1..}c_k x^k` on `[0, x_max]` (no
/// constant term: a zero linear amplitude stays zero), continued beyond
/// `x_max` by its tangent there, so an amplitude past the fitted data grows
/// linearly instead of following a polynomial's tail. Negative inputs map
/// to `-φ(-x)` (odd continuation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Remap<T: Real> {
    coefficients: [T; REMAP_DEGREE],
    x_max: T,
}

impl<T: Real> Remap<T> {
    /// Samples of the monotonicity check over `[0, x_max]`.
    const MONOTONE_SAMPLES: u32 = 64;

    /// The identity `φ(x) = x`.
    pub fn identity() -> Self {
        let mut coefficients = [T::zero(); REMAP_DEGREE];
        coefficients[0] = T::one();
        Self {
            coefficients,
            x_max: T::one(),
        }
    }

    /// The map with `coefficients[k − 1] = c_k` (units: output per input^k)
    /// fitted on `[0, x_max]`. Checked: finite, `x_max > 0`, and a
    /// non-negative slope at 65 evenly spaced points of the range and at
    /// its end (so the tangent continuation does not decrease either).
    pub fn new(coefficients: [T; REMAP_DEGREE], x_max: T) -> Result<Self, RemapError> {
        if !x_max.finite() || !coefficients.iter().all(|c| c.finite()) {
            return Err(RemapError::NonFinite);
        }
        if x_max <= T::zero() {
            return Err(RemapError::EmptyRange);
        }
        let remap = Self {
            coefficients,
            x_max,
        };
        for i in 0..=Self::MONOTONE_SAMPLES {
            let x = x_max * T::of_f64(f64::from(i) / f64::from(Self::MONOTONE_SAMPLES));
            if remap.value_and_slope(x).1 < T::zero() {
                return Err(RemapError::Decreasing { at: x.as_f64() });
            }
        }
        Ok(remap)
    }

    /// The coefficients `c_1..c_D`.
    pub fn coefficients(&self) -> &[T; REMAP_DEGREE] {
        &self.coefficients
    }

    /// End of the fitted range, input units.
    pub fn x_max(&self) -> T {
        self.x_max
    }

    /// `φ(x)` and `φ'(x)` on the polynomial (Horner), for `0 ≤ x ≤ x_max`.
    fn value_and_slope(&self, x: T) -> (T, T) {
        // p(x) = Σ c_k x^(k−1), φ = x p, φ' = p + x p'.
        let (mut p, mut dp) = (T::zero(), T::zero());
        for &c in self.coefficients.iter().rev() {
            dp = dp * x + p;
            p = p * x + c;
        }
        (x * p, p + x * dp)
    }

    /// `φ(x)`: the polynomial on `[0, x_max]`, its tangent beyond, odd for
    /// `x < 0`.
    pub fn apply(&self, x: T) -> T {
        let magnitude = x.abs();
        let mapped = if magnitude <= self.x_max {
            self.value_and_slope(magnitude).0
        } else {
            let (end, slope) = self.value_and_slope(self.x_max);
            end + slope * (magnitude - self.x_max)
        };
        if x < T::zero() { -mapped } else { mapped }
    }
}

/// The two remaps of the quasi-non-linear model: `φ` on the orthogonal
/// displacement amplitude (m → m) and `ψ` on the colinear contact force
/// amplitude (N → N). See the module documentation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuasiNonLinear<T: Real> {
    /// `φ`: the radial (orthogonal) displacement amplitude, m → m.
    pub radial: Remap<T>,
    /// `ψ`: the colinear contact force amplitude, N → N.
    pub force: Remap<T>,
}

impl<T: Real> QuasiNonLinear<T> {
    /// The direction `d̂` of an imposed displacement `displacement_m`:
    /// normalized; `None` (no remap) below `1e-12` m, where no direction is
    /// defined.
    pub fn direction(displacement_m: &Vector3<T>) -> Option<Vector3<T>> {
        let norm = displacement_m.norm();
        (norm > T::of_f64(1e-12) && norm.finite()).then(|| displacement_m / norm)
    }

    /// `u` with its orthogonal amplitude remapped by `φ`, m.
    pub fn displacement(&self, direction: &Vector3<T>, u: Vector3<T>) -> Vector3<T> {
        let colinear = direction * u.dot(direction);
        let orthogonal = u - colinear;
        let amplitude = orthogonal.norm();
        if amplitude > T::zero() {
            colinear + orthogonal * (self.radial.apply(amplitude) / amplitude)
        } else {
            u
        }
    }

    /// `g` with its colinear amplitude remapped by `ψ`, N.
    pub fn force(&self, direction: &Vector3<T>, g: Vector3<T>) -> Vector3<T> {
        let amplitude = g.dot(direction);
        g + direction * (self.force.apply(amplitude) - amplitude)
    }
}
