//! The C ABI of the Palpate kernel (`include/palpate.h`, generated from this
//! crate by `tools/ffi-header`): what a device controller's C firmware
//! links to run the haptic loop.
//!
//! - Tables ([`table`]): load and validate a pre-computed, tensor-mass or
//!   interface table from a pointer and a length (flash or RAM), once.
//! - The pre-computed solve ([`solve`]): a scripted contact set's forces and
//!   the displacement field (RR-3510 §4; what `palpate precomputed replay`
//!   runs).
//! - The haptic loops ([`precomputed_loop`], [`dynamic_loop`],
//!   [`hybrid_loop`]): create over caller memory (the caller asks for the
//!   sizes first), tick with the tool points, read force and status, reset
//!   after a fault, physics updates (tensor-mass and hybrid), the
//!   displacement field for a renderer.
//! - Every function returns a [`status::Status`]; a failure's details
//!   (which contact, which vertex, which section) are in an optional
//!   [`error::Error`], formatted by `palpate_error_message`.
//!
//! Memory: no allocation. Every object lives in memory the caller provides:
//! the handles are fixed-size structs (their sizes are in the header, per
//! pointer width), the dynamic and hybrid loops' buffers one block whose
//! size `palpate_*_memory_size` gives. Handles are opaque; a handle whose
//! creation failed is refused by every function
//! ([`status::Status::NotInitialized`]).
//!
//! Nothing panics across the boundary: the entry points use no indexing,
//! `unwrap` or `panic!` (denied by this crate's lints), and
//! `tools/firmware-check.sh --c` links every entry point for the Cortex-M4F
//! against a panic handler that calls a function defined nowhere (feature
//! `prove-no-panic`): the link fails if any panic is reachable. On the host
//! the crate links `std`, and a panic (none is reachable) would abort, never
//! unwind into C.
//!
//! Capacities: the kernel's types are generic over capacities; the ABI
//! fixes them ([`PALPATE_TOOL_POINTS`], [`PALPATE_MAX_CONTACTS`]) and the
//! scalar (f32, the firmware precision: tables built with
//! `--precision f32`).
#![no_std]

// The host build (the C test program, the Rust tests) links std, for its
// panic handler (`panic = "abort"` in the release profile; a panic in an
// `extern "C"` function aborts in any profile). Firmware builds have none.
#[cfg(not(target_os = "none"))]
extern crate std;

// In the header's order (cbindgen reads the modules in this order): status
// codes and errors, tables, the scripted solve, the loops.
mod handle;

pub mod status;

pub mod error;

pub mod table;

pub mod solve;

pub mod haptic;

pub mod precomputed_loop;

pub mod dynamic_loop;

pub mod hybrid_loop;

use palpate_kernel::MAX_CONTACTS;
use palpate_kernel::table::format::FORMAT_VERSION;

/// Version of this C ABI: raised whenever a function, a struct's layout, a
/// handle's size or a code's meaning changes. Compare
/// `palpate_abi_version()` with it at start-up to catch a header and a
/// library of different versions.
pub const PALPATE_ABI_VERSION: u32 = 6;

/// The table format version this library reads (`palpate tables build`
/// writes it; any other version is refused with
/// `PALPATE_STATUS_TABLE_UNSUPPORTED_VERSION`).
pub const PALPATE_TABLE_FORMAT_VERSION: u32 = 6;
const _: () = assert!(PALPATE_TABLE_FORMAT_VERSION == FORMAT_VERSION);

/// Tool points of a haptic loop, at most (a probe tip, a grasper's two
/// jaws, a spare): a loop is created with 1 to this many.
pub const PALPATE_TOOL_POINTS: u32 = 4;

/// Simultaneous contacts, at most: of a scripted solve and of a haptic
/// loop (a fifth tool point in contact is refused and counted).
pub const PALPATE_MAX_CONTACTS: u32 = 4;
const _: () = assert!(PALPATE_MAX_CONTACTS as usize == MAX_CONTACTS);

/// Alignment, bytes, of the memory block given to
/// `palpate_dynamic_loop_create` and `palpate_hybrid_loop_create`.
pub const PALPATE_MEMORY_ALIGN: u32 = 8;

/// The tool points of a loop, as a const generic.
pub(crate) const P: usize = PALPATE_TOOL_POINTS as usize;
/// The contact capacity of a loop and a solve, as a const generic.
pub(crate) const M: usize = PALPATE_MAX_CONTACTS as usize;

/// The ABI version of this library, `PALPATE_ABI_VERSION`.
#[unsafe(no_mangle)]
pub extern "C" fn palpate_abi_version() -> u32 {
    PALPATE_ABI_VERSION
}

/// Firmware builds: no panic is reachable (the entry points' proof:
/// `prove-no-panic` below); were one reached, the core would take a
/// HardFault at once (`udf`), which firmware handles as a fault (the safe
/// state), rather than run on.
#[cfg(all(target_os = "none", not(feature = "prove-no-panic")))]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo<'_>) -> ! {
    loop {
        #[cfg(target_arch = "arm")]
        // SAFETY: `udf` raises the undefined-instruction fault; it reads and
        // writes no memory.
        unsafe {
            core::arch::asm!("udf #0", options(nomem, nostack));
        }
    }
}

/// The link-time proof's build (`--features prove-no-panic`,
/// `tools/firmware-check.sh --c`): the panic handler calls a function
/// defined nowhere, so a program that links every entry point
/// (`tools/firmware-c/entry_points.c`) links only if no panic is reachable
/// from any of them, on any input (a C caller's arguments are opaque to the
/// optimiser).
#[cfg(all(target_os = "none", feature = "prove-no-panic"))]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo<'_>) -> ! {
    unsafe extern "C" {
        /// Defined nowhere (see [`panic`]).
        fn palpate_ffi_panic_is_reachable() -> !;
    }
    // SAFETY: never runs: the program links only if this call is removed as
    // unreachable.
    unsafe { palpate_ffi_panic_is_reachable() }
}
