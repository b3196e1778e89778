//! The surface of a hybrid tissue for the haptic loop: the whole mesh's
//! boundary at the current positions (RR-3510 §6.2; MODELS.md §6),
//! re-binned at every physics update like the tensor-mass model's
//! ([`crate::tensor_mass::DeformingSurface`], Cotin 1999 §4).
//!
//! Slots: `0..B` hold the pre-computed table's boundary triangles in its
//! order, the faces it shares with the tensor-mass region left empty
//! ([`DEAD_TRIANGLE`]: they are inside the organ); `B..B + F` the
//! tensor-mass region's surface slots (its
//! [`crate::tensor_mass::DeformingSurface::triangles`], faces a cut exposes
//! included) in mesh vertex numbers, its copies of the shared faces empty
//! too. A cut that removes a tensor-mass tet on a shared face leaves that
//! face out of the surface (the pre-computed side cannot answer a contact
//! there: its vertices are all connection nodes, held in its table), so
//! cuts belong inside the tensor-mass region, which the zones' margin
//! keeps away from the interface (README "Scenes that model no more than
//! they need"). Positions: a tensor-mass vertex at its
//! displacement, a touchable pre-computed vertex at its background (the
//! displacement the connection nodes and the load give it; a contact's own
//! dimple is the contact's), every other vertex at rest.

use super::region::CondensedRegion;
use crate::Real;
use crate::contact::grid::{Rebinned, SurfaceLists};
use crate::contact::{Supports, SurfaceGeometry};
use crate::table::{DEAD_TRIANGLE, Plane, PrecomputedTable, TensorMassTable, TriangleIndex};
use crate::tensor_mass::{NonFinitePosition, SurfaceBufferError, TensorMassModel, check_lengths};

/// The caller's buffers of a hybrid surface (static arrays on firmware);
/// lengths from [`HybridSurfaceBuffers::lengths`].
pub struct HybridSurfaceBuffers<'s, T> {
    /// Current position of every mesh vertex, m: `N`.
    pub positions_m: &'s mut [[T; 3]],
    /// The triangle in each slot (module docs): `B + F`.
    pub triangles: &'s mut [[u32; 3]],
    /// Plane of every slot's triangle: `B + F`.
    pub planes: &'s mut [Plane<T>],
    /// Start of each vertex's triangle list: `N + 1`.
    pub vertex_triangle_start: &'s mut [u32],
    /// The triangles around each vertex: `3 (B + F)`.
    pub vertex_triangle: &'s mut [u32],
    /// Start of each grid cell's vertex list: the grid's capacity in cells
    /// plus one, at least 2.
    pub cell_start: &'s mut [u32],
    /// Surface vertices filed by cell: `N`.
    pub grid_vertex: &'s mut [u32],
    /// The mesh vertex of each tensor-mass vertex: `N_d`.
    pub mesh_vertex: &'s mut [u32],
}

/// Buffer lengths of a hybrid surface (see [`HybridSurfaceBuffers`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HybridSurfaceLengths {
    /// `positions_m` and `grid_vertex` (`N`).
    pub vertices: usize,
    /// `triangles` and `planes` (`B + F`).
    pub triangles: usize,
    /// `cell_start`.
    pub cell_start: usize,
    /// `mesh_vertex` (`N_d`).
    pub dynamic_vertices: usize,
}

impl<T> HybridSurfaceBuffers<'_, T> {
    /// The lengths for the region tables with room for `cells` grid cells.
    pub fn lengths<R: Real>(
        precomputed: &PrecomputedTable<'_, R>,
        dynamic: &TensorMassTable<'_, R>,
        cells: usize,
    ) -> HybridSurfaceLengths {
        HybridSurfaceLengths {
            vertices: precomputed.vertex_count(),
            triangles: precomputed.surface_triangles().len() + dynamic.mesh_triangles().len(),
            cell_start: cells.max(1) + 1,
            dynamic_vertices: dynamic.vertex_count(),
        }
    }
}

/// Where a surface slot lies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SlotRegion {
    /// A boundary triangle of the pre-computed region.
    Precomputed,
    /// The tensor-mass region's surface slot of this index.
    Dynamic(TriangleIndex),
}

/// The hybrid tissue's surface at the positions of the last
/// [`Self::rebuild`].
pub struct HybridSurface<'s, T: Real> {
    buffers: HybridSurfaceBuffers<'s, T>,
    /// First slot of the tensor-mass region (`B`).
    dynamic_first: usize,
    bins: Rebinned<T>,
}

