//! The hierarchical surface compliance of a pre-computed table as stored
//! ([`super::format::hierarchy`]): checked once at load
//! (`HierarchicalBlocks::load`), then read by the step path in bounded
//! time: a contact block `C_nk` by two binary searches and `9r`
//! multiply-adds ([`HierarchicalBlocks::block`]), a compliance column by one
//! pass over the blocks of its leaf column ([`HierarchicalBlocks::add_column`],
//! a hierarchical matrix–vector product with one non-zero input vertex).
//! Its numbers are the table scalar or q16 codes decoded on the fly, the
//! block's scale applied once per block (to the input vector).

use nalgebra::Vector3;

use super::LoadError;
use super::container::Container;
use super::format::{
    HIERARCHY_MAX_RANK, HIERARCHY_MIRRORED, HierarchyBlock, HierarchyRecord, Q16_LARGEST_CODE,
    SectionKind, q16_value,
};
use crate::Real;
use crate::math::block;

/// The hierarchy's numbers as stored (validated at load: the offsets of
/// every block lie within them).
#[derive(Clone, Copy, Debug)]
enum Values<'a, T: Real> {
    /// In the table scalar, every one finite
    /// ([`super::format::BlockEncoding::Hierarchical`]).
    Scalar(&'a [T]),
    /// q16 codes (none −32768) and one `[s₀, s₁]` per block
    /// ([`super::format::BlockEncoding::HierarchicalQ16`]).
    Q16 {
        codes: &'a [u16],
        scales: &'a [[T; 2]],
    },
}

/// One stored number: the table scalar itself or a q16 code (its value
/// before the block's scale).
trait Stored<T: Real>: Copy {
    /// The number it stands for.
    fn value(self) -> T;
}

impl<T: Real> Stored<T> for T {
    #[inline(always)]
    fn value(self) -> T {
        self
    }
}

impl<T: Real> Stored<T> for u16 {
    #[inline(always)]
    fn value(self) -> T {
        T::of_f32(q16_value(self))
    }
}

/// A hierarchical surface part, validated at load. Invariants from
/// `load`:
/// - `leaves` is `0`, strictly ascending, `S` last (`leaf_count + 1`
///   entries);
/// - every block spans a non-empty range of rows and of columns within
///   `0..S`, has a rank `≤ record.max_rank ≤ HIERARCHY_MAX_RANK`, and its
///   data lie within `values` (every scalar finite; q16: every scale pair
///   such that each decoded number is finite);
/// - each leaf's column list holds at most `record.max_column_blocks`
///   blocks, each covering the leaf's columns, sorted by row, their rows
///   tiling `0..S`: every `C_nk` is in exactly one listed block of `k`'s
///   leaf.
#[derive(Clone, Copy, Debug)]
pub struct HierarchicalBlocks<'a, T: Real> {
    record: &'a HierarchyRecord,
    /// Per leaf, then one past the last: `[first touchable index, first
    /// entry of its column list]`.
    leaves: &'a [[u32; 2]],
    blocks: &'a [HierarchyBlock],
    column_blocks: &'a [u32],
    values: Values<'a, T>,
}

