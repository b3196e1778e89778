//! The haptic loop over the hybrid model (RR-3510 §6.2; MODELS.md §5-6): a
//! pre-computed region and a tensor-mass region joined at connection
//! nodes, from three tables (`palpate scene tables`). Contacts on the
//! pre-computed region are solved every tick against the background the
//! connection nodes give it; contacts on the tensor-mass region are held
//! and imposed at the physics rate, as in the dynamic loop.
//!
//! Memory: the tensor-mass region's state, surface and force scratch (as
//! the dynamic loop's), the coupling's buffers and the whole mesh's
//! surface, in one block of `palpate_hybrid_memory_size` bytes; the whole
//! surface's collision grid has room for one cell per mesh vertex.

use core::ffi::c_void;
use palpate_kernel::table::format::PLANE_LEN;

use palpate_kernel::PrecomputedTable;
use palpate_kernel::hybrid::{HybridBuffers, HybridSurfaceBuffers, HybridTissue};
use palpate_kernel::table::{InterfaceTable, TensorMassTable};

use crate::dynamic_loop::DynamicParts;
use crate::error::{Detail, Error, finish};
use crate::handle::{self, Arena, Handle};
use crate::haptic::{Force, Live, LoopConfig, PhysicsConfig, PhysicsReport, Tool, copy_removed};
use crate::status::Status;
use crate::table::{self, Table};
use crate::{M, P};

/// Words of a `palpate_hybrid_loop` on 64-bit targets (the host).
#[cfg(target_pointer_width = "64")]
pub const PALPATE_HYBRID_LOOP_WORDS: usize = 670;
/// Words of a `palpate_hybrid_loop` on 32-bit targets (Cortex-M).
#[cfg(not(target_pointer_width = "64"))]
pub const PALPATE_HYBRID_LOOP_WORDS: usize = 523;

/// A haptic loop over the hybrid model (opaque), as `palpate_dynamic_loop`.
#[repr(C)]
pub struct HybridLoop {
    opaque: [u64; PALPATE_HYBRID_LOOP_WORDS],
}

/// Zeroed, as C's static storage: not initialized until created.
impl Default for HybridLoop {
    fn default() -> Self {
        Self {
            opaque: [0; PALPATE_HYBRID_LOOP_WORDS],
        }
    }
}

// SAFETY: `HybridLoop` is a `#[repr(C)]` struct of `u64` words.
unsafe impl Handle for HybridLoop {
    type Value = Live<HybridTissue<'static, 'static, f32, P, M>>;
    const MAGIC: u32 = u32::from_le_bytes(*b"PHyb");
}

/// The three tables of a hybrid.
struct Tables {
    precomputed: PrecomputedTable<'static, f32>,
    dynamic: TensorMassTable<'static, f32>,
    interface: InterfaceTable<'static, f32>,
}

impl Tables {
    /// The tables of the three handles, each of its kind.
    ///
    /// # Safety
    ///
    /// Each is `NULL` or points to a table whose bytes outlive the loop.
    unsafe fn of(
        precomputed: *const Table,
        dynamic: *const Table,
        interface: *const Table,
    ) -> Result<Self, Status> {
        // SAFETY: the contract (the views are copied; their bytes outlive
        // the loop, hence `'static`).
        unsafe {
            Ok(Self {
                precomputed: *table::view(precomputed)?.precomputed()?,
                dynamic: table::view(dynamic)?.tensor_mass()?,
                interface: table::view(interface)?.interface()?,
            })
        }
    }
}

/// The hybrid's own buffers (the coupling's and the whole surface's) cut
/// from `arena`, after the tensor-mass region's parts.
fn hybrid_parts(
    arena: &mut Arena,
    tables: &Tables,
) -> Result<
    (
        HybridBuffers<'static, f32>,
        HybridSurfaceBuffers<'static, f32>,
    ),
    Status,
> {
    let zero = [0.0f32; 3];
    let coupling = HybridBuffers {
        passed_force_n: arena.take(tables.interface.connection_count(), zero)?,
        background_m: arena.take(tables.interface.free_count(), zero)?,
    };
    // One grid cell per mesh vertex at most.
    let cells = tables.precomputed.vertex_count();
    let l = HybridSurfaceBuffers::<f32>::lengths(&tables.precomputed, &tables.dynamic, cells);
    let surface = HybridSurfaceBuffers {
        positions_m: arena.take(l.vertices, zero)?,
        triangles: arena.take(l.triangles, [0; 3])?,
        planes: arena.take(l.triangles, [0.0; PLANE_LEN])?,
        vertex_triangle_start: arena.take(l.vertices.saturating_add(1), 0)?,
        vertex_triangle: arena.take(l.triangles.saturating_mul(3), 0)?,
        cell_start: arena.take(l.cell_start, 0)?,
        grid_vertex: arena.take(l.vertices, 0)?,
        mesh_vertex: arena.take(l.dynamic_vertices, 0)?,
    };
    Ok((coupling, surface))
}

/// Writes to `bytes` the size of the memory block a hybrid loop over the
/// three tables with `physics` (the tensor-mass region's) needs.
///
/// # Safety
///
/// `precomputed`, `dynamic`, `interface` and `physics` are `NULL` or point
/// to a table of each kind and a `palpate_physics_config`; `bytes` is
/// `NULL` or points to a writable `size_t`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn palpate_hybrid_memory_size(
    precomputed: *const Table,
    dynamic: *const Table,
    interface: *const Table,
    physics: *const PhysicsConfig,
    bytes: *mut usize,
) -> Status {
    let result = (|| -> Result<(), Status> {
        // SAFETY: the contract.
        let tables = unsafe { Tables::of(precomputed, dynamic, interface) }?;
        // SAFETY: the contract.
        let physics = unsafe { handle::read(physics) }?;
        let mut arena = Arena::measure();
        DynamicParts::take(&mut arena, &tables.dynamic, &physics)?;
        hybrid_parts(&mut arena, &tables)?;
        // SAFETY: the contract.
        unsafe { handle::out(bytes, arena.used()) }
    })();
    result.err().unwrap_or(Status::Ok)
}

