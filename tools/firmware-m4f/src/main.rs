//! Palpate on a Cortex-M4F: the kernel's tables are linked into flash, the
//! kernel validates them once, then replays a scripted sequence and prints one
//! line per step over semihosting, in the format the host prints for the
//! same sequence (the `palpate-script` crate), so the two can be compared
//! byte for byte (`tools/firmware-check.sh`). Lines starting with `#` are
//! reports, not compared. Two builds (one mode each):
//!
//! - default: the pre-computed model ([`precomputed`], RR-3510 §4) replays
//!   `sequence.txt`, as `palpate precomputed replay`;
//! - `--features hybrid`: the hybrid model ([`hybrid`], RR-3510 §6.2) on the
//!   three tables of `hybrid-scene.toml` replays `hybrid-sequence.txt`, as
//!   `palpate scene replay-hybrid`.
#![no_std]
#![no_main]

#[cfg(feature = "hybrid")]
mod hybrid;
#[cfg(not(feature = "hybrid"))]
mod precomputed;

use core::fmt::Write;

use cortex_m_rt::entry;
use cortex_m_semihosting::{debug, hio};

#[cfg(feature = "hybrid")]
use hybrid::run;
#[cfg(not(feature = "hybrid"))]
use precomputed::run;

/// Runs the replay, then ends QEMU through semihosting with the exit status
/// (success only if the whole sequence was replayed and printed).
#[entry]
fn main() -> ! {
    let ok = run().is_ok();
    debug::exit(if ok {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    loop {
        cortex_m::asm::bkpt();
    }
}

/// Prints the panic on a `#` line and ends QEMU with failure. Not expected to
/// run: `tools/nopanic-check` proves the kernel's step path has no panic.
#[panic_handler]
fn panic(info: &core::panic::PanicInfo<'_>) -> ! {
    if let Ok(mut out) = hio::hstdout() {
        let _ = writeln!(out, "# panic: {info}");
    }
    debug::exit(debug::EXIT_FAILURE);
    loop {
        cortex_m::asm::bkpt();
    }
}
