//! The collision surface of a deforming (dynamic tensor-mass) tissue: the
//! table's boundary triangles at the current vertex positions, re-binned
//! into a fresh bucket grid at every physics update (Cotin 1999 §4: "the
//! bucket data structure must be updated" for a deformed mesh; MODELS.md
//! §6).
//!
//! Bounded re-binning: [`DeformingSurface::rebin`] is four passes over the
//! `N` vertices (positions, bounding box, the two counting-sort passes),
//! one over the `T` surface triangles and two over the `C` grid cells of
//! the caller's buffer; the
//! cell edge is the longest current surface edge (so the 27 cells around a
//! point hold every vertex of a triangle under it, as in the table-built
//! index), enlarged by doubling (at most [`MAX_CELL_DOUBLINGS`] times) until
//! the grid fits the `C` cells.

use core::fmt;

use nalgebra::Vector3;

use super::contact::{Supports, SurfaceGeometry};
use super::surface::{BuiltLists, Grid, SurfaceIndex, max_row};
use crate::Real;
use crate::tensor_mass::TensorMassModel;

/// Largest number of cell-edge doublings of one re-bin; a grid still too
/// large after them (a non-physical state) becomes a single cell.
pub const MAX_CELL_DOUBLINGS: u32 = 64;

/// The caller's buffers of a deforming surface (static arrays on
/// firmware). Lengths for a table of `N` vertices and `T` surface
/// triangles: see each field; [`SurfaceBuffers::lengths`] computes them.
pub struct SurfaceBuffers<'s, T> {
    /// Current position of every vertex, m: `N`.
    pub positions_m: &'s mut [[T; 3]],
    /// Plane of every surface triangle (unit outward normal, offset `n·p`
    /// in m): `T`.
    pub planes: &'s mut [[T; 4]],
    /// Start of each vertex's triangle list: `N + 1`.
    pub vertex_triangle_start: &'s mut [u32],
    /// The triangles around each vertex, ascending: `3 T`.
    pub vertex_triangle: &'s mut [u32],
    /// Start of each grid cell's vertex list: the grid's capacity in cells
    /// plus one, at least 2 (more cells: fewer vertices per bucket).
    pub cell_start: &'s mut [u32],
    /// Surface vertices filed by cell: `N`.
    pub grid_vertex: &'s mut [u32],
}

/// Buffer lengths a table needs (see [`SurfaceBuffers`]), with the given
/// grid capacity.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SurfaceLengths {
    /// `positions_m` and `grid_vertex`.
    pub vertices: usize,
    /// `planes`.
    pub triangles: usize,
    /// `vertex_triangle_start`.
    pub vertex_triangle_start: usize,
    /// `vertex_triangle`.
    pub vertex_triangle: usize,
    /// `cell_start`.
    pub cell_start: usize,
}

impl<T> SurfaceBuffers<'_, T> {
    /// The lengths for `model`'s table with room for `cells` grid cells.
    pub fn lengths<R: Real>(model: &TensorMassModel<'_, '_, R>, cells: usize) -> SurfaceLengths {
        let n = model.table().vertex_count();
        let t = model.table().surface_triangles().len();
        SurfaceLengths {
            vertices: n,
            triangles: t,
            vertex_triangle_start: n + 1,
            vertex_triangle: 3 * t,
            cell_start: cells.max(1) + 1,
        }
    }
}

/// A buffer of the wrong length.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SurfaceBufferError {
    /// The field of [`SurfaceBuffers`].
    pub buffer: &'static str,
    /// The length it needs (the least, for `cell_start`).
    pub expected: usize,
    /// The length it has.
    pub found: usize,
}

impl fmt::Display for SurfaceBufferError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "surface buffer {}: length {}, expected {}",
            self.buffer, self.found, self.expected
        )
    }
}

impl core::error::Error for SurfaceBufferError {}

/// A re-bin found a non-finite vertex position (the model diverged).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NonFinitePosition {
    /// The vertex.
    pub vertex: u32,
}

impl fmt::Display for NonFinitePosition {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "vertex {}: non-finite position", self.vertex)
    }
}

impl core::error::Error for NonFinitePosition {}

/// The deforming surface: the table's surface triangles at the positions
/// of the last [`Self::rebin`].
pub struct DeformingSurface<'a, 's, T: Real> {
    rest_m: &'a [[T; 3]],
    triangles: &'a [[u32; 3]],
    buffers: SurfaceBuffers<'s, T>,
    grid: Grid<T>,
    /// Cells of the current grid.
    cells: usize,
    /// Surface vertices filed (the used prefix of `grid_vertex`).
    filed: usize,
    /// Most vertices in one cell of the current grid; most triangles
    /// around one vertex.
    max_bucket: u32,
    max_valence: u32,
}

