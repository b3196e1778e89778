//! The St Venant-Kirchhoff force computed tet by tet from the deformation
//! gradient (MODELS.md §4; Picinbono 2001 §3, eq. 10–11), and the
//! incompressibility penalty of Picinbono 2001 §3.2, in one vectorized pass
//! over blocks of tets.
//!
//! With the rest shape-function gradients `a_j` (1/m) and rest volume `V`
//! (m³) of a tet and the displacements `u_j` (m) of its corners:
//! `∇U = Σ_j u_j a_jᵀ`, `F = I + ∇U`, Green strain `E = ½(FᵀF − I)`,
//! second Piola-Kirchhoff stress `S = λ tr(E) I + 2μE`, energy
//! `W = V (λ/2 (tr E)² + μ tr E²)` and force on corner `j`
//! `f_j = −∂W/∂u_j = −V F S a_j`, with each tet's own `(λ, μ)` (the table's
//! `tet-material` section: heterogeneous tissue).

use crate::Real;
use crate::math::polar::cofactor;
use crate::table::TensorMassTable;
use crate::table::TetLanes;
use crate::table::format::{TET_LANES, tet_lane_row};

/// What the per-tet passes read: the table (tets, rest shapes and
/// positions) and which tets are alive.
pub(crate) struct TetPass<'b, 'a, T: Real> {
    pub(crate) table: &'b TensorMassTable<'a, T>,
    pub(crate) tet_alive: &'b [bool],
}

/// Tets evaluated together: the arithmetic of the per-tet force runs on
/// `[T; LANES]` arrays, which the compiler turns into SIMD operations (8 f32
/// per AVX2 register), while gathering and scattering stay per tet. The
/// table's `tet-lanes` blocks hold the rest data in this layout.
pub(super) const LANES: usize = TET_LANES;

/// One value per lane.
pub(super) type Lanes<T> = [T; LANES];

/// What a per-tet law computes for a block: per lane, the gradients
/// `V P a_j` (N, `j = 1..3`, by component) and the energies (J).
pub(super) type TetTerms<T> = ([[Lanes<T>; 3]; 3], Lanes<T>);

/// Lane `l` of three per-lane rows: `[x, y, z]` (zero for a lane out of range).
#[inline(always)]
fn lane<T: Real>(rows: &[Lanes<T>; 3], l: usize) -> [T; 3] {
    let mut out = [T::zero(); 3];
    for (o, row) in out.iter_mut().zip(rows) {
        if let Some(&x) = row.get(l) {
            *o = x;
        }
    }
    out
}

/// The [`LANES`] tets of one `tet-lanes` block for the force pass: their
/// corners, which lanes hold a live tet, the edge displacements
/// `u_j − u_0` (m, `j = 1..3`, by component) gathered from the field, and
/// the block's rest data read in place ([`TetLanes`]: gradients `a_j`
/// (1/m), volumes (m³), Lamé coefficients (Pa)). A lane without a live tet
/// (cut, torn, or past the last tet) has zero edge displacements, so
/// `F = I`, and computes a zero force, energy and penalty; it is not
/// scattered.
pub(super) struct Block<'t, T> {
    corners: [[u32; 4]; LANES],
    live: [bool; LANES],
    du: [[Lanes<T>; 3]; 3],
    pub(super) rest: &'t TetLanes<T>,
}

// The lane loops index fixed-size arrays with literals < 3 and loop
// counters < LANES (the form the vectorizer needs); tools/nopanic-check
// proves that no panic is left after inlining.
#[expect(
    clippy::indexing_slicing,
    reason = "indices are literals < 3, row constants < TET_LANE_ROWS and loop counters < LANES over fixed-size arrays"
)]
impl<'t, T: Real> Block<'t, T> {
    /// Puts live tet `tet` with corner displacements `u` (m) in lane `l`
    /// (`< LANES`): its edge displacements `u_j − u_0`.
    #[inline(always)]
    fn gather(&mut self, l: usize, tet: [u32; 4], u: [&[T; 3]; 4]) {
        let [u0, u1, u2, u3] = u;
        for (j, uj) in [u1, u2, u3].into_iter().enumerate() {
            for c in 0..3 {
                if let Some(d) = self.du[j][c].get_mut(l) {
                    *d = uj[c] - u0[c];
                }
            }
        }
        if let (Some(corners), Some(live)) = (self.corners.get_mut(l), self.live.get_mut(l)) {
            *corners = tet;
            *live = true;
        }
    }

