//! Compressed compliance tables (`tables build --compress f16|q16
//! [--drop-below REL] [--contact-blocks coded|f32|dropped]`; format in
//! `palpate_kernel::table::format`,
//! "Compressed compliance"): the 16-bit coding of the compliance blocks with
//! a per-column scale, the truncation of far-field blocks, and the error
//! that cost, measured against the `f32` table of the same compliance on a
//! fixed probe set before it is stored in the table.
//!
//! Coding, per part (surface or interior) and column `k` (a touchable
//! vertex), with `M_k` the largest entry magnitude of the column's blocks in
//! that part and every scale rounded to `f32` first (the table stores it so):
//! - f16: scale `s = M_k`; code = the binary16 value of `x / s` rounded to
//!   nearest, ties to even ([`f16_bits`]): relative error `≤ 2⁻¹¹` for
//!   `|x| ≥ 2⁻¹⁴ s`, absolute `≤ 2⁻²⁵ s` below;
//! - q16: scale `s = M_k / 32767` (the quantum); code = `round(x / s)`,
//!   ties to even, in `−32767..=32767`: absolute error `≤ s / 2`.
//!
//! The diagonal blocks `C_kk` are symmetrized (`(C + Cᵀ)/2`) before coding,
//! so their codes are symmetric. An interior block `C_nk` is dropped when
//! `max |C_nk| < REL · m_k`, `m_k` the largest entry magnitude of the whole
//! column `k` of `C` (both parts, the surface rows above and below the
//! diagonal): its influence on the displacement field of a contact at `k`
//! is below `REL` of the largest. The touchable–touchable blocks (the
//! contact solve's, and the surface a renderer shows) are not dropped
//! unless asked ([`ContactBlocks::Dropped`]: then `C_nk`, `n ≠ k`, goes when
//! `max |C_nk| < REL · min(m_n, m_k)`): on the built-in block and the former
//! voxel-carved organ (5868 tets), dropping them saves under 0.3 % of their
//! blocks at `REL = 0.01`, and costs 2.6 % of contact force on the organ at
//! `REL = 0.02`, 3.0 % (block) and 4.9 % (organ) at 0.05 (two distant contacts
//! lose their coupling), where dropping interior blocks costs no force at all.

use anyhow::{Context, bail, ensure};
use bytemuck::Zeroable;
use nalgebra::Vector3;
use palpate_kernel::table::format::{
    self, BlockEncoding, CompressionRecord, HierarchyBlock, HierarchyRecord, KEPT_BITS,
    PROBE_SET_EVERY_TOUCHABLE, surface_block_index,
};
use palpate_kernel::{Constraint, MAX_CONTACTS, PrecomputedModel, PrecomputedTable};

use super::compliance::Compliance;
use super::load::TableFile;

/// The 16-bit code of a compressed table.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum BlockCode {
    /// IEEE 754 binary16 times the column's largest entry.
    F16,
    /// 16-bit fixed point: the column's largest entry is ±32767 quanta.
    Q16,
    /// A hierarchical matrix of the touchable compliance (near blocks in
    /// f32, far blocks as low-rank factors within `--tolerance`); the
    /// interior displacements are not stored (`table::hmatrix`).
    Hmatrix,
    /// The same hierarchical matrix with its near entries and far factors
    /// in 16-bit fixed point, a scale per block and factor (about half the
    /// bytes).
    HmatrixQ16,
}

impl BlockCode {
    /// The format's encoding value.
    pub fn encoding(self) -> BlockEncoding {
        match self {
            BlockCode::F16 => BlockEncoding::F16,
            BlockCode::Q16 => BlockEncoding::Q16,
            BlockCode::Hmatrix => BlockEncoding::Hierarchical,
            BlockCode::HmatrixQ16 => BlockEncoding::HierarchicalQ16,
        }
    }

    /// `true` for the hierarchical tables (`hmatrix`, `hmatrix-q16`).
    pub fn is_hierarchical(self) -> bool {
        matches!(self, BlockCode::Hmatrix | BlockCode::HmatrixQ16)
    }

