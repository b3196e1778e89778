//! Compressed compliance (format version 3, additive): how a part of the
//! compliance is stored ([`BlockEncoding`], [`CompressionRecord`]), the
//! binary16 decoding and the kept-block bitmap. The layout is the
//! format's ([`super`], "Compressed compliance"; "module docs" below).

use bytemuck::{Pod, Zeroable};

/// The largest magnitude of a [`BlockEncoding::Q16`] code (`i16` in
/// `−32767..=32767`).
pub const Q16_LARGEST_CODE: f32 = 32767.0;

/// The largest magnitude a [`BlockEncoding::F16`] code decodes to
/// (binary16's largest finite value).
pub const F16_LARGEST_CODE: f32 = 65504.0;

/// How one compliance part (surface or interior) is stored: the values of
/// [`CompressionRecord::surface_encoding`] and
/// [`CompressionRecord::interior_encoding`] (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum BlockEncoding {
    /// Every block in the table scalar (`f32` or `f64`), the dense section.
    Scalar = 0,
    /// IEEE 754 binary16 codes times a per-column scale; blocks may be dropped.
    F16 = 1,
    /// 16-bit fixed point (`i16` in `−32767..=32767`) times a per-column
    /// scale (the quantum); blocks may be dropped.
    Q16 = 2,
    /// The surface part as a hierarchical matrix: near blocks entry by
    /// entry, far blocks as low-rank factors ([`super::hierarchy`]). Not an
    /// encoding of the interior part.
    Hierarchical = 3,
    /// The surface part as a hierarchical matrix whose near entries and
    /// far factors are 16-bit fixed point (`i16` in `−32767..=32767`) times
    /// a scale per block and factor ([`super::hierarchy`], "q16 data").
    /// Not an encoding of the interior part.
    HierarchicalQ16 = 4,
}

impl BlockEncoding {
    /// Every encoding, in value order.
    pub const ALL: [BlockEncoding; 5] = [
        BlockEncoding::Scalar,
        BlockEncoding::F16,
        BlockEncoding::Q16,
        BlockEncoding::Hierarchical,
        BlockEncoding::HierarchicalQ16,
    ];

    /// The encoding of a record's value, `None` if unknown.
    pub fn of_u32(value: u32) -> Option<Self> {
        Self::ALL.into_iter().find(|e| *e as u32 == value)
    }

    /// Human-readable name, for `tables info`: `uncompressed` (the table
    /// scalar), `f16`, `q16`, `hmatrix`, `hmatrix-q16`.
    pub const fn name(self) -> &'static str {
        match self {
            BlockEncoding::Scalar => "uncompressed",
            BlockEncoding::F16 => "f16",
            BlockEncoding::Q16 => "q16",
            BlockEncoding::Hierarchical => "hmatrix",
            BlockEncoding::HierarchicalQ16 => "hmatrix-q16",
        }
    }

    /// `true` for the hierarchical encodings of the surface part
    /// ([`Self::Hierarchical`], [`Self::HierarchicalQ16`]).
    pub const fn is_hierarchical(self) -> bool {
        matches!(
            self,
            BlockEncoding::Hierarchical | BlockEncoding::HierarchicalQ16
        )
    }
}

/// The value of a q16 code ([`BlockEncoding::Q16`],
/// [`BlockEncoding::HierarchicalQ16`]): the code as a two's complement
/// `i16`, exact in `f32`; a table is refused at load if it holds −32768.
#[inline(always)]
pub fn q16_value(code: u16) -> f32 {
    f32::from(code.cast_signed())
}

/// Identifies the probe set of [`CompressionRecord::probe_set`]: at every
/// touchable vertex `k`, a press of 1 mm along each axis alone (three
/// solves), and two two-contact presses of 1 mm along `−z`, `k` with the
/// nearest other touchable vertex and `k` with touchable vertex
/// `(k + ⌊S/2⌋) mod S` (`5S` contact sets in all, the vertex contacts of the
/// `precomputed solve` command).
pub const PROBE_SET_EVERY_TOUCHABLE: u32 = 1;

/// Identifies a sampled probe set: the five contact sets of
/// [`PROBE_SET_EVERY_TOUCHABLE`] at the touchable indices `⌊i·S/P⌋`,
/// `i` in `0..P`, `P` = [`PROBE_SAMPLE_COUNT`] (the partners still taken
/// among every touchable vertex), for a table whose `S` exceeds `P`; its
/// errors are measured against the exact compliance columns (a
/// hierarchical table's writer).
pub const PROBE_SET_SAMPLED: u32 = 2;

/// The touchable indices of [`PROBE_SET_SAMPLED`].
pub const PROBE_SAMPLE_COUNT: usize = 256;

