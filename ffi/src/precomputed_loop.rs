//! The haptic loop over the pre-computed model (Cotin 1999; MODELS.md §6):
//! the contact solve runs every tick (the local contact stiffness applied
//! to the tool's displacement, exact for the linear model); the
//! displacement field is the renderer's call, at its own rate. No memory
//! beyond the handle: the table is read in place.

use palpate_kernel::precomputed::{Constraint, PrecomputedTissue};
use palpate_kernel::{ContactSolution, PrecomputedModel};

use crate::M;
use crate::error::{Detail, Error, finish};
use crate::handle::{self, Handle};
use crate::haptic::{Force, Live, LoopConfig, Tool};
use crate::status::Status;
use crate::table::{self, Table};

/// Words of a `palpate_precomputed_loop` on 64-bit targets (the host).
#[cfg(target_pointer_width = "64")]
pub const PALPATE_PRECOMPUTED_LOOP_WORDS: usize = 402;
/// Words of a `palpate_precomputed_loop` on 32-bit targets (Cortex-M).
#[cfg(not(target_pointer_width = "64"))]
pub const PALPATE_PRECOMPUTED_LOOP_WORDS: usize = 356;

/// A haptic loop over a pre-computed table (opaque). It reads its table
/// handle, which must outlive it and stay in place. Do not copy it: pass
/// its address. Not thread-safe: one caller at a time (the haptic task).
#[repr(C)]
pub struct PrecomputedLoop {
    opaque: [u64; PALPATE_PRECOMPUTED_LOOP_WORDS],
}

/// Zeroed, as C's static storage: not initialized until created.
impl Default for PrecomputedLoop {
    fn default() -> Self {
        Self {
            opaque: [0; PALPATE_PRECOMPUTED_LOOP_WORDS],
        }
    }
}

// SAFETY: `PrecomputedLoop` is a `#[repr(C)]` struct of `u64` words.
unsafe impl Handle for PrecomputedLoop {
    type Value = Live<PrecomputedTissue<'static, f32, M>>;
    const MAGIC: u32 = u32::from_le_bytes(*b"PPre");
}

/// Creates in `haptic` a loop at rest (no contact, zero force) over
/// pre-computed table `table` with `config`. Refused: a table of another
/// kind, `tool_points` outside 1 to `PALPATE_TOOL_POINTS`
/// (`PALPATE_STATUS_BAD_ARGUMENT`), a radius or period not finite and
/// positive, limits not finite and positive. On failure `haptic` is marked
/// not initialized.
///
/// # Safety
///
/// `haptic` is `NULL` or points to a writable `palpate_precomputed_loop`;
/// `table` is `NULL` or points to a table that outlives the loop, in place;
/// `config` is `NULL` or points to a `palpate_loop_config`; `error` is
/// `NULL` or points to a writable `palpate_error`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn palpate_precomputed_loop_create(
    haptic: *mut PrecomputedLoop,
    table: *const Table,
    config: *const LoopConfig,
    error: *mut Error,
) -> Status {
    let result = (|| -> Result<(), Detail> {
        handle::check(haptic)?;
        // SAFETY: `table` is null or a table handle that outlives the loop
        // in place (contract; hence `'static`).
        let table = unsafe { table::view(table) }?.precomputed()?;
        // SAFETY: `config` is null or a readable configuration (contract).
        let config = unsafe { handle::read(config) }?;
        let live = Live::new(PrecomputedTissue::new(table), &config)?;
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

/// One haptic tick: the `count` tool points at `tools` (`count` is the
/// loop's `tool_points`) are tracked or detected on the surface, the
/// contacts solved, the force passed through the supervisor; the result to
/// `force`. A non-finite position or a model fault is not a failure of the
/// call: it latches a fault in `force->status` (zero force until
/// `palpate_precomputed_loop_reset`). Bounded: detection and tracking per
/// point, at most `PALPATE_TOOL_POINTS + 1` solves of at most
/// `PALPATE_MAX_CONTACTS` contacts.
///
/// # Safety
///
/// `haptic` is `NULL` or points to a loop nothing else uses during the
/// call; `tools` is `NULL` or points to `count` readable `palpate_tool`;
/// `force` is `NULL` or points to a writable `palpate_force`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn palpate_precomputed_loop_tick(
    haptic: *mut PrecomputedLoop,
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

/// Clears a latched fault and every contact; the force ramps up from zero
/// at the slew limit.
///
/// # Safety
///
/// `haptic` is `NULL` or points to a loop nothing else uses during the call.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn palpate_precomputed_loop_reset(haptic: *mut PrecomputedLoop) -> Status {
    // SAFETY: the contract.
    match unsafe { handle::get_mut(haptic) } {
        Ok(live) => {
            live.haptic.reset();
            Status::Ok
        }
        Err(s) => s,
    }
}

/// Writes the displacement of every vertex (m, mesh vertex order) for the
/// last tick's contacts to `displacements_m` (`vertex_count` entries: the
/// table's vertex count); all zero before the first contact and after a
/// fault. For a renderer, at its own rate: `O(F)` per contact term, not on
/// the haptic path.
///
/// # Safety
///
/// `haptic` is `NULL` or points to a loop; `displacements_m` is `NULL` or
/// points to `vertex_count` writable, 4-byte-aligned `float[3]`; `error`
/// is `NULL` or points to a writable `palpate_error`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn palpate_precomputed_loop_displacements(
    haptic: *const PrecomputedLoop,
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
        let model: &PrecomputedModel<'_, f32> = tissue.model();
        // Before the first contact: the empty set's solution (zero field).
        let at_rest: ContactSolution<f32, M>;
        let solution = match tissue.solution() {
            Some(s) => s,
            None => {
                at_rest = model.contact_forces::<M>(&[] as &[Constraint<f32>])?;
                &at_rest
            }
        };
        model.displacements(solution, out)?;
        Ok(())
    })();
    // SAFETY: `error` is null or a writable error (contract).
    unsafe { finish(result, error) }
}
