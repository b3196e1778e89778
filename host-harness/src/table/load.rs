//! Reading table files on the host: aligned buffers, scalar dispatch, `tables info`.

use core::fmt::Write as _;
use std::fs::File;
use std::path::Path;

use anyhow::{Context, bail};
use palpate_kernel::table::format::{
    BlockEncoding, CRC_LEN, CRC32, CompressionRecord, HEADER_LEN, RawHeader, SECTION_ENTRY_LEN,
    SectionEntry, SectionKind, TableKind,
};
use palpate_kernel::table::{InterfaceTable, LoadError, TensorMassTable};
use palpate_kernel::{PrecomputedModel, PrecomputedTable};

use super::report::describe_hierarchy;
use crate::limits::{MAX_TABLE_FILE_BYTES, read_bounded};

/// Fills `buf` from `reader` as far as it goes; the bytes read (fewer only
/// at the end of the input).
fn read_up_to(reader: &mut impl std::io::Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut filled = 0;
    while filled < buf.len() {
        match reader.read(&mut buf[filled..]) {
            Ok(0) => break,
            Ok(n) => filled += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(filled)
}

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
    /// Reads a table file, its fixed-size header first: the magic, the
    /// format version and the file length the header declares are checked
    /// (that length against the file's real size and against
    /// [`MAX_TABLE_FILE_BYTES`]) before anything else is read or allocated,
    /// so `/dev/zero` or a large file of garbage is refused at once. A pipe
    /// or a device is read up to the declared length and refused if it has
    /// more. The rest is read straight into the aligned buffer (one copy).
    /// Everything else (sections, CRC, values) is the kernel loader's.
    pub fn read(path: &Path) -> anyhow::Result<Self> {
        let name = path.display();
        let mut file = File::open(path).with_context(|| format!("{name}: cannot read"))?;
        let meta = file
            .metadata()
            .with_context(|| format!("{name}: cannot read"))?;
        let real_len = meta.is_file().then_some(meta.len());
        let mut head = [0u8; HEADER_LEN];
        let got =
            read_up_to(&mut file, &mut head).with_context(|| format!("{name}: cannot read"))?;
        if got < HEADER_LEN {
            bail!(
                "{name}: not a Palpate table: {got} bytes, shorter than the {HEADER_LEN}-byte table header"
            );
        }
        let h: RawHeader = bytemuck::pod_read_unaligned(&head);
        h.check_identity().map_err(|e| match e {
            LoadError::UnsupportedVersion { .. } => {
                anyhow::anyhow!("{name}: {e}: rebuild the table with `palpate tables build`")
            }
            _ => anyhow::anyhow!("{name}: {e}"),
        })?;
        let declared = h.file_len;
        if declared > MAX_TABLE_FILE_BYTES {
            bail!(
                "{name}: the header declares {declared} bytes, above the largest table file, {MAX_TABLE_FILE_BYTES} bytes (MAX_TABLE_FILE_BYTES)"
            );
        }
        if declared < (HEADER_LEN + CRC_LEN) as u64 {
            bail!("{name}: the header declares {declared} bytes, shorter than a table");
        }
        if let Some(real) = real_len
            && real != declared
        {
            bail!(
                "{name}: the file is {real} bytes but its header declares {declared}: truncated or padded"
            );
        }
        // At most MAX_TABLE_FILE_BYTES: fits usize on the 64-bit hosts the
        // harness runs on; a failed allocation is an error, not an abort.
        let len = usize::try_from(declared)
            .with_context(|| format!("{name}: {declared} bytes do not fit this host's memory"))?;
        let mut words: Vec<u128> = Vec::new();
        words
            .try_reserve_exact(len.div_ceil(16))
            .map_err(|e| anyhow::anyhow!("{name}: cannot allocate {declared} bytes: {e}"))?;
        words.resize(len.div_ceil(16), 0);
        let buf = &mut bytemuck::cast_slice_mut::<u128, u8>(&mut words)[..len];
        buf[..HEADER_LEN].copy_from_slice(&head);
        let rest = read_up_to(&mut file, &mut buf[HEADER_LEN..])
            .with_context(|| format!("{name}: cannot read"))?;
        if HEADER_LEN + rest < len {
            bail!(
                "{name}: {} bytes, shorter than the {declared} its header declares: truncated",
                HEADER_LEN + rest
            );
        }
        if real_len.is_none() && read_up_to(&mut file, &mut [0u8; 1]).unwrap_or(0) > 0 {
            bail!("{name}: longer than the {declared} bytes its header declares");
        }
        Ok(Self { words, len })
    }

    /// Reads a table for a report (`tables info`), which shows what is wrong
    /// with a damaged table, its header first: a regular file whose header is
    /// not a table's (or that is shorter than one) is reported from those
    /// bytes alone, never read further; one whose header declares at most
    /// [`MAX_TABLE_FILE_BYTES`] and no fewer bytes than the file has (a
    /// truncated table) is read whole; anything else goes through
    /// [`TableFile::read`] (refused unless its header is right, with the
    /// figures).
    pub fn read_for_report(path: &Path) -> anyhow::Result<Self> {
        let Some(real) = std::fs::metadata(path)
            .ok()
            .filter(|meta| meta.is_file() && meta.len() <= MAX_TABLE_FILE_BYTES)
            .map(|meta| meta.len())
        else {
            return Self::read(path);
        };
        let name = path.display();
        let mut file = File::open(path).with_context(|| format!("{name}: cannot read"))?;
        let mut head = [0u8; HEADER_LEN];
        let got =
            read_up_to(&mut file, &mut head).with_context(|| format!("{name}: cannot read"))?;
        if got < HEADER_LEN {
            return Ok(Self::from_bytes(&head[..got]));
        }
        let h: RawHeader = bytemuck::pod_read_unaligned(&head);
        if h.check_identity().is_err() {
            return Ok(Self::from_bytes(&head));
        }
        if h.file_len > MAX_TABLE_FILE_BYTES || real > h.file_len {
            return Self::read(path);
        }
        drop(file);
        let bytes = read_bounded(
            path,
            MAX_TABLE_FILE_BYTES,
            "a table file (MAX_TABLE_FILE_BYTES)",
        )
        .with_context(|| format!("{}: cannot read", path.display()))?;
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

    /// The section directory as stored, if the header's section count fits
    /// the bytes (not validated).
    pub fn directory(&self, h: &RawHeader) -> Option<Vec<SectionEntry>> {
        let len = (h.section_count as usize).checked_mul(SECTION_ENTRY_LEN)?;
        let raw = self.bytes().get(HEADER_LEN..HEADER_LEN.checked_add(len)?)?;
        Some(
            raw.chunks_exact(SECTION_ENTRY_LEN)
                .map(bytemuck::pod_read_unaligned)
                .collect(),
        )
    }

    /// The table kind the header declares, if it is one this kernel knows.
    pub fn kind(&self) -> Option<TableKind> {
        match self.raw_header()?.table_kind {
            k if k == TableKind::Precomputed as u32 => Some(TableKind::Precomputed),
            k if k == TableKind::TensorMass as u32 => Some(TableKind::TensorMass),
            k if k == TableKind::Interface as u32 => Some(TableKind::Interface),
            _ => None,
        }
    }

    /// Validates the table with the kernel's loader of the kind and
    /// precision the header declares (an unknown kind goes to the
    /// pre-computed loader, which names it).
    pub fn validate(&self) -> Result<(), palpate_kernel::LoadError> {
        let bytes = self.bytes();
        let f64_table = self.raw_header().map(|h| h.scalar_bytes) == Some(8);
        match (self.kind(), f64_table) {
            (Some(TableKind::TensorMass), true) => TensorMassTable::<f64>::load(bytes).map(drop),
            (Some(TableKind::TensorMass), false) => TensorMassTable::<f32>::load(bytes).map(drop),
            (Some(TableKind::Interface), true) => InterfaceTable::<f64>::load(bytes).map(drop),
            (Some(TableKind::Interface), false) => InterfaceTable::<f32>::load(bytes).map(drop),
            _ => self.model().map(drop),
        }
    }

    /// The `tables info` report: counts, sizes, material, checksum and
    /// validation status, for either kind of table. `Err` carries the same
    /// report when the table is bad.
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
        let kind = self.kind();
        let kind_name = match kind {
            Some(TableKind::Precomputed) => "pre-computed (compliance)",
            Some(TableKind::TensorMass) => "tensor-mass (dynamic)",
            Some(TableKind::Interface) => "interface (hybrid model)",
            None => "unknown",
        };
        let _ = writeln!(out, "table kind: {kind_name}");
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
        if kind == Some(TableKind::Interface) {
            let _ = writeln!(out, "connection nodes: {}", h.connection_count);
        }
        if kind == Some(TableKind::TensorMass) {
            let _ = writeln!(out, "edges: {}", h.edge_count);
            let _ = writeln!(out, "mesh triangles: {}", h.mesh_triangle_count);
        } else {
            let _ = writeln!(
                out,
                "touchable (free surface) vertices: {}",
                h.touchable_count
            );
        }
        let _ = writeln!(out, "surface triangles: {}", h.triangle_count);
        let _ = writeln!(out, "young modulus: {} Pa", h.young_pa);
        let _ = writeln!(out, "poisson ratio: {}", h.poisson);
        if kind == Some(TableKind::TensorMass) {
            let _ = writeln!(out, "density: {} kg/m3", h.density_kg_m3);
        }
        let _ = writeln!(out, "mesh hash: {:016x}", h.mesh_hash);
        match self.directory(&h) {
            Some(entries) => footprint(&mut out, &h, &entries),
            None => {
                // No readable directory: the sizes the header implies, only
                // for a scalar size the format has, with checked arithmetic.
                let _ = writeln!(out, "section directory: unreadable");
                let sections = match (kind, h.scalar_bytes) {
                    (Some(kind), 4 | 8) => kind.sections(),
                    _ => &[][..],
                };
                for &kind in sections {
                    if let Some(count) = kind.expected_count(&h) {
                        section_line(
                            &mut out,
                            kind.name(),
                            count,
                            kind.elem_bytes(h.scalar_bytes),
                        );
                    }
                }
            }
        }
        if kind == Some(TableKind::Precomputed) {
            self.compliance_lines(&mut out);
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
        match self.validate() {
            Ok(()) => {
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

impl TableFile {
    /// A pre-computed table's compression record, hierarchy and contact
    /// candidate lists, for [`Self::info`] (nothing for a table that does
    /// not load).
    fn compliance_lines(&self, out: &mut String) {
        let Ok(model) = self.model() else {
            return;
        };
        let (record, hierarchy) = match &model {
            AnyModel::F32(m) => (
                m.table().compression().copied(),
                m.table()
                    .surface_blocks()
                    .as_hierarchical()
                    .map(describe_hierarchy),
            ),
            AnyModel::F64(m) => (
                m.table().compression().copied(),
                m.table()
                    .surface_blocks()
                    .as_hierarchical()
                    .map(describe_hierarchy),
            ),
        };
        if let Some(record) = record {
            let _ = writeln!(out, "compression: {}", describe_compression(&record));
        }
        if let Some(hierarchy) = hierarchy {
            let _ = writeln!(out, "{hierarchy}");
        }
        let _ = writeln!(out, "{}", describe_candidates(&model));
    }
}

/// The contact candidate lists of a pre-computed table's collision index:
/// the tool radius they serve, their cells and their longest list, next to
/// the walk over 27 cells a larger tool does.
fn describe_candidates(model: &AnyModel<'_>) -> String {
    fn describe<T: palpate_kernel::Real + Into<f64>>(
        index: &palpate_kernel::table::SurfaceIndex<'_, T>,
    ) -> String {
        let lists = index.list_grid();
        format!(
            "contact candidates: per-cell lists for tools of radius up to {:.3} mm over {} x {} x \
             {} cells of {:.3} mm, at most {} triangles per cell (a larger tool walks 27 cells: \
             at most {})",
            1e3 * index.candidate_radius_m().map_or(0.0, Into::into),
            lists.dims[0],
            lists.dims[1],
            lists.dims[2],
            1e3 * lists.cell_m.into(),
            index.max_cell_triangles(),
            index.max_query_triangles()
        )
    }
    match model {
        AnyModel::F32(m) => describe(m.table().surface_index()),
        AnyModel::F64(m) => describe(m.table().surface_index()),
    }
}

/// One `section NAME: COUNT x ELEM bytes = SIZE bytes` line.
fn section_line(out: &mut String, name: &str, count: u64, elem: u32) {
    let _ = match count.checked_mul(u64::from(elem)) {
        Some(size) => writeln!(out, "section {name}: {count} x {elem} bytes = {size} bytes"),
        None => writeln!(
            out,
            "section {name}: {count} x {elem} bytes: overflows 64 bits"
        ),
    };
}

/// The flash footprint of a table (what `include_table!` links): the total,
/// then the header and directory, each section as the directory declares it,
/// the alignment padding and the checksum.
fn footprint(out: &mut String, h: &RawHeader, entries: &[SectionEntry]) {
    let sections = entries.iter().fold(0u64, |total, e| {
        total.saturating_add(e.count.saturating_mul(u64::from(e.elem_bytes)))
    });
    let header = u64::from(h.header_len);
    let padding = h
        .file_len
        .saturating_sub(header)
        .saturating_sub(sections)
        .saturating_sub(CRC_LEN as u64);
    let _ = writeln!(
        out,
        "flash footprint: {} bytes: header and directory {header}, sections {sections}, \
         alignment padding {padding}, checksum {CRC_LEN}",
        h.file_len
    );
    for e in entries {
        let name = SectionKind::ALL
            .iter()
            .find(|k| **k as u32 == e.kind)
            .map_or_else(
                || format!("(unknown kind {})", e.kind),
                |k| k.name().to_owned(),
            );
        section_line(out, &name, e.count, e.elem_bytes);
    }
}

/// A compressed table's encoding record for people: how each part is
/// stored, the drop threshold, and the errors measured at build time.
pub fn describe_compression(r: &CompressionRecord) -> String {
    let name = |value: u32| BlockEncoding::of_u32(value).map_or("unknown", BlockEncoding::name);
    if BlockEncoding::of_u32(r.surface_encoding).is_some_and(BlockEncoding::is_hierarchical) {
        return format!(
            "contact (surface) blocks {} (no interior rows: the displacements of interior \
             vertices are not stored), interior blocks {}; measured at build against the exact \
             compliance columns over {} contact sets: max force error {:.3e}, max touchable \
             displacement error {:.3e}, relative",
            name(r.surface_encoding),
            name(r.interior_encoding),
            r.probe_count,
            r.max_force_error,
            r.max_surface_displacement_error
        );
    }
    format!(
        "contact (surface) blocks {}, interior blocks {}, dropped below {} of a column's \
         largest; measured at build against the f32 table over {} contact sets (a 1 mm press \
         at every touchable vertex along each axis, and with two partners): max force error \
         {:.3e}, max displacement error {:.3e} (surface vertices {:.3e}), relative",
        name(r.surface_encoding),
        name(r.interior_encoding),
        r.drop_below,
        r.probe_count,
        r.max_force_error,
        r.max_displacement_error,
        r.max_surface_displacement_error
    )
}