    /// Gradient component `c` of `a_{j+1}`, per lane.
    #[inline(always)]
    pub(super) fn a(&self, j: usize, c: usize) -> &'t Lanes<T> {
        &self.rest[3 * j + c]
    }

    /// `F = I + Σ_j (u_j − u_0) a_jᵀ` of lane `l`, rows. Written out entry
    /// by entry (no `from_fn` loop) so the lane loops that call it stay
    /// vectorizable.
    #[inline(always)]
    pub(super) fn deformation(&self, l: usize) -> [[T; 3]; 3] {
        let (du, one) = (&self.du, T::one());
        let g = |r: usize, c: usize| {
            du[0][r][l] * self.a(0, c)[l]
                + du[1][r][l] * self.a(1, c)[l]
                + du[2][r][l] * self.a(2, c)[l]
        };
        [
            [g(0, 0) + one, g(0, 1), g(0, 2)],
            [g(1, 0), g(1, 1) + one, g(1, 2)],
            [g(2, 0), g(2, 1), g(2, 2) + one],
        ]
    }

    /// Stores lane `l`'s gradients `(V P) a_j` (N, `j = 1..3`) from `vp`,
    /// the first Piola-Kirchhoff stress times the rest volume (N·m, rows).
    #[inline(always)]
    pub(super) fn store_gradients(
        &self,
        l: usize,
        vp: &[[T; 3]; 3],
        gradients: &mut [[Lanes<T>; 3]; 3],
    ) {
        for (j, out) in gradients.iter_mut().enumerate() {
            let (g0, g1, g2) = (self.a(j, 0)[l], self.a(j, 1)[l], self.a(j, 2)[l]);
            for (row, p) in out.iter_mut().zip(vp) {
                row[l] = p[0] * g0 + p[1] * g1 + p[2] * g2;
            }
        }
    }

    /// Per lane, the gradients `V P a_j` (N, `j = 1..3`, by component) of
    /// the St Venant-Kirchhoff energy, `P = F S`, whose negatives are the
    /// forces on corners 1–3 (corner 0 takes minus their sum, since
    /// `a_0 = −(a_1 + a_2 + a_3)`), and the energies
    /// `V (λ/2 (tr E)² + μ tr E²)` (J), each lane with its tet's `λ`, `μ`.
    ///
    /// One loop over the lanes with a branch-free body on
    /// structure-of-arrays data: the form the compiler vectorizes.
    #[inline(always)]
    pub(super) fn elastic(&self) -> TetTerms<T> {
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
        for l in 0..LANES {
            let (lambda, mu) = (lambda[l], mu[l]);
            let two_mu = mu + mu;
            let [[f00, f01, f02], [f10, f11, f12], [f20, f21, f22]] = self.deformation(l);
            // E = ½(FᵀF − I), symmetric.
            let e00 = (f00 * f00 + f10 * f10 + f20 * f20 - one) * half;
            let e11 = (f01 * f01 + f11 * f11 + f21 * f21 - one) * half;
            let e22 = (f02 * f02 + f12 * f12 + f22 * f22 - one) * half;
            let e01 = (f00 * f01 + f10 * f11 + f20 * f21) * half;
            let e02 = (f00 * f02 + f10 * f12 + f20 * f22) * half;
            let e12 = (f01 * f02 + f11 * f12 + f21 * f22) * half;
            let trace = e00 + e11 + e22;
            // V S = V (λ tr(E) I + 2μ E).
            let v = volume[l];
            let diagonal = lambda * trace;
            let s00 = (diagonal + two_mu * e00) * v;
            let s11 = (diagonal + two_mu * e11) * v;
            let s22 = (diagonal + two_mu * e22) * v;
            let (s01, s02, s12) = (two_mu * e01 * v, two_mu * e02 * v, two_mu * e12 * v);
            // V P = F (V S).
            let p00 = f00 * s00 + f01 * s01 + f02 * s02;
            let p01 = f00 * s01 + f01 * s11 + f02 * s12;
            let p02 = f00 * s02 + f01 * s12 + f02 * s22;
            let p10 = f10 * s00 + f11 * s01 + f12 * s02;
            let p11 = f10 * s01 + f11 * s11 + f12 * s12;
            let p12 = f10 * s02 + f11 * s12 + f12 * s22;
            let p20 = f20 * s00 + f21 * s01 + f22 * s02;
            let p21 = f20 * s01 + f21 * s11 + f22 * s12;
            let p22 = f20 * s02 + f21 * s12 + f22 * s22;
            for (j, out) in gradients.iter_mut().enumerate() {
                let (g0, g1, g2) = (self.a(j, 0)[l], self.a(j, 1)[l], self.a(j, 2)[l]);
                out[0][l] = p00 * g0 + p01 * g1 + p02 * g2;
                out[1][l] = p10 * g0 + p11 * g1 + p12 * g2;
                out[2][l] = p20 * g0 + p21 * g1 + p22 * g2;
            }
            let squares = e00 * e00
                + e11 * e11
                + e22 * e22
                + (e01 * e01 + e02 * e02 + e12 * e12) * (one + one);
            energy[l] = v * (lambda * half * trace * trace + mu * squares);
        }
        (gradients, energy)
    }

    /// Per lane, the incompressibility forces (N, by corner and component)
    /// of Picinbono 2001 §3.2 with `gamma_n` (N): with `J = det F`, so
    /// `(V − V₀)/V₀ = J − 1`, and `n_j = cof(F) a_j`, the direction of
    /// `∂V/∂x_j` (towards corner `j`: minus the outward normal of the face
    /// opposite it), the force on corner `j` is
    /// `−γ sign(J − 1)(J − 1)² n_j/|n_j|`, restoring the rest volume.
    #[inline(always)]
    fn penalty(&self, gamma_n: T) -> [[Lanes<T>; 3]; 4] {
        let z = [T::zero(); LANES];
        let mut forces = [[z; 3]; 4];
        for l in 0..LANES {
            let [[f00, f01, f02], [f10, f11, f12], [f20, f21, f22]] = self.deformation(l);
            let cof = cofactor(&[[f00, f01, f02], [f10, f11, f12], [f20, f21, f22]]);
            let change = f00 * cof[0][0] + f01 * cof[0][1] + f02 * cof[0][2] - T::one();
            let magnitude = gamma_n * change * change.abs();
            let a1: [T; 3] = core::array::from_fn(|c| self.a(0, c)[l]);
            let a2: [T; 3] = core::array::from_fn(|c| self.a(1, c)[l]);
            let a3: [T; 3] = core::array::from_fn(|c| self.a(2, c)[l]);
            let a0: [T; 3] = core::array::from_fn(|c| -(a1[c] + a2[c] + a3[c]));
            for (out, aj) in forces.iter_mut().zip([a0, a1, a2, a3]) {
                let n: [T; 3] = core::array::from_fn(|r| {
                    cof[r][0] * aj[0] + cof[r][1] * aj[1] + cof[r][2] * aj[2]
                });
                let length = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                let scale = if length > T::zero() {
                    -magnitude / length
                } else {
                    T::zero()
                };
                for (row, nr) in out.iter_mut().zip(n) {
                    row[l] = nr * scale;
                }
            }
        }
        forces
    }
}

