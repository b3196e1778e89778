//! The table file format, version 6: one definition shared by the host writer
//! and the kernel reader.
//!
//! ```text
//! offset 0            RawHeader (112 bytes)
//! offset 112          SectionEntry × section_count (24 bytes each)
//! …                   sections, each starting at a multiple of SECTION_ALIGN
//! file_len - 4        CRC-32/ISO-HDLC of bytes [0, file_len - 4), little-endian
//! ```
//!
//! All integers and floats are little-endian. Floats in the sections are the
//! table scalar (`scalar_bytes` = 4 for `f32`, 8 for `f64`).
//!
//! Vertex numbering is the source mesh's input order. The free vertices (not
//! fixed) are renumbered by a *free index*: first the `touchable_count` free
//! surface vertices (the ones a tool can touch) in ascending vertex order,
//! then the interior free vertices in ascending order.
//!
//! Compliance blocks `C_nk` (RR-3510 §4, MODELS.md §2; `C = A⁻¹`, `A` the
//! stiffness restricted to free DOFs; unit m/N) are stored for every free `n`
//! and every touchable `k`, row-major 3×3: element `3a + b` is
//! `C[(n, a), (k, b)]`. Blocks that occur twice by symmetry (`C_kn = C_nkᵀ`,
//! both touchable) are stored once:
//! - [`SectionKind::ComplianceSurface`]: `S(S+1)/2` blocks, packed upper by
//!   columns: column `k` holds rows `n = 0..=k` at index `k(k+1)/2 + n`;
//! - [`SectionKind::ComplianceInterior`]: `I·S` blocks (`I = F − S`): column `k`
//!   holds interior rows `i = 0..I` (free index `S + i`) at index `k·I + i`.
//!
//! Version history: 1 had a 96-byte header; 2 appends
//! [`RawHeader::mesh_triangle_count`] and the St Venant-Kirchhoff term
//! sections of tensor-mass tables ([`SectionKind::VertexTerms`] to
//! [`SectionKind::TetTerms`], Picinbono 2001 §3.1, table 1; the monomial
//! layouts are documented in the tensor-mass model's `stvk_terms` module),
//! a 104-byte header at first, then [`RawHeader::grid_cell_count`] and
//! [`RawHeader::surface_vertex_count`] with the collision-index sections of
//! pre-computed tables: the 112-byte header of today ([`HEADER_LEN`]). 3 adds
//! [`SectionKind::TetMaterial`], each tet's own Lamé coefficients, required
//! in both table kinds (heterogeneous tissue); the header's `young_pa` and
//! `poisson` stay as the scene's default `[material]` (informative: every
//! model reads the per-tet section). 4 adds [`SectionKind::TetLanes`] to
//! tensor-mass tables: the rest shapes and Lamé coefficients again, by
//! blocks of [`TET_LANES`] tets in structure-of-arrays form, which the
//! St Venant-Kirchhoff pass reads with vector loads instead of gathering
//! them tet by tet. 5 widens [`SectionKind::SurfacePlane`] from 4 to
//! [`PLANE_LEN`] scalars: after the plane, the in-plane gradients of the
//! triangle's second and third barycentric weights, so that a contact test
//! weighs a point with two dot products instead of two cross products and
//! two divisions over the corners; it also adds to pre-computed tables
//! the collision index's per-cell candidate lists
//! ([`SectionKind::CellTriangleStart`], [`SectionKind::CellTriangle`]: the
//! triangles a detection in a cell tests, filed against the tool radius the
//! table declares in [`SectionKind::SurfaceGrid`], read as one list instead
//! of a walk over 27 cells). 6 files the lists by each triangle's prism (its
//! box widened along its normal, not on every axis: a contact test takes a
//! triangle only from a centre over it) on a finer lists' grid, the second
//! row of [`SectionKind::GridDims`] ([`MAX_LIST_SUBDIVISION`]). A table of
//! an earlier version is refused ([`super::LoadError::UnsupportedVersion`]),
//! never misread.
//!
//! ## Compressed compliance (version 3, additive)
//!
//! A pre-computed table may store its compliance blocks compressed, to fit a
//! microcontroller's flash. It is the same table kind and version: the
//! [`SectionKind::ComplianceEncoding`] section (one [`CompressionRecord`])
//! says, for each of the two compliance parts, which [`BlockEncoding`]
//! stores it. Without that section (every table written before it existed)
//! both parts are [`BlockEncoding::Scalar`]. A kernel that predates it
//! refuses a compressed table (`unknown section kind 50`), never misreads it.
//!
//! A part stored as [`BlockEncoding::Scalar`] is the section above
//! ([`SectionKind::ComplianceSurface`], [`SectionKind::ComplianceInterior`]).
//! A part stored as [`BlockEncoding::F16`] or [`BlockEncoding::Q16`] replaces
//! it by three sections (`X` = surface or interior):
//! - `X-scale`: one scale per column `k` (touchable vertex), m/N, finite and
//!   `> 0`, in the table scalar;
//! - `X-codes`: `[u16; 9]` per *stored* block, in the dense layout's block
//!   order (column by column as above) with the dropped blocks left out.
//!   Block entry `e` of column `k` is `decode(code) · scale[k]`: for F16,
//!   `decode` is the IEEE 754 binary16 value of the code ([`f16_to_f32`];
//!   infinities and NaNs are refused at load); for Q16 it is the code as a
//!   two's complement `i16` in `−32767..=32767` (`−32768` is refused);
//! - `X-kept` (only when some blocks were dropped, not all: without it
//!   `X-codes` holds every block, or none when all were dropped): which
//!   blocks of the dense layout are stored, one bit per block (bit `j % 32` of word `j / 32`,
//!   least significant first), each word followed by the number of bits set
//!   in the words before it (a rank directory, so a block is found in
//!   constant time: [`kept_position`]). A dropped block is zero. Bits past
//!   the block count are zero, the ranks are exact, the bits set are the
//!   `X-codes` count, and every diagonal block `C_kk` is kept.