    /// The column scale (m/N, an `f32` value) for a column whose largest
    /// entry magnitude is `largest` (m/N; a column of zeros gets 1).
    fn scale(self, largest: f64) -> f64 {
        // `encode` refuses Hmatrix: it never codes a block (the q16
        // hierarchy's quanta are those of Q16).
        let scale = match self {
            BlockCode::F16 | BlockCode::Hmatrix => largest,
            BlockCode::Q16 | BlockCode::HmatrixQ16 => largest / f64::from(format::Q16_LARGEST_CODE),
        };
        if largest > 0.0 {
            f64::from(scale as f32)
        } else {
            1.0
        }
    }

    /// The code of `x` (m/N) in a column of scale `scale`.
    fn code(self, x: f64, scale: f64) -> u16 {
        match self {
            BlockCode::F16 | BlockCode::Hmatrix => f16_bits(x / scale),
            BlockCode::Q16 | BlockCode::HmatrixQ16 => q16_code(x / scale),
        }
    }
}

/// How a compressed table stores the touchable–touchable compliance blocks
/// (the surface part: the contact solve reads them, and they move the
/// touchable vertices).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum ContactBlocks {
    /// In the table's 16-bit code, none dropped.
    #[default]
    Coded,
    /// In `f32`, uncompressed, none dropped.
    F32,
    /// In the 16-bit code, with the drop threshold applied to them too.
    Dropped,
}

/// What `tables build --compress` asks for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Compression {
    /// The 16-bit code of the compressed parts.
    pub code: BlockCode,
    /// The drop threshold `REL` (module docs), in `[0, 1)`; 0 drops nothing.
    pub drop_below: f64,
    /// How the touchable–touchable blocks are stored.
    pub contact: ContactBlocks,
    /// [`BlockCode::Hmatrix`]: the far blocks' relative truncation
    /// tolerance (Frobenius norm per block), in `(0, 1)`; unused otherwise.
    pub tolerance: f64,
}

impl Compression {
    /// Checks `drop_below` (finite, in `[0, 1)`).
    pub fn check(&self) -> anyhow::Result<()> {
        ensure!(
            self.drop_below.is_finite() && (0.0..1.0).contains(&self.drop_below),
            "--drop-below {}: must be a fraction in [0, 1) of a column's largest compliance",
            self.drop_below
        );
        if self.code.is_hierarchical() {
            ensure!(
                self.drop_below == 0.0 && self.contact == ContactBlocks::Coded,
                "--compress hmatrix stores every touchable block (near ones in f32, far ones as \
                 low-rank factors) and no interior block: --drop-below and --contact-blocks do \
                 not apply"
            );
            ensure!(
                self.tolerance.is_finite() && self.tolerance > 0.0 && self.tolerance < 1.0,
                "--tolerance {}: must be a relative error in (0, 1), e.g. 1e-4",
                self.tolerance
            );
        }
        Ok(())
    }
}

/// The binary16 bit pattern of `x`, rounded to nearest, ties to even (IEEE
/// 754 `convertFormat`): `±0`, the subnormals `f · 2⁻²⁴`, the normals, `±∞`
/// from `65520` up (halfway between 65504 and 2¹⁶), NaN as a quiet NaN. The
/// inverse of `palpate_kernel::table::format::f16_to_f32` on every finite
/// code.
pub fn f16_bits(x: f64) -> u16 {
    let sign: u16 = if x.is_sign_negative() { 0x8000 } else { 0 };
    let a = x.abs();
    if a.is_nan() {
        return 0x7e00;
    }
    if a >= 65520.0 {
        return sign | 0x7c00;
    }
    const MIN_NORMAL: f64 = 1.0 / 16384.0; // 2^-14
    if a < MIN_NORMAL {
        // Quanta of 2^-24; 1024 of them is the smallest normal, 0x0400.
        return sign | (a * 16_777_216.0).round_ties_even() as u16;
    }
    // A normal f64 in [2^-14, 65520): its binary exponent e in -14..=15.
    let e = ((a.to_bits() >> 52) & 0x7ff) as i32 - 1023;
    // 2^10 quanta per binade: m in 1024..=2048 (2048 carries into the exponent).
    let m = (a * 2f64.powi(10 - e)).round_ties_even() as u32;
    let bits = (((e + 15) as u32) << 10) + m - 1024;
    sign | bits as u16
}

