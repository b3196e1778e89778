//! The collision index (Cotin 1999 §4, collision buckets; MODELS.md §6):
//! the boundary-surface vertices filed in a regular grid over their bounding
//! box, and the surface triangles around each vertex. The sections of a
//! pre-computed table are built offline (`palpate tables build`, with
//! [`crate::contact::grid`]) and validated once by [`SurfaceIndex::new`]
//! (called from `PrecomputedTable::load`); a deforming surface's index is
//! assembled from lists the kernel built itself. Both are then
//! queried in bounded time: a query visits the 27 cells around a point,
//! each holding at most [`SurfaceIndex::max_bucket`] vertices, each with at
//! most [`SurfaceIndex::max_valence`] triangles; or, in a table (format 6),
//! reads the candidate list of the point's cell of the lists' finer grid,
//! filed for a declared tool radius ([`SurfaceIndex::candidates`], at most
//! [`SurfaceIndex::max_cell_triangles`] triangles). Each triangle's plane
//! carries its barycentric frame ([`SurfaceIndex::weights`]).
//!
//! The grid's geometry is [`super::grid`], the lists' filing rule
//! [`super::candidates`], the validation at load [`load`].

mod load;

use nalgebra::Vector3;

use super::format::GRID_LEN;
use super::grid::{CellBox, Grid};
use super::index::{TriangleIndex, VertexIndex, csr_row, span};
use super::plane::{Plane, parts_of};
use crate::Real;

/// The validated collision index (a view into the table), with the surface
/// triangles it was built over.
///
/// Invariants (checked by [`super::PrecomputedTable::load`], by
/// construction for an index the kernel assembled): every filed vertex and every triangle
/// corner is a vertex of the surface's positions, and every triangle in a
/// vertex's list is a surface triangle containing it, so the indices it
/// hands out ([`VertexIndex`], [`TriangleIndex`]) are in range.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceIndex<'a, T> {
    grid: Grid<T>,
    triangles: &'a [[u32; 3]],
    cell_start: &'a [u32],
    grid_vertex: &'a [u32],
    vertex_triangle_start: &'a [u32],
    vertex_triangle: &'a [u32],
    planes: &'a [Plane<T>],
    /// The box of the surface triangles' corners, m (lowest and highest
    /// corner; [`Self::surface_box`]).
    surface_box_m: [Vector3<T>; 2],
    /// The candidate lists' grid: the grid's box in cells `k` times finer
    /// (the grid itself for an index the kernel assembled).
    lists: Grid<T>,
    /// Each list cell's candidate triangles (CSR; empty for an index the
    /// kernel assembled) and the largest tool radius they serve, m
    /// (`None`: no lists, every query walks the cells).
    cell_triangle_start: &'a [u32],
    cell_triangle: &'a [u32],
    candidate_radius_m: Option<T>,
    max_bucket: u32,
    max_valence: u32,
    max_query_triangles: u32,
    max_cell_triangles: u32,
}

/// The raw sections of a collision index, before validation.
pub(crate) struct SurfaceSections<'a, T> {
    pub(crate) grid: &'a [[T; GRID_LEN]],
    pub(crate) dims: &'a [[u32; 3]],
    pub(crate) cell_start: &'a [u32],
    pub(crate) grid_vertex: &'a [u32],
    pub(crate) vertex_triangle_start: &'a [u32],
    pub(crate) vertex_triangle: &'a [u32],
    pub(crate) planes: &'a [Plane<T>],
    pub(crate) cell_triangle_start: &'a [u32],
    pub(crate) cell_triangle: &'a [u32],
}

/// The lists of an index the kernel built itself (re-binning a deforming
/// surface), consistent by construction.
pub(crate) struct BuiltLists<'a, T> {
    /// The surface triangles (vertices of the surface's positions).
    pub(crate) triangles: &'a [[u32; 3]],
    pub(crate) cell_start: &'a [u32],
    pub(crate) grid_vertex: &'a [u32],
    pub(crate) vertex_triangle_start: &'a [u32],
    pub(crate) vertex_triangle: &'a [u32],
    pub(crate) planes: &'a [Plane<T>],
    /// The box of the surface vertices (those with a triangle), m
    /// ([`super::grid::box_of`]).
    pub(crate) surface_box_m: [Vector3<T>; 2],
    /// The largest row of `cell_start` and of `vertex_triangle_start`.
    pub(crate) max_bucket: u32,
    pub(crate) max_valence: u32,
}

/// One cell's candidate triangles, ascending
/// ([`SurfaceIndex::candidates`]).
#[derive(Clone, Copy, Debug)]
pub struct CandidateList<'a>(&'a [u32]);

