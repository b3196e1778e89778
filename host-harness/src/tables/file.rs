//! Writes the table file format defined in `palpate_kernel::table::format`.

use palpate_kernel::table::format::{
    CRC_LEN, CRC32, FORMAT_VERSION, HEADER_LEN, MAGIC, RawHeader, SECTION_ALIGN, SECTION_ENTRY_LEN,
    SectionEntry, SectionKind,
};

/// Float width of the stored tables: `f32` for firmware (the default), `f64`
/// for verification against reference data.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Precision {
    /// 4-byte floats.
    F32,
    /// 8-byte floats.
    F64,
}

/// Everything a pre-computed table holds, in `f64` before rounding.
pub struct TableContents<'a> {
    /// Tetrahedra of the source mesh (informative).
    pub tet_count: usize,
    /// Young's modulus, Pa.
    pub young_pa: f64,
    /// Poisson ratio.
    pub poisson: f64,
    /// CRC-64 of the source mesh (`TetMesh::content_hash`).
    pub mesh_hash: u64,
    /// Mesh vertex → free index, `u32::MAX` for fixed (N entries).
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
}

/// Serializes `c` with floats of `precision`: header, directory, 16-byte
/// aligned sections, CRC-32 trailer.
pub fn write_table(c: &TableContents<'_>, precision: Precision) -> Vec<u8> {
    let scalar_bytes: u32 = match precision {
        Precision::F32 => 4,
        Precision::F64 => 8,
    };
    let floats = |values: &mut dyn Iterator<Item = f64>| -> Vec<u8> {
        match precision {
            Precision::F32 => values.flat_map(|x| (x as f32).to_le_bytes()).collect(),
            Precision::F64 => values.flat_map(f64::to_le_bytes).collect(),
        }
    };
    let ints = |values: &mut dyn Iterator<Item = u32>| -> Vec<u8> {
        values.flat_map(u32::to_le_bytes).collect()
    };
    let payloads: Vec<(SectionKind, u64, Vec<u8>)> = vec![
        (
            SectionKind::VertexSlot,
            c.vertex_slot.len() as u64,
            ints(&mut c.vertex_slot.iter().copied()),
        ),
        (
            SectionKind::FreeVertex,
            c.free_vertex.len() as u64,
            ints(&mut c.free_vertex.iter().copied()),
        ),
        (
            SectionKind::RestPositions,
            c.positions.len() as u64,
            floats(&mut c.positions.iter().flatten().copied()),
        ),
        (
            SectionKind::SurfaceTriangles,
            c.triangles.len() as u64,
            ints(&mut c.triangles.iter().flatten().copied()),
        ),
        (
            SectionKind::ComplianceSurface,
            c.surface.len() as u64,
            floats(&mut c.surface.iter().flatten().copied()),
        ),
        (
            SectionKind::ComplianceInterior,
            c.interior.len() as u64,
            floats(&mut c.interior.iter().flatten().copied()),
        ),
    ];
    let header_len = HEADER_LEN + payloads.len() * SECTION_ENTRY_LEN;
    let mut offset = header_len.next_multiple_of(SECTION_ALIGN);
    let mut entries = Vec::with_capacity(payloads.len());
    for (kind, count, bytes) in &payloads {
        entries.push(SectionEntry {
            kind: *kind as u32,
            elem_bytes: kind.elem_bytes(scalar_bytes),
            offset: offset as u64,
            count: *count,
        });
        offset = (offset + bytes.len()).next_multiple_of(SECTION_ALIGN);
    }
    let file_len = offset + CRC_LEN;
    let header = RawHeader {
        magic: MAGIC,
        format_version: FORMAT_VERSION,
        header_len: header_len as u32,
        scalar_bytes,
        section_count: payloads.len() as u32,
        vertex_count: c.vertex_slot.len() as u32,
        tet_count: c.tet_count as u32,
        free_count: c.free_vertex.len() as u32,
        touchable_count: c.touchable_count as u32,
        triangle_count: c.triangles.len() as u32,
        reserved: 0,
        young_pa: c.young_pa,
        poisson: c.poisson,
        mesh_hash: c.mesh_hash,
        file_len: file_len as u64,
    };
    let mut out = Vec::with_capacity(file_len);
    out.extend_from_slice(bytemuck::bytes_of(&header));
    for entry in &entries {
        out.extend_from_slice(bytemuck::bytes_of(entry));
    }
    for (entry, (_, _, bytes)) in entries.iter().zip(&payloads) {
        out.resize(entry.offset as usize, 0);
        out.extend_from_slice(bytes);
    }
    out.resize(offset, 0);
    let crc = crc::Crc::<u32>::new(&CRC32).checksum(&out);
    out.extend_from_slice(&crc.to_le_bytes());
    out
}
