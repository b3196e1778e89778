//! Hierarchical compliance (additive to version 6): the touchable–touchable
//! compliance of a pre-computed table as a hierarchical matrix (Hackbusch,
//! *Hierarchical Matrices*, 2015, ch. 5–6; the far-field blocks of an elastic
//! body's Green's function are numerically low-rank, James & Pai 2003).
//!
//! A table stores it when its [`super::CompressionRecord::surface_encoding`]
//! is [`super::BlockEncoding::Hierarchical`]; the dense surface section
//! ([`super::SectionKind::ComplianceSurface`]) and the coded surface sections
//! are then absent and the five sections below present. The interior part
//! keeps its own encoding (a writer that has no interior rows stores it
//! coded with every block dropped).
//!
//! **Ordering.** The touchable free indices `0..S` of such a table are in the
//! order of the cluster tree's leaves (the writer numbers them so; the
//! `free-vertex` section maps them to mesh vertices as always): every
//! cluster is a range of free indices.
//!
//! **Sections.**
//! - [`super::SectionKind::HierarchyRecord`]: one [`HierarchyRecord`], the
//!   declared counts and bounds;
//! - [`super::SectionKind::HierarchyLeaves`]: `[u32; 2]` × (`leaf_count` +
//!   1): per leaf cluster, its first touchable index (`0`, strictly
//!   ascending, `S` last) and the first entry of its column list (`0`,
//!   ascending, the entry count last);
//! - [`super::SectionKind::HierarchyBlocks`]: one [`HierarchyBlock`] per
//!   block of the partition of `S × S` (both triangles: a block below the
//!   diagonal refers to the data of its mirror above it, see
//!   [`HierarchyBlock`]);
//! - [`super::SectionKind::HierarchyColumnBlocks`]: for each leaf `ℓ`, the
//!   blocks whose column range contains it (`u32` block indices from the
//!   leaf's list start to the next leaf's), sorted by row start;
//!   their row ranges tile `0..S` exactly (first starts at 0, each starts
//!   where the previous ends, the last ends at `S`). A list holds at most
//!   [`HierarchyRecord::max_column_blocks`] blocks;
//! - [`super::SectionKind::HierarchyData`]: the table scalar, the near blocks'
//!   entries and the far blocks' factors at the offsets the blocks give, all
//!   finite.
//!
//! **A block's entries.** Rows `i` in `row_start..row_end`, columns `j` in
//! `col_start..col_end` (touchable indices), `C_ij` the 3×3 compliance block
//! (m/N), row-major:
//! - near (`rank` 0), not mirrored: `C_ij` is the 9 scalars at
//!   `left + 9·((i − row_start)·cols + (j − col_start))`, `cols = col_end −
//!   col_start`;
//! - near, mirrored ([`HIERARCHY_MIRRORED`] set): the data are the block's
//!   mirror's (rows and columns swapped), `C_ij = D_jiᵀ`, `D_ji` at
//!   `left + 9·((j − col_start)·rows + (i − row_start))`, `rows = row_end −
//!   row_start`;
//! - far (`rank` `r ≥ 1`): `C = L Rᵀ`, `L` the `3·rows × r` left factor
//!   row-major at `left`, `R` the `3·cols × r` right factor row-major at
//!   `right`: `C_ij[a][b] = Σ_l L[(3(i − row_start) + a)·r + l] ·
//!   R[(3(j − col_start) + b)·r + l]`, `9r` multiply-adds. A mirror's
//!   factors are the same numbers with `left` and `right` swapped, so a far
//!   block is never flagged mirrored.
//!
//! **q16 data.** A [`super::BlockEncoding::HierarchicalQ16`] part holds
//! [`super::SectionKind::HierarchyCodes`] (`u16`, the same count and offsets
//! as the data above) and [`super::SectionKind::HierarchyScales`] (one
//! `[s₀, s₁]` per block, in the table scalar) in place of
//! [`super::SectionKind::HierarchyData`]. A code `q` is the two's complement
//! `i16` in `−32767..=32767` ([`super::q16_value`]); with `Q`, `Q_L`, `Q_R`
//! the codes read where the entries, `L` and `R` are read above:
//! - near: `C_ij = s₀ · Q_ij`, `s₁ = 0` (`s₀ = max |entry| / 32767`, the
//!   quantum, rounded to the scalar first; the writer rounds `x / s₀` to
//!   nearest: absolute error `≤ s₀ / 2` per entry);
//! - far: `C = (s₀ s₁) · Q_L Q_Rᵀ`, `s₀` and `s₁` the quanta of `L` and
//!   `R` (error `≤ r (|L|_max s₁ + |R|_max s₀) / 2` per entry, first order).
//!
//! A block's scales are computed from the data it reads, so a mirrored near
//! block has its mirror's `s₀` and a far mirror the swapped pair. Every
//! scale is finite and `> 0` (`s₁` of a near block: 0), and `32767 s` (far:
//! `r · 32767² s₀ s₁`) finite: every decoded number is.

