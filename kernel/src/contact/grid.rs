//! The one builder of the collision bucket grid (Cotin 1999 §4, collision
//! buckets; MODELS.md §6), allocation-free, into the caller's buffers. The
//! host's table writer calls it once on the rest surface (the sections of a
//! pre-computed table, validated again at load by
//! [`crate::table::SurfaceIndex`]); the tensor-mass model's deforming
//! surface calls it at every physics update on the current positions.
//!
//! Sizing rule (one rule for both): the cell edge starts at the longest
//! surface edge, so that the 27 cells around any point on (or just off) the
//! surface hold every vertex of the triangle under it, and grows by
//! [`CELL_GROWTH`] until the grid has at most as many cells as the caller's
//! `cell_start` buffer holds (at most [`MAX_CELL_GROWTHS`] times; a grid
//! still too large after them, a non-physical state, becomes one cell).
//!
//! Cost: [`vertex_triangles`] is one pass over the `T` triangles and two
//! over the `N` vertices; [`bin`] one pass over the triangles, three over the
//! vertices, two over the cells and at most [`MAX_CELL_GROWTHS`] dimension
//! computations. Every loop runs over slice lengths.
//!
//! The builder reads raw `u32` lists (the host's mesh at table build, the
//! table's validated triangles at run time) and writes `u32` sections, so it
//! widens their entries itself; the checked index types of [`crate::table`]
//! are handed out by the [`crate::table::SurfaceIndex`] over its lists.

use nalgebra::Vector3;

use crate::Real;
use crate::table::format::PLANE_LEN;
use crate::table::{
    BuiltLists, DEAD_TRIANGLE, Grid, Plane, SurfaceIndex, box_of, for_each_candidate_filing,
    max_row, plane_record,
};

/// Factor by which the cell edge grows until the grid fits its capacity.
pub const CELL_GROWTH: f64 = 1.25;

/// Most growths of the cell edge in one [`bin`]: `1.25^200 ≈ 4·10¹⁹`, more
/// than any ratio of box to capacity a `u32` cell count can need.
pub const MAX_CELL_GROWTHS: u32 = 200;

/// Least cell edge, m (a surface of coincident vertices still bins).
pub const MIN_CELL_M: f64 = 1e-6;

/// The buffers [`bin`] fills.
pub struct BinBuffers<'b, T> {
    /// Plane and barycentric frame of every surface triangle
    /// ([`crate::table::format::SectionKind::SurfacePlane`]; zero for a
    /// collapsed triangle, which is never touched): `T`.
    pub planes: &'b mut [Plane<T>],
    /// Start of each cell's vertex list: capacity in cells plus one, at
    /// least 2; the grid uses the first `cells + 1`.
    pub cell_start: &'b mut [u32],
    /// Surface vertices filed by cell: `N` (the first `filed` are used).
    pub grid_vertex: &'b mut [u32],
}

/// What [`bin`] built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Binned<T> {
    /// The grid.
    pub grid: Grid<T>,
    /// Its cells (`cell_start[..=cells]` is the list).
    pub cells: usize,
    /// Surface vertices filed (`grid_vertex[..filed]`).
    pub filed: usize,
    /// Most vertices in one cell.
    pub max_bucket: u32,
    /// The box of the surface vertices, m ([`crate::table::box_of`]; the
    /// grid's cells reach up to a cell past it).
    pub surface_box_m: [Vector3<T>; 2],
}

/// A moving surface's grid: what [`vertex_triangles`] and [`bin`] last left
/// in its owner's buffers, re-binned at each physics update, and the index
/// over those buffers. The tensor-mass model's deforming surface and the
/// hybrid's whole surface both keep one.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Rebinned<T> {
    grid: Grid<T>,
    /// The surface vertices' box at the last re-bin, m.
    surface_box_m: [Vector3<T>; 2],
    /// Cells of the current grid.
    cells: usize,
    /// Surface vertices filed (the used prefix of `grid_vertex`).
    filed: usize,
    /// Most vertices in one cell of the current grid; most triangles
    /// around one vertex.
    max_bucket: u32,
    max_valence: u32,
}

