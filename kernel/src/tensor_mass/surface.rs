//! The collision surface of a deforming (dynamic tensor-mass) tissue: the
//! table's boundary triangles at the current vertex positions, re-binned
//! into a fresh bucket grid at every physics update (Cotin 1999 §4: "the
//! bucket data structure must be updated" for a deformed mesh; MODELS.md
//! §6).
//!
//! Bounded re-binning: [`DeformingSurface::rebin`] moves the vertices (one
//! pass over the `N` vertices) and re-bins them with the crate's one grid
//! builder ([`crate::contact::grid::bin`], whose sizing rule and bounds are
//! documented there) into the caller's buffers.

use core::fmt;

use nalgebra::Vector3;

use super::TensorMassModel;
use crate::Real;
use crate::contact::grid::{self, BinBuffers, Binned};
use crate::contact::{Supports, SurfaceGeometry};
use crate::table::{BuiltLists, Grid, SurfaceIndex};

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
        surface.max_valence = grid::vertex_triangles(
            surface.triangles,
            surface.buffers.vertex_triangle_start,
            surface.buffers.vertex_triangle,
        );
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
        let Binned {
            grid,
            cells,
            filed,
            max_bucket,
        } = grid::bin(
            self.buffers.positions_m,
            self.triangles,
            self.buffers.vertex_triangle_start,
            BinBuffers {
                planes: self.buffers.planes,
                cell_start: self.buffers.cell_start,
                grid_vertex: self.buffers.grid_vertex,
            },
        );
        (self.grid, self.cells, self.filed, self.max_bucket) = (grid, cells, filed, max_bucket);
        Ok(())
    }

    /// The index over the current lists (constant time).
    fn index(&self) -> SurfaceIndex<'_, T> {
        SurfaceIndex::assembled(
            self.grid,
            BuiltLists {
                triangles: self.triangles,
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
        SurfaceGeometry::of_parts(self.buffers.positions_m, self.index(), supports)
    }
}