impl<'a, T: Real> HierarchicalBlocks<'a, T> {
    /// Reads and checks the hierarchy sections of a table of `s` touchable
    /// vertices (invariants on the type), its numbers q16 codes if `q16`
    /// (else the table scalar). Linear in the sections' size.
    pub(crate) fn load(c: &Container<'a>, s: usize, q16: bool) -> Result<Self, LoadError> {
        let records: &'a [HierarchyRecord] = c.section(SectionKind::HierarchyRecord)?;
        let record = records.first().ok_or(LoadError::SectionSize {
            kind: SectionKind::HierarchyRecord,
        })?;
        let unexpected: &[SectionKind] = if q16 {
            &[SectionKind::HierarchyData]
        } else {
            &[SectionKind::HierarchyCodes, SectionKind::HierarchyScales]
        };
        if let Some(&kind) = unexpected.iter().find(|&&kind| c.has(kind)) {
            return Err(LoadError::UnexpectedSection { kind });
        }
        let values = if q16 {
            Values::Q16 {
                codes: c.section(SectionKind::HierarchyCodes)?,
                scales: c.section(SectionKind::HierarchyScales)?,
            }
        } else {
            Values::Scalar(c.section(SectionKind::HierarchyData)?)
        };
        let h = Self {
            record,
            leaves: c.section(SectionKind::HierarchyLeaves)?,
            blocks: c.section(SectionKind::HierarchyBlocks)?,
            column_blocks: c.section(SectionKind::HierarchyColumnBlocks)?,
            values,
        };
        h.check_record(s)?;
        check_leaves(h.leaves, s)?;
        for (index, block) in h.blocks.iter().enumerate() {
            h.check_block(block, s)
                .map_err(|what| bad(SectionKind::HierarchyBlocks, index, what))?;
        }
        for leaf in 0..h.leaf_count() {
            h.check_column(leaf, s)
                .map_err(|what| bad(SectionKind::HierarchyColumnBlocks, leaf, what))?;
        }
        h.check_values()?;
        Ok(h)
    }

    /// The numbers: every scalar finite; q16: no code −32768, one scale
    /// pair per block, each such that its block's decoded numbers are
    /// finite (module docs of [`super::format::hierarchy`], "q16 data").
    fn check_values(&self) -> Result<(), LoadError> {
        match self.values {
            Values::Scalar(data) => match data.iter().position(|x| !x.finite()) {
                Some(index) => Err(LoadError::NonFinite {
                    kind: SectionKind::HierarchyData,
                    index: index as u64,
                }),
                None => Ok(()),
            },
            Values::Q16 { codes, scales } => {
                if let Some(index) = codes.iter().position(|&q| q == 0x8000) {
                    return Err(bad(
                        SectionKind::HierarchyCodes,
                        index,
                        "code -32768 (q16 codes lie in -32767..=32767)",
                    ));
                }
                if scales.len() != self.blocks.len() {
                    return Err(bad(
                        SectionKind::HierarchyScales,
                        0,
                        "scale pair count not the block count",
                    ));
                }
                match self
                    .blocks
                    .iter()
                    .zip(scales)
                    .position(|(b, s)| !scales_ok(b, *s))
                {
                    Some(index) => Err(bad(
                        SectionKind::HierarchyScales,
                        index,
                        "scale not finite and > 0, a near block's second not 0, or a decoded \
                         number beyond the scalar's range",
                    )),
                    None => Ok(()),
                }
            }
        }
    }

    /// Numbers stored (scalars or codes).
    fn values_len(&self) -> usize {
        match self.values {
            Values::Scalar(data) => data.len(),
            Values::Q16 { codes, .. } => codes.len(),
        }
    }

    /// `true` if the numbers are q16 codes.
    pub fn is_q16(&self) -> bool {
        matches!(self.values, Values::Q16 { .. })
    }

    /// Bytes per stored number: 2 (q16 codes) or the table scalar's.
    pub fn value_bytes(&self) -> usize {
        match self.values {
            Values::Scalar(_) => core::mem::size_of::<T>(),
            Values::Q16 { .. } => 2,
        }
    }

    /// The record's counts match the sections, its bounds the kernel's.
    fn check_record(&self, s: usize) -> Result<(), LoadError> {
        let r = self.record;
        let leaves = r.leaf_count as usize;
        let fail = |what| Err(bad(SectionKind::HierarchyRecord, 0, what));
        if (s > 0) != (leaves > 0) || leaves > s {
            return fail("leaf count not in 1..=S");
        }
        if self.leaves.len() != leaves + 1 {
            return fail("leaf count not leaf_count + 1");
        }
        if self.blocks.len() != r.block_count as usize {
            return fail("block count not the blocks section's");
        }
        if r.max_rank as usize > HIERARCHY_MAX_RANK {
            return fail("max rank above the kernel's HIERARCHY_MAX_RANK");
        }
        if !(r.tolerance.is_finite() && r.tolerance >= 0.0 && r.eta.is_finite() && r.eta >= 0.0) {
            return fail("tolerance or eta negative or not finite");
        }
        Ok(())
    }

