//! The tensor-mass model's buffers from the arena, of the lengths the host's
//! heap-owned ones have (`palpate::tensor_mass::OwnedState::for_table`,
//! `OwnedSurface::for_model`): the state with RK4 scratch, the St
//! Venant-Kirchhoff split terms only for the law that reads them, and the
//! deforming surface with one grid cell per surface vertex.

use palpate_kernel::table::TensorMassTable;
use palpate_kernel::table::format::PLANE_LEN;
use palpate_kernel::table::format::{
    EDGE_TERMS_LEN, TET_TERMS_LEN, TRIANGLE_TERMS_LEN, VERTEX_TERMS_LEN,
};
use palpate_kernel::tensor_mass::stvk_terms::TermArraysMut;
use palpate_kernel::tensor_mass::{
    DynamicParams, EdgeGroup, ElasticLaw, StateBuffers, StvkForm, SurfaceBuffers, TensorMassModel,
    VertexMode,
};

use crate::arena::Arena;

/// A tensor-mass model, its surface buffers and its force scratch.
pub type ModelParts<'a> = (
    TensorMassModel<'a, 'a, f32>,
    SurfaceBuffers<'a, f32>,
    &'a mut [[f32; 3]],
);

/// The tensor-mass model of `table` with `params` at rest, its surface
/// buffers and force scratch; `Err` names what failed.
pub fn model_parts<'a>(
    arena: &'a Arena,
    table: TensorMassTable<'a, f32>,
    params: DynamicParams<f32>,
) -> Result<ModelParts<'a>, &'static str> {
    let full = "arena full";
    let n = table.vertex_count();
    let e = table.edge_count();
    let zero = [0.0f32; 3];
    // Split terms only for the form that reads them (as the host's).
    let terms = params.law == ElasticLaw::StVenantKirchhoff(StvkForm::Tensors);
    let split = |len: usize| if terms { len } else { 0 };
    let state = StateBuffers {
        vertex_tensors: arena.slice(n, [0.0; 9]).ok_or(full)?,
        edge_groups: arena
            .slice(StateBuffers::edge_group_count(&table), EdgeGroup::default())
            .ok_or(full)?,
        edge_group_starts: arena.slice(n + 1, 0).ok_or(full)?,
        masses_kg: arena.slice(n, 0.0).ok_or(full)?,
        tet_alive: arena.slice(table.tet_count(), true).ok_or(full)?,
        live_tets: arena.slice(n, 0).ok_or(full)?,
        modes: arena.slice(n, VertexMode::Free).ok_or(full)?,
        displacement_m: arena.slice(n, zero).ok_or(full)?,
        velocity_m_s: arena.slice(n, zero).ok_or(full)?,
        previous_displacement_m: arena.slice(n, zero).ok_or(full)?,
        external_force_n: arena.slice(n, zero).ok_or(full)?,
        force_n: arena.slice(n, zero).ok_or(full)?,
        rk4_scratch: arena.slice(4 * n, zero).ok_or(full)?,
        stvk_terms: TermArraysMut {
            vertex: arena.slice(split(n), [0.0; VERTEX_TERMS_LEN]).ok_or(full)?,
            edge: arena.slice(split(e), [0.0; EDGE_TERMS_LEN]).ok_or(full)?,
            triangle: arena
                .slice(
                    split(table.mesh_triangles().len()),
                    [0.0; TRIANGLE_TERMS_LEN],
                )
                .ok_or(full)?,
            tet: arena
                .slice(split(table.tet_count()), [0.0; TET_TERMS_LEN])
                .ok_or(full)?,
        },
    };
    let model = TensorMassModel::new(table, state, params).map_err(|_| "tensor-mass model")?;
    // One grid cell per surface vertex.
    let seen = arena.slice(n, false).ok_or(full)?;
    for &v in model.table().surface_triangles().iter().flatten() {
        if let Some(s) = seen.get_mut(v as usize) {
            *s = true;
        }
    }
    let cells = seen.iter().filter(|&&s| s).count();
    let l = SurfaceBuffers::<f32>::lengths(&model, cells);
    let surface = SurfaceBuffers {
        positions_m: arena.slice(l.vertices, zero).ok_or(full)?,
        triangles: arena.slice(l.triangles, [0; 3]).ok_or(full)?,
        face_slot: arena.slice(l.triangles, 0).ok_or(full)?,
        slot_tet: arena.slice(l.triangles, 0).ok_or(full)?,
        planes: arena.slice(l.triangles, [0.0; PLANE_LEN]).ok_or(full)?,
        vertex_triangle_start: arena.slice(l.vertex_triangle_start, 0).ok_or(full)?,
        vertex_triangle: arena.slice(l.vertex_triangle, 0).ok_or(full)?,
        cell_start: arena.slice(l.cell_start, 0).ok_or(full)?,
        grid_vertex: arena.slice(l.vertices, 0).ok_or(full)?,
    };
    let forces = arena.slice(l.vertices, zero).ok_or(full)?;
    Ok((model, surface, forces))
}
