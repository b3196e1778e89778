//! The kernel's hybrid model over heap buffers, for the harness's runs and
//! tests (firmware keeps the same buffers in static arrays).

use anyhow::{Context, anyhow};
use palpate_kernel::hybrid::{HybridBuffers, HybridModel, HybridSurfaceBuffers, HybridTissue};
use palpate_kernel::table::Plane;
use palpate_kernel::table::format::PLANE_LEN;
use palpate_kernel::table::{InterfaceTable, TensorMassTable};
use palpate_kernel::tensor_mass::{DynamicParams, PhysicsConfig, TensorMassModel};
use palpate_kernel::{PrecomputedTable, Real};

use super::build::HybridTables;
use crate::table::load::TableFile;
use crate::tensor_mass::{OwnedState, OwnedSurface};

/// Loads `tables` in precision `T`, builds the hybrid model with `params`
/// for its tensor-mass region over heap buffers, and runs `run` on it.
pub fn with_hybrid<T: Real, R>(
    tables: &HybridTables,
    params: DynamicParams<T>,
    run: impl FnOnce(&mut HybridModel<'_, '_, T>) -> R,
) -> anyhow::Result<R> {
    with_hybrid_files(
        [&tables.precomputed, &tables.dynamic, &tables.interface],
        params,
        run,
    )
}

/// [`with_hybrid`] on the three tables given as files: pre-computed region,
/// tensor-mass region, interface (`palpate scene tables` writes them).
pub fn with_hybrid_files<T: Real, R>(
    files: [&TableFile; 3],
    params: DynamicParams<T>,
    run: impl FnOnce(&mut HybridModel<'_, '_, T>) -> R,
) -> anyhow::Result<R> {
    with_parts(files, params, |model, precomputed, interface, owned| {
        let (buffers, _) = owned.buffers();
        let mut hybrid = HybridModel::new(model, precomputed, interface, buffers)?;
        Ok(run(&mut hybrid))
    })
}

/// Builds the hybrid tissue (`P` tool points, `M` contacts) of the three
/// tables given as files, its tensor-mass region with `params` and
/// `physics`, over heap buffers, and runs `run` on it (tests and benches:
/// wrap it in a `HybridLoop`).
pub fn with_hybrid_tissue<T: Real, const P: usize, const M: usize, R>(
    files: [&TableFile; 3],
    params: DynamicParams<T>,
    physics: PhysicsConfig<T>,
    run: impl FnOnce(HybridTissue<'_, '_, T, P, M>) -> R,
) -> anyhow::Result<R> {
    with_parts(files, params, |model, precomputed, interface, owned| {
        let mut surface = OwnedSurface::for_model(&model);
        let (surface_buffers, forces) = surface.buffers();
        let (coupling, hybrid_surface) = owned.buffers();
        let tissue = HybridTissue::new(
            model,
            surface_buffers,
            forces,
            physics,
            precomputed,
            interface,
            coupling,
            hybrid_surface,
        )?;
        Ok(run(tissue))
    })
}

/// Loads the three tables in precision `T` and builds the tensor-mass
/// region's model with `params` over heap buffers; runs `body` on the
/// model, the two other tables and the hybrid's own buffers.
fn with_parts<T: Real, R>(
    [precomputed, dynamic, interface]: [&TableFile; 3],
    params: DynamicParams<T>,
    body: impl FnOnce(
        TensorMassModel<'_, '_, T>,
        PrecomputedTable<'_, T>,
        InterfaceTable<'_, T>,
        &mut OwnedHybridBuffers<T>,
    ) -> anyhow::Result<R>,
) -> anyhow::Result<R> {
    let precomputed =
        PrecomputedTable::<T>::load(precomputed.bytes()).context("pre-computed region")?;
    let dynamic = TensorMassTable::<T>::load(dynamic.bytes()).context("tensor-mass region")?;
    let interface = InterfaceTable::<T>::load(interface.bytes()).context("interface")?;
    let mut state = OwnedState::for_table(&dynamic);
    let mut owned = OwnedHybridBuffers::for_tables(&precomputed, &dynamic, &interface);
    let model = TensorMassModel::new(dynamic, state.buffers(), params)
        .map_err(|e| anyhow!("tensor-mass region: {e}"))?;
    body(model, precomputed, interface, &mut owned)
}

/// Heap storage for a hybrid tissue's own buffers: the coupling's
/// ([`HybridBuffers`]) and the whole surface's ([`HybridSurfaceBuffers`]).
pub struct OwnedHybridBuffers<T> {
    passed_force_n: Vec<[T; 3]>,
    background_m: Vec<[T; 3]>,
    positions_m: Vec<[T; 3]>,
    triangles: Vec<[u32; 3]>,
    planes: Vec<Plane<T>>,
    vertex_triangle_start: Vec<u32>,
    vertex_triangle: Vec<u32>,
    cell_start: Vec<u32>,
    grid_vertex: Vec<u32>,
    mesh_vertex: Vec<u32>,
}

impl<T: Real> OwnedHybridBuffers<T> {
    /// Buffers for the three tables, with a grid of up to one cell per
    /// mesh vertex.
    pub fn for_tables(
        precomputed: &PrecomputedTable<'_, T>,
        dynamic: &TensorMassTable<'_, T>,
        interface: &InterfaceTable<'_, T>,
    ) -> Self {
        let n =
            HybridSurfaceBuffers::<T>::lengths(precomputed, dynamic, precomputed.vertex_count());
        let zero = [T::zero(); 3];
        Self {
            passed_force_n: vec![zero; interface.connection_count()],
            background_m: vec![zero; interface.free_count()],
            positions_m: vec![zero; n.vertices],
            triangles: vec![[0; 3]; n.triangles],
            planes: vec![[T::zero(); PLANE_LEN]; n.triangles],
            vertex_triangle_start: vec![0; n.vertices + 1],
            vertex_triangle: vec![0; 3 * n.triangles],
            cell_start: vec![0; n.cell_start],
            grid_vertex: vec![0; n.vertices],
            mesh_vertex: vec![0; n.dynamic_vertices],
        }
    }

    /// The kernel's views of the coupling and surface buffers.
    pub fn buffers(&mut self) -> (HybridBuffers<'_, T>, HybridSurfaceBuffers<'_, T>) {
        (
            HybridBuffers {
                passed_force_n: &mut self.passed_force_n,
                background_m: &mut self.background_m,
            },
            HybridSurfaceBuffers {
                positions_m: &mut self.positions_m,
                triangles: &mut self.triangles,
                planes: &mut self.planes,
                vertex_triangle_start: &mut self.vertex_triangle_start,
                vertex_triangle: &mut self.vertex_triangle,
                cell_start: &mut self.cell_start,
                grid_vertex: &mut self.grid_vertex,
                mesh_vertex: &mut self.mesh_vertex,
            },
        )
    }
}
