//! Palpate on a Cortex-M4F: the pre-computed table is linked into flash, the
//! kernel validates it once, then replays `sequence.txt` (one contact set per
//! step) and prints one line per step over semihosting, in the format of
//! `palpate precomputed replay` (the `palpate-script` crate), so the host can
//! compare the two byte for byte. Lines starting with `#` are reports, not
//! compared.
#![no_std]
#![no_main]

use core::fmt::Write;

use cortex_m_rt::entry;
use cortex_m_semihosting::{debug, hio};
use palpate_kernel::{ContactSolution, MAX_CONTACTS, PrecomputedModel, PrecomputedTable};

/// The f32 table, 16-byte aligned in flash.
static TABLE: &[u8] = palpate_kernel::include_table!(concat!(env!("OUT_DIR"), "/table.bin"));
/// The scripted contact sequence.
static SEQUENCE: &str = include_str!("../sequence.txt");
/// Vertices of `mesh/box.node` (4 × 4 × 4).
const VERTICES: usize = 64;

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
    let mut displacements = [[0.0f32; 3]; VERTICES];
    palpate_script::replay(&model, SEQUENCE, &mut displacements, &mut out).map_err(|e| {
        let _ = writeln!(out, "# replay failed: {e}");
    })
}

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
