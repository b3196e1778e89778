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

use nalgebra::Vector3;

use super::LoadError;
use super::format::{GRID_LEN, MAX_LIST_SUBDIVISION, PLANE_LEN};
use super::index::{TriangleIndex, VertexIndex, csr_row, span};
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

/// A regular grid over a box: origin (its lowest corner), cell edge and
/// cells per axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid<T> {
    /// The lowest corner, m.
    pub origin_m: Vector3<T>,
    /// The cell edge, m.
    pub cell_m: T,
    /// Cells per axis.
    pub dims: [u32; 3],
}

/// `true` if `p` lies in the box `[lo, hi]` (a non-finite coordinate does
/// not).
pub fn within<T: Real>(p: &Vector3<T>, [lo, hi]: &[Vector3<T>; 2]) -> bool {
    p.iter()
        .zip(lo.iter().zip(hi.iter()))
        .all(|(&x, (&l, &h))| x >= l && x <= h)
}

/// Cell coordinates or counts per axis, widened for indexing.
#[inline(always)]
fn widen(c: [u32; 3]) -> [usize; 3] {
    c.map(|x| x as usize)
}

impl<T> Grid<T> {
    /// Cells of the grid (`nx · ny · nz`), `None` if that overflows.
    pub(crate) fn cell_count(&self) -> Option<usize> {
        widen(self.dims)
            .iter()
            .try_fold(1usize, |n, &d| n.checked_mul(d))
    }

    /// The linear index `i + nx (j + ny k)` of cell `c = [i, j, k]`.
    #[inline(always)]
    pub(crate) fn linear(&self, c: [u32; 3]) -> usize {
        let ([i, j, k], [nx, ny, _]) = (widen(c), widen(self.dims));
        i + nx * (j + ny * k)
    }

    /// The cell `[i, j, k]` of linear index `cell` (its inverse).
    fn coordinates(&self, cell: usize) -> [u32; 3] {
        let [nx, ny, _] = widen(self.dims);
        let (x, rest) = (cell.checked_rem(nx), cell.checked_div(nx));
        let (y, z) = (
            rest.and_then(|r| r.checked_rem(ny)),
            rest.and_then(|r| r.checked_div(ny)),
        );
        [x, y, z].map(|c| c.unwrap_or(0) as u32)
    }
}

impl<T: Real> Grid<T> {
    /// The same box in cells `k` times finer on every axis (edge
    /// `cell_m / k`), `None` for `k = 0` or cell counts past `u32`.
    pub fn subdivided(&self, k: u32) -> Option<Self> {
        let [x, y, z] = self.dims;
        let dims = [x.checked_mul(k)?, y.checked_mul(k)?, z.checked_mul(k)?];
        (k > 0).then(|| Self {
            origin_m: self.origin_m,
            cell_m: self.cell_m / T::of_u32(k),
            dims,
        })
    }

    /// The candidate lists' grid of `list_dims` cells per axis over this
    /// grid's box ([`super::format::SectionKind::GridDims`]): this grid
    /// [`Self::subdivided`] `k` times, `None` unless `list_dims` is `k`
    /// times its cells on every axis with `k` in
    /// `1..=`[`MAX_LIST_SUBDIVISION`]. The one rule of the loader and the
    /// host's writer.
    pub fn lists(&self, list_dims: [u32; 3]) -> Option<Self> {
        let k = list_dims[0].checked_div(self.dims[0])?;
        self.subdivided(k)
            .filter(|l| l.dims == list_dims && k <= MAX_LIST_SUBDIVISION)
    }