impl<T: Real> TetPass<'_, '_, T> {
    /// Calls `visit` on each `tet-lanes` block with its live tets'
    /// displacements gathered from `u` (m), in tet order. Bounded by the
    /// table's block count; a tet whose references fall outside `u` is
    /// left out like a dead one (validated at load).
    ///
    /// `visit` has one call site, so that inlining it (the passes ask for
    /// it, for [`crate::math::Dispatch`]) does not copy it. The tets are
    /// read by index rather than by a zip of slices: inside a pass a host
    /// compiles for more CPU features, the compiler left a zip's `next` out
    /// of line, a call per tet.
    #[inline(always)]
    fn for_each_block(&self, u: &[[T; 3]], visit: impl FnMut(&Block<'_, T>)) {
        self.for_blocks(0..self.table.tet_lanes().len(), u, visit);
    }

    /// [`Self::for_each_block`] on the blocks `blocks` only (those past the
    /// last left out).
    #[inline(always)]
    fn for_blocks(
        &self,
        blocks: core::ops::Range<usize>,
        u: &[[T; 3]],
        mut visit: impl FnMut(&Block<'_, T>),
    ) {
        let (tets, lanes) = (self.table.tets(), self.table.tet_lanes());
        for b in blocks {
            let Some(rest) = lanes.get(b) else {
                break;
            };
            let z = [T::zero(); LANES];
            let mut block = Block {
                corners: [[0; 4]; LANES],
                live: [false; LANES],
                du: [[z; 3]; 3],
                rest,
            };
            for l in 0..LANES {
                let t = b * LANES + l;
                let (Some(&tet), Some(&true)) = (tets.get(t), self.tet_alive.get(t)) else {
                    continue;
                };
                let (Some(u0), Some(u1), Some(u2), Some(u3)) = (
                    u.get(tet[0] as usize),
                    u.get(tet[1] as usize),
                    u.get(tet[2] as usize),
                    u.get(tet[3] as usize),
                ) else {
                    continue;
                };
                block.gather(l, tet, [u0, u1, u2, u3]);
            }
            visit(&block);
        }
    }

    /// Adds to `f` (N) the forces `f_j = −V P a_j` of displacements `u`
    /// (m) under a per-tet law: `law` gives a block's gradients `V P a_j`
    /// (`j = 1..3`) and energies ([`Block::elastic`] for St Venant-Kirchhoff,
    /// [`Block::neo_hookean`], [`Block::corotational`]); corner 0 takes
    /// minus their sum (`a_0 = −(a_1 + a_2 + a_3)`). Always inlined, with its
    /// block visit, so that a [`crate::math::Dispatch`] compiles it where it
    /// runs.
    #[inline(always)]
    pub(super) fn add_tet_forces(
        &self,
        u: &[[T; 3]],
        f: &mut [[T; 3]],
        law: impl Fn(&Block<'_, T>) -> TetTerms<T>,
    ) {
        self.for_each_block(
            u,
            #[inline(always)]
            |block| {
                let ([r1, r2, r3], _) = law(block);
                for (l, tet) in block.corners.iter().enumerate() {
                    if block.live.get(l) != Some(&true) {
                        continue;
                    }
                    let (g1, g2, g3) = (lane(&r1, l), lane(&r2, l), lane(&r3, l));
                    let g0 = [
                        -(g1[0] + g2[0] + g3[0]),
                        -(g1[1] + g2[1] + g3[1]),
                        -(g1[2] + g2[2] + g3[2]),
                    ];
                    for (&v, gv) in tet.iter().zip([g0, g1, g2, g3]) {
                        if let Some(out) = f.get_mut(v as usize) {
                            *out = [out[0] - gv[0], out[1] - gv[1], out[2] - gv[2]];
                        }
                    }
                }
            },
        );
    }

    /// Writes the gradients `V P a_j` (N, `j = 1..3`) of a per-tet `law`
    /// (see [`Self::add_tet_forces`]) at displacements `u` (m) of the
    /// blocks from `first_block` on, as many as `out` holds, into `out`:
    /// `3·LANES` entries per block, tet `8b + l`'s at `3l..3l + 3` of block
    /// `b`'s (a lane without a live tet gets zeros, which nothing reads).
    #[inline(always)]
    pub(super) fn store_gradients(
        &self,
        first_block: usize,
        u: &[[T; 3]],
        out: &mut [[T; 3]],
        law: impl Fn(&Block<'_, T>) -> TetTerms<T>,
    ) {
        let blocks = first_block..first_block + out.len() / (3 * LANES);
        let mut chunks = out.chunks_exact_mut(3 * LANES);
        self.for_blocks(
            blocks,
            u,
            #[inline(always)]
            |block| {
                let ([r1, r2, r3], _) = law(block);
                let Some(chunk) = chunks.next() else {
                    return;
                };
                for (l, slot) in chunk.chunks_exact_mut(3).enumerate() {
                    for (s, r) in slot.iter_mut().zip([&r1, &r2, &r3]) {
                        *s = lane(r, l);
                    }
                }
            },
        );
    }

    /// Adds to `f` (N) the incompressibility penalty with `gamma_n` (N) at
    /// displacements `u` (m), see [`Block::penalty`]. Always inlined, as
    /// [`Self::add_stvk_forces`].
    #[inline(always)]
    pub(crate) fn add_incompressibility(&self, gamma_n: T, u: &[[T; 3]], f: &mut [[T; 3]]) {
        self.for_each_block(
            u,
            #[inline(always)]
            |block| {
                let forces = block.penalty(gamma_n);
                for (l, tet) in block.corners.iter().enumerate() {
                    if block.live.get(l) != Some(&true) {
                        continue;
                    }
                    for (&v, fj) in tet.iter().zip(&forces) {
                        if let Some(out) = f.get_mut(v as usize) {
                            let x = lane(fj, l);
                            *out = [out[0] + x[0], out[1] + x[1], out[2] + x[2]];
                        }
                    }
                }
            },
        );
    }

    /// The energy `Σ V ψ` (J) of displacements `u` (m) under a per-tet law
    /// (see [`Self::add_tet_forces`]), each tet with its own `λ`, `μ`.
    pub(super) fn tet_energy_j(
        &self,
        u: &[[T; 3]],
        law: impl Fn(&Block<'_, T>) -> TetTerms<T>,
    ) -> T {
        let mut energy = T::zero();
        self.for_each_block(u, |block| {
            // A lane without a live tet has `F = I`: zero energy.
            let (_, w) = law(block);
            for x in w {
                energy += x;
            }
        });
        energy
    }
}
