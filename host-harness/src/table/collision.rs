//! The collision index of a pre-computed table (Cotin 1999 §4, collision
//! buckets): the boundary-surface vertices filed in a regular grid, and the
//! surface triangles around each vertex. Built by the kernel's one grid
//! builder (`palpate_kernel::contact::grid`, the same code that re-bins a
//! deforming surface); the kernel view and its checks are
//! `palpate_kernel::table::SurfaceIndex`.

use palpate_kernel::Real;
use palpate_kernel::contact::grid::{self, BinBuffers, Binned};
use palpate_kernel::table::{Grid, candidate_radius_m, list_subdivision};

use super::precision::Precision;
use palpate_kernel::table::Plane;
use palpate_kernel::table::format::{GRID_LEN, PLANE_LEN};

/// The index, ready to be written as sections.
#[derive(Clone, Debug, PartialEq)]
pub struct CollisionIndex {
    /// Grid origin `x, y, z` and cell edge, m, and the tool radius the
    /// candidate lists serve, m.
    pub grid: [f64; GRID_LEN],
    /// Cells per axis.
    pub dims: [u32; 3],
    /// Cells per axis of the candidate lists' grid (the grid's box in
    /// cells `palpate_kernel::table::list_subdivision` times finer).
    pub list_dims: [u32; 3],
    /// CSR starts of each cell's vertices (cells + 1).
    pub cell_start: Vec<u32>,
    /// Surface vertices by cell, each once.
    pub grid_vertex: Vec<u32>,
    /// CSR starts of each vertex's triangles (N + 1).
    pub vertex_triangle_start: Vec<u32>,
    /// Triangles around each vertex, ascending.
    pub vertex_triangle: Vec<u32>,
    /// Each triangle's unit outward normal, offset `n·p₀` (m) and
    /// barycentric frame (layout: `SectionKind::SurfacePlane`).
    pub planes: Vec<Plane<f64>>,
    /// CSR starts of each cell's candidate triangles (cells + 1).
    pub cell_triangle_start: Vec<u32>,
    /// Each cell's candidate triangles for the grid record's tool radius,
    /// ascending (`grid::cell_triangles`).
    pub cell_triangle: Vec<u32>,
}

/// Most grid cells per surface vertex in a table's index (the grid
/// builder grows the cell edge until the grid fits).
pub const CELLS_PER_SURFACE_VERTEX: usize = 8;

/// Builds the index of the surface `triangles` over `positions` (m), with
/// at most [`CELLS_PER_SURFACE_VERTEX`] cells per surface vertex, and its
/// per-cell candidate lists for tools of radius up to `tool_radius_m` (m;
/// at most the grid's cell edge over the margin's radii,
/// `palpate_kernel::table::candidate_radius_m`) over the lists' grid
/// (`palpate_kernel::table::list_subdivision` times finer),
/// filed in `precision` (the loader files every triangle again in the
/// table's scalar, from the stored positions and grid, and must find the
/// same cells). A triangle corner outside `positions` (a corrupted input)
/// is left out of the lists; the loader reports the triangle itself.
pub fn collision_index(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    tool_radius_m: f64,
    precision: Precision,
) -> CollisionIndex {
    let n = positions.len();
    let mut vertex_triangle_start = vec![0; n + 1];
    let mut vertex_triangle = vec![0; 3 * triangles.len()];
    grid::vertex_triangles(triangles, &mut vertex_triangle_start, &mut vertex_triangle);
    vertex_triangle.truncate(vertex_triangle_start[n] as usize);
    let surface = grid::surface_vertex_count(&vertex_triangle_start);
    let mut planes = vec![[0.0; PLANE_LEN]; triangles.len()];
    let mut cell_start = vec![0; CELLS_PER_SURFACE_VERTEX * surface.max(1) + 1];
    let mut grid_vertex = vec![0; n];
    let Binned {
        grid, cells, filed, ..
    } = grid::bin(
        positions,
        triangles,
        &vertex_triangle_start,
        BinBuffers {
            planes: &mut planes,
            cell_start: &mut cell_start,
            grid_vertex: &mut grid_vertex,
        },
    );
    cell_start.truncate(cells + 1);
    grid_vertex.truncate(filed);
    // Capped a millionth below the cap, so that the radius rounded to f32
    // still widens a box by at most a cell.
    let most_m = candidate_radius_m(&grid, f64::INFINITY) * (1.0 - 1e-6);
    let radius_m = candidate_radius_m(&grid, tool_radius_m).min(most_m);
    // The lists' grid; the grid's cells fit the table's `u32` count, and
    // `k` is at most `MAX_LIST_SUBDIVISION`: it is never `None` (the grid
    // itself, `k = 1`, otherwise).
    let k = list_subdivision(&grid, radius_m);
    let lists = grid.subdivided(k).unwrap_or(grid);
    let (cell_triangle_start, cell_triangle) = match precision {
        Precision::F32 => candidate_lists::<f32>(&grid, lists.dims, positions, triangles, radius_m),
        Precision::F64 => candidate_lists::<f64>(&grid, lists.dims, positions, triangles, radius_m),
    };
    let o = grid.origin_m;
    CollisionIndex {
        grid: [o.x, o.y, o.z, grid.cell_m, radius_m],
        dims: grid.dims,
        list_dims: lists.dims,
        cell_start,
        grid_vertex,
        vertex_triangle_start,
        vertex_triangle,
        planes,
        cell_triangle_start,
        cell_triangle,
    }
}

/// The per-cell candidate lists (CSR starts, entries) of the surface
/// `triangles` over `positions` for tools of radius up to `radius_m`, over
/// the lists' grid of `list_dims` cells over `grid`'s box (a whole number of
/// times `grid`'s), filed in the scalar `T` with the grid, positions and
/// radius rounded to it, as the loader files them (from the grid record and
/// `list_dims`).
fn candidate_lists<T: Real>(
    grid: &Grid<f64>,
    list_dims: [u32; 3],
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    radius_m: f64,
) -> (Vec<u32>, Vec<u32>) {
    let grid = Grid {
        origin_m: grid.origin_m.map(T::of_f64),
        cell_m: T::of_f64(grid.cell_m),
        dims: grid.dims,
    };
    let grid = grid.lists(list_dims).unwrap_or(grid);
    let positions: Vec<[T; 3]> = positions.iter().map(|p| p.map(T::of_f64)).collect();
    let radius_m = T::of_f64(radius_m);
    let cells = grid.dims.iter().map(|&d| d as usize).product::<usize>();
    let mut start = vec![0; cells + 1];
    let mut list = vec![0; grid::candidate_count(&grid, &positions, triangles, radius_m)];
    grid::cell_triangles(
        &grid, &positions, triangles, radius_m, &mut start, &mut list,
    );
    (start, list)
}