use bytemuck::{Pod, Zeroable};

/// First 8 bytes of every table.
pub const MAGIC: [u8; 8] = *b"PALPTBL\0";
/// The format version this kernel reads and the host writes.
pub const FORMAT_VERSION: u32 = 6;
/// Every section starts at a multiple of this many bytes from the file start.
pub const SECTION_ALIGN: usize = 16;
/// The most list cells per grid cell and axis: the candidate lists' grid
/// ([`SectionKind::GridDims`]) is the grid in cells 1 to this many times
/// finer.
pub const MAX_LIST_SUBDIVISION: u32 = 4;
/// The most candidate lists one triangle is in: `(k + 3)³` for the
/// largest subdivision `k` ([`SectionKind::CellTriangle`]).
pub const MAX_LISTS_PER_TRIANGLE: u64 = (MAX_LIST_SUBDIVISION as u64 + 3).pow(3);
/// Size of the CRC-32 trailer.
pub const CRC_LEN: usize = 4;
/// Marks a fixed vertex in [`SectionKind::VertexSlot`].
pub const FIXED_SLOT: u32 = u32::MAX;
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
    /// What the table is for: a [`TableKind`] value.
    pub table_kind: u32,
    /// Vertices of the source mesh (`N`).
    pub vertex_count: u32,
    /// Tetrahedra of the source mesh (both kinds: the count of
    /// [`SectionKind::TetMaterial`]).
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
    /// Pa; each tet's own is in [`SectionKind::TetMaterial`].
    pub young_pa: f64,
    /// Poisson ratio of the default material, dimensionless; each tet's own
    /// is in [`SectionKind::TetMaterial`].
    pub poisson: f64,
    /// Mass density, kg/m³ (tensor-mass tables; zero otherwise).
    pub density_kg_m3: f64,
    /// CRC-64/XZ of the source mesh (positions as f64 LE, then tets as u32 LE).
    pub mesh_hash: u64,
    /// Total file length in bytes, trailer included.
    pub file_len: u64,
    /// Triangles of the whole mesh, every face of every tet once, interior
    /// and boundary ([`SectionKind::MeshTriangle`]; tensor-mass tables, zero
    /// otherwise). 64 bits so that the header has no padding; at most
    /// `u32::MAX` (triangle indices are `u32`), checked at load.
    pub mesh_triangle_count: u64,
    /// Cells of the surface-vertex grid ([`SectionKind::GridCellStart`];
    /// pre-computed tables, zero otherwise).
    pub grid_cell_count: u32,
    /// Distinct vertices of the boundary surface triangles
    /// ([`SectionKind::GridVertex`]; pre-computed tables, zero otherwise).
    pub surface_vertex_count: u32,
}

impl RawHeader {
    /// The checks that come before any other, on the header alone: the
    /// magic and the format version. The loader starts with them, and a
    /// reader that has only the header so far (the host reading a file
    /// header first) calls them before reading on.
    pub fn check_identity(&self) -> Result<(), super::LoadError> {
        if self.magic != MAGIC {
            return Err(super::LoadError::BadMagic);
        }
        if self.format_version != FORMAT_VERSION {
            return Err(super::LoadError::UnsupportedVersion {
                found: self.format_version,
            });
        }
        Ok(())
    }
}

/// Size of [`RawHeader`] in bytes.
pub const HEADER_LEN: usize = core::mem::size_of::<RawHeader>();
const _: () = assert!(HEADER_LEN == 112);

/// What a table is for; each kind has its own required sections.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum TableKind {
    /// The pre-computed quasi-static model (RR-3510 §4).
    Precomputed = 1,
    /// The dynamic tensor-mass model (RR-3510 §5): stiffness on vertices and
    /// edges, lumped masses, per-tet rest data for local removal.
    TensorMass = 2,
    /// The interface of the hybrid model (RR-3510 §6.2): how a pre-computed
    /// region answers the displacements of its connection nodes, condensed
    /// offline. Read with the region's pre-computed table (connection nodes
    /// fixed in it) and the tensor-mass table of the dynamic region.
    Interface = 3,
}

