//! The container's fixed parts: the identity and layout constants, the
//! file header ([`RawHeader`]) and the section directory's entries
//! ([`SectionEntry`]).

use bytemuck::{Pod, Zeroable};

/// First 8 bytes of every table.
pub const MAGIC: [u8; 8] = *b"PALPTBL\0";
/// The format version this kernel reads and the host writes.
pub const FORMAT_VERSION: u32 = 6;
/// Every section starts at a multiple of this many bytes from the file start.
pub const SECTION_ALIGN: usize = 16;
/// Size of the CRC-32 trailer.
pub const CRC_LEN: usize = 4;
/// The checksum algorithm over the file (all bytes but the trailer).
pub const CRC32: crc::Algorithm<u32> = crc::CRC_32_ISO_HDLC;

/// The fixed-size file header.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct RawHeader {
    /// [`MAGIC`].
    pub magic: [u8; 8],
    /// [`FORMAT_VERSION`].
    pub format_version: u32,
    /// Bytes of header plus section directory.
    pub header_len: u32,
    /// Bytes per stored float: 4 (`f32`) or 8 (`f64`).
    pub scalar_bytes: u32,
    /// Number of [`SectionEntry`] after the header.
    pub section_count: u32,
    /// What the table is for: a [`super::TableKind`] value.
    pub table_kind: u32,
    /// Vertices of the source mesh (`N`).
    pub vertex_count: u32,
    /// Tetrahedra of the source mesh (both kinds: the count of
    /// [`super::SectionKind::TetMaterial`]).
    pub tet_count: u32,
    /// Free (not fixed) vertices (`F`).
    pub free_count: u32,
    /// Free surface vertices, the touchable ones (`S`).
    pub touchable_count: u32,
    /// Boundary surface triangles.
    pub triangle_count: u32,
    /// Mesh edges (tensor-mass tables; zero otherwise).
    pub edge_count: u32,
    /// Connection nodes (`c`) of an interface table (RR-3510 §6.2): the
    /// vertices shared by the pre-computed and the tensor-mass region. Zero
    /// in the other kinds (and it keeps the floats 8-byte aligned).
    pub connection_count: u32,
    /// Young's modulus of the default material (the scene's `[material]`),
    /// Pa; each tet's own is in [`super::SectionKind::TetMaterial`].
    pub young_pa: f64,
    /// Poisson ratio of the default material, dimensionless; each tet's own
    /// is in [`super::SectionKind::TetMaterial`].
    pub poisson: f64,
    /// Mass density, kg/m³ (tensor-mass tables; zero otherwise).
    pub density_kg_m3: f64,
    /// CRC-64/XZ of the source mesh (positions as f64 LE, then tets as u32 LE).
    pub mesh_hash: u64,
    /// Total file length in bytes, trailer included.
    pub file_len: u64,
    /// Triangles of the whole mesh, every face of every tet once, interior
    /// and boundary ([`super::SectionKind::MeshTriangle`]; tensor-mass tables, zero
    /// otherwise). 64 bits so that the header has no padding; at most
    /// `u32::MAX` (triangle indices are `u32`), checked at load.
    pub mesh_triangle_count: u64,
    /// Cells of the surface-vertex grid ([`super::SectionKind::GridCellStart`];
    /// pre-computed tables, zero otherwise).
    pub grid_cell_count: u32,
    /// Distinct vertices of the boundary surface triangles
    /// ([`super::SectionKind::GridVertex`]; pre-computed tables, zero otherwise).
    pub surface_vertex_count: u32,
}

/// Size of [`RawHeader`] in bytes.
pub const HEADER_LEN: usize = core::mem::size_of::<RawHeader>();
const _: () = assert!(HEADER_LEN == 112);

/// One entry of the section directory.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Pod, Zeroable)]
pub struct SectionEntry {
    /// A [`super::SectionKind`] value.
    pub kind: u32,
    /// Bytes per element (e.g. 36 for an `f32` 3×3 block).
    pub elem_bytes: u32,
    /// Byte offset from the file start; a multiple of [`SECTION_ALIGN`].
    pub offset: u64,
    /// Number of elements.
    pub count: u64,
}

/// Size of [`SectionEntry`] in bytes.
pub const SECTION_ENTRY_LEN: usize = core::mem::size_of::<SectionEntry>();
const _: () = assert!(SECTION_ENTRY_LEN == 24);