    /// One block's ranges, rank and data offsets.
    fn check_block(&self, b: &HierarchyBlock, s: usize) -> Result<(), &'static str> {
        let range_ok = |start: u32, end: u32| start < end && end as usize <= s;
        if !range_ok(b.row_start, b.row_end) || !range_ok(b.col_start, b.col_end) {
            return Err("row or column range empty or beyond S");
        }
        if b.rank > self.record.max_rank {
            return Err("rank above the record's max rank");
        }
        let within = |offset: u32, len: u64| {
            u64::from(offset)
                .checked_add(len)
                .is_some_and(|end| end <= self.values_len() as u64)
        };
        let (rows, cols, rank) = (b.rows() as u64, b.cols() as u64, u64::from(b.rank));
        let ok = if b.rank == 0 {
            b.flags & !HIERARCHY_MIRRORED == 0 && b.right == 0 && within(b.left, 9 * rows * cols)
        } else {
            b.flags == 0 && within(b.left, 3 * rows * rank) && within(b.right, 3 * cols * rank)
        };
        if ok {
            Ok(())
        } else {
            Err("flags or data offsets invalid")
        }
    }

    /// One leaf's column list: bounded, each block covering the leaf's
    /// columns, rows tiling `0..S` in order.
    fn check_column(&self, leaf: usize, s: usize) -> Result<(), &'static str> {
        let (Some(&[lo, first]), Some(&[hi, end])) =
            (self.leaves.get(leaf), self.leaves.get(leaf + 1))
        else {
            return Err("leaf missing");
        };
        let list = (first <= end)
            .then(|| self.column_blocks.get(first as usize..end as usize))
            .flatten()
            .ok_or("column starts not ascending or beyond the entries")?;
        let last = leaf + 1 == self.leaf_count();
        if (leaf == 0 && first != 0) || (last && end as usize != self.column_blocks.len()) {
            return Err("column starts do not begin at 0 and end at the entry count");
        }
        if list.len() > self.record.max_column_blocks as usize {
            return Err("column list longer than the record's max_column_blocks");
        }
        let mut row = 0u32;
        for &index in list {
            let b = self
                .blocks
                .get(index as usize)
                .ok_or("block index beyond the blocks")?;
            if b.col_start > lo || b.col_end < hi {
                return Err("a listed block does not cover the leaf's columns");
            }
            if b.row_start != row {
                return Err("the listed blocks' rows do not tile 0..S in order");
            }
            row = b.row_end;
        }
        if row as usize == s {
            Ok(())
        } else {
            Err("the listed blocks' rows do not reach S")
        }
    }

    /// Touchable vertices (`S`): the last leaf's end.
    pub fn touchable_count(&self) -> usize {
        self.leaves.last().map_or(0, |&[s, _]| s as usize)
    }

    /// Leaf clusters.
    pub fn leaf_count(&self) -> usize {
        self.record.leaf_count as usize
    }

    /// The record: counts, bounds, tolerance, admissibility.
    pub fn record(&self) -> &'a HierarchyRecord {
        self.record
    }

    /// Every block of the partition.
    pub fn blocks(&self) -> &'a [HierarchyBlock] {
        self.blocks
    }

    /// Per leaf cluster, then one past the last: its first touchable index
    /// (`S` last) and the first entry of its column list (their count last).
    pub fn leaves(&self) -> &'a [[u32; 2]] {
        self.leaves
    }

    /// Numbers stored (near entries and far factors, scalars or codes).
    pub fn data_len(&self) -> usize {
        self.values_len()
    }

    /// The blocks over touchable column `k`'s leaf, sorted by row: empty
    /// for `k ≥ S`. Bounded by the record's `max_column_blocks`; the leaf
    /// found by binary search over the leaves (`log₂` of their count).
    #[inline]
    fn column(&self, k: usize) -> &'a [u32] {
        let leaf = self
            .leaves
            .partition_point(|&[start, _]| start as usize <= k)
            .wrapping_sub(1);
        match (self.leaves.get(leaf), self.leaves.get(leaf.wrapping_add(1))) {
            (Some(&[_, a]), Some(&[_, b])) => self
                .column_blocks
                .get(a as usize..b as usize)
                .unwrap_or(&[]),
            _ => &[],
        }
    }

    /// The block `C_nk` (m/N, row-major) of touchable rows `n` and column
    /// `k`, `None` beyond `0..S`. Two binary searches, then 9 reads (near)
    /// or `9r` multiply-adds (far), times the block's scale (q16).
    #[inline]
    pub fn block(&self, n: usize, k: usize) -> Option<[T; 9]> {
        let list = self.column(k);
        let at = list.partition_point(|&b| {
            self.blocks
                .get(b as usize)
                .is_some_and(|b| b.row_end as usize <= n)
        });
        let index = *list.get(at)? as usize;
        let b = self.blocks.get(index)?;
        if n < b.row_start as usize {
            return None;
        }
        let (i, j) = (
            n - b.row_start as usize,
            k.checked_sub(b.col_start as usize)?,
        );
        match self.values {
            Values::Scalar(data) => entries(data, b, i, j),
            Values::Q16 { codes, scales } => {
                let scale = block_scale(b, *scales.get(index)?);
                Some(entries::<T, u16>(codes, b, i, j)?.map(|x| x * scale))
            }
        }
    }

    /// `out[i] += C_{first+i, k} w` (m, for `w` in N) for the touchable rows
    /// `first .. first + out.len()` (rows `≥ S` add nothing): one pass over
    /// the blocks of `k`'s leaf column (at most `max_column_blocks`), a far
    /// block as `L (Rₖᵀ w)` (`3r` then `3r` per row); q16: `w` times the
    /// block's scale first.
    #[inline]
    pub fn add_column(&self, k: usize, w: &Vector3<T>, first: usize, out: &mut [[T; 3]]) {
        let end = first + out.len();
        let w = [w.x, w.y, w.z];
        for &index in self.column(k) {
            let Some(b) = self.blocks.get(index as usize) else {
                continue;
            };
            let (lo, hi) = (
                (b.row_start as usize).max(first),
                (b.row_end as usize).min(end),
            );
            let (Some(j), true) = (k.checked_sub(b.col_start as usize), lo < hi) else {
                continue;
            };
            let Some(rows) = out.get_mut(lo - first..hi - first) else {
                continue;
            };
            let i0 = lo - b.row_start as usize;
            let rows_of = i0..i0 + rows.len();
            // Each row's part added to its slot of `out`.
            let add = |i: usize, v: [T; 3]| {
                if let Some(u) = rows.get_mut(i - i0) {
                    *u = [u[0] + v[0], u[1] + v[1], u[2] + v[2]];
                }
            };
            match self.values {
                Values::Scalar(data) => {
                    block_rows(data, b, rows_of, j..j + 1, |_| Some(w), T::one(), add);
                }
                Values::Q16 { codes, scales } => {
                    if let Some(&pair) = scales.get(index as usize) {
                        let ws = w.map(|x| x * block_scale(b, pair));
                        block_rows(codes, b, rows_of, j..j + 1, |_| Some(ws), T::one(), add);
                    }
                }
            }
        }
    }
}

