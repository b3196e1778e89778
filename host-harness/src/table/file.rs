//! Writes the table file format defined in `palpate_kernel::table::format`.

use bytemuck::Zeroable;

use super::collision::CollisionIndex;
use super::compress::{CodedPart, CompressedCompliance, Hierarchy};
use palpate_kernel::table::format::{
    CRC_LEN, CRC32, FORMAT_VERSION, HEADER_LEN, MAGIC, RawHeader, SECTION_ALIGN, SECTION_ENTRY_LEN,
    SectionEntry, SectionKind, TableKind,
};

/// The stored float width, defined in [`super::precision`] and named here
/// too, beside the writer that takes it.
pub use super::precision::Precision;

/// Everything a pre-computed table holds, in `f64` before rounding.
pub struct TableContents<'a> {
    /// Each tet's Lamé coefficients `[λ, μ]`, Pa, in the source mesh's tet
    /// order (one per tet: their number is the header's tet count).
    pub tet_lame: &'a [[f64; 2]],
    /// Young's modulus of the default material, Pa.
    pub young_pa: f64,
    /// Poisson ratio of the default material.
    pub poisson: f64,
    /// CRC-64 of the source mesh (`TetMesh::content_hash`).
    pub mesh_hash: u64,
    /// Mesh vertex → free index, or the format's `FIXED_SLOT` for a fixed
    /// vertex (N entries, as stored: [`FreeOrdering::slot_entries`]).
    ///
    /// [`FreeOrdering::slot_entries`]: crate::fem::assembly::FreeOrdering::slot_entries
    pub vertex_slot: &'a [u32],
    /// Free index → mesh vertex; the first `touchable_count` are touchable.
    pub free_vertex: &'a [u32],
    /// Free surface vertices (`S`).
    pub touchable_count: usize,
    /// Rest positions, m (N entries).
    pub positions: &'a [[f64; 3]],
    /// Boundary triangles, outward.
    pub triangles: &'a [[u32; 3]],
    /// Packed touchable compliance blocks, m/N.
    pub surface: &'a [[f64; 9]],
    /// Interior compliance blocks, m/N.
    pub interior: &'a [[f64; 9]],
    /// The compliance compressed (`tables build --compress`): its parts
    /// replace [`Self::surface`] and [`Self::interior`] where coded, and
    /// its record is written; `None` for a table all in the scalar.
    pub compressed: Option<&'a CompressedCompliance>,
    /// The collision index of `triangles` over `positions`
    /// ([`super::collision::collision_index`]).
    pub collision: &'a CollisionIndex,
}

