//! The collision index (Cotin 1999 §4, collision buckets; MODELS.md §6):
//! the boundary-surface vertices filed in a regular grid over their bounding
//! box, and the surface triangles around each vertex. The sections of a
//! pre-computed table are built offline (`palpate tables build`, with
//! [`crate::contact::grid`]) and validated once by [`SurfaceIndex::new`]
//! (called from `PrecomputedTable::load`); a deforming surface's index is
//! assembled from lists the kernel built itself. Both are then
//! queried in bounded time: a query visits the 27 cells around a point,
//! each holding at most [`SurfaceIndex::max_bucket`] vertices, each with at
//! most [`SurfaceIndex::max_valence`] triangles.

use nalgebra::Vector3;

use super::LoadError;
use crate::Real;

/// The validated collision index (a view into the table).
#[derive(Clone, Copy, Debug)]
pub struct SurfaceIndex<'a, T> {
    origin_m: Vector3<T>,
    cell_m: T,
    dims: [u32; 3],
    cell_start: &'a [u32],
    grid_vertex: &'a [u32],
    vertex_triangle_start: &'a [u32],
    vertex_triangle: &'a [u32],
    planes: &'a [[T; 4]],
    max_bucket: u32,
    max_valence: u32,
    max_query_triangles: u32,
}

/// The raw sections of a collision index, before validation.
pub(crate) struct SurfaceSections<'a, T> {
    pub(crate) grid: &'a [[T; 4]],
    pub(crate) dims: &'a [[u32; 3]],
    pub(crate) cell_start: &'a [u32],
    pub(crate) grid_vertex: &'a [u32],
    pub(crate) vertex_triangle_start: &'a [u32],
    pub(crate) vertex_triangle: &'a [u32],
    pub(crate) planes: &'a [[T; 4]],
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