/// The factor a q16 block's decoded products take: `s₀` near, `s₀ s₁` far.
#[inline(always)]
fn block_scale<T: Real>(b: &HierarchyBlock, [s0, s1]: [T; 2]) -> T {
    if b.rank == 0 { s0 } else { s0 * s1 }
}

/// A q16 block's scale pair is valid (module docs of
/// [`super::format::hierarchy`], "q16 data").
fn scales_ok<T: Real>(b: &HierarchyBlock, [s0, s1]: [T; 2]) -> bool {
    let largest = T::of_f32(Q16_LARGEST_CODE);
    let positive = |s: T| s.finite() && s > T::zero() && (s * largest).finite();
    if b.rank == 0 {
        positive(s0) && s1 == T::zero()
    } else {
        let rank = T::of_u32(b.rank);
        positive(s0)
            && positive(s1)
            && (s0 * s1 > T::zero())
            && ((s0 * largest) * (s1 * largest) * rank).finite()
    }
}

/// Entry `C_ij` of block `b` (block-relative `i`, `j`) before its scale:
/// a near block's (or, mirrored, its mirror's transposed), a far block's
/// `L_i R_jᵀ` (`9r` multiply-adds).
#[inline(always)]
fn entries<T: Real, E: Stored<T>>(
    values: &[E],
    b: &HierarchyBlock,
    i: usize,
    j: usize,
) -> Option<[T; 9]> {
    if b.rank == 0 {
        return near_entry(values, b, i, j);
    }
    let r = (b.rank as usize).clamp(1, HIERARCHY_MAX_RANK);
    let left = factor_rows(values, b.left, i, r)?;
    let right = factor_rows(values, b.right, j, r)?;
    // One pass over the rank: each of the `6r` factor numbers read (and a
    // q16 code decoded) once, not three times, the nine sums kept apart,
    // each summed in the order of `l` from zero (`C_ab = Σ_l L_al R_bl`).
    let mut c = [T::zero(); 9];
    for (lv, rv) in columns(left, r).zip(columns(right, r)) {
        for (row, &la) in c.chunks_exact_mut(3).zip(&lv) {
            for (x, &rb) in row.iter_mut().zip(&rv) {
                *x += la * rb;
            }
        }
    }
    Some(c)
}

