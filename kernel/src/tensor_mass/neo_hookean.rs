//! The compressible neo-Hookean force per tet (Bonet & Wood, "Nonlinear
//! continuum mechanics for finite element analysis", 2nd ed., §6.4.3,
//! eq. 6.28; MODELS.md §8), on the blocks of the per-tet pass
//! ([`super::stvk`]).
//!
//! Energy density `ψ = μ/2 (I₁ − 3) + g(J)`, `I₁ = tr(FᵀF)`, `J = det F`,
//! with `g(J) = −μ ln J + λ/2 (ln J)²`; first Piola-Kirchhoff stress
//! `P = μ F + g'(J) cof F` (`∂J/∂F = cof F = J F⁻ᵀ`, so for `J > 0` this
//! is Bonet & Wood's `μ (F − F⁻ᵀ) + λ ln J F⁻ᵀ`); force on corner `j`
//! `f_j = −V P a_j`. At `F = I` it linearizes to the linear law with the
//! same `λ, μ`.
//!
//! Inverted and nearly inverted tets: `g` is undefined for `J ≤ 0` and
//! stiffens without bound as `J → 0`. Below the floor
//! [`NEO_HOOKEAN_J_FLOOR`] `J₀`, `g` is continued by its second-order Taylor
//! expansion at `J₀`:
//! `g(J) = g(J₀) + g'(J₀)(J − J₀) + ½ g''(J₀)(J − J₀)²`, with
//! `g'(J) = (λ ln J − μ)/J` and `g''(J) = (λ (1 − ln J) + μ)/J²`. The
//! energy stays C¹ (the force continuous) at `J₀`, and finite for every
//! finite `F`, also inverted (`J ≤ 0`); since `g'(J₀) < 0` and
//! `g''(J₀) > 0` (`J₀ < 1`), `g'(J) < 0` for every `J < J₀`: the volume
//! term always pushes the tet back towards positive volume, with a
//! stiffness `V g''(J₀)` that grows linearly in how far it is inverted.

use super::stvk::{Block, LANES, TetTerms};
use crate::Real;
use crate::math::polar::cofactor;
use crate::table::format::tet_lane_row;

/// The volume ratio `J₀` below which the neo-Hookean volume energy is its
/// quadratic continuation (see the module documentation). At `J₀ = 0.2`
/// the continuation's stiffness `g''(J₀)` is `(2.61 λ + μ)/0.04`, about 65
/// times the rest stiffness `λ + μ` for a nearly incompressible tissue:
/// large enough that the law is followed down to a fifth of the rest
/// volume, small enough that the explicit step is not ruined by a
/// collapsing tet.
pub const NEO_HOOKEAN_J_FLOOR: f64 = 0.2;

// As in `super::stvk`: literal indices < 3 and loop counters < LANES over
// fixed-size arrays; tools/nopanic-check proves no panic is left.
#[expect(
    clippy::indexing_slicing,
    reason = "indices are literals < 3, row constants < TET_LANE_ROWS and loop counters < LANES over fixed-size arrays"
)]
impl<T: Real> Block<'_, T> {
    /// Per lane, the gradients `V P a_j` (N, `j = 1..3`) of the neo-Hookean
    /// energy and the energies `V ψ` (J) (see the module documentation),
    /// each lane with its tet's `λ`, `μ`. A lane without a live tet has
    /// `F = I`: zero gradients and energy.
    ///
    /// Three lane loops: `J` (vectorized), `ln max(J, J₀)` (a
    /// [`Real::portable_ln`] call per lane: the same bits on every target), then the stress (vectorized, one division per lane: `g'` and
    /// `g''` share `1/max(J, J₀)`, and `J` is not computed twice).
    #[inline(always)]
    pub(super) fn neo_hookean(&self) -> TetTerms<T> {
        let z = [T::zero(); LANES];
        let floor = T::of_f64(NEO_HOOKEAN_J_FLOOR);
        let (mut dets, mut clamped) = (z, z);
        for (l, (det, j)) in dets.iter_mut().zip(&mut clamped).enumerate() {
            let [f0, f1, f2] = self.deformation(l);
            *det = f0[0] * (f1[1] * f2[2] - f1[2] * f2[1])
                + f0[1] * (f1[2] * f2[0] - f1[0] * f2[2])
                + f0[2] * (f1[0] * f2[1] - f1[1] * f2[0]);
            *j = det.larger(floor);
        }
        let mut logs = z;
        for (log, &j) in logs.iter_mut().zip(&clamped) {
            *log = j.portable_ln();
        }
        let mut gradients = [[z; 3]; 3];
        let mut energy = z;
        let (one, half) = (T::one(), T::of_f64(0.5));
        let rest = self.rest;
        let (volume, lambda, mu) = (
            &rest[tet_lane_row::VOLUME],
            &rest[tet_lane_row::LAMBDA],
            &rest[tet_lane_row::MU],
        );
        for l in 0..LANES {
            let (lambda, mu, v, jc, log) = (lambda[l], mu[l], volume[l], clamped[l], logs[l]);
            let f = self.deformation(l);
            let cof = cofactor(&f);
            // d = J − J₀ below the floor, 0 above it (then J = jc exactly).
            let d = dets[l] - jc;
            let inverse = one / jc;
            let g1 = (lambda * log - mu) * inverse;
            let g2 = (lambda * (one - log) + mu) * inverse * inverse;
            let g = (lambda * half * log - mu) * log + (g1 + half * g2 * d) * d;
            let slope = g1 + g2 * d;
            // V P = V (μ F + g'(J) cof F).
            let (mu_v, slope_v) = (mu * v, slope * v);
            let p = |r: usize| {
                [
                    mu_v * f[r][0] + slope_v * cof[r][0],
                    mu_v * f[r][1] + slope_v * cof[r][1],
                    mu_v * f[r][2] + slope_v * cof[r][2],
                ]
            };
            self.store_gradients(l, &[p(0), p(1), p(2)], &mut gradients);
            let [[f00, f01, f02], [f10, f11, f12], [f20, f21, f22]] = f;
            let i1 = f00 * f00
                + f01 * f01
                + f02 * f02
                + f10 * f10
                + f11 * f11
                + f12 * f12
                + f20 * f20
                + f21 * f21
                + f22 * f22;
            energy[l] = v * (mu * half * (i1 - T::of_f64(3.0)) + g);
        }
        (gradients, energy)
    }
}