impl TableKind {
    /// The sections a table of this kind must hold, in file order.
    pub const fn sections(self) -> &'static [SectionKind] {
        match self {
            TableKind::Precomputed => &[
                SectionKind::VertexSlot,
                SectionKind::FreeVertex,
                SectionKind::RestPositions,
                SectionKind::SurfaceTriangles,
                SectionKind::ComplianceSurface,
                SectionKind::ComplianceInterior,
                SectionKind::SurfaceGrid,
                SectionKind::GridDims,
                SectionKind::GridCellStart,
                SectionKind::GridVertex,
                SectionKind::VertexTriangleStart,
                SectionKind::VertexTriangle,
                SectionKind::SurfacePlane,
                SectionKind::CellTriangleStart,
                SectionKind::CellTriangle,
                SectionKind::TetMaterial,
            ],
            TableKind::TensorMass => &[
                SectionKind::VertexSlot,
                SectionKind::RestPositions,
                SectionKind::SurfaceTriangles,
                SectionKind::LumpedMass,
                SectionKind::VertexTensor,
                SectionKind::EdgeRowStart,
                SectionKind::EdgeColumn,
                SectionKind::EdgeTensor,
                SectionKind::Tet,
                SectionKind::TetEdge,
                SectionKind::TetShape,
                SectionKind::TetNeighbour,
                SectionKind::VertexTerms,
                SectionKind::EdgeTerms,
                SectionKind::MeshTriangle,
                SectionKind::TriangleTerms,
                SectionKind::TetTriangle,
                SectionKind::TetTerms,
                SectionKind::TetMaterial,
                SectionKind::TetLanes,
            ],
            TableKind::Interface => &[
                SectionKind::ConnectionVertex,
                SectionKind::CondensedStiffness,
                SectionKind::ConnectionResponse,
                SectionKind::LoadDisplacement,
                SectionKind::LoadForce,
                SectionKind::DynamicVertex,
                SectionKind::RegionChecksums,
            ],
        }
    }
}

