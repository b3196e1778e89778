//! The co-rotational linear force per tet (stiffness warping: Müller &
//! Gross 2004, "Interactive virtual materials", §4, eq. 10; SOFA's
//! `TetrahedronFEMForceField` method `large`; MODELS.md §8), on the blocks
//! of the per-tet pass ([`super::stvk`]).
//!
//! With `R` the proper rotation closest to the deformation gradient `F`
//! ([`closest_rotation`]), the element force
//! `f_e = −R K_e (Rᵀ x_e − X_e)` with `K_e` the linear tet stiffness
//! (MODELS.md §1, [`crate::math::element::stiffness_block`]) is, corner by
//! corner, `f_j = −V R σ a_j` with the linear stress `σ = λ tr(ε) I + 2μ ε`
//! of the strain `ε = sym(RᵀF) − I` (the gradient of the rotated-back
//! displacements `Rᵀ x_j − X_j` is `RᵀF − I`, and `K_e u` is `V σ(∇u) a_j`).
//!
//! Since `RᵀF` is symmetric for the polar rotation, `R σ = 2μ (F − R) +
//! λ tr(RᵀF − I) R`, the first Piola-Kirchhoff stress of the co-rotated
//! energy `ψ = μ |F − R|² + λ/2 (tr(RᵀF) − 3)²` (McAdams et al. 2011,
//! "Efficient elasticity for character skinning with contact and
//! collisions", §4): the force is the gradient of `V ψ`, which this pass
//! also returns. Zero for any rigid motion; the linear force for a pure
//! strain (`F` symmetric positive definite, `R = I`); rotating the
//! deformed state rotates the forces.

use super::stvk::{Block, LANES, Lanes, TetTerms};
use crate::Real;
use crate::math::polar::{Mat3, closest_rotations};
use crate::table::format::tet_lane_row;

#[expect(
    clippy::indexing_slicing,
    reason = "indices are literals < 3, row constants < TET_LANE_ROWS and loop counters < LANES over fixed-size arrays"
)]
impl<T: Real> Block<'_, T> {
    /// Per lane, the gradients `V R σ a_j` (N, `j = 1..3`) and the
    /// co-rotated energies `V ψ` (J) (see the module documentation), each
    /// lane with its tet's `λ`, `μ`. A lane without a live tet has `F = I`,
    /// `R = I`: zero gradients and energy.
    #[inline(always)]
    pub(super) fn corotational(&self) -> TetTerms<T> {
        let z = [T::zero(); LANES];
        let mut gradients = [[z; 3]; 3];
        let mut energy = z;
        let (one, half) = (T::one(), T::of_f64(0.5));
        let rest = self.rest;
        let (volume, lambda, mu) = (
            &rest[tet_lane_row::VOLUME],
            &rest[tet_lane_row::LAMBDA],
            &rest[tet_lane_row::MU],
        );
        // F per lane, then R for all lanes at once (its lane loops are
        // what vectorizes the polar step).
        let mut f_lanes: Mat3<Lanes<T>> = [[z; 3]; 3];
        for l in 0..LANES {
            let f = self.deformation(l);
            for (row, f_row) in f_lanes.iter_mut().zip(&f) {
                row[0][l] = f_row[0];
                row[1][l] = f_row[1];
                row[2][l] = f_row[2];
            }
        }
        let r_lanes = closest_rotations(&f_lanes);
        for l in 0..LANES {
            let (lambda, mu, v) = (lambda[l], mu[l], volume[l]);
            let f = self.deformation(l);
            let r = [0, 1, 2].map(|i| [0, 1, 2].map(|j| r_lanes[i][j][l]));
            // G = RᵀF; ε = sym(G) − I.
            let g: [[T; 3]; 3] = core::array::from_fn(|i| {
                core::array::from_fn(|k| r[0][i] * f[0][k] + r[1][i] * f[1][k] + r[2][i] * f[2][k])
            });
            let e00 = g[0][0] - one;
            let e11 = g[1][1] - one;
            let e22 = g[2][2] - one;
            let e01 = (g[0][1] + g[1][0]) * half;
            let e02 = (g[0][2] + g[2][0]) * half;
            let e12 = (g[1][2] + g[2][1]) * half;
            let trace = e00 + e11 + e22;
            let two_mu = mu + mu;
            // V σ, symmetric.
            let diagonal = lambda * trace;
            let sigma = [
                [
                    (diagonal + two_mu * e00) * v,
                    two_mu * e01 * v,
                    two_mu * e02 * v,
                ],
                [
                    two_mu * e01 * v,
                    (diagonal + two_mu * e11) * v,
                    two_mu * e12 * v,
                ],
                [
                    two_mu * e02 * v,
                    two_mu * e12 * v,
                    (diagonal + two_mu * e22) * v,
                ],
            ];
            // V P = R (V σ).
            let vp: [[T; 3]; 3] = core::array::from_fn(|i| {
                core::array::from_fn(|k| {
                    r[i][0] * sigma[0][k] + r[i][1] * sigma[1][k] + r[i][2] * sigma[2][k]
                })
            });
            self.store_gradients(l, &vp, &mut gradients);
            let squares = e00 * e00
                + e11 * e11
                + e22 * e22
                + (e01 * e01 + e02 * e02 + e12 * e12) * (one + one);
            energy[l] = v * (lambda * half * trace * trace + mu * squares);
        }
        (gradients, energy)
    }
}
