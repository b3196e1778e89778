//! The per-tet force pass split into parts that a host may run on several
//! threads ([`crate::math::Dispatch::parts`] and
//! [`crate::math::Dispatch::each`]), with the same bits as the pass in one
//! piece for any number of parts.
//!
//! The pass in one piece ([`super::stvk::TetPass::add_tet_forces`])
//! scatters: tet by tet in index order, it subtracts each corner's force
//! from `f`, so vertex `v` receives `f_v = ((0 − g_{t₁}) − g_{t₂}) − …`
//! over its tets `t₁ < t₂ < …`. Split, it runs in two stages, each cut
//! into parts that write disjoint data:
//!
//! 1. blocks of tets `b₀..b₁` per part: each live tet's gradients
//!    `V P a_j` (N, `j = 1..3`) into [`SplitBuffers::gradients`];
//! 2. vertices `v₀..v₁` per part: each vertex gathers its corners' forces
//!    from the list [`SplitBuffers::corners`] (its tets in index order,
//!    built once by `TensorMassModel::with_split`), subtracting
//!    them in that order from zero: the same operations in the same order
//!    as the scatter, so the same bits.
//!
//! Memory: `4(N + 1) + 16 M` bytes for the lists and `12·8` values per
//! block of 8 tets for the gradients (`M` tets, `N` vertices). Only the
//! per-tet laws (St Venant-Kirchhoff per tet, co-rotational, neo-Hookean)
//! are split; the linear and split-term passes, the incompressibility
//! penalty and a coupled region's force run in one piece after it.

use super::state::StateError;
use super::stvk::{Block, LANES, TetPass, TetTerms};
use crate::Real;
use crate::math::{Dispatch, MAX_PARTS};
use crate::table::TensorMassTable;
use crate::table::span;

/// Caller-provided storage of the split per-tet pass (module docs), for
/// `TensorMassModel::with_split`: `N` vertices, `M` tets, `B`
/// blocks of [`crate::table::format::TET_LANES`] tets.
pub struct SplitBuffers<'s, T> {
    /// `N + 1`: where each vertex's entries of [`Self::corners`] start, and
    /// their end.
    pub corner_starts: &'s mut [u32],
    /// `4M`: `4t + c` for corner `c` of tet `t`, by vertex, each vertex's
    /// in tet order (written by the model).
    pub corners: &'s mut [u32],
    /// `3·8·B`: the gradients `V P a_j` (N, `j = 1..3`) of tet `t` at
    /// `3t..3t + 3` (scratch of each force pass).
    pub gradients: &'s mut [[T; 3]],
}