/// The one element of [`super::SectionKind::ComplianceEncoding`]: how the
/// compliance is stored, and the error that cost, measured by the host at
/// build time against the `f32` table of the same compliance.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct CompressionRecord {
    /// A [`BlockEncoding`] value: how the touchable–touchable blocks (the
    /// contact solve's) are stored.
    pub surface_encoding: u32,
    /// A [`BlockEncoding`] value: how the interior blocks are stored.
    pub interior_encoding: u32,
    /// The drop threshold the writer applied, relative, in `[0, 1)`: a block
    /// `C_nk` (`n ≠ k`) of a part with a kept-block bitmap was dropped when
    /// its largest entry was below this fraction of the largest entry of
    /// both its columns `n` and `k` (of column `k` for an interior row).
    /// Zero: none dropped.
    pub drop_below: f64,
    /// Largest relative contact-force error over the probe set, against the
    /// `f32` table: per contact set `max_p |g_p − g'_p| / max_p |g'_p|`.
    /// Finite, `≥ 0`.
    pub max_force_error: f64,
    /// Largest relative displacement error over the probe set, against the
    /// `f32` table, over every free vertex: per contact set
    /// `max_n |u_n − u'_n| / max_n |u'_n|`. Finite, `≥ 0`.
    pub max_displacement_error: f64,
    /// The same over the touchable (surface) vertices only, what a surface
    /// renderer shows: `max_{n<S} |u_n − u'_n| / max_n |u'_n|`. Finite,
    /// `≥ 0`.
    pub max_surface_displacement_error: f64,
    /// Contact sets in the probe set.
    pub probe_count: u64,
    /// Which probe set: [`PROBE_SET_EVERY_TOUCHABLE`] or
    /// [`PROBE_SET_SAMPLED`].
    pub probe_set: u32,
    /// Zero.
    pub reserved: u32,
}

/// Size of [`CompressionRecord`] in bytes.
pub const COMPRESSION_RECORD_LEN: usize = core::mem::size_of::<CompressionRecord>();
const _: () = assert!(COMPRESSION_RECORD_LEN == 56);

/// The value of an IEEE 754 binary16 code (1 sign, 5 exponent bits biased
/// by 15, 10 fraction bits), exactly: `(−1)^s · 2^(e−15) · (1 + f/1024)`
/// for `e` in `1..=30`, `(−1)^s · f · 2^−24` for `e = 0` (zero and the
/// subnormals). `e = 31` (infinities, NaNs) gives the `f32` infinity or a
/// quiet NaN with the same payload; a coded table holding one is refused at
/// load, so the step path never decodes one. Every binary16 value is an
/// `f32`, so the result is exact; no rounding mode or flush-to-zero setting
/// of the FPU enters (the subnormals are computed as `f · 2^−24`, a normal
/// `f32`).
#[inline]
pub fn f16_to_f32(code: u16) -> f32 {
    let sign = u32::from(code & 0x8000) << 16;
    let exponent = u32::from(code >> 10) & 0x1f;
    let fraction = u32::from(code & 0x03ff);
    let magnitude = match exponent {
        // 2^-24 is exact in f32; f < 2^10 converts exactly.
        0 => fraction as f32 * (1.0 / 16_777_216.0),
        31 => f32::from_bits(0x7f80_0000 | (fraction << 13)),
        // Re-biased from 15 to 127.
        _ => f32::from_bits(((exponent + 112) << 23) | (fraction << 13)),
    };
    f32::from_bits(magnitude.to_bits() | sign)
}

/// Blocks per word of a kept-block bitmap ([`super::SectionKind::SurfaceKept`],
/// [`super::SectionKind::InteriorKept`]).
pub const KEPT_BITS: usize = 32;

/// Words of a kept-block bitmap over `blocks` blocks, `None` on overflow.
pub fn kept_words(blocks: u64) -> Option<u64> {
    Some(blocks.checked_add(KEPT_BITS as u64 - 1)? / KEPT_BITS as u64)
}

/// The number of blocks kept before block `j` of the dense layout, in a
/// part whose kept-block bitmap is `kept` (`[bits, rank]` words, module
/// docs): the rank of the word plus the bits set below `j` in it. `None` if
/// `j` lies beyond the bitmap. Constant time.
#[inline]
pub fn kept_rank(kept: &[[u32; 2]], j: usize) -> Option<usize> {
    let [bits, rank] = *kept.get(j / KEPT_BITS)?;
    let below = (1u32 << (j % KEPT_BITS)) - 1;
    Some(rank as usize + (bits & below).count_ones() as usize)
}

/// `true` if block `j` of the dense layout is kept in a part whose
/// kept-block bitmap is `kept`; `false` if it was dropped or lies beyond.
#[inline]
pub fn is_kept(kept: &[[u32; 2]], j: usize) -> bool {
    kept.get(j / KEPT_BITS)
        .is_some_and(|[bits, _]| bits & (1u32 << (j % KEPT_BITS)) != 0)
}

/// Where block `j` of the dense layout is stored (its index among the
/// stored blocks) in a part whose kept-block bitmap is `kept`: `None` if it
/// was dropped or lies beyond the bitmap. Constant time: one word, one
/// population count.
#[inline]
pub fn kept_position(kept: &[[u32; 2]], j: usize) -> Option<usize> {
    if is_kept(kept, j) {
        kept_rank(kept, j)
    } else {
        None
    }
}