/// The `r` columns of a vertex's three factor rows (`3r` numbers, row
/// after row): column `l` as `[row₀[l], row₁[l], row₂[l]]`, decoded.
#[inline(always)]
fn columns<T: Real, E: Stored<T>>(rows: &[E], r: usize) -> impl Iterator<Item = [T; 3]> + '_ {
    factor_row(rows, 0, r)
        .iter()
        .zip(factor_row(rows, 1, r))
        .zip(factor_row(rows, 2, r))
        .map(|((&a, &b), &c)| [a.value(), b.value(), c.value()])
}

/// Entry `C_ij` of near block `b` (block-relative `i`, `j`), from its
/// data or, mirrored, its mirror's transposed, before its scale.
#[inline(always)]
fn near_entry<T: Real, E: Stored<T>>(
    values: &[E],
    b: &HierarchyBlock,
    i: usize,
    j: usize,
) -> Option<[T; 9]> {
    let mirrored = b.flags & HIERARCHY_MIRRORED != 0;
    let at = if mirrored {
        j * b.rows() + i
    } else {
        i * b.cols() + j
    };
    let start = b.left as usize + 9 * at;
    let d: &[E; 9] = values.get(start..start + 9)?.try_into().ok()?;
    let d = d.map(E::value);
    Some(if mirrored { transpose(&d) } else { d })
}

/// The three rows (`3r` numbers) of vertex `i` of a factor at `offset`.
#[inline(always)]
fn factor_rows<E>(values: &[E], offset: u32, i: usize, r: usize) -> Option<&[E]> {
    let start = offset as usize + 3 * i * r;
    values.get(start..start + 3 * r)
}

