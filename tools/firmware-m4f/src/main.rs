//! Palpate on a Cortex-M4F: the pre-computed table is linked into flash, the
//! kernel validates it once, then replays `sequence.txt` (one contact set per
//! step) and prints one line per step over semihosting, in the format of
//! `palpate precomputed replay` (the `palpate-script` crate), so the host can
//! compare the two byte for byte (`tools/firmware-check.sh`). Lines starting
//! with `#` are reports, not compared.
//!
//! Memory: the table and the sequence are read in place from flash; the only
//! static RAM is the displacement buffer (12 bytes per vertex, `.bss`); the
//! contact state (`ContactSolution`) and the Cholesky blocks live on the stack
//! for one step.
#![no_std]
#![no_main]

use core::fmt::Write;

use cortex_m_rt::entry;
use cortex_m_semihosting::{debug, hio};
use palpate_kernel::{ContactSolution, MAX_CONTACTS, PrecomputedModel, PrecomputedTable};

/// The f32 table built by `palpate tables build` from `mesh/box.node`
/// (`build.rs` copies it from `PALPATE_TABLE`), 16-byte aligned in flash as
/// `PrecomputedTable::load` requires.
static TABLE: &[u8] = palpate_kernel::include_table!(concat!(env!("OUT_DIR"), "/table.bin"));
/// The scripted contact sequence (syntax: `palpate-script`), in flash.
static SEQUENCE: &str = include_str!("../sequence.txt");
/// Vertices of `mesh/box.node` (4 × 4 × 4): the length of the displacement
/// buffer. `palpate_script::replay` checks it against the table's
/// `vertex_count` and refuses a mismatch (printed as `# replay failed: ...`).
const VERTICES: usize = 64;

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

/// Loads the table, reports its figures on a `#` line, and replays the
/// sequence to semihosting stdout. Any failure is printed on a `#` line.
fn run() -> Result<(), ()> {
    let mut out = hio::hstdout()?;
    let table = match PrecomputedTable::<f32>::load(TABLE) {
        Ok(table) => table,
        Err(e) => {
            let _ = writeln!(out, "# table refused: {e}");
            return Err(());
        }
    };
    let model = PrecomputedModel::new(table);
    let _ = writeln!(
        out,
        "# table: {} bytes in flash, {} vertices, {} touchable; contact state \
         ContactSolution<f32, {MAX_CONTACTS}>: {} bytes",
        TABLE.len(),
        model.table().vertex_count(),
        model.table().touchable_count(),
        core::mem::size_of::<ContactSolution<f32, MAX_CONTACTS>>()
    );
    // Vertex displacements, m: a static buffer (`.bss`), taken once.
    let Some(displacements) = cortex_m::singleton!(: [[f32; 3]; VERTICES] = [[0.0; 3]; VERTICES])
    else {
        let _ = writeln!(out, "# displacement buffer already taken");
        return Err(());
    };
    palpate_script::replay(&model, SEQUENCE, displacements, &mut out).map_err(|e| {
        let _ = writeln!(out, "# replay failed: {e}");
    })
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