impl<'a, 's, T: Real> DeformingSurface<'a, 's, T> {
    /// Checks the buffer lengths against `model`'s table, builds the
    /// vertex-to-triangle lists (once: the table's surface does not change)
    /// and bins the surface at `model`'s current displacements.
    pub fn new(
        model: &TensorMassModel<'a, '_, T>,
        buffers: SurfaceBuffers<'s, T>,
    ) -> Result<Self, SurfaceBufferError> {
        let need = SurfaceBuffers::<T>::lengths(model, 1);
        let checks = [
            ("positions_m", need.vertices, buffers.positions_m.len()),
            ("planes", need.triangles, buffers.planes.len()),
            (
                "vertex_triangle_start",
                need.vertex_triangle_start,
                buffers.vertex_triangle_start.len(),
            ),
            (
                "vertex_triangle",
                need.vertex_triangle,
                buffers.vertex_triangle.len(),
            ),
            ("grid_vertex", need.vertices, buffers.grid_vertex.len()),
        ];
        if let Some(&(buffer, expected, found)) = checks.iter().find(|(_, e, f)| e != f) {
            return Err(SurfaceBufferError {
                buffer,
                expected,
                found,
            });
        }
        if buffers.cell_start.len() < need.cell_start {
            return Err(SurfaceBufferError {
                buffer: "cell_start",
                expected: need.cell_start,
                found: buffers.cell_start.len(),
            });
        }
        let table = model.table();
        let mut surface = Self {
            rest_m: table.rest_positions(),
            triangles: table.surface_triangles(),
            buffers,
            grid: Grid {
                origin_m: Vector3::zeros(),
                cell_m: T::one(),
                dims: [1; 3],
            },
            cells: 1,
            filed: 0,
            max_bucket: 0,
            max_valence: 0,
        };
        surface.build_vertex_triangles();
        surface.max_valence = max_row(surface.buffers.vertex_triangle_start);
        // The rest state is finite (validated table), so this bins.
        let displacement = model.displacements_m().unwrap_or(&[]);
        surface
            .rebin(displacement)
            .map_err(|_| SurfaceBufferError {
                buffer: "positions_m",
                expected: need.vertices,
                found: 0,
            })?;
        Ok(surface)
    }

    /// Each vertex's surface triangles, ascending (a counting sort over the
    /// triangles, which visits them in order).
    fn build_vertex_triangles(&mut self) {
        let start = &mut *self.buffers.vertex_triangle_start;
        start.fill(0);
        for tri in self.triangles {
            for &v in tri {
                if let Some(s) = start.get_mut(v as usize + 1) {
                    *s += 1;
                }
            }
        }
        prefix_sum(start);
        // `start[v]` is the cursor of vertex v while filling; it ends at the
        // start of v + 1, then everything shifts back by one.
        for (t, tri) in self.triangles.iter().enumerate() {
            for &v in tri {
                let Some(cursor) = start.get_mut(v as usize) else {
                    continue;
                };
                if let Some(slot) = self.buffers.vertex_triangle.get_mut(*cursor as usize) {
                    *slot = t as u32;
                }
                *cursor += 1;
            }
        }
        shift_back(start);
    }

    /// Moves the surface to `rest + displacement_m` (m; one entry per
    /// vertex, a shorter slice leaves the rest at rest): positions, planes
    /// and a new bucket grid. Bounded (see the module docs). A non-finite
    /// position is refused and leaves the grid as it was.
    pub fn rebin(&mut self, displacement_m: &[[T; 3]]) -> Result<(), NonFinitePosition> {
        let zero = [T::zero(); 3];
        for (v, (x, rest)) in self
            .buffers
            .positions_m
            .iter_mut()
            .zip(self.rest_m)
            .enumerate()
        {
            let u = displacement_m.get(v).unwrap_or(&zero);
            *x = [rest[0] + u[0], rest[1] + u[1], rest[2] + u[2]];
            if !x.iter().all(|c| c.finite()) {
                return Err(NonFinitePosition { vertex: v as u32 });
            }
        }
        let longest_m = self.update_planes();
        self.grid = self.fitted_grid(longest_m);
        self.file_vertices();
        Ok(())
    }

    /// Recomputes every triangle's plane; returns the longest edge, m.
    fn update_planes(&mut self) -> T {
        let positions = &*self.buffers.positions_m;
        let at = |v: u32| {
            positions
                .get(v as usize)
                .map_or(Vector3::zeros(), |p| Vector3::new(p[0], p[1], p[2]))
        };
        let mut longest2 = T::zero();
        for (plane, tri) in self.buffers.planes.iter_mut().zip(self.triangles) {
            let [a, b, c] = tri.map(at);
            for e in [b - a, c - b, a - c] {
                longest2 = longest2.max(e.norm_squared());
            }
            let n = (b - a).cross(&(c - a));
            let length = n.norm();
            // A collapsed triangle gets a zero normal: never touched.
            *plane = if length > T::zero() {
                let n = n / length;
                [n.x, n.y, n.z, n.dot(&a)]
            } else {
                [T::zero(); 4]
            };
        }
        longest2.sqrt()
    }