/// Serializes a pre-computed table (`TableKind::Precomputed`) with floats
/// of `precision`, its compliance compressed as [`TableContents::compressed`]
/// says.
pub fn write_table(c: &TableContents<'_>, precision: Precision) -> Vec<u8> {
    let index = c.collision;
    let header = RawHeader {
        table_kind: TableKind::Precomputed as u32,
        grid_cell_count: (index.cell_start.len() - 1) as u32,
        surface_vertex_count: index.grid_vertex.len() as u32,
        vertex_count: c.vertex_slot.len() as u32,
        tet_count: c.tet_lame.len() as u32,
        free_count: c.free_vertex.len() as u32,
        touchable_count: c.touchable_count as u32,
        triangle_count: c.triangles.len() as u32,
        young_pa: c.young_pa,
        poisson: c.poisson,
        mesh_hash: c.mesh_hash,
        ..RawHeader::zeroed()
    };
    let mut sections = vec![
        Section::ints(SectionKind::VertexSlot, c.vertex_slot),
        Section::ints(SectionKind::FreeVertex, c.free_vertex),
        Section::floats(SectionKind::RestPositions, c.positions, precision),
        Section::ints(SectionKind::SurfaceTriangles, c.triangles),
    ];
    let (surface, interior, hierarchy) = match c.compressed {
        Some(compressed) => {
            sections.push(Section {
                kind: SectionKind::ComplianceEncoding,
                count: 1,
                bytes: bytemuck::bytes_of(&compressed.record).to_vec(),
            });
            (
                compressed.surface.as_ref(),
                Some(&compressed.interior),
                compressed.hierarchy.as_ref(),
            )
        }
        None => (None, None, None),
    };
    sections.extend(match (surface, hierarchy) {
        (_, Some(h)) => h.sections(precision),
        (Some(part), None) => part.sections(
            [
                SectionKind::SurfaceScale,
                SectionKind::SurfaceCodes,
                SectionKind::SurfaceKept,
            ],
            precision,
        ),
        (None, None) => vec![Section::floats(
            SectionKind::ComplianceSurface,
            c.surface,
            precision,
        )],
    });
    sections.extend(match interior {
        Some(part) => part.sections(
            [
                SectionKind::InteriorScale,
                SectionKind::InteriorCodes,
                SectionKind::InteriorKept,
            ],
            precision,
        ),
        None => vec![Section::floats(
            SectionKind::ComplianceInterior,
            c.interior,
            precision,
        )],
    });
    sections.extend([
        Section::floats(SectionKind::SurfaceGrid, &[index.grid], precision),
        Section::ints(SectionKind::GridDims, &[index.dims, index.list_dims]),
        Section::ints(SectionKind::GridCellStart, &index.cell_start),
        Section::ints(SectionKind::GridVertex, &index.grid_vertex),
        Section::ints(
            SectionKind::VertexTriangleStart,
            &index.vertex_triangle_start,
        ),
        Section::ints(SectionKind::VertexTriangle, &index.vertex_triangle),
        Section::floats(SectionKind::SurfacePlane, &index.planes, precision),
        Section::ints(SectionKind::CellTriangleStart, &index.cell_triangle_start),
        Section::ints(SectionKind::CellTriangle, &index.cell_triangle),
        Section::floats(SectionKind::TetMaterial, c.tet_lame, precision),
    ]);
    write_container(header, precision, &sections)
}

impl CodedPart {
    /// The part's sections: `[scale, codes, kept]` of `kinds`, the bitmap
    /// only when blocks were dropped.
    fn sections(
        &self,
        [scale, codes, kept]: [SectionKind; 3],
        precision: Precision,
    ) -> Vec<Section> {
        let mut sections = vec![
            Section::floats(scale, &self.scales, precision),
            Section {
                kind: codes,
                count: self.codes.len() as u64,
                bytes: self
                    .codes
                    .iter()
                    .flatten()
                    .flat_map(|c| c.to_le_bytes())
                    .collect(),
            },
        ];
        if let Some(words) = &self.kept {
            sections.push(Section::ints(kept, words));
        }
        sections
    }
}

impl Hierarchy {
    /// The five hierarchy sections, the data rounded to `precision` (or
    /// coded: [`Hierarchy::q16`], the data section replaced by the codes
    /// and scales).
    pub fn sections(&self, precision: Precision) -> Vec<Section> {
        let mut sections = vec![
            Section {
                kind: SectionKind::HierarchyRecord,
                count: 1,
                bytes: bytemuck::bytes_of(&self.record).to_vec(),
            },
            Section::ints(SectionKind::HierarchyLeaves, &self.leaves),
            Section::ints(SectionKind::HierarchyBlocks, &self.blocks),
            Section::ints(SectionKind::HierarchyColumnBlocks, &self.column_blocks),
        ];
        if self.q16 {
            let (codes, scales) = self.q16();
            sections.push(Section {
                kind: SectionKind::HierarchyCodes,
                count: codes.len() as u64,
                bytes: codes.iter().flat_map(|c| c.to_le_bytes()).collect(),
            });
            sections.push(Section::floats(
                SectionKind::HierarchyScales,
                &scales,
                precision,
            ));
        } else {
            sections.push(Section::floats(
                SectionKind::HierarchyData,
                &self.data,
                precision,
            ));
        }
        sections
    }
}