/// One entry of the section directory.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Pod, Zeroable)]
pub struct SectionEntry {
    /// A [`SectionKind`] value.
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

/// What a section holds. Each kind occurs at most once; which are required
/// depends on the [`TableKind`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum SectionKind {
    /// `u32` × N: free index of each vertex, or [`FIXED_SLOT`].
    VertexSlot = 1,
    /// `u32` × F: vertex of each free index (inverse of `VertexSlot`).
    FreeVertex = 2,
    /// `[scalar; 3]` × N: rest positions, mesh units (m).
    RestPositions = 3,
    /// `[u32; 3]` × triangle_count: boundary triangles, outward normals.
    SurfaceTriangles = 4,
    /// `[scalar; 9]` × S(S+1)/2: compliance among touchable vertices, m/N.
    ComplianceSurface = 5,
    /// `[scalar; 9]` × (F−S)·S: compliance of interior rows, m/N.
    ComplianceInterior = 6,
    /// `[scalar; 5]` × 1: the surface-vertex grid (Cotin 1999 collision
    /// buckets): origin `x, y, z` and cell edge, m; then the largest tool
    /// radius (m, ≥ 0) the per-cell candidate lists
    /// ([`SectionKind::CellTriangle`]) serve.
    SurfaceGrid = 7,
    /// `[u32; 3]` × 2: grid cells per axis, their product the header's
    /// `grid_cell_count` (cell `(i, j, k)` has index `i + nx (j + ny k)`);
    /// then (version 6) the cells per axis of the candidate lists' grid
    /// ([`SectionKind::CellTriangleStart`]): the same box in cells `k`
    /// times finer, `k` in `1..=`[`MAX_LIST_SUBDIVISION`] on every axis.
    GridDims = 8,
    /// `u32` × (grid_cell_count + 1): CSR starts of each cell's vertices.
    GridCellStart = 9,
    /// `u32` × surface_vertex_count: every surface vertex once, by cell.
    GridVertex = 10,
    /// `u32` × (N + 1): CSR starts of the surface triangles around each
    /// vertex.
    VertexTriangleStart = 11,
    /// `u32` × 3·triangle_count: the surface triangles around each vertex,
    /// ascending within a vertex.
    VertexTriangle = 12,
    /// `[scalar; PLANE_LEN]` × triangle_count: each surface triangle's
    /// plane, the unit outward normal `n` and the offset `n·p₀` (m), so a
    /// contact test is two dot products; then its barycentric frame, the
    /// in-plane gradients `g₁ = (e₂ × n)/|n|²` and `g₂ = (n × e₁)/|n|²`
    /// (1/m; `e₁ = p₁ − p₀`, `e₂ = p₂ − p₀`, `n` the unnormalized normal
    /// here), so that a point `x` of the plane has the weights
    /// `w₁ = g₁·(x − p₀)`, `w₂ = g₂·(x − p₀)`, `w₀ = 1 − w₁ − w₂`. Layout:
    /// `[n_x, n_y, n_z, n·p₀, g₁ (3), g₂ (3)]`. All zero for a collapsed
    /// triangle.
    SurfacePlane = 13,
    /// `u32` × (list cells + 1; the directory declares the count, at most
    /// `grid_cell_count · MAX_LIST_SUBDIVISION³ + 1`): CSR starts of each
    /// cell's candidate triangles (version 5), over the candidate lists'
    /// grid (version 6, [`SectionKind::GridDims`]).
    CellTriangleStart = 14,
    /// `u32` × (the directory declares the count): each list cell's
    /// candidate triangles, ascending: triangle `t` is in the list of every
    /// cell of the lists' grid between the cells of the lowest and the
    /// highest corner of the box of its prism for the grid record's tool
    /// radius `r` (`table::candidate_cells`, version 6): the corners'
    /// bounding box widened on axis `i` by `2.25 r |n_i|` (`n` the unit
    /// normal: the centres the contact tests accept it from lie over the
    /// triangle, at most the penetration test's depth of 2 radii and slack
    /// from its plane) and by 1e-3 of a list cell on every axis (the weight
    /// tolerance), each clamped to the grid as a query point is. So a
    /// sphere of at most that radius centred in a list cell finds in its
    /// list every triangle a contact test can find from there (one it
    /// touches or lies under, its centre over it). Checked at load (each
    /// listed triangle filed in its cell, as many entries as filings). The
    /// widening is at most a grid cell and a triangle built from a mesh at
    /// most a grid cell wide, so a triangle is in at most `(k + 3)³` lists
    /// ([`MAX_LISTS_PER_TRIANGLE`] for the largest `k`).
    CellTriangle = 15,
    /// `scalar` × N: lumped vertex masses `m_i = ρ Σ_{tets ∋ i} V/4`, kg.
    LumpedMass = 16,
    /// `[scalar; 9]` × N: vertex tensors `K_ii`, row-major, N/m.
    VertexTensor = 17,
    /// `u32` × (N+1): CSR row starts of the edge list; the edges `(i, j)`,
    /// `i < j`, of vertex `i` are `row_start[i]..row_start[i+1]`.
    EdgeRowStart = 18,
    /// `u32` × E: the other end `j > i` of each edge, ascending within a row.
    EdgeColumn = 19,
    /// `[scalar; 9]` × E: edge tensors `K_ij` (`i < j`, row-major, N/m);
    /// `K_ji = K_ijᵀ` is not stored.
    EdgeTensor = 20,
    /// `[u32; 4]` × tet_count: tet vertices, positively oriented.
    Tet = 21,
    /// `[u32; 6]` × tet_count: edge index of the tet's vertex pairs
    /// [`tet_edge_vertices`].
    TetEdge = 22,
    /// `[scalar; 13]` × tet_count: rest shape-function gradients `a_0..a_3`
    /// (1/m, 12 values) and rest volume (m³), to recompute and subtract the
    /// tet's stiffness blocks when it is removed.
    TetShape = 23,
    /// `[u32; 4]` × tet_count: the tet across the face opposite each vertex,
    /// or [`NO_NEIGHBOUR`] on the boundary.
    TetNeighbour = 24,
    /// `[scalar; 4]` × N: St Venant-Kirchhoff cubic and quartic terms owned
    /// by each vertex (Picinbono 2001 eq. 13–14, table 1), summed over its
    /// tets: `[c.x, c.y, c.z, d]` (N/m², N/m³); layout in
    /// the tensor-mass model's `stvk_terms` module.
    VertexTerms = 25,
    /// `[scalar; 16]` × E: the terms owned by each edge `(i, j)`, `i < j`
    /// (local position 0 is `i`), same order as [`SectionKind::EdgeColumn`].
    EdgeTerms = 26,
    /// `[u32; 3]` × mesh_triangle_count: every face of every tet once
    /// (interior and boundary), vertex ids strictly ascending within a
    /// triangle, triangles in strictly ascending lexicographic order.
    MeshTriangle = 27,
    /// `[scalar; 15]` × mesh_triangle_count: the terms owned by each mesh
    /// triangle (local positions in its ascending vertex order).
    TriangleTerms = 28,
    /// `[u32; 4]` × tet_count: the [`SectionKind::MeshTriangle`] index of the
    /// face opposite each local vertex ([`tet_face_vertices`] order).
    TetTriangle = 29,
    /// `[scalar; 3]` × tet_count: the quartic terms owned by each tet (local
    /// positions in the tet's own vertex order), N/m³.
    TetTerms = 30,
    // ---- Version 3: heterogeneous tissue (31..=39). ----
    /// `[scalar; 2]` × tet_count: each tet's Lamé coefficients `(λ, μ)`, Pa
    /// (MODELS.md §1), in the mesh's tet order; required in both kinds.
    /// Checked at load: finite, `μ > 0` and `λ > −2μ/3` (a positive bulk
    /// modulus, i.e. `−1 < ν < 0.5`).
    TetMaterial = 31,
    // ---- Version 4: vectorized St Venant-Kirchhoff (32). ----
    /// `[[scalar; TET_LANES]; TET_LANE_ROWS]` × ⌈tet_count / TET_LANES⌉
    /// (tensor-mass tables): tets `8b..8b + 8` of block `b`, one lane each,
    /// by rows ([`TET_LANE_ROWS`]): the rest gradients `a_1, a_2, a_3`
    /// (1/m) by component (row `3(j − 1) + c` holds component `c` of
    /// `a_j`; `a_0 = −(a_1 + a_2 + a_3)` is implied), the rest volume (m³),
    /// `λ` and `μ` (Pa). The same values as [`SectionKind::TetShape`] and
    /// [`SectionKind::TetMaterial`], bit for bit, and zero in the lanes
    /// past the last tet (checked at load).
    TetLanes = 32,
    /// `[u32; 2]` × c: each connection node `j` of an interface table, as
    /// `[mesh vertex, tensor-mass vertex]`; mesh vertices strictly
    /// ascending, and connection node `j` is tensor-mass vertex `j` (the
    /// dynamic region numbers its connection nodes first, so their
    /// displacements and forces are one contiguous run of `3c` scalars).
    ConnectionVertex = 40,
    /// `[scalar; 3]` × 3c²: the condensed stiffness of the pre-computed
    /// region on its connection nodes (the Schur complement
    /// `S = K_cc − K_ci K_ii⁻¹ K_ic`, N/m) as the `3c × 3c` matrix, row
    /// major: row `r = 3j + a` (connection `j`, component `a`) is the `c`
    /// triples at `r·c .. (r + 1)·c`, triple `k` holding columns `3k..3k+3`.
    /// Symmetric; both halves stored so every row is contiguous.
    CondensedStiffness = 41,
    /// `[scalar; 3]` × 3F·c: the response `H = −K_ii⁻¹ K_ic` of every free
    /// vertex of the pre-computed region (free index `n` of its table, the
    /// connection nodes fixed there) to the connection nodes'
    /// displacements, dimensionless (m/m), as the `3F × 3c` matrix in the
    /// same row-major layout (row `3n + a`).
    ConnectionResponse = 42,
    /// `[scalar; 3]` × F: the displacement (m) of each free vertex of the
    /// pre-computed region under its built-in load (gravity and point loads
    /// given at build time) with the connection nodes held at rest,
    /// `K_ii⁻¹ f_i`; zero without load.
    LoadDisplacement = 43,
    /// `[scalar; 3]` × c: the force (N) that built-in load passes to each
    /// connection node, `Hᵀ f_i`.
    LoadForce = 44,
    /// `u32` × N: the tensor-mass vertex of each mesh vertex, or
    /// [`FIXED_SLOT`] for a vertex of the pre-computed region only.
    DynamicVertex = 45,
    /// `[u32; 2]` × 1: the CRC-32 trailers of the pre-computed region's and
    /// the tensor-mass region's tables this interface was built with: the
    /// three tables of a hybrid are one build (same mesh, partition and
    /// materials), checked where they meet.
    RegionChecksums = 46,
    // ---- Compressed compliance (module docs): 50..=56. ----
    /// [`CompressionRecord`] × 1: how the compliance parts are stored and
    /// the error measured at build time. Absent: both parts in the table
    /// scalar.
    ComplianceEncoding = 50,
    /// `scalar` × S: the per-column scale of a coded surface part, m/N.
    SurfaceScale = 51,
    /// `[u16; 9]` × (at most S(S+1)/2): the stored blocks of a coded surface
    /// part; the count is the directory's (the blocks kept).
    SurfaceCodes = 52,
    /// `[u32; 2]` × ⌈S(S+1)/2 / 32⌉: the kept-block bitmap of a coded
    /// surface part that dropped blocks.
    SurfaceKept = 53,
    /// `scalar` × S: the per-column scale of a coded interior part, m/N.
    InteriorScale = 54,
    /// `[u16; 9]` × (at most (F−S)·S): the stored blocks of a coded
    /// interior part.
    InteriorCodes = 55,
    /// `[u32; 2]` × ⌈(F−S)·S / 32⌉: the kept-block bitmap of a coded
    /// interior part that dropped blocks.
    InteriorKept = 56,
}

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
}

