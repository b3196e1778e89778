//! The haptic loop over the dynamic tensor-mass model (RR-3510 §5; MODELS.md
//! §6): the model steps at the physics rate (`palpate_dynamic_loop_physics_update`,
//! every few ticks: contacts imposed, blades cut, tearing, the surface
//! re-binned); between updates each tick extrapolates the force from the
//! local contact stiffness and the tool's motion.
//!
//! Memory: the model's state, its deforming surface and the force scratch
//! live in one block the caller provides, `palpate_dynamic_memory_size`
//! bytes for the table and physics (RK4 and the split St Venant-Kirchhoff
//! form need more); the collision grid has room for one cell per vertex.

use core::ffi::c_void;
use palpate_kernel::table::format::PLANE_LEN;

use palpate_kernel::table::TensorMassTable;
use palpate_kernel::table::format::{
    EDGE_TERMS_LEN, TET_TERMS_LEN, TRIANGLE_TERMS_LEN, VERTEX_TERMS_LEN,
};
use palpate_kernel::tensor_mass::stvk_terms::TermArraysMut;
use palpate_kernel::tensor_mass::{
    DynamicTissue, EdgeGroup, StateBuffers, SurfaceBuffers, TensorMassModel, VertexMode,
};

use crate::P;
use crate::error::{Detail, Error, finish};
use crate::handle::{self, Arena, Handle};
use crate::haptic::{Force, Live, LoopConfig, PhysicsConfig, PhysicsReport, Tool, copy_removed};
use crate::status::Status;
use crate::table::{self, Table};

/// Words of a `palpate_dynamic_loop` on 64-bit targets (the host).
#[cfg(target_pointer_width = "64")]
pub const PALPATE_DYNAMIC_LOOP_WORDS: usize = 476;
/// Words of a `palpate_dynamic_loop` on 32-bit targets (Cortex-M).
#[cfg(not(target_pointer_width = "64"))]
pub const PALPATE_DYNAMIC_LOOP_WORDS: usize = 380;

/// A haptic loop over a tensor-mass table (opaque). Its memory block must
/// outlive it, in place and untouched (the table's bytes too). Do not copy
/// it: pass its address. Not thread-safe: tick and physics update from one
/// task, or under one lock.
#[repr(C)]
pub struct DynamicLoop {
    opaque: [u64; PALPATE_DYNAMIC_LOOP_WORDS],
}

/// Zeroed, as C's static storage: not initialized until created.
impl Default for DynamicLoop {
    fn default() -> Self {
        Self {
            opaque: [0; PALPATE_DYNAMIC_LOOP_WORDS],
        }
    }
}

// SAFETY: `DynamicLoop` is a `#[repr(C)]` struct of `u64` words.
unsafe impl Handle for DynamicLoop {
    type Value = Live<DynamicTissue<'static, 'static, f32, P>>;
    const MAGIC: u32 = u32::from_le_bytes(*b"PDyn");
}

/// The tensor-mass model's state and surface buffers, and the tissue's
/// force scratch, cut from `arena` (empty while measuring) for `table` and
/// `physics`: what `palpate_dynamic_memory_size` counts and
/// `palpate_dynamic_loop_create` (and the hybrid's) cuts.
pub(crate) struct DynamicParts {
    /// The model's state.
    pub(crate) state: StateBuffers<'static, f32>,
    /// The deforming surface's buffers.
    pub(crate) surface: SurfaceBuffers<'static, f32>,
    /// The tissue's force scratch, one per vertex.
    pub(crate) forces_n: &'static mut [[f32; 3]],
}

