//! The model's own copy of the edge tensors `K_ij` (MODELS.md §1), laid out
//! for the force pass: groups of [`EDGE_LANES`] edges of one row as
//! structure of arrays, so that the pass multiplies 4 blocks at once in
//! vector lanes instead of one 3×3 block in scalars (31 instructions per
//! edge instead of 50 on x86-64 with AVX2, f32, measured with callgrind:
//! README "Timing your own mesh").
//!
//! Layout (rebuilt from the table by [`lay_out`] at construction and reset;
//! the table's format is unchanged): row `i` owns the groups
//! `starts[i]..starts[i+1]`; each lane `l` of a group holds one edge `(i,
//! c_l)` as the block `K_{i c_l}` (row-major, entry `e` of lane `l` at
//! `tensors[e][l]`) and its other end `c_l`. The force pass is symmetric in
//! the two ends (`f_i −= K_ij u_j`, `f_j −= K_ijᵀ u_i`), so an edge `i < j`
//! of the table may be stored in row `i` as `K_ij` or in row `j` as `K_ji =
//! K_ijᵀ`: [`lay_out`] picks, row by row in vertex order, the one that
//! makes the row a multiple of 4 (it moves the last `m` of row `i`'s own
//! edges to their higher ends, `m` = the row's count modulo 4, when the row
//! has that many). The rest of a row's last group is padding: zero blocks
//! whose column is the row itself (they add `0 · u_i`). On the 6144-tet
//! cylinder of `palpate bench` (`cylinder_mesh(0.1, 4, 16)`), 8160 edges take 2051 groups (8204 lanes, 1.005×;
//! every edge in its lower row would take 10 048 lanes, 1.23×).

use crate::Real;
use crate::math::block::{mul, mul_transposed};
use crate::table::{TensorMassTable, span};

/// Edges per group: one 128-bit vector of f32, one 256-bit of f64.
pub const EDGE_LANES: usize = 4;

/// [`EDGE_LANES`] edges of one row of the model's edge tensors (module
/// docs): `tensors[e][l]` is entry `e` (row-major, N/m) of lane `l`'s block
/// `K_{i c_l}`, `columns[l]` is `c_l`; a padding lane has a zero block and
/// `c_l = i`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EdgeGroup<T> {
    /// Block entries by entry, then lane, N/m.
    pub tensors: [[T; EDGE_LANES]; 9],
    /// The other end of each lane's edge (the row itself for padding).
    pub columns: [u32; EDGE_LANES],
}

/// Groups [`lay_out`] needs at most for `table` (the length of
/// [`super::StateBuffers::edge_groups`]): `⌈(E + 3 k) / 4⌉` with `k` the
/// rows holding at most 2 of the table's edges. A row with `m ≤ 3` edges
/// too many for a multiple of 4 moves `m` of its own edges away when it has
/// them, so only a row with fewer than 3 own edges can be left with padding,
/// at most 3 lanes. Cost: one pass over the `N` row starts.
pub fn edge_group_capacity<T: Real>(table: &TensorMassTable<'_, T>) -> usize {
    let short_rows = table
        .edge_row_starts()
        .windows(2)
        .filter(|w| matches!(w, [start, end] if end.saturating_sub(*start) <= 2))
        .count();
    (table.edge_count() + 3 * short_rows).div_ceil(EDGE_LANES)
}

/// How many of a row's `own` table edges move to their higher end when
/// `incoming` edges were moved into it: the row's count modulo 4 if it has
/// that many, else none.
fn moved(incoming: u32, own: u32) -> u32 {
    let excess = incoming.wrapping_add(own) % EDGE_LANES as u32;
    if own >= excess { excess } else { 0 }
}