/// One section's payload, ready to be laid out.
pub struct Section {
    kind: SectionKind,
    count: u64,
    bytes: Vec<u8>,
}

impl Section {
    /// A section of elements made of `u32`s (`u32`, `[u32; 3]`, …), little-endian.
    pub fn ints<E: bytemuck::Pod>(kind: SectionKind, items: &[E]) -> Self {
        let values: &[u32] = bytemuck::cast_slice(items);
        Self {
            kind,
            count: items.len() as u64,
            bytes: values.iter().flat_map(|x| x.to_le_bytes()).collect(),
        }
    }

    /// A section of elements made of `f64`s (`[f64; 9]`, …), rounded to
    /// `precision`, little-endian.
    pub fn floats<E: bytemuck::Pod>(kind: SectionKind, items: &[E], precision: Precision) -> Self {
        let values: &[f64] = bytemuck::cast_slice(items);
        let values = values.iter();
        let bytes = match precision {
            Precision::F32 => values.flat_map(|&x| (x as f32).to_le_bytes()).collect(),
            Precision::F64 => values.flat_map(|x| x.to_le_bytes()).collect(),
        };
        Self {
            kind,
            count: items.len() as u64,
            bytes,
        }
    }
}

/// The container's layout for sections of `sizes` bytes, in order: each
/// section's offset (after the header and directory, aligned to
/// [`SECTION_ALIGN`]) and the file length with the CRC-32 trailer. `None`
/// if a length overflows. The one layout of the writer and of the size
/// estimate (`super::estimate`).
pub fn layout(sizes: &[u64]) -> Option<(Vec<u64>, u64)> {
    let align = SECTION_ALIGN as u64;
    let directory = (HEADER_LEN + sizes.len() * SECTION_ENTRY_LEN) as u64;
    let mut offset = directory.checked_next_multiple_of(align)?;
    let mut offsets = Vec::with_capacity(sizes.len());
    for &size in sizes {
        offsets.push(offset);
        offset = offset.checked_add(size)?.checked_next_multiple_of(align)?;
    }
    Some((offsets, offset.checked_add(CRC_LEN as u64)?))
}

/// Lays out any table: `header` supplies the kind, counts and material; this
/// fills in magic, version, lengths, scalar width and section count, aligns
/// each section to 16 bytes and appends the CRC-32 trailer.
pub fn write_container(
    mut header: RawHeader,
    precision: Precision,
    sections: &[Section],
) -> Vec<u8> {
    let scalar_bytes = precision.scalar_bytes();
    let header_len = HEADER_LEN + sections.len() * SECTION_ENTRY_LEN;
    let sizes: Vec<u64> = sections.iter().map(|s| s.bytes.len() as u64).collect();
    // In-memory section lengths: their sum fits a `u64`.
    let (offsets, file_len) = layout(&sizes).unwrap_or_default();
    let file_len = file_len as usize;
    let entries: Vec<SectionEntry> = sections
        .iter()
        .zip(&offsets)
        .map(|(section, &offset)| SectionEntry {
            kind: section.kind as u32,
            elem_bytes: section.kind.elem_bytes(scalar_bytes),
            offset,
            count: section.count,
        })
        .collect();
    header.magic = MAGIC;
    header.format_version = FORMAT_VERSION;
    header.header_len = header_len as u32;
    header.scalar_bytes = scalar_bytes;
    header.section_count = sections.len() as u32;
    header.file_len = file_len as u64;
    let mut out = Vec::with_capacity(file_len);
    out.extend_from_slice(bytemuck::bytes_of(&header));
    for entry in &entries {
        out.extend_from_slice(bytemuck::bytes_of(entry));
    }
    for (entry, section) in entries.iter().zip(sections) {
        out.resize(entry.offset as usize, 0);
        out.extend_from_slice(&section.bytes);
    }
    out.resize(file_len - CRC_LEN, 0);
    let crc = crc::Crc::<u32>::new(&CRC32).checksum(&out);
    out.extend_from_slice(&crc.to_le_bytes());
    out
}