impl<'a> CandidateList<'a> {
    /// The triangles (in range by the loader's check).
    #[inline(always)]
    pub fn iter(&self) -> impl Iterator<Item = TriangleIndex> + '_ {
        self.0.iter().map(|&t| TriangleIndex::checked(t))
    }

    /// The triangle indices (each below the surface's triangle count).
    pub(crate) fn as_slice(&self) -> &'a [u32] {
        self.0
    }
}

/// A triangle slot that holds no triangle (a face of the deforming
/// surface's list that is not on the surface now: an interior face no cut
/// has exposed, or a face whose tets are gone). Skipped by
/// `contact::grid`'s builders; never a valid triangle (its corners are
/// out of every vertex range).
pub const DEAD_TRIANGLE: [u32; 3] = [u32::MAX; 3];

impl<'a, T: Real> SurfaceIndex<'a, T> {
    /// An index over lists the kernel built (no validation needed: see
    /// [`BuiltLists`]). Constant time. Query bound: `27 × max_bucket ×
    /// max_valence`, at most every listed triangle reference.
    pub(crate) fn assembled(grid: Grid<T>, lists: BuiltLists<'a, T>) -> Self {
        let BuiltLists {
            max_bucket,
            max_valence,
            ..
        } = lists;
        let max_query_triangles = max_bucket
            .saturating_mul(27)
            .saturating_mul(max_valence)
            .min(lists.vertex_triangle.len() as u32);
        Self {
            grid,
            lists: grid,
            triangles: lists.triangles,
            cell_start: lists.cell_start,
            grid_vertex: lists.grid_vertex,
            vertex_triangle_start: lists.vertex_triangle_start,
            vertex_triangle: lists.vertex_triangle,
            planes: lists.planes,
            surface_box_m: lists.surface_box_m,
            cell_triangle_start: &[],
            cell_triangle: &[],
            candidate_radius_m: None,
            max_bucket,
            max_valence,
            max_query_triangles,
            max_cell_triangles: 0,
        }
    }