impl BlockEncoding {
    /// Every encoding, in value order.
    pub const ALL: [BlockEncoding; 3] = [
        BlockEncoding::Scalar,
        BlockEncoding::F16,
        BlockEncoding::Q16,
    ];

    /// The encoding of a record's value, `None` if unknown.
    pub fn of_u32(value: u32) -> Option<Self> {
        Self::ALL.into_iter().find(|e| *e as u32 == value)
    }

    /// Human-readable name, for `tables info`: `uncompressed` (the table
    /// scalar), `f16`, `q16`.
    pub const fn name(self) -> &'static str {
        match self {
            BlockEncoding::Scalar => "uncompressed",
            BlockEncoding::F16 => "f16",
            BlockEncoding::Q16 => "q16",
        }
    }
}

/// Identifies the probe set of [`CompressionRecord::probe_set`]: at every
/// touchable vertex `k`, a press of 1 mm along each axis alone (three
/// solves), and two two-contact presses of 1 mm along `−z`, `k` with the
/// nearest other touchable vertex and `k` with touchable vertex
/// `(k + ⌊S/2⌋) mod S` (`5S` contact sets in all, the vertex contacts of the
/// `precomputed solve` command).
pub const PROBE_SET_EVERY_TOUCHABLE: u32 = 1;

/// The one element of [`SectionKind::ComplianceEncoding`]: how the
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
    /// Which probe set: [`PROBE_SET_EVERY_TOUCHABLE`].
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

