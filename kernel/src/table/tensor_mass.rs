//! The validated, zero-copy view of a tensor-mass table (RR-3510 §5).

use nalgebra::{Matrix3, Vector3};

use super::LoadError;
use super::container::{Container, check_finite, check_tet_materials};
use super::format::{
    EDGE_TERMS_LEN, FIXED_SLOT, NO_NEIGHBOUR, RawHeader, SectionKind, TET_LANE_ROWS, TET_LANES,
    TET_MATERIAL_LEN, TET_SHAPE_LEN, TET_TERMS_LEN, TRIANGLE_TERMS_LEN, TableKind,
    VERTEX_TERMS_LEN, tet_edge_vertices, tet_face_vertices, tet_lane_row,
};
use super::index::{EdgeIndex, TetIndex, VertexIndex, csr_row, span};
use crate::Real;

/// A tensor-mass table that passed every load-time check.
///
/// Invariants established by [`TensorMassTable::load`]:
/// - the edge list is a CSR of the pairs `i < j`: row starts ascend from 0 to
///   `E`, columns lie in `i+1..N` and ascend strictly within a row;
/// - every tet has 4 distinct vertices `< N`, its 6 edge references name
///   exactly the edges of its vertex pairs ([`tet_edge_vertices`]), its
///   neighbours are `< tet_count` or [`NO_NEIGHBOUR`], and its rest volume is
///   positive;
/// - the mesh triangles have vertices `< N`, strictly ascending within a
///   triangle, and are in strictly ascending lexicographic order (so
///   distinct); every tet's `tet-triangle` entry `j` names the triangle of its
///   face opposite local vertex `j`, and every triangle is some tet's face
///   (their number equals the distinct faces counted with the neighbours);
/// - masses are `≥ 0`, vertex tensors symmetric, every float finite;
/// - every tet's Lamé coefficients have `μ > 0` and `λ > −2μ/3`;
/// - the `tet-lanes` blocks hold each tet's rest gradients `a_1..a_3`,
///   volume and Lamé coefficients bit for bit as `tet-shape` and
///   `tet-material` do, and zeros past the last tet;
/// - fixed vertices are marked [`FIXED_SLOT`] in the vertex-slot section and
///   their number matches the header's free count.
#[derive(Clone, Copy, Debug)]
pub struct TensorMassTable<'a, T: Real> {
    header: RawHeader,
    checksum: u32,
    vertex_slot: &'a [u32],
    rest_positions: &'a [[T; 3]],
    triangles: &'a [[u32; 3]],
    masses: &'a [T],
    vertex_tensors: &'a [[T; 9]],
    row_start: &'a [u32],
    column: &'a [u32],
    edge_tensors: &'a [[T; 9]],
    tets: &'a [[u32; 4]],
    tet_edges: &'a [[u32; 6]],
    tet_shapes: &'a [[T; TET_SHAPE_LEN]],
    neighbours: &'a [[u32; 4]],
    vertex_terms: &'a [[T; VERTEX_TERMS_LEN]],
    edge_terms: &'a [[T; EDGE_TERMS_LEN]],
    mesh_triangles: &'a [[u32; 3]],
    triangle_terms: &'a [[T; TRIANGLE_TERMS_LEN]],
    tet_triangles: &'a [[u32; 4]],
    tet_terms: &'a [[T; TET_TERMS_LEN]],
    tet_materials: &'a [[T; TET_MATERIAL_LEN]],
    tet_lanes: &'a [TetLanes<T>],
}

/// One [`SectionKind::TetLanes`] element: [`TET_LANES`] tets' rest data by
/// rows ([`tet_lane_row`]), one lane per tet.
pub type TetLanes<T> = [[T; TET_LANES]; TET_LANE_ROWS];

