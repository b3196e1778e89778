//! The two compliance parts of a pre-computed table as stored: every block
//! in the table scalar, or 16-bit codes times a per-column scale with the
//! far-field blocks dropped ([`super::format`], "Compressed compliance").
//! Checked once at load ([`load_parts`]); decoded on the fly by the step
//! path, in constant time per block ([`ComplianceBlocks::block`]) and in one
//! pass per column ([`ComplianceBlocks::add_products`]).

use nalgebra::Vector3;

use super::LoadError;
use super::container::{Container, check_finite};
use super::format::{
    self, BlockEncoding, CompressionRecord, KEPT_BITS, SectionKind, is_kept, kept_position,
    kept_rank, q16_value, surface_block_index,
};
use super::hierarchical::HierarchicalBlocks;
use crate::Real;
use crate::math::block;

/// The 16-bit code of a coded part (a [`BlockEncoding`] other than
/// [`BlockEncoding::Scalar`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Code {
    /// IEEE 754 binary16.
    F16,
    /// `i16` fixed point.
    Q16,
}

impl Code {
    /// The largest magnitude a valid code decodes to.
    fn largest(self) -> f32 {
        match self {
            Code::F16 => format::F16_LARGEST_CODE,
            Code::Q16 => format::Q16_LARGEST_CODE,
        }
    }
}