/// Writes the layout of the module docs for `table` into `starts` (`N + 1`
/// group starts) and `groups` (at least [`edge_group_capacity`]; the groups
/// past `starts[N]` are zeroed). Lengths are checked by the caller
/// ([`super::StateBuffers::check`]); an edge that does not fit is dropped,
/// never a panic. Loops: `N` rows of table-declared length, each edge
/// placed by a scan of one row's lanes. Not for the step path.
pub(crate) fn lay_out<T: Real>(
    table: &TensorMassTable<'_, T>,
    starts: &mut [u32],
    groups: &mut [EdgeGroup<T>],
) {
    let rows = table.edge_row_starts();
    // Pass 1: `starts[i + 1]` counts the edges moved into row `i` until row
    // `i` is reached, then becomes its end (all moves go to higher rows).
    starts.fill(0);
    for (i, pair) in rows.windows(2).enumerate() {
        let [start, end] = [pair.first(), pair.get(1)].map(|x| x.copied().unwrap_or(0));
        let own = end.saturating_sub(start);
        let incoming = starts.get(i + 1).copied().unwrap_or(0);
        let out = moved(incoming, own);
        let first_moved = end.saturating_sub(out);
        for &j in table
            .edge_columns()
            .get(span(first_moved, end))
            .unwrap_or(&[])
        {
            if let Some(count) = starts.get_mut(j as usize + 1) {
                *count += 1;
            }
        }
        let lanes = incoming + own - out;
        let begin = starts.get(i).copied().unwrap_or(0);
        if let Some(s) = starts.get_mut(i + 1) {
            *s = begin + lanes.div_ceil(EDGE_LANES as u32);
        }
    }
    // Pass 2: every group padding, then each edge into its row's first free
    // lane, row by row (so a row's moved-in edges are placed before it is
    // reached, as pass 1 counted them).
    groups.fill(EdgeGroup {
        tensors: [[T::zero(); EDGE_LANES]; 9],
        columns: [0; EDGE_LANES],
    });
    for (i, pair) in starts.windows(2).enumerate() {
        if let (Some(&[start, end]), Ok(row)) = (pair.first_chunk::<2>(), u32::try_from(i)) {
            for g in groups.get_mut(span(start, end)).unwrap_or(&mut []) {
                g.columns = [row; EDGE_LANES];
            }
        }
    }
    let tensors = table.edge_tensors();
    for (i, pair) in rows.windows(2).enumerate() {
        let (Some(&[start, end]), Ok(row)) = (pair.first_chunk::<2>(), u32::try_from(i)) else {
            continue;
        };
        let own = end.saturating_sub(start);
        let placed = |g: &EdgeGroup<T>| g.columns.iter().filter(|&&c| c != row).count();
        let incoming = row_groups(starts, groups, row).map_or(0, |r| r.iter().map(placed).sum());
        let first_moved = end.saturating_sub(moved(incoming as u32, own));
        let range = span(start, end);
        let (Some(columns), Some(blocks)) =
            (table.edge_columns().get(range.clone()), tensors.get(range))
        else {
            continue;
        };
        for ((e, &j), k) in (start..end).zip(columns).zip(blocks) {
            if e < first_moved {
                place(starts, groups, row, j, k);
            } else {
                place(starts, groups, j, row, &transposed(k));
            }
        }
    }
}

/// Row `row`'s groups; `None` past the last row.
fn row_groups<'g, T>(
    starts: &[u32],
    groups: &'g [EdgeGroup<T>],
    row: u32,
) -> Option<&'g [EdgeGroup<T>]> {
    let r = row as usize;
    groups.get(span(*starts.get(r)?, *starts.get(r.checked_add(1)?)?))
}

/// Writes block `k` and column `column` into the first free lane (column
/// `row`) of row `row`; nothing if the row is full.
fn place<T: Real>(starts: &[u32], groups: &mut [EdgeGroup<T>], row: u32, column: u32, k: &[T; 9]) {
    let r = row as usize;
    let (Some(&start), Some(&end)) = (starts.get(r), starts.get(r.wrapping_add(1))) else {
        return;
    };
    for g in groups.get_mut(span(start, end)).unwrap_or(&mut []) {
        if let Some(l) = g.columns.iter().position(|&c| c == row) {
            set_lane(g, l, column, k);
            return;
        }
    }
}

/// Lane `l` of `g` := block `k` of the edge to `column`.
fn set_lane<T: Real>(g: &mut EdgeGroup<T>, l: usize, column: u32, k: &[T; 9]) {
    for (entry, &x) in g.tensors.iter_mut().zip(k) {
        if let Some(v) = entry.get_mut(l) {
            *v = x;
        }
    }
    if let Some(c) = g.columns.get_mut(l) {
        *c = column;
    }
}

/// `Kᵀ` of a row-major 3×3 block.
fn transposed<T: Real>(k: &[T; 9]) -> [T; 9] {
    core::array::from_fn(|e| k.get((e % 3) * 3 + e / 3).copied().unwrap_or(T::zero()))
}

/// Where the edge `(row, column)` is stored as `K_{row column}` in row
/// `row`: its group index and lane; `None` if it is stored in the other
/// row, or for `row == column` (padding is no edge). Cost: one scan of the
/// row's lanes.
fn slot<T>(
    starts: &[u32],
    groups: &[EdgeGroup<T>],
    row: u32,
    column: u32,
) -> Option<(usize, usize)> {
    if row == column {
        return None;
    }
    let first = *starts.get(row as usize)? as usize;
    row_groups(starts, groups, row)?
        .iter()
        .enumerate()
        .find_map(|(g, group)| {
            let l = group.columns.iter().position(|&c| c == column)?;
            Some((first + g, l))
        })
}