impl<'a, T: Real> TensorMassTable<'a, T> {
    /// Validates `bytes` once and returns the view (format in
    /// [`super::format`]). Cost: linear in the table size. Not for the step path.
    pub fn load(bytes: &'a [u8]) -> Result<Self, LoadError> {
        let c = Container::parse::<T>(bytes, TableKind::TensorMass)?;
        let masses: &[T] = c.section(SectionKind::LumpedMass)?;
        let table = Self {
            header: c.header,
            checksum: c.checksum,
            vertex_slot: c.section(SectionKind::VertexSlot)?,
            rest_positions: c.section(SectionKind::RestPositions)?,
            triangles: c.section(SectionKind::SurfaceTriangles)?,
            masses,
            vertex_tensors: c.section(SectionKind::VertexTensor)?,
            row_start: c.section(SectionKind::EdgeRowStart)?,
            column: c.section(SectionKind::EdgeColumn)?,
            edge_tensors: c.section(SectionKind::EdgeTensor)?,
            tets: c.section(SectionKind::Tet)?,
            tet_edges: c.section(SectionKind::TetEdge)?,
            tet_shapes: c.section(SectionKind::TetShape)?,
            neighbours: c.section(SectionKind::TetNeighbour)?,
            vertex_terms: c.section(SectionKind::VertexTerms)?,
            edge_terms: c.section(SectionKind::EdgeTerms)?,
            mesh_triangles: c.section(SectionKind::MeshTriangle)?,
            triangle_terms: c.section(SectionKind::TriangleTerms)?,
            tet_triangles: c.section(SectionKind::TetTriangle)?,
            tet_terms: c.section(SectionKind::TetTerms)?,
            tet_materials: c.section(SectionKind::TetMaterial)?,
            tet_lanes: c.section(SectionKind::TetLanes)?,
        };
        if table.header.mesh_triangle_count > u64::from(u32::MAX) {
            return Err(LoadError::InconsistentHeader);
        }
        let fixed = table
            .vertex_slot
            .iter()
            .filter(|&&s| s == FIXED_SLOT)
            .count();
        if table.vertex_count() - fixed != table.header.free_count as usize {
            return Err(LoadError::InconsistentHeader);
        }
        check_finite(SectionKind::RestPositions, table.rest_positions)?;
        check_finite(SectionKind::VertexTensor, table.vertex_tensors)?;
        check_finite(SectionKind::EdgeTensor, table.edge_tensors)?;
        check_finite(SectionKind::TetShape, table.tet_shapes)?;
        check_finite(SectionKind::VertexTerms, table.vertex_terms)?;
        check_finite(SectionKind::EdgeTerms, table.edge_terms)?;
        check_finite(SectionKind::TriangleTerms, table.triangle_terms)?;
        check_finite(SectionKind::TetTerms, table.tet_terms)?;
        check_tet_materials(table.tet_materials)?;
        table.check_tet_lanes()?;
        table.check_vertices()?;
        table.check_edges()?;
        table.check_tets()?;
        table.check_mesh_triangles()?;
        if let Some(t) = table
            .triangles
            .iter()
            .position(|tri| tri.iter().any(|&v| table.vertex(v).is_none()))
        {
            return Err(LoadError::BadTriangle { triangle: t as u32 });
        }
        log::debug!(
            "tensor-mass table loaded: {} vertices, {} edges, {} tets, {}-byte floats",
            table.vertex_count(),
            table.edge_count(),
            table.tet_count(),
            T::BYTES
        );
        Ok(table)
    }

    /// The header as stored.
    pub fn header(&self) -> &RawHeader {
        &self.header
    }

    /// The table's CRC-32 trailer (checked at load): what identifies its
    /// contents, so a hybrid's interface can name the region tables it was
    /// built with.
    pub fn checksum(&self) -> u32 {
        self.checksum
    }

    /// Vertices (`N`).
    pub fn vertex_count(&self) -> usize {
        self.vertex_slot.len()
    }

    /// Edges (`E`), each stored once.
    pub fn edge_count(&self) -> usize {
        self.column.len()
    }

    /// Tetrahedra.
    pub fn tet_count(&self) -> usize {
        self.tets.len()
    }