impl<T: Real> HierarchicalBlocks<'_, T> {
    /// The product `y = C x` of the whole matrix, delivered in parts: for
    /// every block `b` and each of its rows `i`, `sink(at(i), v)` with
    /// `v = Σ_{j ∈ b} C_ij x_{at(j)}`, so that the parts delivered to a slot
    /// sum to its row of `C x`. `at` maps a hierarchy index to a slot of `x`
    /// and of the sink (`None`: skipped; the identity for a table numbered
    /// in leaf order, a permutation for an interface's connection nodes).
    ///
    /// One pass over the blocks (the record's block count, checked at load),
    /// each over its rows and columns: `9·rows·cols` multiply-adds near,
    /// `3r(rows + cols)` far (`L (Rᵀ x)`, one `r`-vector on the stack); q16:
    /// each part times the block's scale. No allocation, no panic.
    #[inline]
    pub fn products(
        &self,
        at: impl Fn(usize) -> Option<usize>,
        x: &[[T; 3]],
        mut sink: impl FnMut(usize, [T; 3]),
    ) {
        for (index, b) in self.blocks.iter().enumerate() {
            let (r0, c0) = (b.row_start as usize, b.col_start as usize);
            let input = |j: usize| at(c0 + j).and_then(|slot| x.get(slot)).copied();
            let deliver = |i: usize, v: [T; 3]| {
                if let Some(slot) = at(r0 + i) {
                    sink(slot, v);
                }
            };
            let (rows, cols) = (0..b.rows(), 0..b.cols());
            match self.values {
                Values::Scalar(data) => block_rows(data, b, rows, cols, input, T::one(), deliver),
                Values::Q16 { codes, scales } => {
                    if let Some(&pair) = scales.get(index) {
                        let scale = block_scale(b, pair);
                        block_rows(codes, b, rows, cols, input, scale, deliver);
                    }
                }
            }
        }
    }
}

/// The one per-block kernel of [`HierarchicalBlocks::add_column`] (one
/// column, its input already times the block's scale, `scale` one) and
/// [`HierarchicalBlocks::products`] (every column, `scale` the block's):
/// for each block-relative row `i` of `rows`, `out(i, v)` with
/// `v = scale · Σ_{j ∈ cols} C_ij x(j)` (block-relative `j`; a `None` input
/// adds nothing). Near: `v` summed from zero, 9 multiply-adds per entry,
/// then times `scale`; far: `t = scale · Σ_j R_jᵀ x(j)` (`3r` per column,
/// one `r`-vector on the stack), then `v = L_i t` (`3r` per row), so a far
/// block costs `3r(rows + cols)` whatever the column range.
#[inline(always)]
fn block_rows<T: Real, E: Stored<T>>(
    values: &[E],
    b: &HierarchyBlock,
    rows: core::ops::Range<usize>,
    cols: core::ops::Range<usize>,
    x: impl Fn(usize) -> Option<[T; 3]>,
    scale: T,
    mut out: impl FnMut(usize, [T; 3]),
) {
    if b.rank == 0 {
        near_rows(values, b, rows, cols, x, scale, out);
        return;
    }
    let r = (b.rank as usize).clamp(1, HIERARCHY_MAX_RANK);
    let mut t = [T::zero(); HIERARCHY_MAX_RANK];
    let Some(t) = t.get_mut(..r) else {
        return;
    };
    for j in cols {
        let (Some(right), Some(xj)) = (factor_rows(values, b.right, j, r), x(j)) else {
            continue;
        };
        for (bb, &xb) in xj.iter().enumerate() {
            for (tl, &f) in t.iter_mut().zip(factor_row(right, bb, r)) {
                *tl += f.value() * xb;
            }
        }
    }
    t.iter_mut().for_each(|tl| *tl *= scale);
    for i in rows {
        if let Some(left) = factor_rows(values, b.left, i, r) {
            out(
                i,
                core::array::from_fn(|a| dot_scalar(factor_row(left, a, r), t)),
            );
        }
    }
}

/// Columns of a near block whose inputs [`near_rows`] gathers at once (the default leaf size).
const GATHER: usize = 32;