/// The q16 code of `x` (in quanta): `round(x)`, ties to even, clamped to
/// `−32767..=32767`, as its two's complement bits.
fn q16_code(x: f64) -> u16 {
    let largest = f64::from(format::Q16_LARGEST_CODE);
    (x.round_ties_even().clamp(-largest, largest) as i16).cast_unsigned()
}

/// One coded compliance part as written: a scale per column, the kept
/// blocks' codes in the dense layout's order, and the kept-block bitmap
/// (`None`: every block kept).
#[derive(Clone, Debug, PartialEq)]
pub struct CodedPart {
    /// Per-column scale, m/N (`f32` values).
    pub scales: Vec<f64>,
    /// The kept blocks' codes.
    pub codes: Vec<[u16; 9]>,
    /// `[bits, rank]` words over the dense layout, when some blocks were
    /// dropped, not all.
    pub kept: Option<Vec<[u32; 2]>>,
}

/// A table's compliance compressed: the record and the coded parts.
#[derive(Clone, Debug, PartialEq)]
pub struct CompressedCompliance {
    /// The encoding record (errors filled in by [`measure`]).
    pub record: CompressionRecord,
    /// The surface part coded, `None` to store it in the table scalar
    /// ([`ContactBlocks::F32`]) or as [`Self::hierarchy`].
    pub surface: Option<CodedPart>,
    /// The interior part coded.
    pub interior: CodedPart,
    /// The surface part as a hierarchical matrix (`--compress hmatrix`, built
    /// by `table::hmatrix`), `None` otherwise.
    pub hierarchy: Option<Hierarchy>,
}

/// The hierarchy sections of a table, in `f64` before the writer rounds the
/// data to the table scalar (layout: `palpate_kernel::table::format::hierarchy`).
#[derive(Clone, Debug, PartialEq)]
pub struct Hierarchy {
    /// Counts, bounds, tolerance, `η`.
    pub record: HierarchyRecord,
    /// Per leaf and one past the last: `[first touchable index, first
    /// column-list entry]`.
    pub leaves: Vec<[u32; 2]>,
    /// The partition's blocks, both triangles.
    pub blocks: Vec<HierarchyBlock>,
    /// The leaves' column lists, concatenated.
    pub column_blocks: Vec<u32>,
    /// Near entries and far factors, m/N (a far factor's scale is the
    /// square root of the block's).
    pub data: Vec<f64>,
    /// Store `data` as q16 codes, a scale pair per block
    /// ([`Hierarchy::q16`]), instead of in the table scalar.
    pub q16: bool,
}

impl Hierarchy {
    /// The q16 coding of `data` (format: `hierarchy`, "q16 data"): per
    /// block, the quanta `[s₀, s₁]` of the data it reads (near: its
    /// entries and 0; far: `L`, `R`), each `max |x| / 32767` rounded to
    /// `f32` ([`BlockCode::HmatrixQ16`]'s scale); each number coded with
    /// the quantum of the owner block (row start ≤ column start) whose data
    /// hold it, rounded to nearest. A mirror reads its owner's data: its
    /// quanta are its owner's (far: swapped).
    pub fn q16(&self) -> (Vec<u16>, Vec<[f64; 2]>) {
        let code = BlockCode::HmatrixQ16;
        let mut codes = vec![0u16; self.data.len()];
        let mut scales = Vec::with_capacity(self.blocks.len());
        for b in &self.blocks {
            let r = b.rank as usize;
            let parts = if r == 0 {
                [(b.left, 9 * b.rows() * b.cols()), (0, 0)]
            } else {
                [(b.left, 3 * b.rows() * r), (b.right, 3 * b.cols() * r)]
            };
            let ranges = parts.map(|(offset, len)| offset as usize..offset as usize + len);
            let pair = ranges.clone().map(|range| {
                if range.is_empty() {
                    0.0
                } else {
                    code.scale(self.data[range].iter().fold(0.0f64, |m, x| m.max(x.abs())))
                }
            });
            if b.row_start <= b.col_start {
                for (range, s) in ranges.into_iter().zip(pair) {
                    for (q, x) in codes[range.clone()].iter_mut().zip(&self.data[range]) {
                        *q = code.code(*x, s);
                    }
                }
            }
            scales.push(pair);
        }
        (codes, scales)
    }
}