use bytemuck::{Pod, Zeroable};

/// The largest far-block rank a kernel reads ([`HierarchyRecord::max_rank`]
/// is refused above it): the step path keeps one `r`-vector on the stack
/// (`HIERARCHY_MAX_RANK` scalars). A writer stores a block whose rank would
/// exceed it (or whose factors would outweigh its entries) as a near block.
pub const HIERARCHY_MAX_RANK: usize = 64;

/// [`HierarchyBlock::flags`] bit: a near block whose data are its mirror's
/// (see the module docs).
pub const HIERARCHY_MIRRORED: u32 = 1;

/// The one element of [`super::SectionKind::HierarchyRecord`]: the counts
/// the other hierarchy sections hold, the bounds the step path's loops
/// take, and how the writer built the partition (informative).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct HierarchyRecord {
    /// Leaf clusters (`≥ 1` when `S > 0`).
    pub leaf_count: u32,
    /// Blocks of the partition, both triangles.
    pub block_count: u32,
    /// The largest far-block rank, `≤` [`HIERARCHY_MAX_RANK`].
    pub max_rank: u32,
    /// The longest column list (blocks over one leaf column): the bound of
    /// the step path's loop over a column.
    pub max_column_blocks: u32,
    /// The writer's leaf size: a cluster of more touchable vertices than
    /// this was split (informative).
    pub leaf_size: u32,
    /// Levels of the cluster tree, the root's included (informative).
    pub depth: u32,
    /// The far blocks' relative truncation tolerance, Frobenius norm per
    /// block (informative): `‖C_b − L Rᵀ‖_F ≤ tolerance · ‖C_b‖_F`.
    pub tolerance: f64,
    /// The admissibility parameter `η`: a block of clusters `τ, σ` is far
    /// when `min(diam τ, diam σ) ≤ η · dist(τ, σ)` (bounding boxes;
    /// informative).
    pub eta: f64,
}

/// Size of [`HierarchyRecord`] in bytes.
pub const HIERARCHY_RECORD_LEN: usize = core::mem::size_of::<HierarchyRecord>();
const _: () = assert!(HIERARCHY_RECORD_LEN == 40);

/// One element of [`super::SectionKind::HierarchyBlocks`]: a block of the
/// partition and where its data are (module docs, "A block's entries";
/// offsets in scalars from the start of
/// [`super::SectionKind::HierarchyData`]).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Pod, Zeroable)]
pub struct HierarchyBlock {
    /// First row (touchable index).
    pub row_start: u32,
    /// One past the last row, `> row_start`, `≤ S`.
    pub row_end: u32,
    /// First column.
    pub col_start: u32,
    /// One past the last column, `> col_start`, `≤ S`.
    pub col_end: u32,
    /// 0: a near block stored entry by entry; `r ≥ 1`: a far block `L Rᵀ`.
    pub rank: u32,
    /// Offset of the near block's entries, or of the far block's `L`.
    pub left: u32,
    /// Offset of the far block's `R`; 0 for a near block.
    pub right: u32,
    /// [`HIERARCHY_MIRRORED`] or 0 (a far block: 0).
    pub flags: u32,
}

/// Size of [`HierarchyBlock`] in bytes.
pub const HIERARCHY_BLOCK_LEN: usize = core::mem::size_of::<HierarchyBlock>();
const _: () = assert!(HIERARCHY_BLOCK_LEN == 32);

impl HierarchyBlock {
    /// Rows (touchable vertices) the block spans.
    pub const fn rows(&self) -> usize {
        self.row_end.saturating_sub(self.row_start) as usize
    }

    /// Columns (touchable vertices) the block spans.
    pub const fn cols(&self) -> usize {
        self.col_end.saturating_sub(self.col_start) as usize
    }

    /// Scalars of its data: `9·rows·cols` near, `3·(rows + cols)·r` far
    /// (a mirrored near block's data are its mirror's: counted there by a
    /// writer, the same number here).
    pub const fn data_len(&self) -> usize {
        if self.rank == 0 {
            9 * self.rows() * self.cols()
        } else {
            3 * (self.rows() + self.cols()) * self.rank as usize
        }
    }
}