/// One compliance part (the surface or the interior blocks, layouts in
/// [`super::format`]) as the table stores it, validated at load. Blocks are
/// addressed by their index `j` in the dense layout and the column `k` (the
/// touchable vertex) they belong to, whose scale a coded part applies.
#[derive(Clone, Copy, Debug)]
pub enum ComplianceBlocks<'a, T: Real> {
    /// Every block in the table scalar, row-major, m/N
    /// ([`BlockEncoding::Scalar`]).
    Dense(&'a [[T; 9]]),
    /// 16-bit codes times a per-column scale; a dropped block is zero.
    Coded(CodedBlocks<'a, T>),
    /// The surface part as a hierarchical matrix
    /// ([`BlockEncoding::Hierarchical`], [`BlockEncoding::HierarchicalQ16`]): block `j` of column `k` of the
    /// packed layout is `C_nk` with `n = j − k(k+1)/2`, or its mirror
    /// `C_knᵀ` read from column `n` (the same numbers by symmetry).
    Hierarchical(HierarchicalBlocks<'a, T>),
}

/// A coded compliance part: codes, per-column scales, and which blocks are
/// kept. Invariants from `load_parts`: the scales are finite and `> 0`,
/// no code is an infinity or NaN (f16) or −32768 (q16), the kept-block
/// bitmap is consistent and counts exactly the stored codes (without one,
/// every block is stored, or none: the codes are then empty, and a block's
/// position is past them).
#[derive(Clone, Copy, Debug)]
pub struct CodedBlocks<'a, T: Real> {
    code: Code,
    scales: &'a [T],
    codes: &'a [[u16; 9]],
    kept: Option<&'a [[u32; 2]]>,
    blocks: usize,
}

impl<'a, T: Real> ComplianceBlocks<'a, T> {
    /// Blocks of the dense layout (stored or dropped).
    pub fn len(&self) -> usize {
        match self {
            ComplianceBlocks::Dense(blocks) => blocks.len(),
            ComplianceBlocks::Coded(coded) => coded.blocks,
            ComplianceBlocks::Hierarchical(h) => {
                let s = h.touchable_count();
                s * (s + 1) / 2
            }
        }
    }

    /// `true` for a part without blocks (no touchable or no interior
    /// vertex).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Blocks stored: [`Self::len`] less the dropped ones; for a
    /// hierarchical part, its stored scalars over 9 (near entries and far
    /// factors, in 3×3-block equivalents).
    pub fn stored_len(&self) -> usize {
        match self {
            ComplianceBlocks::Dense(blocks) => blocks.len(),
            ComplianceBlocks::Coded(coded) => coded.codes.len(),
            ComplianceBlocks::Hierarchical(h) => h.data_len().div_ceil(9),
        }
    }

    /// How the part is stored.
    pub fn encoding(&self) -> BlockEncoding {
        match self {
            ComplianceBlocks::Dense(_) => BlockEncoding::Scalar,
            ComplianceBlocks::Coded(CodedBlocks {
                code: Code::F16, ..
            }) => BlockEncoding::F16,
            ComplianceBlocks::Coded(CodedBlocks {
                code: Code::Q16, ..
            }) => BlockEncoding::Q16,
            ComplianceBlocks::Hierarchical(h) if h.is_q16() => BlockEncoding::HierarchicalQ16,
            ComplianceBlocks::Hierarchical(_) => BlockEncoding::Hierarchical,
        }
    }

    /// The blocks in the table scalar, `None` for a coded part.
    pub fn as_dense(&self) -> Option<&'a [[T; 9]]> {
        match self {
            ComplianceBlocks::Dense(blocks) => Some(blocks),
            ComplianceBlocks::Coded(_) | ComplianceBlocks::Hierarchical(_) => None,
        }
    }

    /// The hierarchical part, `None` for a dense or coded one.
    pub fn as_hierarchical(&self) -> Option<&HierarchicalBlocks<'a, T>> {
        match self {
            ComplianceBlocks::Hierarchical(h) => Some(h),
            _ => None,
        }
    }

    /// `true` if block `j` of the dense layout is stored (not dropped, not
    /// beyond the layout).
    pub fn is_stored(&self, j: usize) -> bool {
        match self {
            ComplianceBlocks::Dense(blocks) => j < blocks.len(),
            ComplianceBlocks::Coded(coded) => match coded.kept {
                // Without a bitmap: every block stored, or none.
                None => j < coded.codes.len(),
                Some(kept) => j < coded.blocks && is_kept(kept, j),
            },
            ComplianceBlocks::Hierarchical(_) => j < self.len(),
        }
    }

    /// Block `j` of the dense layout, of column `column`, row-major, m/N: a
    /// dropped block is zero. `None` if `j` lies beyond the layout or (coded)
    /// `column` beyond the scales. Constant time.
    #[inline]
    pub fn block(&self, j: usize, column: usize) -> Option<[T; 9]> {
        match self {
            ComplianceBlocks::Dense(blocks) => blocks.get(j).copied(),
            ComplianceBlocks::Coded(coded) => coded.block(j, column),
            ComplianceBlocks::Hierarchical(h) => {
                h.block(j.checked_sub(surface_block_index(0, column))?, column)
            }
        }
    }

    /// `out[i] += C_{first+i} w` (m, for `w` in N) for the blocks
    /// `first .. first + out.len()` of the dense layout, all of column
    /// `column`. Blocks beyond the layout add nothing. Always inlined, as
    /// its one caller in the step path (the pre-computed update, which a
    /// host's run-time CPU-feature dispatch compiles where it runs:
    /// [`crate::math::Dispatch`]).
    #[inline(always)]
    pub fn add_products(&self, first: usize, column: usize, w: &Vector3<T>, out: &mut [[T; 3]]) {
        match self {
            ComplianceBlocks::Dense(blocks) => {
                if let Some(blocks) = blocks.get(first..first + out.len()) {
                    add_products(blocks, w, out);
                }
            }
            ComplianceBlocks::Coded(coded) => coded.add_products(first, column, w, out),
            ComplianceBlocks::Hierarchical(h) => {
                if let Some(n) = first.checked_sub(surface_block_index(0, column)) {
                    h.add_column(column, w, n, out);
                }
            }
        }
    }

    /// `out[i] += C_{k,n}ᵀ w` for `n = first + i` (m): the blocks of row `k`
    /// in the packed surface columns `n > k` ([`surface_block_index`]`(k,
    /// n)`, each of its own column `n`), transposed. Blocks beyond the
    /// layout add nothing. Always inlined, as [`Self::add_products`].
    #[inline(always)]
    pub fn add_transposed_products(
        &self,
        k: usize,
        first: usize,
        w: &Vector3<T>,
        out: &mut [[T; 3]],
    ) {
        match self {
            ComplianceBlocks::Dense(blocks) => {
                for (n, u) in (first..).zip(out) {
                    if let Some(c) = blocks.get(surface_block_index(k, n)) {
                        let v = mul_transposed(c, w);
                        *u = [u[0] + v[0], u[1] + v[1], u[2] + v[2]];
                    }
                }
            }
            ComplianceBlocks::Coded(coded) => {
                for (n, u) in (first..).zip(out) {
                    if let Some(c) = coded.block(surface_block_index(k, n), n) {
                        let v = mul_transposed(&c, w);
                        *u = [u[0] + v[0], u[1] + v[1], u[2] + v[2]];
                    }
                }
            }
            // `C_knᵀ = C_nk`: column `k`'s rows `first..`.
            ComplianceBlocks::Hierarchical(h) => h.add_column(k, w, first, out),
        }
    }
}