impl DynamicParts {
    /// Cuts the parts from `arena` (see the type).
    pub(crate) fn take(
        arena: &mut Arena,
        table: &TensorMassTable<'_, f32>,
        physics: &PhysicsConfig,
    ) -> Result<Self, Status> {
        let (n, e, t) = (table.vertex_count(), table.edge_count(), table.tet_count());
        let triangles = table.mesh_triangles().len();
        let rk4 = if physics.needs_rk4() { 4 * n } else { 0 };
        let terms = usize::from(physics.needs_terms());
        let zero = [0.0f32; 3];
        let state = StateBuffers {
            vertex_tensors: arena.take(n, [0.0; 9])?,
            edge_groups: arena.take(StateBuffers::edge_group_count(table), EdgeGroup::default())?,
            edge_group_starts: arena.take(n + 1, 0)?,
            masses_kg: arena.take(n, 0.0)?,
            tet_alive: arena.take(t, false)?,
            live_tets: arena.take(n, 0)?,
            modes: arena.take(n, VertexMode::Free)?,
            displacement_m: arena.take(n, zero)?,
            velocity_m_s: arena.take(n, zero)?,
            previous_displacement_m: arena.take(n, zero)?,
            external_force_n: arena.take(n, zero)?,
            force_n: arena.take(n, zero)?,
            rk4_scratch: arena.take(rk4, zero)?,
            stvk_terms: TermArraysMut {
                vertex: arena.take(n * terms, [0.0; VERTEX_TERMS_LEN])?,
                edge: arena.take(e * terms, [0.0; EDGE_TERMS_LEN])?,
                triangle: arena.take(triangles * terms, [0.0; TRIANGLE_TERMS_LEN])?,
                tet: arena.take(t * terms, [0.0; TET_TERMS_LEN])?,
            },
        };
        // One grid cell per vertex at most: a bucket holds a few vertices.
        let l = SurfaceBuffers::<f32>::table_lengths(table, n);
        let surface = SurfaceBuffers {
            positions_m: arena.take(l.vertices, zero)?,
            triangles: arena.take(l.triangles, [0; 3])?,
            face_slot: arena.take(l.triangles, 0)?,
            slot_tet: arena.take(l.triangles, 0)?,
            planes: arena.take(l.triangles, [0.0; PLANE_LEN])?,
            vertex_triangle_start: arena.take(l.vertex_triangle_start, 0)?,
            vertex_triangle: arena.take(l.vertex_triangle, 0)?,
            cell_start: arena.take(l.cell_start, 0)?,
            grid_vertex: arena.take(l.vertices, 0)?,
        };
        Ok(Self {
            state,
            surface,
            forces_n: arena.take(n, zero)?,
        })
    }

    /// The tensor-mass model of `table` over these parts' state, with
    /// `physics`'s parameters, and the rest of the parts.
    pub(crate) fn model(
        self,
        table: TensorMassTable<'static, f32>,
        physics: &PhysicsConfig,
    ) -> Result<Region, Detail> {
        Ok(Region {
            model: TensorMassModel::new(table, self.state, physics.params()?)?,
            surface: self.surface,
            forces_n: self.forces_n,
        })
    }
}

/// The tensor-mass model over its state, and what its tissue takes besides.
pub(crate) struct Region {
    /// The model.
    pub(crate) model: TensorMassModel<'static, 'static, f32>,
    /// The deforming surface's buffers.
    pub(crate) surface: SurfaceBuffers<'static, f32>,
    /// The tissue's force scratch.
    pub(crate) forces_n: &'static mut [[f32; 3]],
}

/// Writes to `bytes` the size of the memory block a dynamic loop over
/// tensor-mass table `table` with `physics` needs (aligned to
/// `PALPATE_MEMORY_ALIGN`): `141 N + 36 E + 72 F + T` bytes and a few of
/// alignment for `N` vertices, `E` edges, `F` mesh triangles (every tet
/// face once) and `T` tets; RK4 adds `48 N`, the split St Venant-Kirchhoff
/// form `16 N + 64 E + 60 F + 12 T`. The firmware box (64 vertices, 279
/// edges, 378 faces, 162 tets): 46 456 bytes.
///
/// # Safety
///
/// `table` and `physics` are `NULL` or point to a table and a
/// `palpate_physics_config`; `bytes` is `NULL` or points to a writable
/// `size_t`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn palpate_dynamic_memory_size(
    table: *const Table,
    physics: *const PhysicsConfig,
    bytes: *mut usize,
) -> Status {
    let result = (|| -> Result<(), Status> {
        // SAFETY: the contract.
        let table = unsafe { table::view(table) }?.tensor_mass()?;
        // SAFETY: the contract.
        let physics = unsafe { handle::read(physics) }?;
        let mut arena = Arena::measure();
        DynamicParts::take(&mut arena, &table, &physics)?;
        // SAFETY: the contract.
        unsafe { handle::out(bytes, arena.used()) }
    })();
    result.err().unwrap_or(Status::Ok)
}