/// Blocks per word of a kept-block bitmap ([`SectionKind::SurfaceKept`],
/// [`SectionKind::InteriorKept`]).
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

/// The vertex pairs of a tet's six edges, in [`SectionKind::TetEdge`] order:
/// local pairs (0,1), (0,2), (0,3), (1,2), (1,3), (2,3).
pub const fn tet_edge_vertices(tet: [u32; 4]) -> [[u32; 2]; 6] {
    let [a, b, c, d] = tet;
    [[a, b], [a, c], [a, d], [b, c], [b, d], [c, d]]
}

/// The faces of a positively oriented tet, face `j` opposite local vertex `j`,
/// each ordered so its right-hand normal points out of the tet.
pub const fn tet_face_vertices(tet: [u32; 4]) -> [[u32; 3]; 4] {
    let [a, b, c, d] = tet;
    [[b, c, d], [a, d, c], [a, b, d], [a, c, b]]
}

/// The local vertex pairs `(j, k)` of [`tet_edge_vertices`], for code that
/// needs local indices (stiffness blocks `K_jk`).
pub const TET_EDGE_PAIRS: [[usize; 2]; 6] = [[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]];
/// Marks a boundary face in [`SectionKind::TetNeighbour`].
pub const NO_NEIGHBOUR: u32 = u32::MAX;
/// Scalars per [`SectionKind::TetShape`] element.
pub const TET_SHAPE_LEN: usize = 13;
/// Scalars per [`SectionKind::VertexTerms`] element.
pub const VERTEX_TERMS_LEN: usize = 4;
/// Scalars per [`SectionKind::EdgeTerms`] element.
pub const EDGE_TERMS_LEN: usize = 16;
/// Scalars per [`SectionKind::SurfaceGrid`] element: origin, cell edge and
/// the candidate lists' tool radius.
pub const GRID_LEN: usize = 5;
/// Scalars per [`SectionKind::SurfacePlane`] element: the unit normal, the
/// offset, and the barycentric gradients `g₁`, `g₂`.
pub const PLANE_LEN: usize = 10;
/// Scalars per [`SectionKind::TriangleTerms`] element.
pub const TRIANGLE_TERMS_LEN: usize = 15;
/// Scalars per [`SectionKind::TetTerms`] element.
pub const TET_TERMS_LEN: usize = 3;
/// Scalars per [`SectionKind::TetMaterial`] element: `(λ, μ)`.
pub const TET_MATERIAL_LEN: usize = 2;
/// Tets per [`SectionKind::TetLanes`] element: the lanes of the vectorized
/// St Venant-Kirchhoff pass (8 `f32` fill an AVX2 register).
pub const TET_LANES: usize = 8;
/// Rows per [`SectionKind::TetLanes`] element: 9 gradient components, the
/// volume, `λ` and `μ`.
pub const TET_LANE_ROWS: usize = 12;
/// Rows of a [`SectionKind::TetLanes`] element by what they hold.
pub mod tet_lane_row {
    /// Rest volume, m³.
    pub const VOLUME: usize = 9;
    /// Lamé `λ`, Pa.
    pub const LAMBDA: usize = 10;
    /// Lamé `μ`, Pa.
    pub const MU: usize = 11;
}

impl SectionKind {
    /// Every section kind this version knows.
    pub const ALL: [SectionKind; 46] = [
        SectionKind::VertexSlot,
        SectionKind::FreeVertex,
        SectionKind::RestPositions,
        SectionKind::SurfaceTriangles,
        SectionKind::ComplianceSurface,
        SectionKind::ComplianceInterior,
        SectionKind::SurfaceGrid,
        SectionKind::GridDims,
        SectionKind::GridCellStart,
        SectionKind::GridVertex,
        SectionKind::VertexTriangleStart,
        SectionKind::VertexTriangle,
        SectionKind::SurfacePlane,
        SectionKind::CellTriangleStart,
        SectionKind::CellTriangle,
        SectionKind::LumpedMass,
        SectionKind::VertexTensor,
        SectionKind::EdgeRowStart,
        SectionKind::EdgeColumn,
        SectionKind::EdgeTensor,
        SectionKind::Tet,
        SectionKind::TetEdge,
        SectionKind::TetShape,
        SectionKind::TetNeighbour,
        SectionKind::VertexTerms,
        SectionKind::EdgeTerms,
        SectionKind::MeshTriangle,
        SectionKind::TriangleTerms,
        SectionKind::TetTriangle,
        SectionKind::TetTerms,
        SectionKind::TetMaterial,
        SectionKind::TetLanes,
        SectionKind::ConnectionVertex,
        SectionKind::CondensedStiffness,
        SectionKind::ConnectionResponse,
        SectionKind::LoadDisplacement,
        SectionKind::LoadForce,
        SectionKind::DynamicVertex,
        SectionKind::RegionChecksums,
        SectionKind::ComplianceEncoding,
        SectionKind::SurfaceScale,
        SectionKind::SurfaceCodes,
        SectionKind::SurfaceKept,
        SectionKind::InteriorScale,
        SectionKind::InteriorCodes,
        SectionKind::InteriorKept,
    ];