/// Creates in `haptic` a hybrid loop at rest over its pre-computed region's
/// table `precomputed`, its tensor-mass region's table `dynamic` and the
/// `interface` (the three of one `palpate scene tables` build:
/// `PALPATE_STATUS_HYBRID_MISMATCH` otherwise), as
/// `palpate_dynamic_loop_create`, its buffers in `memory` (at least
/// `palpate_hybrid_memory_size` bytes).
///
/// # Safety
///
/// As `palpate_dynamic_loop_create`, with three table handles.
#[allow(clippy::too_many_arguments)]
#[unsafe(no_mangle)]
pub unsafe extern "C" fn palpate_hybrid_loop_create(
    haptic: *mut HybridLoop,
    precomputed: *const Table,
    dynamic: *const Table,
    interface: *const Table,
    config: *const LoopConfig,
    physics: *const PhysicsConfig,
    memory: *mut c_void,
    memory_bytes: usize,
    error: *mut Error,
) -> Status {
    let result = (|| -> Result<(), Detail> {
        handle::check(haptic)?;
        // SAFETY: the contract.
        let tables = unsafe { Tables::of(precomputed, dynamic, interface) }?;
        // SAFETY: the contract.
        let config = unsafe { handle::read(config) }?;
        // SAFETY: the contract.
        let physics = unsafe { handle::read(physics) }?;
        // SAFETY: the contract: the block is the loop's while it lives.
        let mut arena = unsafe { Arena::over(memory.cast::<u8>(), memory_bytes) }?;
        let parts = DynamicParts::take(&mut arena, &tables.dynamic, &physics)?;
        let (coupling, surface) = hybrid_parts(&mut arena, &tables)?;
        let region = parts.model(tables.dynamic, &physics)?;
        let tissue = HybridTissue::new(
            region.model,
            region.surface,
            region.forces_n,
            physics.physics()?,
            tables.precomputed,
            tables.interface,
            coupling,
            surface,
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

/// One haptic tick, as `palpate_dynamic_loop_tick`: contacts on the
/// pre-computed region are solved every tick, those on the tensor-mass
/// region extrapolated between physics updates.
///
/// # Safety
///
/// As `palpate_precomputed_loop_tick`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn palpate_hybrid_loop_tick(
    haptic: *mut HybridLoop,
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

/// One physics update, as `palpate_dynamic_loop_physics_update`: the
/// pre-computed contacts' forces passed to the connection nodes, the
/// tensor-mass region stepped with the condensed region's force, the
/// background and the whole surface refreshed.
///
/// # Safety
///
/// As `palpate_dynamic_loop_physics_update`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn palpate_hybrid_loop_physics_update(
    haptic: *mut HybridLoop,
    report: *mut PhysicsReport,
    error: *mut Error,
) -> Status {
    let result = (|| -> Result<(), Detail> {
        // SAFETY: the contract.
        let live = unsafe { handle::get_mut(haptic) }?;
        // SAFETY: the contract.
        unsafe { live.physics_update(report, |t| t.dynamic().removed().len()) }
    })();
    // SAFETY: `error` is null or a writable error (contract).
    unsafe { finish(result, error) }
}

/// The tets the last physics update removed (the tensor-mass region's
/// table numbering), as `palpate_dynamic_loop_removed_tets`.
///
/// # Safety
///
/// As `palpate_dynamic_loop_removed_tets`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn palpate_hybrid_loop_removed_tets(
    haptic: *const HybridLoop,
    tets: *mut u32,
    capacity: usize,
    count: *mut usize,
) -> Status {
    // SAFETY: the contract.
    let result = unsafe { handle::get(haptic) }.and_then(|live| {
        let removed = live.haptic.tissue().dynamic().removed();
        // SAFETY: the contract.
        unsafe { copy_removed(removed, tets, capacity, count) }
    });
    result.err().unwrap_or(Status::Ok)
}

/// Back to rest, as `palpate_dynamic_loop_reset` (both regions).
///
/// # Safety
///
/// As `palpate_dynamic_loop_reset`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn palpate_hybrid_loop_reset(haptic: *mut HybridLoop) -> Status {
    // SAFETY: the contract.
    match unsafe { handle::get_mut(haptic) } {
        Ok(live) => {
            live.haptic.reset();
            Status::Ok
        }
        Err(s) => s,
    }
}

/// Writes the displacement of every mesh vertex (m, mesh vertex order) to
/// `displacements_m` (`vertex_count` entries, the interface's vertex
/// count): the tensor-mass region's at the last physics update, the
/// pre-computed region's background plus its response to the last tick's
/// contacts. Refused while the tensor-mass region is faulted.
///
/// # Safety
///
/// As `palpate_dynamic_loop_displacements`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn palpate_hybrid_loop_displacements(
    haptic: *const HybridLoop,
    displacements_m: *mut [f32; 3],
    vertex_count: usize,
    error: *mut Error,
) -> Status {
    let result = (|| -> Result<(), Detail> {
        // SAFETY: the contract.
        let live = unsafe { handle::get(haptic) }?;
        // SAFETY: the contract.
        let out = unsafe { handle::slice_mut(displacements_m, vertex_count) }?;
        let tissue = live.haptic.tissue();
        tissue
            .region()
            .displacements(tissue.dynamic().model(), tissue.solution(), out)?;
        Ok(())
    })();
    // SAFETY: `error` is null or a writable error (contract).
    unsafe { finish(result, error) }
}