/// Creates in `haptic` a loop at rest over tensor-mass table `table` with
/// `config` and `physics`, its buffers in `memory` (`memory_bytes` bytes,
/// aligned to `PALPATE_MEMORY_ALIGN`, at least
/// `palpate_dynamic_memory_size`). The memory's contents are overwritten;
/// it must outlive the loop, in place and untouched. Refused: a table of
/// another kind, bad configuration or physics (`PALPATE_STATUS_BAD_ARGUMENT`
/// for an enum value out of range, the kernel's code otherwise), too
/// little memory. On failure `haptic` is marked not initialized.
///
/// # Safety
///
/// `haptic` is `NULL` or points to a writable `palpate_dynamic_loop`;
/// `table` is `NULL` or points to a table whose bytes outlive the loop;
/// `config` and `physics` are `NULL` or point to their structs; `memory` is
/// `NULL` or points to `memory_bytes` writable bytes nothing else uses
/// while the loop lives; `error` is `NULL` or points to a writable
/// `palpate_error`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn palpate_dynamic_loop_create(
    haptic: *mut DynamicLoop,
    table: *const Table,
    config: *const LoopConfig,
    physics: *const PhysicsConfig,
    memory: *mut c_void,
    memory_bytes: usize,
    error: *mut Error,
) -> Status {
    let result = (|| -> Result<(), Detail> {
        handle::check(haptic)?;
        // SAFETY: the contract (the table view is copied into the loop;
        // its bytes outlive the loop, hence `'static`).
        let table = unsafe { table::view(table) }?.tensor_mass()?;
        // SAFETY: the contract.
        let config = unsafe { handle::read(config) }?;
        // SAFETY: the contract.
        let physics = unsafe { handle::read(physics) }?;
        // SAFETY: the contract: the block is the loop's while it lives.
        let mut arena = unsafe { Arena::over(memory.cast::<u8>(), memory_bytes) }?;
        let parts = DynamicParts::take(&mut arena, &table, &physics)?;
        let region = parts.model(table, &physics)?;
        let tissue = DynamicTissue::new(
            region.model,
            region.surface,
            region.forces_n,
            physics.physics()?,
        )?;
        let live = Live::new(tissue, &config)?;
        // SAFETY: `haptic` is a writable handle (contract, checked).
        unsafe { handle::init(haptic, live) }?;
        Ok(())
    })();
    if result.is_err() {
        // SAFETY: as above.
        unsafe { handle::clear(haptic) };
    }
    // SAFETY: `error` is null or a writable error (contract).
    unsafe { finish(result, error) }
}

/// One haptic tick, as `palpate_precomputed_loop_tick`: between physics
/// updates the force is extrapolated from the contact stiffness and the
/// tool's motion; a blade (`PALPATE_TOOL_ACTION_CUT`) cuts at the next update.
///
/// # Safety
///
/// As `palpate_precomputed_loop_tick`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn palpate_dynamic_loop_tick(
    haptic: *mut DynamicLoop,
    tools: *const Tool,
    count: usize,
    force: *mut Force,
) -> Status {
    // SAFETY: the contract.
    let result = unsafe { handle::get_mut(haptic) }
        // SAFETY: the contract.
        .and_then(|live| unsafe { live.tick(tools, count, force) });
    result.err().unwrap_or(Status::Ok)
}

