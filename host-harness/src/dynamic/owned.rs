//! Heap storage for [`StateBuffers`], sized from a table.

use palpate_kernel::Real;
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::tensor_mass::{StateBuffers, VertexMode};

/// The mutable state of a tensor-mass model in vectors: what firmware keeps
/// in static arrays.
pub struct OwnedState<T> {
    vertex_tensors: Vec<[T; 9]>,
    edge_tensors: Vec<[T; 9]>,
    masses_kg: Vec<T>,
    tet_alive: Vec<bool>,
    live_tets: Vec<u32>,
    modes: Vec<VertexMode>,
    vectors: [Vec<[T; 3]>; 5],
    rk4_scratch: Vec<[T; 3]>,
}

impl<T: Real> OwnedState<T> {
    /// Buffers of the right lengths for `table`, with RK4 scratch.
    pub fn for_table(table: &TensorMassTable<'_, T>) -> Self {
        let n = table.vertex_count();
        let zero = [T::zero(); 3];
        Self {
            vertex_tensors: vec![[T::zero(); 9]; n],
            edge_tensors: vec![[T::zero(); 9]; table.edge_count()],
            masses_kg: vec![T::zero(); n],
            tet_alive: vec![true; table.tet_count()],
            live_tets: vec![0; n],
            modes: vec![VertexMode::Free; n],
            vectors: core::array::from_fn(|_| vec![zero; n]),
            rk4_scratch: vec![zero; 4 * n],
        }
    }

    /// The kernel's view of these buffers.
    pub fn buffers(&mut self) -> StateBuffers<'_, T> {
        let [u, v, previous, external, force] = &mut self.vectors;
        StateBuffers {
            vertex_tensors: &mut self.vertex_tensors,
            edge_tensors: &mut self.edge_tensors,
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
        }
    }
}