/// Largest entry magnitude of a block.
fn largest(block: &[f64; 9]) -> f64 {
    block.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// Codes `compliance` (`s` touchable vertices) as `compression` asks
/// (module docs). The record's errors are zero until [`measure`]d.
pub fn encode(
    compliance: &Compliance,
    s: usize,
    compression: &Compression,
) -> anyhow::Result<CompressedCompliance> {
    compression.check()?;
    ensure!(
        !compression.code.is_hierarchical(),
        "a hierarchical table is built from the compliance columns (table::hmatrix), not coded \
         from the dense compliance"
    );
    let surface = &compliance.surface;
    let interior = &compliance.interior;
    ensure!(
        surface.len() == s * (s + 1) / 2 && (s == 0 || interior.len().is_multiple_of(s)),
        "compliance of {} surface and {} interior blocks is not a table of {s} touchable vertices",
        surface.len(),
        interior.len()
    );
    let rows = interior.len().checked_div(s).unwrap_or(0);
    // m_k: the largest entry of each whole column of C.
    let mut column_max = vec![0.0f64; s];
    for k in 0..s {
        for n in 0..=k {
            let m = largest(&surface[surface_block_index(n, k)]);
            column_max[k] = column_max[k].max(m);
            column_max[n] = column_max[n].max(m);
        }
        for block in &interior[k * rows..(k + 1) * rows] {
            column_max[k] = column_max[k].max(largest(block));
        }
    }
    let rel = compression.drop_below;
    let contact_rel = match compression.contact {
        ContactBlocks::Dropped => rel,
        ContactBlocks::Coded | ContactBlocks::F32 => 0.0,
    };
    let code = compression.code;
    let surface_part = (compression.contact != ContactBlocks::F32)
        .then(|| {
            code_part(
                code,
                s,
                |k| surface_block_index(0, k)..surface_block_index(0, k + 1),
                |k, j| {
                    let n = j - surface_block_index(0, k);
                    let block = surface[j];
                    if n == k {
                        // Symmetrized: the codes of C_kk are symmetric.
                        let mut sym = block;
                        for a in 0..3 {
                            for b in 0..3 {
                                sym[3 * a + b] = 0.5 * (block[3 * a + b] + block[3 * b + a]);
                            }
                        }
                        Some(sym)
                    } else {
                        (largest(&block) >= contact_rel * column_max[n].min(column_max[k]))
                            .then_some(block)
                    }
                },
            )
        })
        .transpose()?;
    let interior_part = code_part(
        code,
        s,
        |k| k * rows..(k + 1) * rows,
        |k, j| {
            let block = interior[j];
            (largest(&block) >= rel * column_max[k]).then_some(block)
        },
    )?;
    let record = CompressionRecord {
        surface_encoding: if surface_part.is_some() {
            code.encoding()
        } else {
            BlockEncoding::Scalar
        } as u32,
        interior_encoding: code.encoding() as u32,
        drop_below: rel,
        probe_set: PROBE_SET_EVERY_TOUCHABLE,
        ..CompressionRecord::zeroed()
    };
    Ok(CompressedCompliance {
        record,
        surface: surface_part,
        interior: interior_part,
        hierarchy: None,
    })
}

/// Codes one part of `columns` columns, column `k` the dense blocks
/// `range(k)`; `kept(k, j)` gives block `j` of column `k` as stored, or
/// `None` to drop it. The scale of a column is taken over its blocks as
/// stored.
fn code_part(
    code: BlockCode,
    columns: usize,
    range: impl Fn(usize) -> core::ops::Range<usize>,
    kept: impl Fn(usize, usize) -> Option<[f64; 9]>,
) -> anyhow::Result<CodedPart> {
    let blocks = (0..columns).map(|k| range(k).len()).sum::<usize>();
    let mut flags = vec![false; blocks];
    let mut scales = Vec::with_capacity(columns);
    let mut codes = Vec::new();
    for k in 0..columns {
        let stored: Vec<(usize, [f64; 9])> = range(k)
            .filter_map(|j| kept(k, j).map(|b| (j, b)))
            .collect();
        let scale = code.scale(stored.iter().fold(0.0f64, |m, (_, b)| m.max(largest(b))));
        if !(scale.is_finite() && scale > 0.0 && scale >= f64::from(f32::MIN_POSITIVE)) {
            bail!(
                "compliance column {k}: scale {scale:e} m/N does not fit f32; give E in Pa and \
                 the mesh in metres (SI units)"
            );
        }
        scales.push(scale);
        for (j, block) in stored {
            flags[j] = true;
            codes.push(block.map(|x| code.code(x, scale)));
        }
    }
    // A bitmap only when some blocks, not all, were dropped (the format's
    // rule: without one, every block is stored or none).
    let kept = (!codes.is_empty() && codes.len() < blocks).then(|| kept_bitmap(&flags));
    Ok(CodedPart {
        scales,
        codes,
        kept,
    })
}

/// The `[bits, rank]` words of a kept-block bitmap (format docs).
pub fn kept_bitmap(flags: &[bool]) -> Vec<[u32; 2]> {
    let mut rank = 0u32;
    flags
        .chunks(KEPT_BITS)
        .map(|chunk| {
            let bits = chunk
                .iter()
                .enumerate()
                .fold(0u32, |w, (b, &f)| w | (u32::from(f) << b));
            let word = [bits, rank];
            rank += bits.count_ones();
            word
        })
        .collect()
}

/// The error of a compressed table against the `f32` table of the same
/// compliance over the probe set ([`PROBE_SET_EVERY_TOUCHABLE`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Measured {
    /// Largest relative contact-force error (record docs).
    pub max_force_error: f64,
    /// Largest relative displacement error, every free vertex (record docs).
    pub max_displacement_error: f64,
    /// Largest relative displacement error, touchable vertices (record docs).
    pub max_surface_displacement_error: f64,
    /// Contact sets solved on both tables.
    pub probes: u64,
    /// Contact sets the reference solved but the compressed table refused
    /// (counted as a relative error of 1 in both).
    pub refused: u64,
}