impl<T: Real> CodedBlocks<'_, T> {
    /// The decoded values of one stored block, before its column's scale.
    #[inline(always)]
    fn values(&self, codes: &[u16; 9]) -> [T; 9] {
        match self.code {
            Code::F16 => codes.map(|c| T::of_f32(format::f16_to_f32(c))),
            Code::Q16 => codes.map(|c| T::of_f32(q16_value(c))),
        }
    }

    /// See [`ComplianceBlocks::block`].
    #[inline]
    fn block(&self, j: usize, column: usize) -> Option<[T; 9]> {
        if j >= self.blocks {
            return None;
        }
        let scale = *self.scales.get(column)?;
        let position = match self.kept {
            None => Some(j),
            Some(kept) => kept_position(kept, j),
        };
        Some(match position.and_then(|p| self.codes.get(p)) {
            Some(codes) => self.values(codes).map(|v| v * scale),
            None => [T::zero(); 9],
        })
    }

    /// See [`ComplianceBlocks::add_products`]: `out[i] += Q_i (s w)`, the
    /// decoded codes times the scaled `w` (`s` the column's scale). Always
    /// inlined, as [`ComplianceBlocks::add_products`].
    #[inline(always)]
    fn add_products(&self, first: usize, column: usize, w: &Vector3<T>, out: &mut [[T; 3]]) {
        let Some(&scale) = self.scales.get(column) else {
            return;
        };
        let w = w * scale;
        match self.kept {
            None => {
                if let Some(codes) = self.codes.get(first..first + out.len()) {
                    match self.code {
                        Code::F16 => add_coded_products(codes, format::f16_to_f32, &w, out),
                        Code::Q16 => add_coded_products(codes, q16_value, &w, out),
                    }
                }
            }
            Some(kept) => {
                // The stored blocks of the range are consecutive from the
                // rank of its first block.
                let Some(mut next) = kept_rank(kept, first) else {
                    return;
                };
                for (j, u) in (first..).zip(out) {
                    if is_kept(kept, j) {
                        if let Some(codes) = self.codes.get(next) {
                            let q = self.values(codes);
                            *u = [
                                u[0] + (q[0] * w.x + q[1] * w.y + q[2] * w.z),
                                u[1] + (q[3] * w.x + q[4] * w.y + q[5] * w.z),
                                u[2] + (q[6] * w.x + q[7] * w.y + q[8] * w.z),
                            ];
                        }
                        next += 1;
                    }
                }
            }
        }
    }
}

/// `out[i] += Q_i w` for the blocks of 16-bit `codes` decoded by `value`,
/// written as [`add_products`] is, one output float per row of 3 codes.
#[inline(always)]
fn add_coded_products<T: Real>(
    codes: &[[u16; 9]],
    value: impl Fn(u16) -> f32,
    w: &Vector3<T>,
    out: &mut [[T; 3]],
) {
    let (rows, _) = codes.as_flattened().as_chunks::<3>();
    let q = |c: u16| T::of_f32(value(c));
    for (r, u) in rows.iter().zip(out.as_flattened_mut()) {
        *u += q(r[0]) * w.x + q(r[1]) * w.y + q(r[2]) * w.z;
    }
}

/// `out[i] += C_i w` for row-major 3×3 blocks `C_i`, written as a product of
/// the `3F × 3` matrix of their rows with `w` so that it vectorizes (one
/// output float per row of 3).
#[inline(always)]
fn add_products<T: Real>(blocks: &[[T; 9]], w: &Vector3<T>, out: &mut [[T; 3]]) {
    let (rows, _) = blocks.as_flattened().as_chunks::<3>();
    for (r, u) in rows.iter().zip(out.as_flattened_mut()) {
        *u += r[0] * w.x + r[1] * w.y + r[2] * w.z;
    }
}