    /// `true` for the sections whose element count the directory declares
    /// (the blocks a compressed part kept, the candidate lists' starts and entries):
    /// the header's counts give only
    /// the most they may hold ([`Self::expected_count`]).
    pub const fn count_is_declared(self) -> bool {
        matches!(
            self,
            SectionKind::SurfaceCodes
                | SectionKind::InteriorCodes
                | SectionKind::CellTriangleStart
                | SectionKind::CellTriangle
        )
    }

    /// `true` for the compliance sections a [`CompressionRecord`] may
    /// replace by coded ones: required by [`TableKind::sections`], but
    /// checked by the pre-computed view against the record, not by the
    /// container.
    pub const fn encodable(self) -> bool {
        matches!(
            self,
            SectionKind::ComplianceSurface | SectionKind::ComplianceInterior
        )
    }

    /// Bytes per element for a table whose floats have `scalar_bytes` bytes.
    pub const fn elem_bytes(self, scalar_bytes: u32) -> u32 {
        match self {
            SectionKind::VertexSlot
            | SectionKind::FreeVertex
            | SectionKind::EdgeRowStart
            | SectionKind::EdgeColumn
            | SectionKind::DynamicVertex => 4,
            SectionKind::ConnectionVertex | SectionKind::RegionChecksums => 8,
            SectionKind::CondensedStiffness
            | SectionKind::ConnectionResponse
            | SectionKind::LoadDisplacement
            | SectionKind::LoadForce => 3 * scalar_bytes,
            SectionKind::RestPositions => 3 * scalar_bytes,
            SectionKind::SurfaceTriangles | SectionKind::MeshTriangle | SectionKind::GridDims => 12,
            SectionKind::SurfaceGrid => GRID_LEN as u32 * scalar_bytes,
            SectionKind::GridCellStart
            | SectionKind::GridVertex
            | SectionKind::VertexTriangleStart
            | SectionKind::VertexTriangle
            | SectionKind::CellTriangleStart
            | SectionKind::CellTriangle => 4,
            SectionKind::SurfacePlane => PLANE_LEN as u32 * scalar_bytes,
            SectionKind::ComplianceSurface
            | SectionKind::ComplianceInterior
            | SectionKind::VertexTensor
            | SectionKind::EdgeTensor => 9 * scalar_bytes,
            SectionKind::LumpedMass => scalar_bytes,
            SectionKind::Tet | SectionKind::TetNeighbour | SectionKind::TetTriangle => 16,
            SectionKind::TetEdge => 24,
            SectionKind::TetShape => TET_SHAPE_LEN as u32 * scalar_bytes,
            SectionKind::VertexTerms => VERTEX_TERMS_LEN as u32 * scalar_bytes,
            SectionKind::EdgeTerms => EDGE_TERMS_LEN as u32 * scalar_bytes,
            SectionKind::TriangleTerms => TRIANGLE_TERMS_LEN as u32 * scalar_bytes,
            SectionKind::TetTerms => TET_TERMS_LEN as u32 * scalar_bytes,
            SectionKind::TetMaterial => TET_MATERIAL_LEN as u32 * scalar_bytes,
            SectionKind::TetLanes => (TET_LANES * TET_LANE_ROWS) as u32 * scalar_bytes,
            SectionKind::ComplianceEncoding => COMPRESSION_RECORD_LEN as u32,
            SectionKind::SurfaceScale | SectionKind::InteriorScale => scalar_bytes,
            SectionKind::SurfaceCodes | SectionKind::InteriorCodes => 18,
            SectionKind::SurfaceKept | SectionKind::InteriorKept => 8,
        }
    }