/// Depth of every probe press, m.
const PROBE_DEPTH_M: f32 = 1e-3;

/// The probe set (`PROBE_SET_EVERY_TOUCHABLE`, format docs) of a table:
/// the contact sets, each one or two vertex contacts.
pub fn probe_set(table: &PrecomputedTable<'_, f32>) -> Vec<Vec<Constraint<f32>>> {
    probe_set_at(table, 0..table.touchable_count())
}

/// The presses of [`probe_set`] at the touchable indices `at` only (each
/// with its partners among every touchable vertex): five contact sets per
/// index.
pub fn probe_set_at(
    table: &PrecomputedTable<'_, f32>,
    at: impl IntoIterator<Item = usize>,
) -> Vec<Vec<Constraint<f32>>> {
    let s = table.touchable_count();
    let touchable = &table.free_vertices()[..s];
    let position = |v: u32| Vector3::from(table.rest_positions()[v as usize]).cast::<f64>();
    let press = |v: u32, d: Vector3<f32>| Constraint::at_vertex(v, d);
    let down = Vector3::new(0.0, 0.0, -PROBE_DEPTH_M);
    let mut probes = Vec::new();
    for k in at {
        let Some(&v) = touchable.get(k) else {
            continue;
        };
        for axis in 0..3 {
            let mut d = Vector3::zeros();
            d[axis] = PROBE_DEPTH_M;
            probes.push(vec![press(v, d)]);
        }
        if s < 2 {
            continue;
        }
        let p = position(v);
        let nearest = touchable
            .iter()
            .filter(|&&w| w != v)
            .min_by(|&&a, &&b| {
                (position(a) - p)
                    .norm()
                    .total_cmp(&(position(b) - p).norm())
            })
            .copied();
        if let Some(w) = nearest {
            probes.push(vec![press(v, down), press(w, down)]);
        }
        let across = touchable[(k + s / 2) % s];
        probes.push(vec![press(v, down), press(across, down)]);
    }
    probes
}

