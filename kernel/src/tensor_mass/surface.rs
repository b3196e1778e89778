//! The collision surface of a deforming (dynamic tensor-mass) tissue: the
//! boundary of the live tets at the current vertex positions, re-binned
//! into a fresh bucket grid at every physics update (Cotin 1999 §4: "the
//! bucket data structure must be updated" for a deformed mesh; MODELS.md
//! §6).
//!
//! Faces a cut exposes (Picinbono 2001 §3.1; MODELS.md §3): the surface
//! keeps one triangle slot per mesh triangle (face) of the table, so that
//! a triangle's index never changes while the session runs. Slots
//! `0..B` hold the table's `B` boundary triangles in the table's order (an
//! uncut tissue numbers its triangles exactly as the table does); slots
//! `B..F` the interior faces, in mesh-triangle order, empty
//! ([`DEAD_TRIANGLE`]) until a removal exposes one. Removing tet `t`
//! ([`DeformingSurface::remove_tets`]) updates its 4 faces in constant time
//! each: a face shared with a live neighbour becomes a surface triangle
//! oriented outward from that neighbour, any other face of `t` leaves the
//! surface. The vertex-to-triangle lists are rebuilt at the next re-bin
//! (one pass over the slots and the vertices), so the exposed faces are
//! touchable from that physics update on.
//!
//! Bounded re-binning: [`DeformingSurface::rebin`] moves the vertices (one
//! pass over the `N` vertices) and re-bins them with the crate's one grid
//! builder ([`crate::contact::grid::bin`], whose sizing rule and bounds are
//! documented there) into the caller's buffers; after removals it first
//! rebuilds the vertex-to-triangle lists (one pass over the `F` slots and
//! two over the vertices).

use core::fmt;

use super::TensorMassModel;
use crate::Real;
use crate::contact::grid::{Rebinned, SurfaceLists};
use crate::contact::{Supports, SurfaceGeometry};
use crate::table::format::{NO_NEIGHBOUR, tet_face_vertices};
use crate::table::{DEAD_TRIANGLE, Plane, SurfaceIndex, TensorMassTable, TetIndex, TriangleIndex};