impl<'s, T: Real> HybridSurface<'s, T> {
    /// Checks the buffer lengths, fills the pre-computed slots (a face
    /// shared with a tensor-mass tet left empty: its sorted tensor-mass
    /// vertices are one of that table's mesh triangles) and the
    /// tensor-mass vertices' mesh numbers, and builds the surface over
    /// `dynamic`'s surface slots `dynamic_triangles` ([`Self::rebuild`]).
    /// Cost: one pass over the pre-computed boundary (a binary search
    /// each) and one over the mesh vertices. Not for the step path.
    pub fn new(
        region: &CondensedRegion<'_, '_, T>,
        dynamic: &TensorMassModel<'_, '_, T>,
        dynamic_triangles: &[[u32; 3]],
        buffers: HybridSurfaceBuffers<'s, T>,
    ) -> Result<Self, SurfaceBufferError> {
        let precomputed = region.precomputed().table();
        let need = HybridSurfaceBuffers::<T>::lengths(precomputed, dynamic.table(), 1);
        let checks = [
            ("positions_m", need.vertices, buffers.positions_m.len()),
            ("triangles", need.triangles, buffers.triangles.len()),
            ("planes", need.triangles, buffers.planes.len()),
            (
                "vertex_triangle_start",
                need.vertices + 1,
                buffers.vertex_triangle_start.len(),
            ),
            (
                "vertex_triangle",
                3 * need.triangles,
                buffers.vertex_triangle.len(),
            ),
            ("grid_vertex", need.vertices, buffers.grid_vertex.len()),
            (
                "mesh_vertex",
                need.dynamic_vertices,
                buffers.mesh_vertex.len(),
            ),
        ];
        check_lengths(&checks, need.cell_start, buffers.cell_start.len())?;
        let interface = region.interface();
        for (v, &d) in interface.dynamic_vertices().iter().enumerate() {
            if let Some(m) = buffers.mesh_vertex.get_mut(d as usize) {
                *m = v as u32;
            }
        }
        let inside = dynamic.table().mesh_triangles();
        for (slot, tri) in buffers
            .triangles
            .iter_mut()
            .zip(precomputed.surface_triangles())
        {
            let shared = match tri.map(|v| interface.dynamic_vertex(v)) {
                [Some(a), Some(b), Some(c)] => {
                    let mut sorted = [a, b, c];
                    sorted.sort_unstable();
                    inside.binary_search(&sorted).is_ok()
                }
                _ => false,
            };
            *slot = if shared { DEAD_TRIANGLE } else { *tri };
        }
        let mut surface = Self {
            buffers,
            dynamic_first: precomputed.surface_triangles().len(),
            bins: Rebinned::empty(),
        };
        // The rest state is finite (validated tables), so this bins.
        surface
            .rebuild(region, dynamic, dynamic_triangles)
            .map_err(|_| SurfaceBufferError {
                buffer: "positions_m",
                expected: need.vertices,
                found: 0,
            })?;
        Ok(surface)
    }

    /// Moves the surface to the current state (module docs): the
    /// tensor-mass slots from `dynamic_triangles` (its surface slots,
    /// renumbered), the positions, the vertex-to-triangle lists, planes and
    /// a new grid. One pass over the slots and three over the vertices,
    /// plus the grid builder's ([`crate::contact::grid::bin`]). A
    /// non-finite position is refused and leaves the grid as it was.
    pub fn rebuild(
        &mut self,
        region: &CondensedRegion<'_, '_, T>,
        dynamic: &TensorMassModel<'_, '_, T>,
        dynamic_triangles: &[[u32; 3]],
    ) -> Result<(), NonFinitePosition> {
        let b = &mut self.buffers;
        let mesh_vertex = &*b.mesh_vertex;
        let table = region.precomputed().table();
        let connections = region.interface().connection_count();
        // A face the tensor-mass region shares with the pre-computed one is
        // inside the organ: its vertices are connection nodes (numbered
        // first) and it is a boundary triangle of the pre-computed table.
        let inside = |tri: &[u32; 3], mapped: [u32; 3]| {
            tri.iter().all(|&d| (d as usize) < connections)
                && match mapped.map(|v| table.vertex(v)) {
                    [Some(a), Some(b), Some(c)] => {
                        table.surface_index().find_triangle([a, b, c]).is_some()
                    }
                    _ => false,
                }
        };
        let slots = b.triangles.get_mut(self.dynamic_first..).unwrap_or(&mut []);
        for (slot, tri) in slots.iter_mut().zip(dynamic_triangles) {
            let mapped = tri.map(|d| mesh_vertex.get(d as usize).copied().unwrap_or(u32::MAX));
            *slot = if *tri == DEAD_TRIANGLE || inside(tri, mapped) {
                DEAD_TRIANGLE
            } else {
                mapped
            };
        }
        let u = dynamic.displacements_m().unwrap_or(&[]);
        let zero = [T::zero(); 3];
        let rest = region.precomputed().table().rest_positions();
        for (v, (x, p)) in b.positions_m.iter_mut().zip(rest).enumerate() {
            let d = region.surface_displacement(u, v as u32).unwrap_or(&zero);
            *x = [p[0] + d[0], p[1] + d[1], p[2] + d[2]];
            if !x.iter().all(|c| c.finite()) {
                return Err(NonFinitePosition { vertex: v as u32 });
            }
        }
        // The tensor-mass slots are copied at every update (a cut changes
        // them), so the lists are always rebuilt.
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
            true,
        );
        Ok(())
    }

    /// Where slot `t` lies; `None` beyond the slots.
    pub fn region_of(&self, t: TriangleIndex) -> Option<SlotRegion> {
        let slots = self.buffers.triangles.len();
        match t.get() {
            s if s < self.dynamic_first => Some(SlotRegion::Precomputed),
            s if s < slots => {
                let d = (s - self.dynamic_first) as u32;
                TriangleIndex::new(d, slots - self.dynamic_first).map(SlotRegion::Dynamic)
            }
            _ => None,
        }
    }

    /// The mesh vertex of each tensor-mass vertex.
    pub fn mesh_vertices(&self) -> &[u32] {
        self.buffers.mesh_vertex
    }

    /// The current vertex positions, m.
    pub fn positions_m(&self) -> &[[T; 3]] {
        self.buffers.positions_m
    }

    /// The surface at the last rebuild, for detection and tracking.
    pub fn geometry<'g>(&'g self, supports: Supports<'g, T>) -> SurfaceGeometry<'g, T> {
        let b = &self.buffers;
        SurfaceGeometry::of_parts(
            b.positions_m,
            self.bins.index(
                b.triangles,
                b.vertex_triangle_start,
                b.vertex_triangle,
                b.planes,
                b.cell_start,
                b.grid_vertex,
            ),
            supports,
        )
    }
}
