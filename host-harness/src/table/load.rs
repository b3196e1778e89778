//! Reading table files on the host: aligned buffers, scalar dispatch, `tables info`.

use core::fmt::Write as _;
use std::path::Path;

use anyhow::Context;
use palpate_kernel::table::format::{CRC_LEN, CRC32, HEADER_LEN, RawHeader, TableKind};
use palpate_kernel::{PrecomputedModel, PrecomputedTable};

/// Table bytes in a 16-byte-aligned buffer, as the kernel's zero-copy view
/// requires (a `Vec<u8>` has no alignment guarantee).
pub struct TableFile {
    words: Vec<u128>,
    len: usize,
}

/// A validated model of either stored precision.
pub enum AnyModel<'a> {
    /// A table of `f32` values (the firmware format).
    F32(PrecomputedModel<'a, f32>),
    /// A table of `f64` values (verification).
    F64(PrecomputedModel<'a, f64>),
}

impl TableFile {
    /// Reads a table file.
    pub fn read(path: &Path) -> anyhow::Result<Self> {
        let bytes =
            std::fs::read(path).with_context(|| format!("{}: cannot read", path.display()))?;
        Ok(Self::from_bytes(&bytes))
    }

    /// Copies `bytes` into an aligned buffer.
    pub fn from_bytes(bytes: &[u8]) -> Self {
        let mut words = vec![0u128; bytes.len().div_ceil(16)];
        bytemuck::cast_slice_mut::<u128, u8>(&mut words)[..bytes.len()].copy_from_slice(bytes);
        Self {
            words,
            len: bytes.len(),
        }
    }

    /// The file bytes, 16-byte aligned.
    pub fn bytes(&self) -> &[u8] {
        &bytemuck::cast_slice::<u128, u8>(&self.words)[..self.len]
    }

    /// The header as stored, if the file is long enough (not validated).
    pub fn raw_header(&self) -> Option<RawHeader> {
        self.bytes()
            .get(..HEADER_LEN)
            .map(bytemuck::pod_read_unaligned)
    }

    /// Validates the table with the kernel's loader, in the precision the
    /// header declares.
    pub fn model(&self) -> Result<AnyModel<'_>, palpate_kernel::LoadError> {
        let bytes = self.bytes();
        match self.raw_header().map(|h| h.scalar_bytes) {
            Some(8) => PrecomputedTable::<f64>::load(bytes)
                .map(|t| AnyModel::F64(PrecomputedModel::new(t))),
            _ => PrecomputedTable::<f32>::load(bytes)
                .map(|t| AnyModel::F32(PrecomputedModel::new(t))),
        }
    }

    /// The `tables info` report: counts, sizes, material, checksum and
    /// validation status. `Err` carries the same report when the table is bad.
    pub fn info(&self, name: &str) -> Result<String, String> {
        let mut out = String::new();
        let bytes = self.bytes();
        let _ = writeln!(out, "table: {name}");
        let _ = writeln!(out, "file size: {} bytes", bytes.len());
        let Some(h) = self.raw_header() else {
            let _ = writeln!(out, "status: too short for a header");
            return Err(out);
        };
        let _ = writeln!(out, "format version: {}", h.format_version);
        let kind = match h.table_kind {
            k if k == TableKind::Precomputed as u32 => "pre-computed (compliance)",
            _ => "unknown",
        };
        let _ = writeln!(out, "table kind: {kind}");
        let precision = match h.scalar_bytes {
            4 => "f32",
            8 => "f64",
            _ => "unknown",
        };
        let _ = writeln!(out, "precision: {precision}");
        let _ = writeln!(out, "vertices: {}", h.vertex_count);
        let _ = writeln!(out, "tets: {}", h.tet_count);
        let _ = writeln!(
            out,
            "fixed vertices: {}",
            h.vertex_count.saturating_sub(h.free_count)
        );
        let _ = writeln!(out, "free vertices: {}", h.free_count);
        let _ = writeln!(
            out,
            "touchable (free surface) vertices: {}",
            h.touchable_count
        );
        let _ = writeln!(out, "surface triangles: {}", h.triangle_count);
        let _ = writeln!(out, "young modulus: {} Pa", h.young_pa);
        let _ = writeln!(out, "poisson ratio: {}", h.poisson);
        let _ = writeln!(out, "mesh hash: {:016x}", h.mesh_hash);
        let sections = match h.table_kind {
            k if k == TableKind::Precomputed as u32 => TableKind::Precomputed.sections(),
            _ => &[],
        };
        for &kind in sections {
            if let Some(count) = kind.expected_count(&h) {
                let size = count * u64::from(kind.elem_bytes(h.scalar_bytes));
                let _ = writeln!(
                    out,
                    "section {}: {count} x {} bytes = {size} bytes",
                    kind.name(),
                    kind.elem_bytes(h.scalar_bytes)
                );
            }
        }
        let checksum_ok = bytes.len() >= HEADER_LEN + CRC_LEN && {
            let (body, trailer) = bytes.split_at(bytes.len() - CRC_LEN);
            let stored = u32::from_le_bytes(trailer.try_into().unwrap_or_default());
            stored == crc::Crc::<u32>::new(&CRC32).checksum(body)
        };
        let _ = writeln!(
            out,
            "checksum: {}",
            if checksum_ok { "ok" } else { "MISMATCH" }
        );
        match self.model() {
            Ok(_) => {
                let _ = writeln!(out, "validation: ok");
                Ok(out)
            }
            Err(e) => {
                let _ = writeln!(out, "validation: FAILED: {e}");
                Err(out)
            }
        }
    }
}