/// The caller's buffers of a deforming surface (static arrays on
/// firmware). Lengths for a table of `N` vertices and `F` mesh triangles
/// (faces, boundary and interior): see each field;
/// [`SurfaceBuffers::lengths`] computes them.
pub struct SurfaceBuffers<'s, T> {
    /// Current position of every vertex, m: `N`.
    pub positions_m: &'s mut [[T; 3]],
    /// The triangle in each slot (module docs), outward right-hand order,
    /// or [`DEAD_TRIANGLE`]: `F`.
    pub triangles: &'s mut [[u32; 3]],
    /// The slot of each mesh triangle: `F`.
    pub face_slot: &'s mut [u32],
    /// The live tet whose face each surface slot holds: `F`.
    pub slot_tet: &'s mut [u32],
    /// Plane and barycentric frame of every slot's triangle
    /// ([`crate::table::Plane`]; zero for an empty slot): `F`.
    pub planes: &'s mut [Plane<T>],
    /// Start of each vertex's triangle list: `N + 1`.
    pub vertex_triangle_start: &'s mut [u32],
    /// The triangles around each vertex, ascending: `3 F`.
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
    /// `triangles`, `face_slot`, `slot_tet` and `planes`.
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
        Self::table_lengths(model.table(), cells)
    }

    /// The lengths for `table` with room for `cells` grid cells (before a
    /// model exists: a caller sizing one memory block for the state and
    /// the surface).
    pub fn table_lengths<R: Real>(table: &TensorMassTable<'_, R>, cells: usize) -> SurfaceLengths {
        let n = table.vertex_count();
        let t = table.mesh_triangles().len();
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

/// `Err` naming the first of `checks` (`(buffer, expected, found)`) whose
/// lengths differ, or `cell_start` if it holds fewer than `cells_needed`
/// entries (`cells_found`): the buffer checks of a surface's constructor.
pub(crate) fn check_lengths(
    checks: &[(&'static str, usize, usize)],
    cells_needed: usize,
    cells_found: usize,
) -> Result<(), SurfaceBufferError> {
    if let Some(&(buffer, expected, found)) = checks.iter().find(|(_, e, f)| e != f) {
        return Err(SurfaceBufferError {
            buffer,
            expected,
            found,
        });
    }
    if cells_found < cells_needed {
        return Err(SurfaceBufferError {
            buffer: "cell_start",
            expected: cells_needed,
            found: cells_found,
        });
    }
    Ok(())
}

/// The deforming surface: the boundary of the live tets at the positions
/// of the last [`Self::rebin`].
pub struct DeformingSurface<'a, 's, T: Real> {
    table: TensorMassTable<'a, T>,
    buffers: SurfaceBuffers<'s, T>,
    /// Faces changed since the vertex-to-triangle lists were built.
    dirty: bool,
    bins: Rebinned<T>,
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
            ("triangles", need.triangles, buffers.triangles.len()),
            ("face_slot", need.triangles, buffers.face_slot.len()),
            ("slot_tet", need.triangles, buffers.slot_tet.len()),
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
        check_lengths(&checks, need.cell_start, buffers.cell_start.len())?;
        let mut surface = Self {
            table: *model.table(),
            buffers,
            dirty: true,
            bins: Rebinned::empty(),
        };
        surface.reset_faces();
        surface.remove_tets(model.tet_alive(), model.table().tet_indices());
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
            .zip(self.table.rest_positions())
            .enumerate()
        {
            let u = displacement_m.get(v).unwrap_or(&zero);
            *x = [rest[0] + u[0], rest[1] + u[1], rest[2] + u[2]];
            if !x.iter().all(|c| c.finite()) {
                return Err(NonFinitePosition { vertex: v as u32 });
            }
        }
        let b = &mut self.buffers;
        self.bins.rebin(
            SurfaceLists {
                positions_m: b.positions_m,
                triangles: b.triangles,
                vertex_triangle_start: b.vertex_triangle_start,
                vertex_triangle: b.vertex_triangle,
                planes: b.planes,
                cell_start: b.cell_start,
                grid_vertex: b.grid_vertex,
            },
            self.dirty,
        );
        self.dirty = false;
        Ok(())
    }

    /// The index over the current lists (constant time).
    fn index(&self) -> SurfaceIndex<'_, T> {
        let b = &self.buffers;
        self.bins.index(
            b.triangles,
            b.vertex_triangle_start,
            b.vertex_triangle,
            b.planes,
            b.cell_start,
            b.grid_vertex,
        )
    }

    /// The current vertex positions, m.
    pub fn positions_m(&self) -> &[[T; 3]] {
        self.buffers.positions_m
    }

    /// The triangle slots (module docs): each live slot's vertices in
    /// outward order, [`DEAD_TRIANGLE`] for the others. As of the last
    /// [`Self::remove_tets`]; the collision lists follow at the next re-bin.
    pub fn triangles(&self) -> &[[u32; 3]] {
        self.buffers.triangles
    }

    /// The live tet whose face surface triangle `t` is; `None` for an
    /// empty slot or an index beyond the slots.
    pub fn tet_of(&self, t: TriangleIndex) -> Option<TetIndex> {
        if *self.buffers.triangles.get(t.get())? == DEAD_TRIANGLE {
            return None;
        }
        self.table.tet(*self.buffers.slot_tet.get(t.get())?)
    }

    /// The uncut surface: the table's boundary triangles in slots `0..B`,
    /// the interior faces empty in the slots after them (module docs).
    /// Cost: `B` binary searches in the `F` mesh triangles, one pass over
    /// the slots and one over the tets' faces.
    pub fn reset_faces(&mut self) {
        let b = &mut self.buffers;
        let mesh = self.table.mesh_triangles();
        b.face_slot.fill(u32::MAX);
        b.triangles.fill(DEAD_TRIANGLE);
        for (k, (tri, slot)) in self
            .table
            .surface_triangles()
            .iter()
            .zip(b.triangles.iter_mut())
            .enumerate()
        {
            let mut sorted = *tri;
            sorted.sort_unstable();
            if let Some(m) = mesh
                .binary_search(&sorted)
                .ok()
                .and_then(|m| b.face_slot.get_mut(m))
            {
                *m = k as u32;
                *slot = *tri;
            }
        }
        // The interior faces take the slots after the boundary, in order.
        let mut next = self.table.surface_triangles().len() as u32;
        for slot in b.face_slot.iter_mut().filter(|s| **s == u32::MAX) {
            *slot = next;
            next = next.saturating_add(1);
        }
        b.slot_tet.fill(u32::MAX);
        for (t, faces) in self.table.tet_triangles().iter().enumerate() {
            for &m in faces {
                if let Some(owner) = b
                    .face_slot
                    .get(m as usize)
                    .filter(|&&s| b.triangles.get(s as usize) != Some(&DEAD_TRIANGLE))
                    .and_then(|&s| b.slot_tet.get_mut(s as usize))
                {
                    *owner = t as u32;
                }
            }
        }
        self.dirty = true;
    }

    /// Updates the faces of every tet of `removed` whose `alive` entry is
    /// `false` (module docs): each face shared with a live neighbour becomes
    /// a surface triangle outward from it, the others leave the surface.
    /// Reads only the final `alive` states, so the order of `removed` does
    /// not matter. Constant work per tet; the collision lists follow at
    /// the next re-bin.
    pub fn remove_tets(&mut self, alive: &[bool], removed: impl Iterator<Item = TetIndex>) {
        let table = &self.table;
        let b = &mut self.buffers;
        let is_alive = |t: u32| alive.get(t as usize) == Some(&true);
        for t in removed.filter(|t| !is_alive(t.as_u32())) {
            let (Some(faces), Some(neighbours)) = (
                table.tet_triangles().get(t.get()),
                table.tet_neighbours().get(t.get()),
            ) else {
                continue;
            };
            for (&m, &other) in faces.iter().zip(neighbours) {
                let Some(&slot) = b.face_slot.get(m as usize) else {
                    continue;
                };
                let exposed = (other != NO_NEIGHBOUR && is_alive(other))
                    .then(|| {
                        let vertices = *table.tets().get(other as usize)?;
                        let across = table.tet_neighbours().get(other as usize)?;
                        let j = across.iter().position(|&n| n == t.as_u32())?;
                        tet_face_vertices(vertices).get(j).copied()
                    })
                    .flatten();
                if let (Some(tri), Some(owner)) = (
                    b.triangles.get_mut(slot as usize),
                    b.slot_tet.get_mut(slot as usize),
                ) {
                    *tri = exposed.unwrap_or(DEAD_TRIANGLE);
                    *owner = if exposed.is_some() { other } else { u32::MAX };
                }
            }
            self.dirty = true;
        }
    }

    /// The surface at the last re-bin, for detection and tracking;
    /// `supports` names the table's fixed vertices.
    pub fn geometry<'g>(&'g self, supports: Supports<'g, T>) -> SurfaceGeometry<'g, T> {
        SurfaceGeometry::of_parts(self.buffers.positions_m, self.index(), supports)
    }
}
