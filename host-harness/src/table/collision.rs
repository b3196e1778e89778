//! The collision index of a pre-computed table (Cotin 1999 §4, collision
//! buckets): the boundary-surface vertices filed in a regular grid, and the
//! surface triangles around each vertex. Built by the kernel's one grid
//! builder (`palpate_kernel::contact::grid`, the same code that re-bins a
//! deforming surface); the kernel view and its checks are
//! `palpate_kernel::table::SurfaceIndex`.

use palpate_kernel::contact::grid::{self, BinBuffers, Binned};

/// The index, ready to be written as sections.
#[derive(Clone, Debug, PartialEq)]
pub struct CollisionIndex {
    /// Grid origin `x, y, z` and cell edge, m.
    pub grid: [f64; 4],
    /// Cells per axis.
    pub dims: [u32; 3],
    /// CSR starts of each cell's vertices (cells + 1).
    pub cell_start: Vec<u32>,
    /// Surface vertices by cell, each once.
    pub grid_vertex: Vec<u32>,
    /// CSR starts of each vertex's triangles (N + 1).
    pub vertex_triangle_start: Vec<u32>,
    /// Triangles around each vertex, ascending.
    pub vertex_triangle: Vec<u32>,
    /// Each triangle's unit outward normal and offset `n·p₀` (m).
    pub planes: Vec<[f64; 4]>,
}

/// Most grid cells per surface vertex in a table's index (the grid
/// builder grows the cell edge until the grid fits).
pub const CELLS_PER_SURFACE_VERTEX: usize = 8;

/// Builds the index of the surface `triangles` over `positions` (m), with
/// at most [`CELLS_PER_SURFACE_VERTEX`] cells per surface vertex. A triangle
/// corner outside `positions` (a corrupted input) is left out of the lists;
/// the loader reports the triangle itself.
pub fn collision_index(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> CollisionIndex {
    let n = positions.len();
    let mut vertex_triangle_start = vec![0; n + 1];
    let mut vertex_triangle = vec![0; 3 * triangles.len()];
    grid::vertex_triangles(triangles, &mut vertex_triangle_start, &mut vertex_triangle);
    vertex_triangle.truncate(vertex_triangle_start[n] as usize);
    let surface = grid::surface_vertex_count(&vertex_triangle_start);
    let mut planes = vec![[0.0; 4]; triangles.len()];
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
    let o = grid.origin_m;
    CollisionIndex {
        grid: [o.x, o.y, o.z, grid.cell_m],
        dims: grid.dims,
        cell_start,
        grid_vertex,
        vertex_triangle_start,
        vertex_triangle,
        planes,
    }
}