/// Transpose of a row-major 3×3 block times a vector
/// (`math::block::mul_transposed`, the same products in the same order).
#[inline(always)]
fn mul_transposed<T: Real>(c: &[T; 9], w: &Vector3<T>) -> [T; 3] {
    block::mul_transposed(c, &[w.x, w.y, w.z])
}

/// The sections of one compliance part.
struct Part {
    dense: SectionKind,
    scale: SectionKind,
    codes: SectionKind,
    kept: SectionKind,
}

const SURFACE: Part = Part {
    dense: SectionKind::ComplianceSurface,
    scale: SectionKind::SurfaceScale,
    codes: SectionKind::SurfaceCodes,
    kept: SectionKind::SurfaceKept,
};

const INTERIOR: Part = Part {
    dense: SectionKind::ComplianceInterior,
    scale: SectionKind::InteriorScale,
    codes: SectionKind::InteriorCodes,
    kept: SectionKind::InteriorKept,
};

/// The sections of a hierarchical surface part (either encoding).
const HIERARCHY: [SectionKind; 7] = [
    SectionKind::HierarchyRecord,
    SectionKind::HierarchyLeaves,
    SectionKind::HierarchyBlocks,
    SectionKind::HierarchyColumnBlocks,
    SectionKind::HierarchyData,
    SectionKind::HierarchyCodes,
    SectionKind::HierarchyScales,
];

/// The compliance of a pre-computed table as loaded: the encoding record
/// (absent: both parts dense) and the two parts.
pub(crate) struct Parts<'a, T: Real> {
    pub(crate) record: Option<CompressionRecord>,
    pub(crate) surface: ComplianceBlocks<'a, T>,
    pub(crate) interior: ComplianceBlocks<'a, T>,
}

/// Reads and checks the encoding record and both compliance parts: each
/// part's sections are those its encoding uses, no other (a dense part: its
/// finite blocks; a coded part: finite positive scales, codes that are not
/// infinities, NaNs or −32768, a consistent kept-block bitmap counting the
/// codes exactly). The diagonal blocks are the view's to check.
pub(crate) fn load_parts<'a, T: Real>(c: &Container<'a>) -> Result<Parts<'a, T>, LoadError> {
    let record = load_record(c)?;
    let (surface, interior) = match &record {
        None => (BlockEncoding::Scalar, BlockEncoding::Scalar),
        Some(r) => (
            encoding(SURFACE.dense, r.surface_encoding)?,
            encoding(INTERIOR.dense, r.interior_encoding)?,
        ),
    };
    if !surface.is_hierarchical()
        && let Some(&kind) = HIERARCHY.iter().find(|&&kind| c.has(kind))
    {
        return Err(LoadError::UnexpectedSection { kind });
    }
    Ok(Parts {
        record,
        surface: load_part(c, &SURFACE, surface)?,
        interior: load_part(c, &INTERIOR, interior)?,
    })
}

fn encoding(part: SectionKind, found: u32) -> Result<BlockEncoding, LoadError> {
    BlockEncoding::of_u32(found).ok_or(LoadError::UnknownEncoding { part, found })
}

/// The [`SectionKind::ComplianceEncoding`] record, if present, checked.
fn load_record(c: &Container<'_>) -> Result<Option<CompressionRecord>, LoadError> {
    let kind = SectionKind::ComplianceEncoding;
    let Some(records) = c.optional_section::<CompressionRecord>(kind)? else {
        return Ok(None);
    };
    let record = *records.first().ok_or(LoadError::SectionSize { kind })?;
    let error_ok = |e: f64| e.is_finite() && e >= 0.0;
    let ok = record.drop_below.is_finite()
        && (0.0..1.0).contains(&record.drop_below)
        && error_ok(record.max_force_error)
        && error_ok(record.max_displacement_error)
        && error_ok(record.max_surface_displacement_error)
        && record.reserved == 0;
    if ok {
        Ok(Some(record))
    } else {
        Err(LoadError::BadCompressionRecord)
    }
}