/// [`block_rows`] of a near block: its columns taken [`GATHER`] at a time, their inputs gathered
/// once (a `None` input as zero), then for each row `i` of `rows`, `out(i, v)` with
/// `v = scale · Σ_j C_ij x(j)` over those columns, summed from zero in column order. A row's
/// entries of a stored block are contiguous (`9` numbers per column); a mirrored block's row `i`
/// is its mirror's column `i`, each entry applied transposed. A block of more than [`GATHER`]
/// columns delivers a row's sum in parts, one per `GATHER` columns.
#[inline(always)]
fn near_rows<T: Real, E: Stored<T>>(
    values: &[E],
    b: &HierarchyBlock,
    rows: core::ops::Range<usize>,
    cols: core::ops::Range<usize>,
    x: impl Fn(usize) -> Option<[T; 3]>,
    scale: T,
    mut out: impl FnMut(usize, [T; 3]),
) {
    let mirrored = b.flags & HIERARCHY_MIRRORED != 0;
    let (n_rows, n_cols) = (b.rows(), b.cols());
    for start in cols.clone().step_by(GATHER) {
        let end = (start + GATHER).min(cols.end);
        let mut gathered = [[T::zero(); 3]; GATHER];
        for (g, j) in gathered.iter_mut().zip(start..end) {
            if let Some(xj) = x(j) {
                *g = xj;
            }
        }
        let xs = gathered.get(..end - start).unwrap_or(&[]);
        for i in rows.clone() {
            let mut v = [T::zero(); 3];
            let mut add = |p: [T; 3]| v = [v[0] + p[0], v[1] + p[1], v[2] + p[2]];
            if mirrored {
                for (j, xj) in (start..end).zip(xs) {
                    let at = b.left as usize + 9 * (j * n_rows + i);
                    if let Some(c) = values
                        .get(at..at + 9)
                        .and_then(|c| <&[E; 9]>::try_from(c).ok())
                    {
                        add(block::mul_transposed(&(*c).map(E::value), xj));
                    }
                }
            } else {
                let at = b.left as usize + 9 * (i * n_cols + start);
                if let Some(row) = values.get(at..at + 9 * xs.len()) {
                    for (c, xj) in row.chunks_exact(9).zip(xs) {
                        if let Ok(c) = <&[E; 9]>::try_from(c) {
                            add(block::mul(&(*c).map(E::value), xj));
                        }
                    }
                }
            }
            out(i, v.map(|e| e * scale));
        }
    }
}

/// Row `a` (`r` numbers) of a vertex's three factor rows; empty if beyond.
#[inline(always)]
fn factor_row<E>(rows: &[E], a: usize, r: usize) -> &[E] {
    rows.get(a * r..a * r + r).unwrap_or(&[])
}

/// `Σ a_l t_l` of a stored row and scalars.
#[inline(always)]
fn dot_scalar<T: Real, E: Stored<T>>(a: &[E], t: &[T]) -> T {
    a.iter()
        .zip(t)
        .fold(T::zero(), |s, (&x, &y)| s + x.value() * y)
}

/// A row-major 3×3 block transposed.
#[inline(always)]
fn transpose<T: Real>(c: &[T; 9]) -> [T; 9] {
    [c[0], c[3], c[6], c[1], c[4], c[7], c[2], c[5], c[8]]
}

/// The leaves' first touchable indices: `0`, strictly ascending, `S` last.
fn check_leaves(leaves: &[[u32; 2]], s: usize) -> Result<(), LoadError> {
    let fail = |index, what| Err(bad(SectionKind::HierarchyLeaves, index, what));
    if s == 0 {
        return if leaves == [[0, 0]] {
            Ok(())
        } else {
            fail(
                0,
                "a table without touchable vertices has the one leaf [0, 0]",
            )
        };
    }
    let start = |l: Option<&[u32; 2]>| l.map(|&[start, _]| start as usize);
    if start(leaves.first()) != Some(0) || start(leaves.last()) != Some(s) {
        return fail(0, "leaves do not start at 0 and end at S");
    }
    match leaves
        .iter()
        .zip(leaves.iter().skip(1))
        .position(|(a, b)| a[0] >= b[0])
    {
        Some(index) => fail(index + 1, "leaf starts not strictly ascending"),
        None => Ok(()),
    }
}

/// A [`LoadError::BadHierarchy`].
fn bad(kind: SectionKind, index: usize, what: &'static str) -> LoadError {
    LoadError::BadHierarchy {
        kind,
        index: index as u64,
        what,
    }
}