/// Measures `candidate` against `reference` (two tables of the same mesh
/// and compliance) over [`probe_set`]: per contact set, the force error
/// `max_p |g_p − g'_p| / max_p |g'_p|` and the displacement error
/// `max_n |u_n − u'_n| / max_n |u'_n|` over the free vertices (and over the
/// touchable ones only), the largest of each. A set the reference refuses is
/// skipped; one only the candidate refuses counts as an error of 1 in all.
pub fn measure(
    reference: &PrecomputedModel<'_, f32>,
    candidate: &PrecomputedModel<'_, f32>,
) -> Measured {
    let free = reference.table().free_count();
    let touchable = reference.table().touchable_count();
    let mut out = Measured::default();
    let (mut u_ref, mut u) = (vec![[0.0f32; 3]; free], vec![[0.0f32; 3]; free]);
    let norm = |v: &[f32; 3]| Vector3::from(*v).cast::<f64>().norm();
    for set in probe_set(reference.table()) {
        let Ok(want) = reference.contact_forces::<MAX_CONTACTS>(&set) else {
            continue;
        };
        out.probes += 1;
        let Ok(got) = candidate.contact_forces::<MAX_CONTACTS>(&set) else {
            out.refused += 1;
            out.max_force_error = out.max_force_error.max(1.0);
            out.max_displacement_error = out.max_displacement_error.max(1.0);
            out.max_surface_displacement_error = out.max_surface_displacement_error.max(1.0);
            continue;
        };
        let forces = want.contact_forces_n().iter().zip(got.contact_forces_n());
        let (diff, scale) = forces.fold((0.0f64, 0.0f64), |(d, s), (a, b)| {
            let a = a.cast::<f64>();
            (d.max((b.cast::<f64>() - a).norm()), s.max(a.norm()))
        });
        if scale > 0.0 {
            out.max_force_error = out.max_force_error.max(diff / scale);
        }
        // Lengths match the tables (same free count): cannot fail.
        if reference.free_displacements(&want, &mut u_ref).is_ok()
            && candidate.free_displacements(&got, &mut u).is_ok()
        {
            let errors: Vec<f64> = u_ref
                .iter()
                .zip(&u)
                .map(|(a, b)| norm(&[b[0] - a[0], b[1] - a[1], b[2] - a[2]]))
                .collect();
            let scale = u_ref.iter().map(norm).fold(0.0f64, f64::max);
            let worst = |rows: &[f64]| rows.iter().fold(0.0f64, |m, &e| m.max(e)) / scale;
            if scale > 0.0 {
                out.max_displacement_error = out.max_displacement_error.max(worst(&errors));
                out.max_surface_displacement_error = out
                    .max_surface_displacement_error
                    .max(worst(&errors[..touchable]));
            }
        }
    }
    out
}

/// Measures the compressed table `candidate` (bytes) against the `f32`
/// table `reference` (bytes) and returns `candidate`'s record with the
/// errors filled in.
pub fn measured_record(
    reference: &[u8],
    candidate: &[u8],
    record: CompressionRecord,
) -> anyhow::Result<(CompressionRecord, Measured)> {
    let (reference, candidate) = (
        TableFile::from_bytes(reference),
        TableFile::from_bytes(candidate),
    );
    fn load<'a>(file: &'a TableFile, what: &str) -> anyhow::Result<PrecomputedModel<'a, f32>> {
        PrecomputedTable::<f32>::load(file.bytes())
            .map(PrecomputedModel::new)
            .with_context(|| format!("the {what} table fails Palpate's own load check"))
    }
    let measured = measure(&load(&reference, "f32")?, &load(&candidate, "compressed")?);
    Ok((
        CompressionRecord {
            max_force_error: measured.max_force_error,
            max_displacement_error: measured.max_displacement_error,
            max_surface_displacement_error: measured.max_surface_displacement_error,
            probe_count: measured.probes,
            ..record
        },
        measured,
    ))
}