    /// The candidate list of cell `cell` (linear index; empty out of range).
    fn cell_triangles_at(&self, cell: usize) -> &'a [u32] {
        csr_row(self.cell_triangle_start, cell)
            .and_then(|row| self.cell_triangle.get(row))
            .unwrap_or(&[])
    }

    /// The candidate triangles of the lists' cell of `p` (m) for a tool of
    /// radius `radius_m` (m): every triangle a contact test can find from a
    /// sphere of that radius centred in the cell (its centre over the
    /// triangle, within the test's depth of its plane:
    /// [`super::format::SectionKind::CellTriangle`]), ascending; `None`
    /// when the index has no lists or they serve a smaller radius (then a
    /// query walks the 27 cells around `p`). Bounded by
    /// [`Self::max_cell_triangles`].
    #[inline]
    pub fn candidates(&self, p: &Vector3<T>, radius_m: T) -> Option<CandidateList<'a>> {
        self.serves(radius_m)
            .then(|| self.candidates_at(self.list_cell_of(p)))
    }

    /// Whether the per-cell candidate lists serve a tool of radius
    /// `radius_m` (m).
    #[inline]
    pub fn serves(&self, radius_m: T) -> bool {
        self.candidate_radius_m.is_some_and(|r| radius_m <= r)
    }

    /// The candidate list of the lists' grid cell `c` ([`Self::list_cell_of`];
    /// empty beyond the grid).
    #[inline]
    pub(crate) fn candidates_at(&self, c: [u32; 3]) -> CandidateList<'a> {
        CandidateList(self.cell_triangles_at(self.lists.linear(c)))
    }

    /// The candidate lists of a sweep between the lists' grid cells `a` and
    /// `b` ([`Self::list_cell_of`]), neighbours (at most one apart on each
    /// axis): each cell of the box of cells between them (at most 8; every
    /// point of a segment between points of `a` and `b` has its cell in
    /// it) but `b` (its list read already, at the tool). `f` gets each
    /// list. For a tool the lists serve ([`Self::serves`]) and a short
    /// motion (`SurfaceGeometry::detect` walks the cells for a longer one).
    pub(crate) fn for_each_candidate_list_between(
        &self,
        a: [u32; 3],
        b: [u32; 3],
        mut f: impl FnMut(CandidateList<'a>),
    ) {
        let [bx, by, bz] = b;
        CellBox::between(a, b).for_each(|[i, j, k]| {
            // Corner by corner: an array comparison is a `memcmp` call on
            // the firmware target.
            let at_b = i == bx && j == by && k == bz;
            if !at_b {
                f(self.candidates_at([i, j, k]));
            }
        });
    }

    /// The longest per-cell candidate list (0 without lists): a
    /// table-declared bound.
    pub fn max_cell_triangles(&self) -> u32 {
        self.max_cell_triangles
    }

    /// The largest tool radius (m) the per-cell candidate lists serve,
    /// `None` without lists.
    pub fn candidate_radius_m(&self) -> Option<T> {
        self.candidate_radius_m
    }

    /// The most triangle tests one detection by a tool of radius
    /// `radius_m` does (`SurfaceGeometry::detect`): with the lists, for a
    /// short motion, the tool's cell twice (the test, and the penetration
    /// test's second pass) and up to `2³ − 1` more cells along the sweep;
    /// a longer motion, or a tool the lists do not serve, walks: `3 ×
    /// max_query_triangles`. The larger of the two when the lists serve;
    /// plus one walk, `max_query_triangles`, for the deep check a
    /// detection that made no contact may be followed by
    /// (`SurfaceGeometry::centre_inside`).
    pub fn max_detection_tests(&self, radius_m: T) -> u32 {
        let walk = self.max_query_triangles.saturating_mul(3);
        let detection = if self.serves(radius_m) {
            walk.max(self.max_cell_triangles.saturating_mul(9))
        } else {
            walk
        };
        detection.saturating_add(self.max_query_triangles)
    }

    /// The most candidate triangles one point query
    /// ([`Self::for_each_vertex_near`] then [`Self::triangles_of`]) visits, over
    /// every cell of the grid (computed at load: the exact table-declared
    /// bound of a detection's work, per query point).
    pub fn max_query_triangles(&self) -> u32 {
        self.max_query_triangles
    }

    /// Grid origin, m.
    pub fn origin_m(&self) -> Vector3<T> {
        self.grid.origin_m
    }

    /// Grid cell edge, m.
    pub fn cell_m(&self) -> T {
        self.grid.cell_m
    }

    /// Cells per axis.
    pub fn dims(&self) -> [u32; 3] {
        self.grid.dims
    }

    /// Most vertices in one cell (a table-declared loop bound).
    pub fn max_bucket(&self) -> u32 {
        self.max_bucket
    }

    /// Most surface triangles around one vertex (a table-declared bound).
    pub fn max_valence(&self) -> u32 {
        self.max_valence
    }

    /// The cell containing `p` (m), clamped to the grid (a point outside
    /// maps to the nearest border cell; non-finite coordinates map to 0).
    pub fn cell_of(&self, p: &Vector3<T>) -> [u32; 3] {
        self.grid.cell_of(p)
    }

    /// The candidate lists' cell containing `p` (m), clamped as
    /// [`Self::cell_of`]: the cell of the grid itself for an index without
    /// lists.
    pub fn list_cell_of(&self, p: &Vector3<T>) -> [u32; 3] {
        self.lists.cell_of(p)
    }

    /// The cell a detection files `p` (m) in: of the candidate lists' grid
    /// when `lists` (the lists serve the tool, [`Self::serves`]), else of
    /// the grid ([`Self::list_cell_of`], [`Self::cell_of`]).
    #[inline(always)]
    pub fn detection_cell_of(&self, p: &Vector3<T>, lists: bool) -> [u32; 3] {
        if lists {
            self.list_cell_of(p)
        } else {
            self.cell_of(p)
        }
    }

    /// The candidate lists' grid: the grid's box in cells `k` times finer
    /// ([`super::format::SectionKind::GridDims`]).
    pub fn list_grid(&self) -> &Grid<T> {
        &self.lists
    }

    /// The box within one cell edge plus `margin_m` (m) of the grid: its
    /// lowest and highest corners, m ([`Grid::reach`]). A point farther out
    /// has no surface vertex within a cell.
    pub fn reach(&self, margin_m: T) -> [Vector3<T>; 2] {
        self.grid.reach(margin_m)
    }

    /// The box of the grid's cells, m ([`Grid::bounds`]): it holds every
    /// filed surface vertex, so a point outside it is outside the body.
    pub fn bounds(&self) -> [Vector3<T>; 2] {
        self.grid.bounds()
    }

    /// The box of the surface's vertices, m (lowest and highest corner,
    /// kept at load and by a deforming surface at each re-bin): the body
    /// lies in it, so a point outside it is outside the body. Tighter than
    /// [`Self::bounds`], whose cells reach up to a cell past the surface.
    pub fn surface_box(&self) -> [Vector3<T>; 2] {
        self.surface_box_m
    }

    /// Calls `f` with each surface vertex filed in the 27 cells around the
    /// cell of `p` (m), cell by cell (`x` fastest), each cell's in filing
    /// order. Bounded by `27 × max_bucket`. A row of up to three cells
    /// along `x` is one run of the filed list, so the visit is nine slices,
    /// in plain loops (an iterator of nested `flat_map`s keeps its state in
    /// memory, a store per step on the firmware target).
    #[inline]
    pub fn for_each_vertex_near(&self, p: &Vector3<T>, mut f: impl FnMut(VertexIndex)) {
        let CellBox {
            lo: [x0, y0, z0],
            hi: [x1, y1, z1],
        } = self.grid.around(self.cell_of(p));
        for k in z0..=z1 {
            for j in y0..=y1 {
                let first = self.grid.linear([x0, j, k]);
                let last = self.grid.linear([x1, j, k]);
                let (Some(&start), Some(&end)) =
                    (self.cell_start.get(first), self.cell_start.get(last + 1))
                else {
                    continue;
                };
                // Filed vertices are vertices of the surface (invariant).
                for &v in self.grid_vertex.get(span(start, end)).unwrap_or(&[]) {
                    f(VertexIndex::checked(v));
                }
            }
        }
    }

    /// The vertices of surface triangle `t`; `None` for an index of
    /// another surface beyond this one's triangles.
    pub fn triangle(&self, t: TriangleIndex) -> Option<[VertexIndex; 3]> {
        // Triangle corners are vertices of the surface (invariant), but for
        // an empty slot of a deforming surface.
        let &[a, b, c] = self.triangles.get(t.get())?;
        // Compared corner by corner: an array comparison is a `memcmp` call
        // on the firmware target.
        if a == u32::MAX && b == u32::MAX && c == u32::MAX {
            return None;
        }
        Some([a, b, c].map(VertexIndex::checked))
    }

    /// The stored plane of surface triangle `t`: unit outward normal and
    /// offset `n·p` (m).
    #[inline(always)]
    pub fn plane(&self, t: TriangleIndex) -> Option<(Vector3<T>, T)> {
        self.planes.get(t.get()).map(|p| {
            let (normal, offset, _) = parts_of(p);
            (normal, offset)
        })
    }

    /// The barycentric weights of `x_m` (m) on surface triangle `t`, of the
    /// point of its plane under `x_m` (the frame's gradients lie in the
    /// plane): `w₁ = g₁·(x − p₀)`, `w₂ = g₂·(x − p₀)`, `w₀ = 1 − w₁ − w₂`
    /// ([`super::format::SectionKind::SurfacePlane`]). All zero for a
    /// collapsed triangle (zero normal), which no test accepts; `None` for an
    /// index beyond this surface's triangles or an empty slot.
    #[inline(always)]
    pub fn weights(
        &self,
        t: TriangleIndex,
        positions_m: &[[T; 3]],
        x_m: &Vector3<T>,
    ) -> Option<[T; 3]> {
        let plane = self.planes.get(t.get())?;
        let &[a, ..] = self.triangles.get(t.get())?;
        let p = positions_m.get(a as usize)?;
        let d = x_m - Vector3::new(p[0], p[1], p[2]);
        let (normal, _, [g1, g2]) = parts_of(plane);
        if normal == Vector3::zeros() {
            return Some([T::zero(); 3]);
        }
        let (w1, w2) = (g1.dot(&d), g2.dot(&d));
        Some([T::one() - w1 - w2, w1, w2])
    }

    /// The surface triangles around `vertex`, ascending. Bounded by
    /// `max_valence`.
    pub fn triangles_of(
        &self,
        vertex: VertexIndex,
    ) -> impl ExactSizeIterator<Item = TriangleIndex> + Clone + use<'a, T> {
        // Listed triangles are surface triangles (invariant).
        self.triangle_row(vertex)
            .iter()
            .map(|&t| TriangleIndex::checked(t))
    }

    /// The surface triangle whose corners are the three distinct
    /// `vertices`, in any order; `None` if they are not a surface triangle.
    /// Bounded by the valence of the first vertex ([`Self::max_valence`]).
    pub fn find_triangle(&self, vertices: [VertexIndex; 3]) -> Option<TriangleIndex> {
        let [a, b, c] = vertices;
        if a == b || b == c || a == c {
            return None;
        }
        // Every listed triangle contains `a` (invariant), so with distinct
        // vertices containing `b` and `c` makes it exactly `{a, b, c}`.
        self.triangles_of(a).find(|&t| {
            self.triangle(t)
                .is_some_and(|corners| corners.contains(&b) && corners.contains(&c))
        })
    }

    /// The surface triangle other than `not` around both `a` and `b` (the
    /// neighbour of `not` across its edge `ab`), the first in ascending
    /// order if several. Bounded by `max_valence` binary searches.
    pub fn across(
        &self,
        not: TriangleIndex,
        a: VertexIndex,
        b: VertexIndex,
    ) -> Option<TriangleIndex> {
        let around_b = self.triangle_row(b);
        self.triangles_of(a)
            .find(|&t| t != not && around_b.binary_search(&t.as_u32()).is_ok())
    }

    /// The row of `vertex` in the vertex-to-triangle list (empty out of
    /// range).
    #[inline]
    fn triangle_row(&self, vertex: VertexIndex) -> &'a [u32] {
        csr_row(self.vertex_triangle_start, vertex.get())
            .and_then(|row| self.vertex_triangle.get(row))
            .unwrap_or(&[])
    }
}