/// The edge between `i` and `j` as stored: `(group, lane, transposed)`,
/// `transposed` when the stored block is `K_ji`. `None` for no edge.
fn find<T>(
    starts: &[u32],
    groups: &[EdgeGroup<T>],
    i: u32,
    j: u32,
) -> Option<(usize, usize, bool)> {
    slot(starts, groups, i, j)
        .map(|(g, l)| (g, l, false))
        .or_else(|| slot(starts, groups, j, i).map(|(g, l)| (g, l, true)))
}

/// Read and update access to the laid-out edge tensors.
pub(crate) struct EdgeTensors<'b, T> {
    pub(crate) starts: &'b [u32],
    pub(crate) groups: &'b [EdgeGroup<T>],
}

impl<T: Real> EdgeTensors<'_, T> {
    /// The current block `K_ij` (row `i`, column `j`, row-major, N/m) of the
    /// edge between `i` and `j`; `None` if there is none.
    pub(crate) fn block(&self, i: u32, j: u32) -> Option<[T; 9]> {
        let (g, l, swap) = find(self.starts, self.groups, i, j)?;
        let group = self.groups.get(g)?;
        let k = group
            .tensors
            .map(|entry| entry.get(l).copied().unwrap_or(T::zero()));
        Some(if swap { transposed(&k) } else { k })
    }
}

/// `K_ij −= block` (row `i`, column `j`, N/m) on the edge between `i` and
/// `j` of the laid-out groups; nothing if there is none.
pub(crate) fn subtract_block<T: Real>(
    starts: &[u32],
    groups: &mut [EdgeGroup<T>],
    i: u32,
    j: u32,
    block: &[T; 9],
) {
    let Some((g, l, swap)) = find(starts, groups, i, j) else {
        return;
    };
    let block = if swap { transposed(block) } else { *block };
    if let Some(group) = groups.get_mut(g) {
        for (entry, &b) in group.tensors.iter_mut().zip(&block) {
            if let Some(x) = entry.get_mut(l) {
                *x -= b;
            }
        }
    }
}

/// `f_i −= Σ_j K_ij u_j` and `f_j −= K_ijᵀ u_i` over every stored edge
/// (MODELS.md §1), `u` in m, `f` in N. Per group: the 3 components of the 4
/// `u_j` gathered into lanes, `K u_j` subtracted from 3 lane accumulators of
/// the row (summed across lanes once per row, pairs first), `Kᵀ u_i` in
/// lanes, then each lane's `f_j` read, decreased and written. Loops: `N`
/// rows over their groups (lengths checked at construction; an
/// out-of-range index is skipped, never a panic). Always inlined, so that a
/// [`crate::math::Dispatch`] compiles it where it runs.
#[inline(always)]
pub(crate) fn add_edge_forces<T: Real>(edges: &EdgeTensors<'_, T>, u: &[[T; 3]], f: &mut [[T; 3]]) {
    // Every column is `< N` (`lay_out` places table edges only) and `u`,
    // `f` hold `N` entries; clamping the columns to the common length lets
    // the compiler drop every bounds check without a panic path.
    let n = u.len().min(f.len());
    let (Some(u), Some(f), Some(last)) = (u.get(..n), f.get_mut(..n), n.checked_sub(1)) else {
        return;
    };
    let at = |j: u32| (j as usize).min(last);
    for ((i, pair), ui) in edges.starts.windows(2).enumerate().zip(u) {
        let Some(groups) = pair
            .first_chunk::<2>()
            .and_then(|&[start, end]| edges.groups.get(span(start, end)))
        else {
            continue;
        };
        // A copy: `f`'s writes below cannot change it.
        let ui = ui.map(|x| T::lanes([x; EDGE_LANES]));
        let mut sum = [T::lanes([T::zero(); EDGE_LANES]); 3];
        for g in groups {
            let k = g.tensors.map(T::lanes);
            let columns = g.columns.map(at);
            let [u0, u1, u2, u3] = columns.map(|j| u.get(j).copied().unwrap_or_default());
            let uj = [
                T::lanes([u0[0], u1[0], u2[0], u3[0]]),
                T::lanes([u0[1], u1[1], u2[1], u3[1]]),
                T::lanes([u0[2], u1[2], u2[2], u3[2]]),
            ];
            let a = mul(&k, &uj);
            sum = [sum[0] - a[0], sum[1] - a[1], sum[2] - a[2]];
            let [b0, b1, b2] = mul_transposed(&k, &ui).map(T::lane_values);
            for (((j, x), y), z) in columns.into_iter().zip(b0).zip(b1).zip(b2) {
                if let Some(fj) = f.get_mut(j) {
                    *fj = [fj[0] - x, fj[1] - y, fj[2] - z];
                }
            }
        }
        if let Some(fi) = f.get_mut(i) {
            let [x, y, z] = sum.map(|s| {
                let [a, b, c, d] = T::lane_values(s);
                (a + b) + (c + d)
            });
            *fi = [fi[0] + x, fi[1] + y, fi[2] + z];
        }
    }
}