impl<T: Real> SplitBuffers<'_, T> {
    /// The lengths `table` needs: `(N + 1, 4M, 3·8·B)` for
    /// `(corner_starts, corners, gradients)`.
    pub fn lengths(table: &TensorMassTable<'_, T>) -> (usize, usize, usize) {
        (
            table.vertex_count() + 1,
            4 * table.tet_count(),
            3 * LANES * table.tet_lanes().len(),
        )
    }

    /// Checks the lengths against `table` and writes the corner lists.
    /// Loops: the `M` tets twice and the `N` vertices twice; not for the
    /// step path.
    pub(crate) fn prepare(&mut self, table: &TensorMassTable<'_, T>) -> Result<(), StateError> {
        let (starts, corners, gradients) = Self::lengths(table);
        let lengths = [
            ("split corner_starts", self.corner_starts.len(), starts),
            ("split corners", self.corners.len(), corners),
            ("split gradients", self.gradients.len(), gradients),
        ];
        if let Some(&(buffer, found, expected)) = lengths.iter().find(|(_, f, e)| f != e) {
            return Err(StateError::BufferLength {
                buffer,
                expected,
                found,
            });
        }
        if u32::try_from(corners).is_err() {
            return Err(StateError::BufferLength {
                buffer: "split corners",
                expected: u32::MAX as usize,
                found: corners,
            });
        }
        let n = table.vertex_count();
        let starts = &mut *self.corner_starts;
        // Counts in `starts[v + 1]`, then their running sum: `starts[v]` is
        // where vertex `v`'s entries begin.
        starts.fill(0);
        let whole = |tet: &[u32; 4]| tet.iter().all(|&v| (v as usize) < n);
        for tet in table.tets().iter().filter(|t| whole(t)) {
            for &v in tet {
                if let Some(count) = starts.get_mut(v as usize + 1) {
                    *count += 1;
                }
            }
        }
        for v in 1..starts.len() {
            let before = starts.get(v - 1).copied();
            if let (Some(before), Some(s)) = (before, starts.get_mut(v)) {
                *s += before;
            }
        }
        // Each entry at its vertex's cursor (`starts[v]`, advanced), in tet
        // order; the cursors end at the next vertex's start, shifted back.
        for (t, tet) in table.tets().iter().enumerate() {
            if !whole(tet) {
                continue;
            }
            for (c, &v) in tet.iter().enumerate() {
                if let Some(cursor) = starts.get_mut(v as usize) {
                    if let Some(slot) = self.corners.get_mut(*cursor as usize) {
                        *slot = (4 * t + c) as u32;
                    }
                    *cursor += 1;
                }
            }
        }
        for v in (1..starts.len()).rev() {
            let before = starts.get(v - 1).copied();
            if let (Some(before), Some(s)) = (before, starts.get_mut(v)) {
                *s = before;
            }
        }
        if let Some(first) = starts.first_mut() {
            *first = 0;
        }
        Ok(())
    }

    /// Overwrites `f` with the forces (N) of displacements `u` (m) under a
    /// per-tet `law` (as [`TetPass::add_tet_forces`] after zeroing `f`,
    /// bit for bit), in the two stages of the module docs, each cut into
    /// `dispatch.parts()` items for [`Dispatch::each`].
    #[inline(always)]
    pub(super) fn tet_forces(
        &mut self,
        dispatch: impl Dispatch,
        tets: &TetPass<'_, '_, T>,
        u: &[[T; 3]],
        f: &mut [[T; 3]],
        law: &(impl Fn(&Block<'_, T>) -> TetTerms<T> + Sync),
    ) {
        let parts = dispatch.parts().clamp(1, MAX_PARTS);
        let per_block = 3 * LANES;
        let blocks = self.gradients.len() / per_block;
        let blocks_per_part = blocks.div_ceil(parts).max(1);
        let mut chunks = self
            .gradients
            .chunks_mut(blocks_per_part * per_block)
            .enumerate();
        let items = core::array::from_fn(|_| chunks.next());
        dispatch.each(
            items,
            #[inline(always)]
            |(k, out): (usize, &mut [[T; 3]])| {
                tets.store_gradients(k * blocks_per_part, u, out, law);
            },
        );
        let vertices_per_part = f.len().div_ceil(parts).max(1);
        let mut chunks = f.chunks_mut(vertices_per_part).enumerate();
        let items = core::array::from_fn(|_| chunks.next());
        let (starts, corners, gradients) = (&*self.corner_starts, &*self.corners, &*self.gradients);
        let alive = tets.tet_alive;
        dispatch.each(
            items,
            #[inline(always)]
            |(k, out): (usize, &mut [[T; 3]])| {
                let first = k * vertices_per_part;
                for (v, fv) in (first..).zip(out.iter_mut()) {
                    let range = match (starts.get(v), starts.get(v + 1)) {
                        (Some(&s), Some(&e)) => span(s, e),
                        _ => 0..0,
                    };
                    let mut sum = [T::zero(); 3];
                    for &entry in corners.get(range).unwrap_or(&[]) {
                        let (t, c) = (entry as usize / 4, entry as usize % 4);
                        if alive.get(t) != Some(&true) {
                            continue;
                        }
                        let g = corner_force(gradients, t, c);
                        sum = [sum[0] - g[0], sum[1] - g[1], sum[2] - g[2]];
                    }
                    *fv = sum;
                }
            },
        );
    }
}

/// Corner `c`'s gradient of tet `t` from the stored `V P a_j` (`j = 1..3`):
/// that of corner `j` for `c = j`, minus their sum for corner 0 (as
/// [`TetPass::add_tet_forces`] forms it).
#[inline(always)]
fn corner_force<T: Real>(gradients: &[[T; 3]], t: usize, c: usize) -> [T; 3] {
    let g = |j: usize| gradients.get(3 * t + j).copied().unwrap_or_default();
    match c {
        0 => {
            let (g1, g2, g3) = (g(0), g(1), g(2));
            [
                -(g1[0] + g2[0] + g3[0]),
                -(g1[1] + g2[1] + g3[1]),
                -(g1[2] + g2[2] + g3[2]),
            ]
        }
        c => g(c - 1),
    }
}