    /// Number of elements the header's counts require, `None` on overflow;
    /// for a section whose count the directory declares
    /// ([`Self::count_is_declared`]), the most it may hold.
    pub fn expected_count(self, h: &RawHeader) -> Option<u64> {
        let n = u64::from(h.vertex_count);
        let f = u64::from(h.free_count);
        let s = u64::from(h.touchable_count);
        let tets = u64::from(h.tet_count);
        let edges = u64::from(h.edge_count);
        let c = u64::from(h.connection_count);
        match self {
            SectionKind::ConnectionVertex | SectionKind::LoadForce => Some(c),
            SectionKind::CondensedStiffness => c.checked_mul(c)?.checked_mul(3),
            SectionKind::ConnectionResponse => f.checked_mul(c)?.checked_mul(3),
            SectionKind::LoadDisplacement => Some(f),
            SectionKind::DynamicVertex => Some(n),
            SectionKind::RegionChecksums => Some(1),
            SectionKind::VertexSlot
            | SectionKind::RestPositions
            | SectionKind::LumpedMass
            | SectionKind::VertexTensor
            | SectionKind::VertexTerms => Some(n),
            SectionKind::EdgeRowStart => n.checked_add(1),
            SectionKind::EdgeColumn | SectionKind::EdgeTensor | SectionKind::EdgeTerms => {
                Some(edges)
            }
            SectionKind::Tet
            | SectionKind::TetEdge
            | SectionKind::TetShape
            | SectionKind::TetNeighbour
            | SectionKind::TetTriangle
            | SectionKind::TetTerms
            | SectionKind::TetMaterial => Some(tets),
            SectionKind::TetLanes => Some(tets.div_ceil(TET_LANES as u64)),
            SectionKind::MeshTriangle | SectionKind::TriangleTerms => Some(h.mesh_triangle_count),
            SectionKind::FreeVertex => Some(f),
            SectionKind::SurfaceGrid => Some(1),
            SectionKind::GridDims => Some(2),
            SectionKind::GridCellStart => u64::from(h.grid_cell_count).checked_add(1),
            SectionKind::CellTriangleStart => u64::from(h.grid_cell_count)
                .checked_mul(u64::from(MAX_LIST_SUBDIVISION).pow(3))?
                .checked_add(1),
            SectionKind::CellTriangle => {
                u64::from(h.triangle_count).checked_mul(MAX_LISTS_PER_TRIANGLE)
            }
            SectionKind::GridVertex => Some(u64::from(h.surface_vertex_count)),
            SectionKind::VertexTriangleStart => n.checked_add(1),
            SectionKind::VertexTriangle => u64::from(h.triangle_count).checked_mul(3),
            SectionKind::SurfacePlane => Some(u64::from(h.triangle_count)),
            SectionKind::SurfaceTriangles => Some(u64::from(h.triangle_count)),
            SectionKind::ComplianceSurface | SectionKind::SurfaceCodes => {
                s.checked_mul(s.checked_add(1)?).map(|x| x / 2)
            }
            SectionKind::ComplianceInterior | SectionKind::InteriorCodes => {
                f.checked_sub(s)?.checked_mul(s)
            }
            SectionKind::ComplianceEncoding => Some(1),
            SectionKind::SurfaceScale | SectionKind::InteriorScale => Some(s),
            SectionKind::SurfaceKept => {
                kept_words(SectionKind::ComplianceSurface.expected_count(h)?)
            }
            SectionKind::InteriorKept => {
                kept_words(SectionKind::ComplianceInterior.expected_count(h)?)
            }
        }
    }

    /// Human-readable name, for errors and `tables info`.
    pub const fn name(self) -> &'static str {
        match self {
            SectionKind::VertexSlot => "vertex-slot",
            SectionKind::FreeVertex => "free-vertex",
            SectionKind::RestPositions => "rest-positions",
            SectionKind::SurfaceTriangles => "surface-triangles",
            SectionKind::ComplianceSurface => "compliance-surface",
            SectionKind::ComplianceInterior => "compliance-interior",
            SectionKind::SurfaceGrid => "surface-grid",
            SectionKind::GridDims => "grid-dims",
            SectionKind::GridCellStart => "grid-cell-start",
            SectionKind::GridVertex => "grid-vertex",
            SectionKind::VertexTriangleStart => "vertex-triangle-start",
            SectionKind::VertexTriangle => "vertex-triangle",
            SectionKind::SurfacePlane => "surface-plane",
            SectionKind::CellTriangleStart => "cell-triangle-start",
            SectionKind::CellTriangle => "cell-triangle",
            SectionKind::LumpedMass => "lumped-mass",
            SectionKind::VertexTensor => "vertex-tensor",
            SectionKind::EdgeRowStart => "edge-row-start",
            SectionKind::EdgeColumn => "edge-column",
            SectionKind::EdgeTensor => "edge-tensor",
            SectionKind::Tet => "tet",
            SectionKind::TetEdge => "tet-edge",
            SectionKind::TetShape => "tet-shape",
            SectionKind::TetNeighbour => "tet-neighbour",
            SectionKind::VertexTerms => "vertex-terms",
            SectionKind::EdgeTerms => "edge-terms",
            SectionKind::MeshTriangle => "mesh-triangle",
            SectionKind::TriangleTerms => "triangle-terms",
            SectionKind::TetTriangle => "tet-triangle",
            SectionKind::TetTerms => "tet-terms",
            SectionKind::TetMaterial => "tet-material",
            SectionKind::TetLanes => "tet-lanes",
            SectionKind::ConnectionVertex => "connection-vertex",
            SectionKind::CondensedStiffness => "condensed-stiffness",
            SectionKind::ConnectionResponse => "connection-response",
            SectionKind::LoadDisplacement => "load-displacement",
            SectionKind::LoadForce => "load-force",
            SectionKind::DynamicVertex => "dynamic-vertex",
            SectionKind::RegionChecksums => "region-checksums",
            SectionKind::ComplianceEncoding => "compliance-encoding",
            SectionKind::SurfaceScale => "surface-scale",
            SectionKind::SurfaceCodes => "surface-codes",
            SectionKind::SurfaceKept => "surface-kept",
            SectionKind::InteriorScale => "interior-scale",
            SectionKind::InteriorCodes => "interior-codes",
            SectionKind::InteriorKept => "interior-kept",
        }
    }
}

/// Index of the packed surface block `C_nk`, `n ≤ k` (see module docs).
#[inline]
pub const fn surface_block_index(n: usize, k: usize) -> usize {
    k * (k + 1) / 2 + n
}