/// A moving surface's buffers, as [`Rebinned::rebin`] reads and writes them
/// (lengths as [`vertex_triangles`] and [`bin`] take them).
pub(crate) struct SurfaceLists<'b, T> {
    pub(crate) positions_m: &'b [[T; 3]],
    pub(crate) triangles: &'b [[u32; 3]],
    pub(crate) vertex_triangle_start: &'b mut [u32],
    pub(crate) vertex_triangle: &'b mut [u32],
    pub(crate) planes: &'b mut [Plane<T>],
    pub(crate) cell_start: &'b mut [u32],
    pub(crate) grid_vertex: &'b mut [u32],
}

impl<T: Real> Rebinned<T> {
    /// Before the first [`Self::rebin`]: one empty cell.
    pub(crate) fn empty() -> Self {
        Self {
            grid: Grid {
                origin_m: Vector3::zeros(),
                cell_m: T::one(),
                dims: [1; 3],
            },
            surface_box_m: box_of([]),
            cells: 1,
            filed: 0,
            max_bucket: 0,
            max_valence: 0,
        }
    }

    /// Rebuilds each vertex's triangle list when `lists_changed` (the
    /// triangles changed since the last call), then the planes and a new
    /// grid at `lists.positions_m`. Bounded (module docs).
    pub(crate) fn rebin(&mut self, lists: SurfaceLists<'_, T>, lists_changed: bool) {
        if lists_changed {
            self.max_valence = vertex_triangles(
                lists.triangles,
                lists.vertex_triangle_start,
                lists.vertex_triangle,
            );
        }
        let Binned {
            grid,
            cells,
            filed,
            max_bucket,
            surface_box_m,
        } = bin(
            lists.positions_m,
            lists.triangles,
            lists.vertex_triangle_start,
            BinBuffers {
                planes: lists.planes,
                cell_start: lists.cell_start,
                grid_vertex: lists.grid_vertex,
            },
        );
        (self.grid, self.cells, self.filed, self.max_bucket) = (grid, cells, filed, max_bucket);
        self.surface_box_m = surface_box_m;
    }

    /// The index over the buffers the last [`Self::rebin`] filled (the
    /// same slices, read back; constant time).
    pub(crate) fn index<'b>(
        &self,
        triangles: &'b [[u32; 3]],
        vertex_triangle_start: &'b [u32],
        vertex_triangle: &'b [u32],
        planes: &'b [Plane<T>],
        cell_start: &'b [u32],
        grid_vertex: &'b [u32],
    ) -> SurfaceIndex<'b, T> {
        SurfaceIndex::assembled(
            self.grid,
            BuiltLists {
                triangles,
                cell_start: cell_start.get(..=self.cells).unwrap_or(&[]),
                grid_vertex: grid_vertex.get(..self.filed).unwrap_or(&[]),
                vertex_triangle_start,
                vertex_triangle,
                planes,
                surface_box_m: self.surface_box_m,
                max_bucket: self.max_bucket,
                max_valence: self.max_valence,
            },
        )
    }
}

/// Each vertex's surface triangles, ascending, as a CSR list: `start` has
/// `N + 1` entries, `list` `3 T` (a counting sort over the triangles, which
/// visits them in order; [`DEAD_TRIANGLE`] slots are skipped, so `list`
/// then has room to spare). A corner beyond the last vertex (a corrupted
/// input) is filed under the last vertex, which keeps the list at `3 T` so
/// that the loader reports the triangle itself. Returns the most triangles
/// around one vertex.
pub fn vertex_triangles(triangles: &[[u32; 3]], start: &mut [u32], list: &mut [u32]) -> u32 {
    start.fill(0);
    let last = start.len().saturating_sub(2);
    let row = |v: u32| (v as usize).min(last);
    for tri in triangles.iter().filter(|t| **t != DEAD_TRIANGLE) {
        for &v in tri {
            if let Some(s) = start.get_mut(row(v) + 1) {
                *s += 1;
            }
        }
    }
    prefix_sum(start);
    // `start[v]` is the cursor of vertex v while filling; it ends at the
    // start of v + 1, then everything shifts back by one.
    for (t, tri) in triangles.iter().enumerate() {
        if *tri == DEAD_TRIANGLE {
            continue;
        }
        for &v in tri {
            if let Some(cursor) = start.get_mut(row(v)) {
                place(list, cursor, t as u32);
            }
        }
    }
    shift_back(start);
    max_row(start)
}