impl<T: Real> Grid<T> {
    /// The cell containing `p` (m), clamped to the grid (a point outside
    /// maps to the nearest border cell; non-finite coordinates map to 0).
    pub fn cell_of(&self, p: &Vector3<T>) -> [u32; 3] {
        let mut cell = [0u32; 3];
        for ((c, (&x, &o)), &d) in cell
            .iter_mut()
            .zip(p.iter().zip(self.origin_m.iter()))
            .zip(&self.dims)
        {
            let f = ((x - o) / self.cell_m).floor();
            let top = T::of_f64(f64::from(d.saturating_sub(1)));
            // NaN fails both comparisons and stays at 0.
            *c = if f > T::zero() {
                let clamped = if f < top { f } else { top };
                clamped.as_f64() as u32
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
    pub(crate) cell_start: &'a [u32],
    pub(crate) grid_vertex: &'a [u32],
    pub(crate) vertex_triangle_start: &'a [u32],
    pub(crate) vertex_triangle: &'a [u32],
    pub(crate) planes: &'a [[T; 4]],
    /// The largest row of `cell_start` and of `vertex_triangle_start`.
    pub(crate) max_bucket: u32,
    pub(crate) max_valence: u32,
}

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
        triangles: &[[u32; 3]],
    ) -> Result<Self, LoadError> {
        let grid_error = |index: usize| LoadError::BadSurfaceGrid {
            index: index as u32,
        };
        let (Some(&[x, y, z, cell_m]), Some(&dims)) = (s.grid.first(), s.dims.first()) else {
            return Err(grid_error(0));
        };
        let cells = dims
            .iter()
            .try_fold(1usize, |n, &d| n.checked_mul(d as usize));
        let geometry_ok = [x, y, z, cell_m].iter().all(|v| v.finite()) && cell_m > T::zero();
        if !geometry_ok
            || dims.contains(&0)
            || cells.and_then(|c| c.checked_add(1)) != Some(s.cell_start.len())
            || !csr_ok(s.cell_start, s.grid_vertex.len())
        {
            return Err(grid_error(0));
        }
        let index = Self {
            origin_m: Vector3::new(x, y, z),
            cell_m,
            dims,
            cell_start: s.cell_start,
            grid_vertex: s.grid_vertex,
            vertex_triangle_start: s.vertex_triangle_start,
            vertex_triangle: s.vertex_triangle,
            planes: s.planes,
            max_bucket: max_row(s.cell_start),
            max_valence: max_row(s.vertex_triangle_start),
            max_query_triangles: 0,
        };
        // Every filed vertex exists and lies within one cell of its own.
        for (cell, bucket) in s.cell_start.windows(2).enumerate() {
            let [start, end] = bucket else { continue };
            let vertices = s
                .grid_vertex
                .get(*start as usize..*end as usize)
                .unwrap_or(&[]);
            for &v in vertices {
                let p = positions.get(v as usize).ok_or(grid_error(v as usize))?;
                let home = index.cell_of(&Vector3::new(p[0], p[1], p[2]));
                let filed = index.coordinates(cell);
                if home.iter().zip(filed).any(|(&a, b)| a.abs_diff(b) > 1) {
                    return Err(grid_error(v as usize));
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
            let list = s
                .vertex_triangle
                .get(*start as usize..*end as usize)
                .ok_or(bad)?;
            if !list.windows(2).all(|w| w.first() < w.get(1)) {
                return Err(bad);
            }
            for &t in list {
                let tri = triangles.get(t as usize).ok_or(bad)?;
                if !tri.contains(&(v as u32)) {
                    return Err(bad);
                }
            }
        }
        // Each plane: finite, unit normal, through the triangle's corners,
        // pointing along the corners' right-hand normal.
        let tolerance = T::of_f64(1e-4);
        for (t, (plane, tri)) in s.planes.iter().zip(triangles).enumerate() {
            let bad = LoadError::BadSurfacePlane { triangle: t as u32 };
            let [nx, ny, nz, d] = *plane;
            let n = Vector3::new(nx, ny, nz);
            let mut corners = [Vector3::zeros(); 3];
            for (c, &v) in corners.iter_mut().zip(tri) {
                let p = positions.get(v as usize).ok_or(bad)?;
                *c = Vector3::new(p[0], p[1], p[2]);
            }
            let [a, b, c] = corners;
            let through = corners
                .iter()
                .all(|p| (n.dot(p) - d).abs() <= tolerance * cell_m);
            let unit = (n.norm_squared() - T::one()).abs() <= tolerance;
            if !(plane.iter().all(|x| x.finite())
                && unit
                && through
                && n.dot(&(b - a).cross(&(c - a))) > T::zero())
            {
                return Err(bad);
            }
        }
        if s.planes.len() != triangles.len() {
            return Err(LoadError::BadSurfacePlane { triangle: 0 });
        }
        // The most triangles one query can visit: over every cell, the
        // triangles around the vertices of its 27-cell neighbourhood.
        let mut index = index;
        let [nx, ny, nz] = dims;
        let mut worst = 0u32;
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let centre = index.cell_centre([i, j, k]);
                    let count = index
                        .vertices_near(&centre)
                        .map(|v| index.triangles_of(v).len() as u32)
                        .fold(0u32, u32::saturating_add);
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
            origin_m: grid.origin_m,
            cell_m: grid.cell_m,
            dims: grid.dims,
            cell_start: lists.cell_start,
            grid_vertex: lists.grid_vertex,
            vertex_triangle_start: lists.vertex_triangle_start,
            vertex_triangle: lists.vertex_triangle,
            planes: lists.planes,
            max_bucket,
            max_valence,
            max_query_triangles,
        }
    }

    /// Centre of cell `c`, m.
    fn cell_centre(&self, c: [u32; 3]) -> Vector3<T> {
        let half = T::of_f64(0.5);
        let at = |axis: usize| {
            let o = self.origin_m.get(axis).copied().unwrap_or(T::zero());
            let i = c.get(axis).copied().unwrap_or(0);
            o + (T::of_f64(f64::from(i)) + half) * self.cell_m
        };
        Vector3::new(at(0), at(1), at(2))
    }

    /// The most candidate triangles one point query
    /// ([`Self::vertices_near`] then [`Self::triangles_of`]) visits, over
    /// every cell of the grid (computed at load: the exact table-declared
    /// bound of a detection's work, per query point).
    pub fn max_query_triangles(&self) -> u32 {
        self.max_query_triangles
    }

    /// Grid origin, m.
    pub fn origin_m(&self) -> Vector3<T> {
        self.origin_m
    }

    /// Grid cell edge, m.
    pub fn cell_m(&self) -> T {
        self.cell_m
    }

    /// Cells per axis.
    pub fn dims(&self) -> [u32; 3] {
        self.dims
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
        Grid {
            origin_m: self.origin_m,
            cell_m: self.cell_m,
            dims: self.dims,
        }
        .cell_of(p)
    }

    /// `true` if `p` (m) lies within one cell edge plus `margin_m` of the
    /// grid's box (a point farther out has no surface vertex within a cell).
    pub fn is_near(&self, p: &Vector3<T>, margin_m: T) -> bool {
        let reach = self.cell_m + margin_m;
        p.iter()
            .zip(self.origin_m.iter())
            .zip(&self.dims)
            .all(|((&x, &o), &d)| {
                let extent = self.cell_m * T::of_f64(f64::from(d));
                x >= o - reach && x <= o + extent + reach
            })
    }

    fn coordinates(&self, cell: usize) -> [u32; 3] {
        let [nx, ny, _] = self.dims.map(|d| d as usize);
        let (x, rest) = (cell.checked_rem(nx), cell.checked_div(nx));
        let (y, z) = (
            rest.and_then(|r| r.checked_rem(ny)),
            rest.and_then(|r| r.checked_div(ny)),
        );
        [x, y, z].map(|c| c.unwrap_or(0) as u32)
    }

    /// The surface vertices filed in the 27 cells around the cell of `p`
    /// (m). Bounded by `27 × max_bucket`.
    pub fn vertices_near(&self, p: &Vector3<T>) -> impl Iterator<Item = u32> + '_ {
        let [cx, cy, cz] = self.cell_of(p);
        let [nx, ny, nz] = self.dims;
        let range = |c: u32, n: u32| c.saturating_sub(1)..=(c + 1).min(n.saturating_sub(1));
        range(cz, nz).flat_map(move |k| {
            range(cy, ny).flat_map(move |j| {
                range(cx, nx).flat_map(move |i| {
                    let cell = i as usize + nx as usize * (j as usize + ny as usize * k as usize);
                    let start = self.cell_start.get(cell).copied().unwrap_or(0) as usize;
                    let end = self.cell_start.get(cell + 1).copied().unwrap_or(0) as usize;
                    self.grid_vertex
                        .get(start..end)
                        .unwrap_or(&[])
                        .iter()
                        .copied()
                })
            })
        })
    }

    /// The stored plane of surface triangle `t`: unit outward normal and
    /// offset `n·p` (m).
    pub fn plane(&self, t: u32) -> Option<(Vector3<T>, T)> {
        let [x, y, z, d] = *self.planes.get(t as usize)?;
        Some((Vector3::new(x, y, z), d))
    }

    /// The surface triangles around `vertex` (indices into the table's
    /// surface triangles), ascending. Bounded by `max_valence`.
    pub fn triangles_of(&self, vertex: u32) -> &'a [u32] {
        let v = vertex as usize;
        let start = self.vertex_triangle_start.get(v).copied().unwrap_or(0) as usize;
        let end = self.vertex_triangle_start.get(v + 1).copied().unwrap_or(0) as usize;
        self.vertex_triangle.get(start..end).unwrap_or(&[])
    }
}
