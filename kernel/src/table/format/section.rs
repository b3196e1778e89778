//! The sections: what each kind holds and its element layout
//! ([`SectionKind`]), which kinds each table kind requires ([`TableKind`]),
//! the sentinels and element widths of their entries, and the element
//! count the header's counts require.

use super::encoding::{COMPRESSION_RECORD_LEN, kept_words};
use super::header::RawHeader;
use super::hierarchy::{HIERARCHY_BLOCK_LEN, HIERARCHY_MAX_RANK, HIERARCHY_RECORD_LEN};

/// The most list cells per grid cell and axis: the candidate lists' grid
/// ([`SectionKind::GridDims`]) is the grid in cells 1 to this many times
/// finer.
pub const MAX_LIST_SUBDIVISION: u32 = 4;
/// The most candidate lists one triangle is in: `(k + 3)³` for the
/// largest subdivision `k` ([`SectionKind::CellTriangle`]).
pub const MAX_LISTS_PER_TRIANGLE: u64 = (MAX_LIST_SUBDIVISION as u64 + 3).pow(3);
/// Marks a fixed vertex in [`SectionKind::VertexSlot`].
pub const FIXED_SLOT: u32 = u32::MAX;

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
    /// [`super::tet_edge_vertices`].
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
    /// face opposite each local vertex ([`super::tet_face_vertices`] order).
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
    /// [`super::CompressionRecord`] × 1: how the compliance parts are stored and
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
    // ---- Hierarchical compliance ([`super::hierarchy`]): 57..=64. ----
    /// [`super::HierarchyRecord`] × 1: the hierarchy's counts and bounds.
    HierarchyRecord = 57,
    /// `[u32; 2]` × (leaves + 1): each leaf cluster's first touchable index
    /// and the first entry of its column list in
    /// [`Self::HierarchyColumnBlocks`]; then `S` and the entry count.
    HierarchyLeaves = 58,
    /// [`super::HierarchyBlock`] × blocks: the partition of `S × S`.
    HierarchyBlocks = 59,
    /// `u32` × entries: the blocks over each leaf column, by row.
    HierarchyColumnBlocks = 61,
    /// `scalar` × entries: near blocks' entries and far blocks' factors, m/N
    /// (a factor's scale is the writer's: only `L Rᵀ` is in m/N; in an
    /// interface table, N/m: [`Self::CondensedStiffness`] hierarchical).
    HierarchyData = 62,
    /// `u16` × entries: the q16 codes of a
    /// [`super::BlockEncoding::HierarchicalQ16`] part, in place of
    /// [`Self::HierarchyData`] (same offsets; [`super::hierarchy`], "q16
    /// data").
    HierarchyCodes = 63,
    /// `[scalar; 2]` × blocks: per block of [`Self::HierarchyBlocks`], the
    /// scales of its codes: a near block's quantum (m/N) and 0, a far
    /// block's `L` and `R` quanta (their product in m/N).
    HierarchyScales = 64,
    /// `[u32; 2]` × c (interface tables with a hierarchical condensed
    /// stiffness, [`super::hierarchy`]): per hierarchy index `i`, the
    /// connection node numbered `i` in the cluster tree's leaf order; then
    /// per connection node `j`, its hierarchy index (the inverse
    /// permutation, so that a load checks the pair in one pass).
    HierarchyOrder = 65,
    /// `[scalar; 3]` × 3S·c: the response `H` of the touchable free vertices
    /// only (free indices `0..S`), in place of
    /// [`Self::ConnectionResponse`] in an interface whose pre-computed
    /// region is hierarchical (`[tables] compress = "hmatrix"`): the
    /// `3S × 3c` matrix in the same row-major layout. The step path reads
    /// only these rows (the background under a contact, the force a contact
    /// passes); such a region moves its touchable vertices only, as a
    /// hierarchical pre-computed table does.
    TouchableResponse = 66,
}

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
    pub const ALL: [SectionKind; 55] = [
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
        SectionKind::HierarchyRecord,
        SectionKind::HierarchyLeaves,
        SectionKind::HierarchyBlocks,
        SectionKind::HierarchyColumnBlocks,
        SectionKind::HierarchyData,
        SectionKind::HierarchyCodes,
        SectionKind::HierarchyScales,
        SectionKind::HierarchyOrder,
        SectionKind::TouchableResponse,
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
                | SectionKind::HierarchyLeaves
                | SectionKind::HierarchyBlocks
                | SectionKind::HierarchyColumnBlocks
                | SectionKind::HierarchyData
                | SectionKind::HierarchyCodes
                | SectionKind::HierarchyScales
        )
    }

    /// `true` for the matrix sections an encoding may replace: the
    /// compliance sections a [`super::CompressionRecord`] may replace by
    /// coded or hierarchical ones, an interface's condensed stiffness,
    /// which the hierarchy sections may replace, and its response, which
    /// [`Self::TouchableResponse`] may replace. Required by
    /// [`TableKind::sections`], but checked by the table's view, not by the
    /// container.
    pub const fn encodable(self) -> bool {
        matches!(
            self,
            SectionKind::ComplianceSurface
                | SectionKind::ComplianceInterior
                | SectionKind::CondensedStiffness
                | SectionKind::ConnectionResponse
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
            | SectionKind::TouchableResponse
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
            SectionKind::HierarchyRecord => HIERARCHY_RECORD_LEN as u32,
            SectionKind::HierarchyBlocks => HIERARCHY_BLOCK_LEN as u32,
            SectionKind::HierarchyLeaves | SectionKind::HierarchyOrder => 8,
            SectionKind::HierarchyColumnBlocks => 4,
            SectionKind::HierarchyData => scalar_bytes,
            SectionKind::HierarchyCodes => 2,
            SectionKind::HierarchyScales => 2 * scalar_bytes,
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
        // The hierarchy's order: the touchable vertices of a pre-computed
        // table, the connection nodes of an interface.
        let hs = if h.table_kind == TableKind::Interface as u32 {
            c
        } else {
            s
        };
        match self {
            SectionKind::ConnectionVertex | SectionKind::LoadForce => Some(c),
            SectionKind::CondensedStiffness => c.checked_mul(c)?.checked_mul(3),
            SectionKind::ConnectionResponse => f.checked_mul(c)?.checked_mul(3),
            SectionKind::TouchableResponse => s.checked_mul(c)?.checked_mul(3),
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
            // Declared counts: the most a partition of `S × S` may hold
            // (every block one vertex pair; its data no more than the
            // entries of the full matrix and the factors of every block at
            // the largest rank). The view checks the exact structure.
            SectionKind::HierarchyRecord => Some(1),
            SectionKind::HierarchyLeaves => hs.checked_add(1),
            SectionKind::HierarchyBlocks
            | SectionKind::HierarchyColumnBlocks
            | SectionKind::HierarchyScales => hs.checked_mul(hs),
            SectionKind::HierarchyOrder => Some(c),
            SectionKind::HierarchyData | SectionKind::HierarchyCodes => hs
                .checked_mul(hs)?
                .checked_mul(6 * HIERARCHY_MAX_RANK as u64 + 9),
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
            SectionKind::HierarchyRecord => "hierarchy-record",
            SectionKind::HierarchyLeaves => "hierarchy-leaves",
            SectionKind::HierarchyBlocks => "hierarchy-blocks",
            SectionKind::HierarchyColumnBlocks => "hierarchy-column-blocks",
            SectionKind::HierarchyData => "hierarchy-data",
            SectionKind::HierarchyCodes => "hierarchy-codes",
            SectionKind::HierarchyScales => "hierarchy-scales",
            SectionKind::HierarchyOrder => "hierarchy-order",
            SectionKind::TouchableResponse => "touchable-response",
        }
    }
}

/// Index of the packed surface block `C_nk`, `n ≤ k` (see module docs).
#[inline]
pub const fn surface_block_index(n: usize, k: usize) -> usize {
    k * (k + 1) / 2 + n
}
