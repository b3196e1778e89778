//! The collision index of a pre-computed table validated once at load
//! ([`SurfaceIndex::new`], called from `PrecomputedTable::load`), stage by
//! stage: the grid record, the filed vertices, each vertex's triangles,
//! the planes, the candidate lists; then the most triangles one query
//! visits. Cost: linear in the index size.

use nalgebra::Vector3;

use super::{SurfaceIndex, SurfaceSections};
use crate::Real;
use crate::table::LoadError;
use crate::table::candidates::{candidate_cells, candidate_margin_m, corners_of};
use crate::table::grid::{Grid, box_of, neighbours};
use crate::table::index::{TriangleIndex, VertexIndex, csr_ok, max_row, span};
use crate::table::plane::parts_of;

impl<'a, T: Real> SurfaceIndex<'a, T> {
    /// Validates the sections against the rest `positions` (m) and surface
    /// `triangles` of the table. Cost: linear in the index size.
    pub(crate) fn new(
        s: &SurfaceSections<'a, T>,
        positions: &[[T; 3]],
        triangles: &'a [[u32; 3]],
    ) -> Result<Self, LoadError> {
        let (grid, lists, radius_m) = grid_record(s)?;
        let mut index = Self {
            grid,
            lists,
            triangles,
            cell_start: s.cell_start,
            grid_vertex: s.grid_vertex,
            vertex_triangle_start: s.vertex_triangle_start,
            vertex_triangle: s.vertex_triangle,
            planes: s.planes,
            surface_box_m: surface_box(positions, triangles),
            cell_triangle_start: s.cell_triangle_start,
            cell_triangle: s.cell_triangle,
            candidate_radius_m: Some(radius_m),
            max_bucket: max_row(s.cell_start),
            max_valence: max_row(s.vertex_triangle_start),
            max_query_triangles: 0,
            max_cell_triangles: max_row(s.cell_triangle_start),
        };
        index.check_filed_vertices(positions)?;
        index.check_vertex_triangles(positions.len())?;
        index.check_planes(positions)?;
        index.check_cell_triangles(positions)?;
        index.max_query_triangles = index.worst_query();
        Ok(index)
    }

    /// Every filed vertex exists and lies within one cell of its own.
    fn check_filed_vertices(&self, positions: &[[T; 3]]) -> Result<(), LoadError> {
        let grid_error = |index: u32| LoadError::BadSurfaceGrid { index };
        for (cell, bucket) in self.cell_start.windows(2).enumerate() {
            let [start, end] = bucket else { continue };
            let vertices = self.grid_vertex.get(span(*start, *end)).unwrap_or(&[]);
            for &v in vertices {
                let p = VertexIndex::new(v, positions.len())
                    .and_then(|v| positions.get(v.get()))
                    .ok_or(grid_error(v))?;
                let home = self.grid.cell_of(&Vector3::new(p[0], p[1], p[2]));
                if !neighbours(home, self.grid.coordinates(cell)) {
                    return Err(grid_error(v));
                }
            }
        }
        Ok(())
    }

    /// Each of the `n` vertices' triangles: in range, containing it,
    /// ascending.
    fn check_vertex_triangles(&self, n: usize) -> Result<(), LoadError> {
        if self.vertex_triangle_start.len() != n + 1
            || !csr_ok(self.vertex_triangle_start, self.vertex_triangle.len())
        {
            return Err(LoadError::BadVertexTriangles { vertex: 0 });
        }
        for (v, row) in self.vertex_triangle_start.windows(2).enumerate() {
            let bad = LoadError::BadVertexTriangles { vertex: v as u32 };
            let [start, end] = row else { continue };
            let list = self.vertex_triangle.get(span(*start, *end)).ok_or(bad)?;
            if !list.windows(2).all(|w| w.first() < w.get(1)) {
                return Err(bad);
            }
            for &t in list {
                let tri = TriangleIndex::new(t, self.triangles.len())
                    .and_then(|t| self.triangles.get(t.get()))
                    .ok_or(bad)?;
                if !tri.contains(&(v as u32)) {
                    return Err(bad);
                }
            }
        }
        Ok(())
    }

    /// Each plane: finite, unit normal, through the triangle's corners,
    /// pointing along the corners' right-hand normal; its frame: the
    /// gradients weigh the corners 1 and 0 (within the tolerance, in units
    /// of the weights) and lie in the plane. One plane per triangle.
    fn check_planes(&self, positions: &[[T; 3]]) -> Result<(), LoadError> {
        let tolerance = T::of_f64(1e-4);
        let cell_m = self.grid.cell_m;
        for (t, (plane, tri)) in self.planes.iter().zip(self.triangles).enumerate() {
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
        if self.planes.len() != self.triangles.len() {
            return Err(LoadError::BadSurfacePlane { triangle: 0 });
        }
        Ok(())
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
                if !candidate_cells(&self.lists, &corners, radius_m).contains(c) {
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
            let cells = candidate_cells(&self.lists, &corners, radius_m);
            filings = filings.saturating_add(cells.count());
            if filings > listed {
                return Err(bad(self.lists.linear(cells.lo)));
            }
        }
        if filings == listed {
            Ok(())
        } else {
            Err(bad(0))
        }
    }

    /// The most triangles one query can visit: over every cell, the
    /// triangles around the vertices of its 27-cell neighbourhood.
    fn worst_query(&self) -> u32 {
        let mut worst = 0u32;
        self.grid.all().for_each(|c| {
            let centre = self.grid.centre(c);
            let mut count = 0u32;
            self.for_each_vertex_near(&centre, |v| {
                count = count.saturating_add(self.triangles_of(v).len() as u32);
            });
            worst = worst.max(count);
        });
        worst
    }
}

/// The grid record and dimensions of `s`: the grid, the candidate lists'
/// grid, and the tool radius (m) the lists serve. Finite, a positive cell
/// edge, a radius `≥ 0` whose candidate margin is at most a cell, no empty
/// axis, and a cell-start list over the grid's cells.
fn grid_record<T: Real>(s: &SurfaceSections<'_, T>) -> Result<(Grid<T>, Grid<T>, T), LoadError> {
    let grid_error = LoadError::BadSurfaceGrid { index: 0 };
    let (Some(&[x, y, z, cell_m, radius_m]), Some(&dims), Some(&list_dims)) =
        (s.grid.first(), s.dims.first(), s.dims.get(1))
    else {
        return Err(grid_error);
    };
    let grid = Grid {
        origin_m: Vector3::new(x, y, z),
        cell_m,
        dims,
    };
    let lists = grid.lists(list_dims).ok_or(grid_error)?;
    let geometry_ok = [x, y, z, cell_m, radius_m].iter().all(|v| v.finite())
        && cell_m > T::zero()
        && radius_m >= T::zero()
        && candidate_margin_m(&grid, radius_m) <= cell_m;
    if !geometry_ok
        || dims.contains(&0)
        || grid.cell_count().and_then(|c| c.checked_add(1)) != Some(s.cell_start.len())
        || !csr_ok(s.cell_start, s.grid_vertex.len())
    {
        return Err(grid_error);
    }
    Ok((grid, lists, radius_m))
}

/// The box of the corners of `triangles` over `positions` (m); a corner out
/// of range (refused by the triangles' own check) is left out.
fn surface_box<T: Real>(positions: &[[T; 3]], triangles: &[[u32; 3]]) -> [Vector3<T>; 2] {
    box_of(
        triangles
            .iter()
            .flatten()
            .filter_map(|&v| positions.get(v as usize))
            .map(|p| Vector3::new(p[0], p[1], p[2])),
    )
}
