//! The co-rotational linear force per tet (stiffness warping: Müller &
//! Gross 2004, "Interactive virtual materials", §4, eq. 10; SOFA's
//! `TetrahedronFEMForceField` method `large`; MODELS.md §8), on the blocks
//! of the per-tet pass ([`super::stvk`]).
//!
//! With `R` the proper rotation closest to the deformation gradient `F`
//! ([`closest_rotations`]), the element force
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
//! also returns, and the pass evaluates it in that form (no product
//! `RᵀF`, no second product by `R`). Zero for any rigid motion; the linear
//! force for a pure strain (`F` symmetric positive definite, `R = I`);
//! rotating the deformed state rotates the forces.
//!
//! Cost: the rotation ([`closest_rotations`]: a few Newton steps, cold,
//! for all lanes at once) and two branch-free lane loops (`F`, then the
//! stress, the gradients and the energy), vectorized as the St Venant-
//! Kirchhoff pass.

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
        let half = T::of_f64(0.5);
        let three = T::of_f64(3.0);
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
            let f = |i: usize, j: usize| f_lanes[i][j][l];
            let r = |i: usize, j: usize| r_lanes[i][j][l];
            // tr(RᵀF) − 3 = tr ε, and F − R.
            let trace = r(0, 0) * f(0, 0)
                + r(0, 1) * f(0, 1)
                + r(0, 2) * f(0, 2)
                + r(1, 0) * f(1, 0)
                + r(1, 1) * f(1, 1)
                + r(1, 2) * f(1, 2)
                + r(2, 0) * f(2, 0)
                + r(2, 1) * f(2, 1)
                + r(2, 2) * f(2, 2)
                - three;
            let d = |i: usize, j: usize| f(i, j) - r(i, j);
            let d = [
                [d(0, 0), d(0, 1), d(0, 2)],
                [d(1, 0), d(1, 1), d(1, 2)],
                [d(2, 0), d(2, 1), d(2, 2)],
            ];
            // V P = V (2μ (F − R) + λ tr ε R).
            let (two_mu_v, lambda_trace_v) = ((mu + mu) * v, lambda * trace * v);
            let p = |i: usize, j: usize| two_mu_v * d[i][j] + lambda_trace_v * r(i, j);
            let vp = [
                [p(0, 0), p(0, 1), p(0, 2)],
                [p(1, 0), p(1, 1), p(1, 2)],
                [p(2, 0), p(2, 1), p(2, 2)],
            ];
            self.store_gradients(l, &vp, &mut gradients);
            let squares = d[0][0] * d[0][0]
                + d[0][1] * d[0][1]
                + d[0][2] * d[0][2]
                + d[1][0] * d[1][0]
                + d[1][1] * d[1][1]
                + d[1][2] * d[1][2]
                + d[2][0] * d[2][0]
                + d[2][1] * d[2][1]
                + d[2][2] * d[2][2];
            energy[l] = v * (lambda * half * trace * trace + mu * squares);
        }
        (gradients, energy)
    }
}