    /// Every tet's Lamé coefficients `[λ, μ]`, Pa, in tet order (checked at
    /// load: `μ > 0`, `λ > −2μ/3`).
    pub fn tet_materials(&self) -> &'a [[T; TET_MATERIAL_LEN]] {
        self.tet_materials
    }

    /// The Lamé coefficients `(λ, μ)` of `tet`, Pa (MODELS.md §1); `None`
    /// only for an index of a larger table.
    pub fn tet_lame(&self, tet: TetIndex) -> Option<(T, T)> {
        let &[lambda, mu] = self.tet_materials.get(tet.get())?;
        Some((lambda, mu))
    }

    /// Mass density, kg/m³.
    pub fn density_kg_m3(&self) -> f64 {
        self.header.density_kg_m3
    }

    /// `vertex` as a checked index of this table's vertices; `None` out of
    /// range.
    pub fn vertex(&self, vertex: u32) -> Option<VertexIndex> {
        VertexIndex::new(vertex, self.vertex_count())
    }

    /// `tet` as a checked index of this table's tets; `None` out of range.
    pub fn tet(&self, tet: u32) -> Option<TetIndex> {
        TetIndex::new(tet, self.tet_count())
    }

    /// `true` if `vertex` is fixed by the table (out of range: `false`).
    pub fn is_fixed(&self, vertex: u32) -> bool {
        self.vertex(vertex).is_some_and(|v| self.is_fixed_vertex(v))
    }

    /// `true` if the checked `vertex` is fixed ([`Self::is_fixed`] without
    /// the range check).
    pub fn is_fixed_vertex(&self, vertex: VertexIndex) -> bool {
        self.vertex_slot.get(vertex.get()) == Some(&FIXED_SLOT)
    }

    /// Every tet index, ascending.
    pub fn tet_indices(&self) -> impl ExactSizeIterator<Item = TetIndex> + use<T> {
        let count = u32::try_from(self.tet_count()).unwrap_or(u32::MAX);
        (0..count).map(TetIndex::checked)
    }

    /// The vertices of `tet` (checked at load: `< N`).
    pub fn tet_vertices(&self, tet: TetIndex) -> Option<[VertexIndex; 4]> {
        Some(self.tets.get(tet.get())?.map(VertexIndex::checked))
    }

    /// The edges of `tet` in [`tet_edge_vertices`] order (checked at load:
    /// `< E`).
    pub fn tet_edge_indices(&self, tet: TetIndex) -> Option<[EdgeIndex; 6]> {
        Some(self.tet_edges.get(tet.get())?.map(EdgeIndex::checked))
    }

    /// The neighbour of `tet` across the face opposite each local vertex,
    /// `None` where the face is on the boundary ([`NO_NEIGHBOUR`] in the
    /// section) or `tet` is out of range.
    pub fn neighbours_of(&self, tet: TetIndex) -> [Option<TetIndex>; 4] {
        let row = self.neighbours.get(tet.get()).copied();
        // Checked at load: `< tet_count` or the sentinel.
        row.unwrap_or([NO_NEIGHBOUR; 4])
            .map(|o| (o != NO_NEIGHBOUR).then_some(TetIndex::checked(o)))
    }

    /// Rest positions, m.
    pub fn rest_positions(&self) -> &'a [[T; 3]] {
        self.rest_positions
    }

    /// Boundary surface triangles of the uncut mesh, outward normals.
    pub fn surface_triangles(&self) -> &'a [[u32; 3]] {
        self.triangles
    }

    /// Lumped masses of the uncut mesh, kg.
    pub fn masses_kg(&self) -> &'a [T] {
        self.masses
    }

    /// Vertex tensors `K_ii` of the uncut mesh, row-major, N/m.
    pub fn vertex_tensors(&self) -> &'a [[T; 9]] {
        self.vertex_tensors
    }

    /// Edge tensors `K_ij`, `i < j`, of the uncut mesh, row-major, N/m.
    pub fn edge_tensors(&self) -> &'a [[T; 9]] {
        self.edge_tensors
    }

    /// CSR row starts (`N + 1` entries).
    pub fn edge_row_starts(&self) -> &'a [u32] {
        self.row_start
    }

    /// CSR columns: the end `j > i` of each edge.
    pub fn edge_columns(&self) -> &'a [u32] {
        self.column
    }

    /// Tet vertices.
    pub fn tets(&self) -> &'a [[u32; 4]] {
        self.tets
    }

    /// Edge indices of each tet, in [`tet_edge_vertices`] order.
    pub fn tet_edges(&self) -> &'a [[u32; 6]] {
        self.tet_edges
    }

    /// Neighbour across the face opposite each local vertex, or [`NO_NEIGHBOUR`].
    pub fn tet_neighbours(&self) -> &'a [[u32; 4]] {
        self.neighbours
    }

    /// St Venant-Kirchhoff terms owned by each vertex of the uncut mesh,
    /// `[c.x, c.y, c.z, d]` (N/m², N/m³; Picinbono 2001 eq. 14, table 1;
    /// layout in the tensor-mass model's `stvk_terms` module).
    pub fn vertex_terms(&self) -> &'a [[T; VERTEX_TERMS_LEN]] {
        self.vertex_terms
    }

    /// St Venant-Kirchhoff terms owned by each edge `(i, j)`, `i < j`, of the
    /// uncut mesh, in CSR order (N/m², N/m³).
    pub fn edge_terms(&self) -> &'a [[T; EDGE_TERMS_LEN]] {
        self.edge_terms
    }

    /// Every face of every tet once, vertex ids ascending, triangles in
    /// ascending lexicographic order (find one with `binary_search`).
    pub fn mesh_triangles(&self) -> &'a [[u32; 3]] {
        self.mesh_triangles
    }

    /// St Venant-Kirchhoff terms owned by each mesh triangle of the uncut
    /// mesh (N/m², N/m³).
    pub fn triangle_terms(&self) -> &'a [[T; TRIANGLE_TERMS_LEN]] {
        self.triangle_terms
    }

    /// Mesh-triangle index of each tet's face opposite each local vertex
    /// ([`tet_face_vertices`] order).
    pub fn tet_triangles(&self) -> &'a [[u32; 4]] {
        self.tet_triangles
    }

    /// St Venant-Kirchhoff quartic terms owned by each tet (N/m³).
    pub fn tet_terms(&self) -> &'a [[T; TET_TERMS_LEN]] {
        self.tet_terms
    }

    /// Every tet's rest shape as stored: `a_0..a_3` (1/m, 12 values), then
    /// the rest volume (m³).
    pub fn tet_shapes(&self) -> &'a [[T; TET_SHAPE_LEN]] {
        self.tet_shapes
    }

    /// The rest gradients, volumes and Lamé coefficients by blocks of
    /// [`TET_LANES`] tets, structure of arrays (block `b` holds tets
    /// `8b..8b + 8`; lanes past the last tet are zero).
    pub fn tet_lanes(&self) -> &'a [TetLanes<T>] {
        self.tet_lanes
    }

    /// Rest shape-function gradients `a_0..a_3` (1/m) and rest volume (m³)
    /// of `tet`; `None` out of range.
    pub fn tet_shape(&self, tet: usize) -> Option<([Vector3<T>; 4], T)> {
        let [x0, y0, z0, x1, y1, z1, x2, y2, z2, x3, y3, z3, volume] = *self.tet_shapes.get(tet)?;
        let a = [
            Vector3::new(x0, y0, z0),
            Vector3::new(x1, y1, z1),
            Vector3::new(x2, y2, z2),
            Vector3::new(x3, y3, z3),
        ];
        Some((a, volume))
    }

    /// The edge `(i, j)` (either order) if it exists: its index. Bounded by
    /// the row length of `min(i, j)`.
    pub fn edge_index(&self, i: u32, j: u32) -> Option<u32> {
        let (i, j) = (self.vertex(i)?, self.vertex(j)?);
        self.edge_between(i, j).map(EdgeIndex::as_u32)
    }

    /// The edge between the checked vertices `i` and `j` (either order), if
    /// any ([`Self::edge_index`] on checked indices).
    pub fn edge_between(&self, i: VertexIndex, j: VertexIndex) -> Option<EdgeIndex> {
        let (lo, hi) = if i < j { (i, j) } else { (j, i) };
        let row = csr_row(self.row_start, lo.get())?;
        let start = row.start;
        let k = self.column.get(row)?.binary_search(&hi.as_u32()).ok()?;
        // An edge of the validated CSR list: `< E`.
        Some(EdgeIndex::checked(u32::try_from(start + k).ok()?))
    }

    /// Each lane of `tet-lanes` against its tet's `tet-shape` (`a_1..a_3`,
    /// volume) and `tet-material` entries, bit for bit (`==` on finite
    /// values, checked before), and the lanes past the last tet zero.
    fn check_tet_lanes(&self) -> Result<(), LoadError> {
        for (b, block) in self.tet_lanes.iter().enumerate() {
            for l in 0..TET_LANES {
                let t = b * TET_LANES + l;
                let expected = match (self.tet_shapes.get(t), self.tet_materials.get(t)) {
                    (Some(shape), Some(&[lambda, mu])) => {
                        let mut rows = [T::zero(); TET_LANE_ROWS];
                        for (row, &x) in rows.iter_mut().zip(shape.iter().skip(3)) {
                            *row = x;
                        }
                        for (r, x) in [(tet_lane_row::LAMBDA, lambda), (tet_lane_row::MU, mu)] {
                            if let Some(row) = rows.get_mut(r) {
                                *row = x;
                            }
                        }
                        rows
                    }
                    _ => [T::zero(); TET_LANE_ROWS],
                };
                let stored = block.iter().map(|row| row.get(l).copied());
                if !stored.zip(expected).all(|(s, e)| s == Some(e)) {
                    return Err(LoadError::BadTetLanes { tet: t as u32 });
                }
            }
        }
        Ok(())
    }

    fn check_vertices(&self) -> Result<(), LoadError> {
        for (v, (m, k)) in self.masses.iter().zip(self.vertex_tensors).enumerate() {
            let bad = LoadError::BadVertexData { vertex: v as u32 };
            if !m.finite() {
                return Err(LoadError::NonFinite {
                    kind: SectionKind::LumpedMass,
                    index: v as u64,
                });
            }
            let k = Matrix3::from_row_slice(k);
            let asym = (k - k.transpose()).abs().max();
            if *m < T::zero() || asym > T::of_f64(1e-4) * k.abs().max() {
                return Err(bad);
            }
        }
        Ok(())
    }

    fn check_edges(&self) -> Result<(), LoadError> {
        let n = self.vertex_count();
        let edges = self.edge_count();
        if self.row_start.first() != Some(&0) || self.row_start.last() != Some(&(edges as u32)) {
            return Err(LoadError::BadEdges { vertex: 0 });
        }
        for (i, pair) in self.row_start.windows(2).enumerate() {
            let bad = LoadError::BadEdges { vertex: i as u32 };
            let [start, end] = *pair else {
                return Err(bad);
            };
            let row = self.column.get(span(start, end)).ok_or(bad)?;
            let mut previous = i as u32;
            for &j in row {
                if j <= previous || VertexIndex::new(j, n).is_none() {
                    return Err(bad);
                }
                previous = j;
            }
        }
        Ok(())
    }

    fn check_tets(&self) -> Result<(), LoadError> {
        let n = self.vertex_count() as u32;
        let m = self.tet_count() as u32;
        let rows = self.tets.iter().zip(self.tet_edges).zip(self.neighbours);
        for (t, ((tet, edges), neighbours)) in rows.enumerate() {
            let bad = LoadError::BadTet { tet: t as u32 };
            if tet.iter().any(|&v| v >= n)
                || neighbours.iter().any(|&o| o >= m && o != NO_NEIGHBOUR)
            {
                return Err(bad);
            }
            for ([a, b], &edge) in tet_edge_vertices(*tet).into_iter().zip(edges) {
                if a == b || self.edge_index(a, b) != Some(edge) {
                    return Err(bad);
                }
            }
            let (_, volume) = self.tet_shape(t).ok_or(bad)?;
            if volume <= T::zero() {
                return Err(bad);
            }
        }
        Ok(())
    }

    fn check_mesh_triangles(&self) -> Result<(), LoadError> {
        let n = self.vertex_count() as u32;
        let mut previous: Option<[u32; 3]> = None;
        for (t, &tri) in self.mesh_triangles.iter().enumerate() {
            let [p, q, r] = tri;
            if !(p < q && q < r && r < n) || previous.is_some_and(|before| before >= tri) {
                return Err(LoadError::BadMeshTriangle { triangle: t as u32 });
            }
            previous = Some(tri);
        }
        let rows = self
            .tets
            .iter()
            .zip(self.tet_triangles)
            .zip(self.neighbours);
        let mut distinct_faces = 0u64;
        for (t, ((&tet, triangles), neighbours)) in rows.enumerate() {
            let faces = tet_face_vertices(tet).into_iter().zip(triangles);
            for (mut face, &triangle) in faces {
                face.sort_unstable();
                if self.mesh_triangles.get(triangle as usize) != Some(&face) {
                    return Err(LoadError::BadTetTriangle { tet: t as u32 });
                }
            }
            // A face shared by two tets is counted by the lower-numbered one.
            distinct_faces += neighbours
                .iter()
                .filter(|&&o| o == NO_NEIGHBOUR || o as usize > t)
                .count() as u64;
        }
        if distinct_faces != self.mesh_triangles.len() as u64 {
            return Err(LoadError::InconsistentHeader);
        }
        Ok(())
    }
}