fn load_part<'a, T: Real>(
    c: &Container<'a>,
    part: &Part,
    encoding: BlockEncoding,
) -> Result<ComplianceBlocks<'a, T>, LoadError> {
    let code = match encoding {
        BlockEncoding::Scalar => {
            if let Some(&kind) = [part.scale, part.codes, part.kept]
                .iter()
                .find(|&&kind| c.has(kind))
            {
                return Err(LoadError::UnexpectedSection { kind });
            }
            let blocks: &'a [[T; 9]] = c.section(part.dense)?;
            check_finite(part.dense, blocks)?;
            return Ok(ComplianceBlocks::Dense(blocks));
        }
        BlockEncoding::F16 => Code::F16,
        BlockEncoding::Q16 => Code::Q16,
        BlockEncoding::Hierarchical | BlockEncoding::HierarchicalQ16 => {
            // Only the surface part; its dense and coded sections absent.
            if part.dense != SURFACE.dense {
                return Err(LoadError::UnknownEncoding {
                    part: part.dense,
                    found: encoding as u32,
                });
            }
            if let Some(&kind) = [part.dense, part.scale, part.codes, part.kept]
                .iter()
                .find(|&&kind| c.has(kind))
            {
                return Err(LoadError::UnexpectedSection { kind });
            }
            let s = c.header.touchable_count as usize;
            let q16 = encoding == BlockEncoding::HierarchicalQ16;
            return Ok(ComplianceBlocks::Hierarchical(HierarchicalBlocks::load(
                c, s, q16,
            )?));
        }
    };
    if c.has(part.dense) {
        return Err(LoadError::UnexpectedSection { kind: part.dense });
    }
    let size = LoadError::SectionSize { kind: part.codes };
    let blocks = part
        .dense
        .expected_count(&c.header)
        .and_then(|b| usize::try_from(b).ok())
        .ok_or(size)?;
    let scales: &'a [T] = c.section(part.scale)?;
    let codes: &'a [[u16; 9]] = c.section(part.codes)?;
    let kept: Option<&'a [[u32; 2]]> = c.optional_section(part.kept)?;
    // A scale that a valid code would take past the scalar's range is
    // refused too: every decoded block is then finite.
    let largest = T::of_f32(code.largest());
    let scale_ok = |s: T| s.finite() && s > T::zero() && (s * largest).finite();
    if let Some(column) = scales.iter().position(|&s| !scale_ok(s)) {
        return Err(LoadError::BadScale {
            kind: part.scale,
            column: column as u32,
        });
    }
    let count_ok = match kept {
        Some(kept) => codes.len() == check_kept(part.kept, kept, blocks)?,
        // Every block stored, or every one dropped.
        None => codes.len() == blocks || codes.is_empty(),
    };
    if !count_ok {
        return Err(size);
    }
    let bad = |codes: &[u16; 9]| match code {
        Code::F16 => codes.iter().any(|&c| (c >> 10) & 0x1f == 0x1f),
        Code::Q16 => codes.contains(&0x8000),
    };
    if let Some(index) = codes.iter().position(bad) {
        let (kind, index) = (part.codes, index as u64);
        return Err(match code {
            Code::F16 => LoadError::NonFinite { kind, index },
            Code::Q16 => LoadError::BadCode { kind, index },
        });
    }
    Ok(ComplianceBlocks::Coded(CodedBlocks {
        code,
        scales,
        codes,
        kept,
        blocks,
    }))
}

/// Checks a kept-block bitmap over `blocks` blocks (its word count is the
/// container's): each rank is the number of bits set before its word, no
/// bit is set past `blocks`. Returns the bits set.
fn check_kept(kind: SectionKind, kept: &[[u32; 2]], blocks: usize) -> Result<usize, LoadError> {
    let mut total = 0usize;
    for (word, &[bits, rank]) in kept.iter().enumerate() {
        let valid = blocks.saturating_sub(word.saturating_mul(KEPT_BITS));
        let past = if valid >= KEPT_BITS {
            0
        } else {
            u32::MAX << valid
        };
        if rank as usize != total || bits & past != 0 {
            return Err(LoadError::BadKeptBlocks {
                kind,
                word: word as u64,
            });
        }
        total += bits.count_ones() as usize;
    }
    Ok(total)
}