/// Computes every triangle's plane over `positions_m` and files each
/// surface vertex (one with a triangle in `vertex_triangle_start`) in a grid
/// sized by the module's rule. Bounded (module docs).
pub fn bin<T: Real>(
    positions_m: &[[T; 3]],
    triangles: &[[u32; 3]],
    vertex_triangle_start: &[u32],
    buffers: BinBuffers<'_, T>,
) -> Binned<T> {
    let longest_m = planes(positions_m, triangles, buffers.planes);
    let capacity = buffers.cell_start.len().saturating_sub(1).max(1);
    let surface_box_m = box_of(
        positions_m
            .iter()
            .enumerate()
            .filter(|&(v, _)| has_triangles(vertex_triangle_start, v))
            .map(|(_, p)| Vector3::new(p[0], p[1], p[2])),
    );
    let grid = fitted_grid(&surface_box_m, longest_m, capacity);
    let (cells, filed, max_bucket) = file_vertices(
        &grid,
        positions_m,
        vertex_triangle_start,
        buffers.cell_start,
        buffers.grid_vertex,
    );
    Binned {
        grid,
        cells,
        filed,
        max_bucket,
        surface_box_m,
    }
}

/// Each cell's candidate triangles as a CSR list, ascending within a cell
/// (a counting sort over the triangles in order): triangle `t` in every
/// cell of its [`crate::table::candidate_cells`] for a tool of radius up to `radius_m`
/// (m). `start` has the grid's cells plus one entries; `list` room for
/// every filing ([`candidate_count`]; a shorter one drops the rest).
/// [`DEAD_TRIANGLE`] slots and triangles with a corner beyond
/// `positions_m` are not filed. Returns the longest list.
pub fn cell_triangles<T: Real>(
    grid: &Grid<T>,
    positions_m: &[[T; 3]],
    triangles: &[[u32; 3]],
    radius_m: T,
    start: &mut [u32],
    list: &mut [u32],
) -> u32 {
    start.fill(0);
    for_each_candidate_filing(grid, positions_m, triangles, radius_m, |cell, _| {
        if let Some(s) = start.get_mut(cell + 1) {
            *s += 1;
        }
    });
    prefix_sum(start);
    for_each_candidate_filing(grid, positions_m, triangles, radius_m, |cell, t| {
        if let Some(cursor) = start.get_mut(cell) {
            place(list, cursor, t);
        }
    });
    shift_back(start);
    max_row(start)
}

/// The entries [`cell_triangles`] files.
pub fn candidate_count<T: Real>(
    grid: &Grid<T>,
    positions_m: &[[T; 3]],
    triangles: &[[u32; 3]],
    radius_m: T,
) -> usize {
    let mut count = 0usize;
    for_each_candidate_filing(grid, positions_m, triangles, radius_m, |_, _| count += 1);
    count
}

/// Surface vertices (with at least one triangle) of a CSR vertex list.
pub fn surface_vertex_count(vertex_triangle_start: &[u32]) -> usize {
    (0..vertex_triangle_start.len().saturating_sub(1))
        .filter(|&v| has_triangles(vertex_triangle_start, v))
        .count()
}