/// One physics update with the current contacts at the last tick's tool
/// positions and its blades: cut, impose, `substeps` steps, tear, re-bin
/// the surface (call it every few ticks, after a tick). Its report to
/// `report` (may be `NULL`). On failure (divergence: `PALPATE_STATUS_FAULT_*`)
/// the next tick latches a model fault (zero force) until
/// `palpate_dynamic_loop_reset`.
///
/// # Safety
///
/// `haptic` is `NULL` or points to a loop nothing else uses during the
/// call; `report` is `NULL` or points to a writable
/// `palpate_physics_report`; `error` is `NULL` or points to a writable
/// `palpate_error`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn palpate_dynamic_loop_physics_update(
    haptic: *mut DynamicLoop,
    report: *mut PhysicsReport,
    error: *mut Error,
) -> Status {
    let result = (|| -> Result<(), Detail> {
        // SAFETY: the contract.
        let live = unsafe { handle::get_mut(haptic) }?;
        // SAFETY: the contract.
        unsafe { live.physics_update(report, |t| t.removed().len()) }
    })();
    // SAFETY: `error` is null or a writable error (contract).
    unsafe { finish(result, error) }
}

/// Copies the tets the last physics update removed (tensor-mass table
/// numbering, removal order) to `tets` (`capacity` entries; may be `NULL`
/// when 0) and their number to `count`. `PALPATE_STATUS_BAD_ARGUMENT` when they
/// do not fit (`count` is still written).
///
/// # Safety
///
/// `haptic` is `NULL` or points to a loop; `tets` is `NULL` or points to
/// `capacity` writable `uint32_t`; `count` is `NULL` or points to a
/// writable `size_t`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn palpate_dynamic_loop_removed_tets(
    haptic: *const DynamicLoop,
    tets: *mut u32,
    capacity: usize,
    count: *mut usize,
) -> Status {
    // SAFETY: the contract.
    let result = unsafe { handle::get(haptic) }
        // SAFETY: the contract.
        .and_then(|live| unsafe {
            copy_removed(live.haptic.tissue().removed(), tets, capacity, count)
        });
    result.err().unwrap_or(Status::Ok)
}

/// Back to rest: every tet alive again, no contact, no fault; the force
/// ramps up from zero at the slew limit.
///
/// # Safety
///
/// `haptic` is `NULL` or points to a loop nothing else uses during the call.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn palpate_dynamic_loop_reset(haptic: *mut DynamicLoop) -> Status {
    // SAFETY: the contract.
    match unsafe { handle::get_mut(haptic) } {
        Ok(live) => {
            live.haptic.reset();
            Status::Ok
        }
        Err(s) => s,
    }
}

/// Writes the displacement of every vertex (m, table vertex order) at the
/// last physics update to `displacements_m` (`vertex_count` entries).
/// Refused while the model is faulted (`PALPATE_STATUS_FAULT_*`).
///
/// # Safety
///
/// `haptic` is `NULL` or points to a loop; `displacements_m` is `NULL` or
/// points to `vertex_count` writable, 4-byte-aligned `float[3]`; `error`
/// is `NULL` or points to a writable `palpate_error`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn palpate_dynamic_loop_displacements(
    haptic: *const DynamicLoop,
    displacements_m: *mut [f32; 3],
    vertex_count: usize,
    error: *mut Error,
) -> Status {
    let result = (|| -> Result<(), Detail> {
        // SAFETY: the contract.
        let live = unsafe { handle::get(haptic) }?;
        // SAFETY: the contract.
        let out = unsafe { handle::slice_mut(displacements_m, vertex_count) }?;
        let u = live.haptic.tissue().model().displacements_m()?;
        if u.len() != out.len() {
            return Err(palpate_kernel::precomputed::DisplacementError {
                expected: u.len(),
                found: out.len(),
            }
            .into());
        }
        for (o, u) in out.iter_mut().zip(u) {
            *o = *u;
        }
        Ok(())
    })();
    // SAFETY: `error` is null or a writable error (contract).
    unsafe { finish(result, error) }
}
