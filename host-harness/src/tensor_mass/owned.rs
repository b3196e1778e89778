//! Heap storage for [`StateBuffers`] and [`SurfaceBuffers`], sized from a
//! table.

use palpate_kernel::Real;
use palpate_kernel::table::Plane;
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::table::format::PLANE_LEN;
use palpate_kernel::table::format::{
    EDGE_TERMS_LEN, TET_TERMS_LEN, TRIANGLE_TERMS_LEN, VERTEX_TERMS_LEN,
};
use palpate_kernel::tensor_mass::SurfaceBuffers;
use palpate_kernel::tensor_mass::stvk_terms::TermArraysMut;
use palpate_kernel::tensor_mass::{EdgeGroup, StateBuffers, TensorMassModel, VertexMode};

/// The mutable state of a tensor-mass model in vectors: what firmware keeps
/// in static arrays.
pub struct OwnedState<T> {
    vertex_tensors: Vec<[T; 9]>,
    edge_groups: Vec<EdgeGroup<T>>,
    edge_group_starts: Vec<u32>,
    masses_kg: Vec<T>,
    tet_alive: Vec<bool>,
    live_tets: Vec<u32>,
    modes: Vec<VertexMode>,
    vectors: [Vec<[T; 3]>; 5],
    rk4_scratch: Vec<[T; 3]>,
    vertex_terms: Vec<[T; VERTEX_TERMS_LEN]>,
    edge_terms: Vec<[T; EDGE_TERMS_LEN]>,
    triangle_terms: Vec<[T; TRIANGLE_TERMS_LEN]>,
    tet_terms: Vec<[T; TET_TERMS_LEN]>,
}

impl<T: Real> OwnedState<T> {
    /// Buffers of the right lengths for `table`, with RK4 scratch and the
    /// St Venant-Kirchhoff split terms (every law and integrator works).
    pub fn for_table(table: &TensorMassTable<'_, T>) -> Self {
        let n = table.vertex_count();
        let zero = [T::zero(); 3];
        Self {
            vertex_tensors: vec![[T::zero(); 9]; n],
            edge_groups: vec![EdgeGroup::default(); StateBuffers::edge_group_count(table)],
            edge_group_starts: vec![0; n + 1],
            masses_kg: vec![T::zero(); n],
            tet_alive: vec![true; table.tet_count()],
            live_tets: vec![0; n],
            modes: vec![VertexMode::Free; n],
            vectors: core::array::from_fn(|_| vec![zero; n]),
            rk4_scratch: vec![zero; 4 * n],
            vertex_terms: vec![[T::zero(); VERTEX_TERMS_LEN]; n],
            edge_terms: vec![[T::zero(); EDGE_TERMS_LEN]; table.edge_count()],
            triangle_terms: vec![[T::zero(); TRIANGLE_TERMS_LEN]; table.mesh_triangles().len()],
            tet_terms: vec![[T::zero(); TET_TERMS_LEN]; table.tet_count()],
        }
    }

    /// The same without the St Venant-Kirchhoff split-term buffers: the
    /// tensors form is then refused, and a cut skips the terms' subtraction.
    pub fn without_split_terms(mut self) -> Self {
        self.vertex_terms = Vec::new();
        self.edge_terms = Vec::new();
        self.triangle_terms = Vec::new();
        self.tet_terms = Vec::new();
        self
    }

    /// The kernel's view of these buffers.
    pub fn buffers(&mut self) -> StateBuffers<'_, T> {
        let [u, v, previous, external, force] = &mut self.vectors;
        StateBuffers {
            vertex_tensors: &mut self.vertex_tensors,
            edge_groups: &mut self.edge_groups,
            edge_group_starts: &mut self.edge_group_starts,
            masses_kg: &mut self.masses_kg,
            tet_alive: &mut self.tet_alive,
            live_tets: &mut self.live_tets,
            modes: &mut self.modes,
            displacement_m: u,
            velocity_m_s: v,
            previous_displacement_m: previous,
            external_force_n: external,
            force_n: force,
            rk4_scratch: &mut self.rk4_scratch,
            stvk_terms: TermArraysMut {
                vertex: &mut self.vertex_terms,
                edge: &mut self.edge_terms,
                triangle: &mut self.triangle_terms,
                tet: &mut self.tet_terms,
            },
        }
    }
}

/// Heap storage for a deforming surface's [`SurfaceBuffers`] and the
/// dynamic tissue's force scratch (what firmware keeps in static arrays).
pub struct OwnedSurface<T> {
    positions_m: Vec<[T; 3]>,
    triangles: Vec<[u32; 3]>,
    face_slot: Vec<u32>,
    slot_tet: Vec<u32>,
    planes: Vec<Plane<T>>,
    vertex_triangle_start: Vec<u32>,
    vertex_triangle: Vec<u32>,
    cell_start: Vec<u32>,
    grid_vertex: Vec<u32>,
    forces_n: Vec<[T; 3]>,
}

impl<T: Real> OwnedSurface<T> {
    /// Buffers for `model`'s table with a grid of up to one cell per
    /// surface vertex (a bucket then holds a few vertices on average).
    pub fn for_model(model: &TensorMassModel<'_, '_, T>) -> Self {
        let surface_vertices = {
            let mut seen = vec![false; model.table().vertex_count()];
            for &v in model.table().surface_triangles().iter().flatten() {
                seen[v as usize] = true;
            }
            seen.iter().filter(|&&s| s).count()
        };
        let n = SurfaceBuffers::<T>::lengths(model, surface_vertices);
        Self {
            positions_m: vec![[T::zero(); 3]; n.vertices],
            triangles: vec![[0; 3]; n.triangles],
            face_slot: vec![0; n.triangles],
            slot_tet: vec![0; n.triangles],
            planes: vec![[T::zero(); PLANE_LEN]; n.triangles],
            vertex_triangle_start: vec![0; n.vertex_triangle_start],
            vertex_triangle: vec![0; n.vertex_triangle],
            cell_start: vec![0; n.cell_start],
            grid_vertex: vec![0; n.vertices],
            forces_n: vec![[T::zero(); 3]; n.vertices],
        }
    }

    /// The kernel's view of the surface buffers and the force scratch.
    pub fn buffers(&mut self) -> (SurfaceBuffers<'_, T>, &mut [[T; 3]]) {
        (
            SurfaceBuffers {
                positions_m: &mut self.positions_m,
                triangles: &mut self.triangles,
                face_slot: &mut self.face_slot,
                slot_tet: &mut self.slot_tet,
                planes: &mut self.planes,
                vertex_triangle_start: &mut self.vertex_triangle_start,
                vertex_triangle: &mut self.vertex_triangle,
                cell_start: &mut self.cell_start,
                grid_vertex: &mut self.grid_vertex,
            },
            &mut self.forces_n,
        )
    }
}