    /// The cell containing `p` (m), clamped to the grid (a point outside
    /// maps to the nearest border cell; non-finite coordinates map to 0).
    pub fn cell_of(&self, p: &Vector3<T>) -> [u32; 3] {
        let mut cell = [0u32; 3];
        for ((c, (&x, &o)), &d) in cell
            .iter_mut()
            .zip(p.iter().zip(self.origin_m.iter()))
            .zip(&self.dims)
        {
            // Truncation is the floor for the positive values it sees.
            let f = (x - o) / self.cell_m;
            let top = T::of_u32(d.saturating_sub(1));
            // NaN fails both comparisons and stays at 0.
            *c = if f > T::zero() {
                let clamped = if f < top { f } else { top };
                clamped.trunc_u32()
            } else {
                0
            };
        }
        cell
    }
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

/// A surface triangle's stored plane and barycentric frame (layout:
/// [`super::format::SectionKind::SurfacePlane`]).
pub type Plane<T> = [T; PLANE_LEN];

/// `true` if `starts` begins at 0, never decreases and ends at `total`.
fn csr_ok(starts: &[u32], total: usize) -> bool {
    starts.first() == Some(&0)
        && starts.windows(2).all(|w| w.first() <= w.get(1))
        && starts.last().map(|&x| x as usize) == Some(total)
}

/// The largest row of a CSR list.
pub fn max_row(starts: &[u32]) -> u32 {
    starts
        .windows(2)
        .map(|w| match w {
            [a, b] => b.saturating_sub(*a),
            _ => 0,
        })
        .max()
        .unwrap_or(0)
}

impl<'a, T: Real> SurfaceIndex<'a, T> {
    /// Validates the sections against the rest `positions` (m) and surface
    /// `triangles` of the table. Cost: linear in the index size.
    pub(crate) fn new(
        s: &SurfaceSections<'a, T>,
        positions: &[[T; 3]],
        triangles: &'a [[u32; 3]],
    ) -> Result<Self, LoadError> {
        let grid_error = |index: u32| LoadError::BadSurfaceGrid { index };
        let (Some(&[x, y, z, cell_m, radius_m]), Some(&dims), Some(&list_dims)) =
            (s.grid.first(), s.dims.first(), s.dims.get(1))
        else {
            return Err(grid_error(0));
        };
        let grid = Grid {
            origin_m: Vector3::new(x, y, z),
            cell_m,
            dims,
        };
        let lists = grid.lists(list_dims).ok_or(grid_error(0))?;
        let geometry_ok = [x, y, z, cell_m, radius_m].iter().all(|v| v.finite())
            && cell_m > T::zero()
            && radius_m >= T::zero()
            && candidate_margin_m(&grid, radius_m) <= cell_m;
        if !geometry_ok
            || dims.contains(&0)
            || grid.cell_count().and_then(|c| c.checked_add(1)) != Some(s.cell_start.len())
            || !csr_ok(s.cell_start, s.grid_vertex.len())
        {
            return Err(grid_error(0));
        }
        let index = Self {
            grid,
            lists,
            triangles,
            cell_start: s.cell_start,
            grid_vertex: s.grid_vertex,
            vertex_triangle_start: s.vertex_triangle_start,
            vertex_triangle: s.vertex_triangle,
            planes: s.planes,
            cell_triangle_start: s.cell_triangle_start,
            cell_triangle: s.cell_triangle,
            candidate_radius_m: Some(radius_m),
            max_bucket: max_row(s.cell_start),
            max_valence: max_row(s.vertex_triangle_start),
            max_query_triangles: 0,
            max_cell_triangles: max_row(s.cell_triangle_start),
        };
        // Every filed vertex exists and lies within one cell of its own.
        for (cell, bucket) in s.cell_start.windows(2).enumerate() {
            let [start, end] = bucket else { continue };
            let vertices = s.grid_vertex.get(span(*start, *end)).unwrap_or(&[]);
            for &v in vertices {
                let p = VertexIndex::new(v, positions.len())
                    .and_then(|v| positions.get(v.get()))
                    .ok_or(grid_error(v))?;
                let home = grid.cell_of(&Vector3::new(p[0], p[1], p[2]));
                let filed = grid.coordinates(cell);
                if home.iter().zip(filed).any(|(&a, b)| a.abs_diff(b) > 1) {
                    return Err(grid_error(v));
                }
            }
        }
        // Each vertex's triangles: in range, containing it, ascending.
        let n = positions.len();
        if s.vertex_triangle_start.len() != n + 1
            || !csr_ok(s.vertex_triangle_start, s.vertex_triangle.len())
        {
            return Err(LoadError::BadVertexTriangles { vertex: 0 });
        }
        for (v, row) in s.vertex_triangle_start.windows(2).enumerate() {
            let bad = LoadError::BadVertexTriangles { vertex: v as u32 };
            let [start, end] = row else { continue };
            let list = s.vertex_triangle.get(span(*start, *end)).ok_or(bad)?;
            if !list.windows(2).all(|w| w.first() < w.get(1)) {
                return Err(bad);
            }
            for &t in list {
                let tri = TriangleIndex::new(t, triangles.len())
                    .and_then(|t| triangles.get(t.get()))
                    .ok_or(bad)?;
                if !tri.contains(&(v as u32)) {
                    return Err(bad);
                }
            }
        }
        // Each plane: finite, unit normal, through the triangle's corners,
        // pointing along the corners' right-hand normal; its frame: the
        // gradients weigh the corners 1 and 0 (within the tolerance, in
        // units of the weights) and lie in the plane.
        let tolerance = T::of_f64(1e-4);
        for (t, (plane, tri)) in s.planes.iter().zip(triangles).enumerate() {
            let bad = LoadError::BadSurfacePlane { triangle: t as u32 };
            let (n, d, [g1, g2]) = parts_of(plane);
            let mut corners = [Vector3::zeros(); 3];
            for (c, &v) in corners.iter_mut().zip(tri) {
                let p = VertexIndex::new(v, positions.len())
                    .and_then(|v| positions.get(v.get()))
                    .ok_or(bad)?;
                *c = Vector3::new(p[0], p[1], p[2]);
            }
            let [a, b, c] = corners;
            let through = corners
                .iter()
                .all(|p| (n.dot(p) - d).abs() <= tolerance * cell_m);
            let unit = (n.norm_squared() - T::one()).abs() <= tolerance;
            let (e1, e2) = (b - a, c - a);
            let near = |x: T, want: T| (x - want).abs() <= tolerance;
            let frame = near(g1.dot(&e1), T::one())
                && near(g1.dot(&e2), T::zero())
                && near(g2.dot(&e1), T::zero())
                && near(g2.dot(&e2), T::one())
                && near(g1.dot(&n) * e1.norm(), T::zero())
                && near(g2.dot(&n) * e2.norm(), T::zero());
            if !(plane.iter().all(|x| x.finite())
                && unit
                && through
                && frame
                && n.dot(&e1.cross(&e2)) > T::zero())
            {
                return Err(bad);
            }
        }
        if s.planes.len() != triangles.len() {
            return Err(LoadError::BadSurfacePlane { triangle: 0 });
        }
        index.check_cell_triangles(positions)?;
        // The most triangles one query can visit: over every cell, the
        // triangles around the vertices of its 27-cell neighbourhood.
        let mut index = index;
        let [nx, ny, nz] = dims;
        let mut worst = 0u32;
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let centre = index.cell_centre([i, j, k]);
                    let mut count = 0u32;
                    index.for_each_vertex_near(&centre, |v| {
                        count = count.saturating_add(index.triangles_of(v).len() as u32);
                    });
                    worst = worst.max(count);
                }
            }
        }
        index.max_query_triangles = worst;
        Ok(index)
    }

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
            cell_triangle_start: &[],
            cell_triangle: &[],
            candidate_radius_m: None,
            max_bucket,
            max_valence,
            max_query_triangles,
            max_cell_triangles: 0,
        }
    }

    /// Checks the per-cell candidate lists: CSR over the lists' grid's cells, each
    /// list strictly ascending, and exactly the filings of
    /// [`candidate_cells`] for the declared radius (each listed triangle
    /// filed in its cell, and as many entries as filings: every triangle in
    /// each of its cells' lists). Cost: linear in the entries and the
    /// triangles.
    fn check_cell_triangles(&self, positions: &[[T; 3]]) -> Result<(), LoadError> {
        let bad = |cell: usize| LoadError::BadCellTriangles { cell: cell as u32 };
        let cells = self.lists.cell_count().unwrap_or(0);
        if self.cell_triangle_start.len() != cells + 1
            || !csr_ok(self.cell_triangle_start, self.cell_triangle.len())
        {
            return Err(bad(0));
        }
        for cell in 0..cells {
            let list = self.cell_triangles_at(cell);
            let in_range = list.iter().all(|&t| (t as usize) < self.triangles.len());
            if !in_range || !list.windows(2).all(|w| w.first() < w.get(1)) {
                return Err(bad(cell));
            }
        }
        let radius_m = self.candidate_radius_m.unwrap_or(T::zero());
        // Nothing else: each listed triangle is filed in its cell.
        for cell in 0..cells {
            let c = self.lists.coordinates(cell);
            for &t in self.cell_triangles_at(cell) {
                let corners = self
                    .triangles
                    .get(t as usize)
                    .and_then(|tri| corners_of(positions, tri))
                    .ok_or(bad(cell))?;
                let [lo, hi] = candidate_cells(&self.lists, &corners, radius_m);
                let filed = c
                    .iter()
                    .zip(lo.iter().zip(&hi))
                    .all(|(x, (l, h))| l <= x && x <= h);
                if !filed {
                    return Err(bad(cell));
                }
            }
        }
        // Everything: the lists hold as many entries as there are filings
        // (with the above, listed ⊆ filed and no entry twice in a list:
        // the same sets). Each triangle's count is the product of its
        // spans, so this is linear in the triangles whatever their size; a
        // total past the lists' names the first cell of the triangle that
        // passed it.
        let listed = self.cell_triangle.len() as u64;
        let mut filings = 0u64;
        for tri in self.triangles {
            let Some(corners) = corners_of(positions, tri) else {
                continue;
            };
            let [lo, hi] = candidate_cells(&self.lists, &corners, radius_m);
            let span = |axis: usize| {
                let (l, h) = (lo.get(axis).copied(), hi.get(axis).copied());
                u64::from(h.unwrap_or(0).saturating_sub(l.unwrap_or(0))) + 1
            };
            filings = filings.saturating_add(span(0) * span(1) * span(2));
            if filings > listed {
                return Err(bad(self.lists.linear(lo)));
            }
        }
        if filings == listed {
            Ok(())
        } else {
            Err(bad(0))
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
        [ax, ay, az]: [u32; 3],
        [bx, by, bz]: [u32; 3],
        mut f: impl FnMut(CandidateList<'a>),
    ) {
        let span = |p: u32, q: u32| (p.min(q), p.max(q));
        let ((x0, x1), (y0, y1), (z0, z1)) = (span(ax, bx), span(ay, by), span(az, bz));
        for k in z0..=z1 {
            for j in y0..=y1 {
                for i in x0..=x1 {
                    // Corner by corner: an array comparison is a `memcmp`
                    // call on the firmware target.
                    let at_b = i == bx && j == by && k == bz;
                    if !at_b {
                        f(self.candidates_at([i, j, k]));
                    }
                }
            }
        }
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

    /// Centre of cell `c`, m.
    fn cell_centre(&self, c: [u32; 3]) -> Vector3<T> {
        let half = T::of_f64(0.5);
        let at = |axis: usize| {
            let o = self.grid.origin_m.get(axis).copied().unwrap_or(T::zero());
            let i = c.get(axis).copied().unwrap_or(0);
            o + (T::of_f64(f64::from(i)) + half) * self.grid.cell_m
        };
        Vector3::new(at(0), at(1), at(2))
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

    /// The candidate lists' grid: the grid's box in cells `k` times finer
    /// ([`super::format::SectionKind::GridDims`]).
    pub fn list_grid(&self) -> &Grid<T> {
        &self.lists
    }

    /// The box within one cell edge plus `margin_m` (m) of the grid: its
    /// lowest and highest corners, m. A point farther out has no surface
    /// vertex within a cell.
    pub fn reach(&self, margin_m: T) -> [Vector3<T>; 2] {
        let Grid {
            origin_m,
            cell_m,
            dims,
        } = &self.grid;
        let margin = Vector3::repeat(*cell_m + margin_m);
        let extent = Vector3::from(dims.map(|d| *cell_m * T::of_f64(f64::from(d))));
        [origin_m - margin, origin_m + extent + margin]
    }

    /// Calls `f` with each surface vertex filed in the 27 cells around the
    /// cell of `p` (m), cell by cell (`x` fastest), each cell's in filing
    /// order. Bounded by `27 × max_bucket`. A row of up to three cells
    /// along `x` is one run of the filed list, so the visit is nine slices,
    /// in plain loops (an iterator of nested `flat_map`s keeps its state in
    /// memory, a store per step on the firmware target).
    #[inline]
    pub fn for_each_vertex_near(&self, p: &Vector3<T>, mut f: impl FnMut(VertexIndex)) {
        let [cx, cy, cz] = self.cell_of(p);
        let [nx, ny, nz] = self.grid.dims;
        let range = |c: u32, n: u32| (c.saturating_sub(1), (c + 1).min(n.saturating_sub(1)));
        let ((x0, x1), (y0, y1), (z0, z1)) = (range(cx, nx), range(cy, ny), range(cz, nz));
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

/// The unit normal, offset (m) and barycentric gradients `g₁`, `g₂` (1/m)
/// of a stored plane (layout: [`super::format::SectionKind::SurfacePlane`]).
#[inline(always)]
fn parts_of<T: Real>(plane: &Plane<T>) -> (Vector3<T>, T, [Vector3<T>; 2]) {
    let [nx, ny, nz, d, g1x, g1y, g1z, g2x, g2y, g2z] = *plane;
    (
        Vector3::new(nx, ny, nz),
        d,
        [Vector3::new(g1x, g1y, g1z), Vector3::new(g2x, g2y, g2z)],
    )
}

/// A stored plane of unit normal `normal`, offset `offset_m` (m) and
/// barycentric gradients `g` (1/m): the inverse of [`parts_of`].
pub(crate) fn plane_record<T: Real>(
    normal: &Vector3<T>,
    offset_m: T,
    g: &[Vector3<T>; 2],
) -> Plane<T> {
    let [g1, g2] = g;
    [
        normal.x, normal.y, normal.z, offset_m, g1.x, g1.y, g1.z, g2.x, g2.y, g2.z,
    ]
}

/// The corners (m) of triangle `tri` over `positions`, `None` for a corner
/// beyond them.
pub(crate) fn corners_of<T: Real>(positions: &[[T; 3]], tri: &[u32; 3]) -> Option<[Vector3<T>; 3]> {
    let at = |v: u32| {
        positions
            .get(v as usize)
            .map(|p| Vector3::new(p[0], p[1], p[2]))
    };
    let [a, b, c] = tri.map(at);
    Some([a?, b?, c?])
}

/// How far from a triangle's plane, on either side, in tool radii, the
/// per-cell candidate lists reach ([`candidate_cells`]): the contact test's
/// depth (`contact::PENETRATION_DEPTH_RADII`, 2: the penetration test takes
/// a plane up to that far behind the centre, the check of the planes it
/// does not reach up to that far in front, each with the centre over its
/// triangle; the contact layer asserts it fits) plus a quarter radius of
/// slack; the sweep's hit lies one radius in front.
pub const CANDIDATE_MARGIN_RADII: f64 = 2.25;

/// The part of a list cell's edge the candidate lists add on every axis
/// ([`candidate_cells`]): the weight tolerance's reach past a triangle's
/// edges (`WEIGHT_TOLERANCE` of an edge, a grid cell at most, on both
/// weights of an edge: 2e-5 of a grid cell in f32), the loader's tolerance
/// on a stored frame (1e-4 in units of the weights: 1e-4 of a grid cell)
/// and the normal's rounding, with a margin: at least 2.5e-4 of a grid
/// cell, whose list cells are at most
/// [`super::format::MAX_LIST_SUBDIVISION`] times finer.
pub const CANDIDATE_MARGIN_CELLS: f64 = 1e-3;

/// The widest margin (m) by which candidate lists over `grid` (or a finer
/// lists' grid of its box) widen a triangle's bounding box on an axis, for
/// a tool of radius up to `radius_m`: [`CANDIDATE_MARGIN_RADII`] radii (on
/// an axis along the triangle's normal) and [`CANDIDATE_MARGIN_CELLS`] of a
/// cell of `grid`.
pub fn candidate_margin_m<T: Real>(grid: &Grid<T>, radius_m: T) -> T {
    radius_m * T::of_f64(CANDIDATE_MARGIN_RADII) + grid.cell_m * T::of_f64(CANDIDATE_MARGIN_CELLS)
}

/// The tool radius (m) a table's candidate lists serve when asked for
/// `tool_radius_m`: at most the cell edge over [`CANDIDATE_MARGIN_RADII`],
/// so that a triangle's widened box spans at most `k + 3` cells of the
/// lists' grid per axis (its box is at most an edge, at most a grid cell,
/// wide; [`candidate_margin_m`] at most a grid cell): at most `(k + 3)³`
/// lists per triangle. Negative or non-finite asks give 0.
pub fn candidate_radius_m<T: Real>(grid: &Grid<T>, tool_radius_m: T) -> T {
    let most = grid.cell_m * T::of_f64((1.0 - CANDIDATE_MARGIN_CELLS) / CANDIDATE_MARGIN_RADII);
    if tool_radius_m > T::zero() {
        if tool_radius_m < most {
            tool_radius_m
        } else {
            most
        }
    } else {
        T::zero()
    }
}

/// The subdivision `k` of the candidate lists' grid a builder chooses for
/// `grid` and tools of radius up to `radius_m` (m): list cells no finer than
/// the lists' depth, [`CANDIDATE_MARGIN_RADII`] radii (a face's prism spans
/// at most three of them across), in `1..=`[`MAX_LIST_SUBDIVISION`]. Finer
/// cells hold fewer triangles each, in more lists.
pub fn list_subdivision<T: Real>(grid: &Grid<T>, radius_m: T) -> u32 {
    let depth_m = radius_m * T::of_f64(CANDIDATE_MARGIN_RADII);
    (1..MAX_LIST_SUBDIVISION)
        .rev()
        .map(|k| k + 1)
        .find(|&k| T::of_u32(k) * depth_m <= grid.cell_m)
        .unwrap_or(1)
}

/// The cells (lowest and highest, per axis, clamped to the grid as a query
/// point is) whose candidate lists hold the triangle of `corners_m` (m)
/// for a tool of radius up to `radius_m` (m): the one rule of the lists'
/// builder (`contact::grid::cell_triangles`) and of the loader's check.
///
/// The contact tests accept a triangle only from a sphere centre whose
/// projection on its plane falls in it (within the weight tolerance) and
/// that lies at most [`CANDIDATE_MARGIN_RADII`] radii from the plane (the
/// sweep's hit, one radius in front; the penetration test, two behind; the
/// check of the planes it does not reach, two in front): the triangle's
/// prism along its unit normal `n`, on both sides. Its box is the
/// triangle's, widened on axis `i` by `2.25 r |n_i|`, and by
/// [`CANDIDATE_MARGIN_CELLS`] of a cell of `grid` (the lists' grid) on
/// every axis. A face along the
/// grid's axes is widened in its plane by that slack alone, so a cell's
/// list holds the triangles over or under the cell, not all within reach
/// around it. A collapsed triangle (no normal), which no test accepts, is
/// widened by the whole margin on every axis. Clamping is monotone, so
/// the cell of any centre in the prism is in the range.
pub fn candidate_cells<T: Real>(
    grid: &Grid<T>,
    corners_m: &[Vector3<T>; 3],
    radius_m: T,
) -> [[u32; 3]; 2] {
    let [a, b, c] = corners_m;
    let normal = (b - a).cross(&(c - a));
    let length = normal.norm();
    let depth_m = radius_m * T::of_f64(CANDIDATE_MARGIN_RADII);
    let slack_m = grid.cell_m * T::of_f64(CANDIDATE_MARGIN_CELLS);
    let reach = normal.map(|x| {
        let along = if length > T::zero() {
            (x / length).abs()
        } else {
            T::one()
        };
        along * depth_m + slack_m
    });
    let lo = a.inf(b).inf(c) - reach;
    let hi = a.sup(b).sup(c) + reach;
    [grid.cell_of(&lo), grid.cell_of(&hi)]
}

/// `f(cell, t)` for every cell of every triangle `t`'s
/// [`candidate_cells`], triangles in order, cells `x` fastest (a triangle
/// with a corner beyond `positions_m`, a dead slot, is not filed).
pub(crate) fn for_each_candidate_filing<T: Real>(
    grid: &Grid<T>,
    positions_m: &[[T; 3]],
    triangles: &[[u32; 3]],
    radius_m: T,
    mut f: impl FnMut(usize, u32),
) {
    for (t, tri) in triangles.iter().enumerate() {
        let Some(corners) = corners_of(positions_m, tri) else {
            continue;
        };
        let [[x0, y0, z0], [x1, y1, z1]] = candidate_cells(grid, &corners, radius_m);
        for k in z0..=z1 {
            for j in y0..=y1 {
                for i in x0..=x1 {
                    f(grid.linear([i, j, k]), t as u32);
                }
            }
        }
    }
}