    /// The grid over the surface vertices' box with cells of at least
    /// `longest_m`, within the cell capacity.
    fn fitted_grid(&self, longest_m: T) -> Grid<T> {
        let starts = &*self.buffers.vertex_triangle_start;
        let mut lo = Vector3::repeat(T::of_f64(f64::MAX));
        let mut hi = -lo;
        let mut any = false;
        for (v, p) in self.buffers.positions_m.iter().enumerate() {
            if has_triangles(starts, v) {
                let p = Vector3::new(p[0], p[1], p[2]);
                lo = lo.inf(&p);
                hi = hi.sup(&p);
                any = true;
            }
        }
        if !any {
            lo = Vector3::zeros();
            hi = Vector3::zeros();
        }
        let extent = hi - lo;
        let capacity = self.buffers.cell_start.len().saturating_sub(1).max(1);
        let floor_m = T::of_f64(1e-6);
        let mut cell_m = if longest_m > floor_m {
            longest_m
        } else {
            floor_m
        };
        let dims_for =
            |cell: T| extent.map(|e| ((e / cell).floor().as_f64() as u32).saturating_add(1));
        let fits = |d: &Vector3<u32>| {
            d.iter()
                .try_fold(1usize, |n, &k| n.checked_mul(k as usize))
                .is_some_and(|n| n <= capacity)
        };
        for _ in 0..MAX_CELL_DOUBLINGS {
            let dims = dims_for(cell_m);
            if fits(&dims) {
                return Grid {
                    origin_m: lo,
                    cell_m,
                    dims: [dims.x, dims.y, dims.z],
                };
            }
            cell_m = cell_m + cell_m;
        }
        // One cell over the whole box (every query visits it).
        let whole = extent.max() + floor_m;
        Grid {
            origin_m: lo,
            cell_m: if whole > cell_m { whole } else { cell_m },
            dims: [1; 3],
        }
    }

    /// Files each surface vertex in its cell (a counting sort).
    fn file_vertices(&mut self) {
        let [nx, ny, nz] = self.grid.dims.map(|d| d as usize);
        self.cells = nx * ny * nz;
        let grid = self.grid;
        let starts = &*self.buffers.vertex_triangle_start;
        let cell_start = self
            .buffers
            .cell_start
            .get_mut(..=self.cells)
            .unwrap_or_default();
        cell_start.fill(0);
        let cell_of = |p: &[T; 3]| {
            let [i, j, k] = grid
                .cell_of(&Vector3::new(p[0], p[1], p[2]))
                .map(|c| c as usize);
            i + nx * (j + ny * k)
        };
        for (v, p) in self.buffers.positions_m.iter().enumerate() {
            if has_triangles(starts, v)
                && let Some(count) = cell_start.get_mut(cell_of(p) + 1)
            {
                *count += 1;
            }
        }
        prefix_sum(cell_start);
        for (v, p) in self.buffers.positions_m.iter().enumerate() {
            if !has_triangles(starts, v) {
                continue;
            }
            let Some(cursor) = cell_start.get_mut(cell_of(p)) else {
                continue;
            };
            if let Some(slot) = self.buffers.grid_vertex.get_mut(*cursor as usize) {
                *slot = v as u32;
            }
            *cursor += 1;
        }
        shift_back(cell_start);
        self.filed = cell_start.last().copied().unwrap_or(0) as usize;
        self.max_bucket = max_row(cell_start);
    }

    /// The index over the current lists (constant time).
    fn index(&self) -> SurfaceIndex<'_, T> {
        SurfaceIndex::assembled(
            self.grid,
            BuiltLists {
                cell_start: self.buffers.cell_start.get(..=self.cells).unwrap_or(&[]),
                grid_vertex: self.buffers.grid_vertex.get(..self.filed).unwrap_or(&[]),
                vertex_triangle_start: self.buffers.vertex_triangle_start,
                vertex_triangle: self.buffers.vertex_triangle,
                planes: self.buffers.planes,
                max_bucket: self.max_bucket,
                max_valence: self.max_valence,
            },
        )
    }

    /// The current vertex positions, m.
    pub fn positions_m(&self) -> &[[T; 3]] {
        self.buffers.positions_m
    }

    /// The surface at the last re-bin, for detection and tracking;
    /// `supports` names the table's fixed vertices.
    pub fn geometry<'g>(&'g self, supports: Supports<'g, T>) -> SurfaceGeometry<'g, T> {
        SurfaceGeometry::of_parts(
            self.buffers.positions_m,
            self.triangles,
            self.index(),
            supports,
        )
    }
}

/// `true` if vertex `v` has a surface triangle.
fn has_triangles(starts: &[u32], v: usize) -> bool {
    matches!((starts.get(v), starts.get(v + 1)), (Some(a), Some(b)) if a < b)
}

/// Counts (entry `i + 1` holds row `i`'s count) to starts, in place.
fn prefix_sum(starts: &mut [u32]) {
    let mut total = 0u32;
    for s in starts.iter_mut() {
        total = total.saturating_add(*s);
        *s = total;
    }
}

/// After filling with `starts[i]` as row `i`'s cursor (now the start of
/// row `i + 1`): shifts every entry up by one and restores `starts[0] = 0`.
fn shift_back(starts: &mut [u32]) {
    let mut previous = 0u32;
    for s in starts.iter_mut() {
        (*s, previous) = (previous, *s);
    }
}