/// Recomputes every triangle's plane and barycentric frame
/// ([`crate::table::format::SectionKind::SurfacePlane`]): with
/// `e₁ = b − a`, `e₂ = c − a` and `m = e₁ × e₂`, the unit normal `m/|m|`,
/// the offset `n·a`, and the gradients `g₁ = (e₂ × m)/|m|²`,
/// `g₂ = (m × e₁)/|m|²` (so `gᵢ·eⱼ = δᵢⱼ` and `gᵢ·m = 0`). Returns the
/// longest edge, m.
fn planes<T: Real>(positions_m: &[[T; 3]], triangles: &[[u32; 3]], planes: &mut [Plane<T>]) -> T {
    let at = |v: u32| {
        positions_m
            .get(v as usize)
            .map_or(Vector3::zeros(), |p| Vector3::new(p[0], p[1], p[2]))
    };
    let mut longest2 = T::zero();
    for (plane, tri) in planes.iter_mut().zip(triangles) {
        if *tri == DEAD_TRIANGLE {
            *plane = [T::zero(); PLANE_LEN];
            continue;
        }
        let [a, b, c] = tri.map(at);
        for e in [b - a, c - b, a - c] {
            longest2 = longest2.max(e.norm_squared());
        }
        let (e1, e2) = (b - a, c - a);
        let m = e1.cross(&e2);
        let area2 = m.norm_squared();
        // A collapsed triangle gets a zero normal: never touched.
        *plane = if area2 > T::zero() {
            let n = m / area2.sqrt();
            plane_record(&n, n.dot(&a), &[e2.cross(&m) / area2, m.cross(&e1) / area2])
        } else {
            [T::zero(); PLANE_LEN]
        };
    }
    longest2.sqrt()
}

/// The grid over the surface vertices' box `surface_box_m` (m; the empty
/// box for no vertex: a grid at the origin) with cells of at least
/// `longest_m`, within `capacity` cells.
fn fitted_grid<T: Real>(surface_box_m: &[Vector3<T>; 2], longest_m: T, capacity: usize) -> Grid<T> {
    let [mut lo, mut hi] = *surface_box_m;
    if lo.x > hi.x {
        lo = Vector3::zeros();
        hi = Vector3::zeros();
    }
    let extent = hi - lo;
    let floor_m = T::of_f64(MIN_CELL_M);
    let mut cell_m = if longest_m > floor_m {
        longest_m
    } else {
        floor_m
    };
    for _ in 0..MAX_CELL_GROWTHS {
        let grid = Grid::covering(lo, &extent, cell_m);
        if grid.cell_count().is_some_and(|n| n <= capacity) {
            return grid;
        }
        cell_m *= T::of_f64(CELL_GROWTH);
    }
    // One cell over the whole box (every query visits it).
    let whole = extent.max() + floor_m;
    Grid {
        origin_m: lo,
        cell_m: if whole > cell_m { whole } else { cell_m },
        dims: [1; 3],
    }
}

/// Files each surface vertex in its cell (a counting sort); returns the
/// cells, the vertices filed and the largest bucket.
fn file_vertices<T: Real>(
    grid: &Grid<T>,
    positions_m: &[[T; 3]],
    starts: &[u32],
    cell_start: &mut [u32],
    grid_vertex: &mut [u32],
) -> (usize, usize, u32) {
    // A fitted grid's cells fit the buffer (module docs).
    let cells = grid.cell_count().unwrap_or(0);
    let cell_start = cell_start.get_mut(..=cells).unwrap_or_default();
    cell_start.fill(0);
    let cell_of = |p: &[T; 3]| grid.linear(grid.cell_of(&Vector3::new(p[0], p[1], p[2])));
    for (v, p) in positions_m.iter().enumerate() {
        if has_triangles(starts, v)
            && let Some(count) = cell_start.get_mut(cell_of(p) + 1)
        {
            *count += 1;
        }
    }
    prefix_sum(cell_start);
    for (v, p) in positions_m.iter().enumerate() {
        if !has_triangles(starts, v) {
            continue;
        }
        if let Some(cursor) = cell_start.get_mut(cell_of(p)) {
            place(grid_vertex, cursor, v as u32);
        }
    }
    shift_back(cell_start);
    let filed = cell_start.last().copied().unwrap_or(0) as usize;
    (cells, filed, max_row(cell_start))
}

/// `true` if vertex `v` has a surface triangle.
fn has_triangles(starts: &[u32], v: usize) -> bool {
    matches!((starts.get(v), starts.get(v + 1)), (Some(a), Some(b)) if a < b)
}

/// The fill step of a counting sort: `list[cursor] = value`, then the
/// cursor (a row's next free entry) moves on.
fn place(list: &mut [u32], cursor: &mut u32, value: u32) {
    if let Some(slot) = list.get_mut(*cursor as usize) {
        *slot = value;
    }
    *cursor += 1;
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
