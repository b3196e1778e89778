//! The pre-computed model's replay (RR-3510 §4): the table is linked into
//! flash, the kernel validates it once, then replays `sequence.txt` (one
//! contact set per step) in the format of `palpate precomputed replay`.
//!
//! Memory: the table and the sequence are read in place from flash; the only
//! static RAM is the displacement buffer (12 bytes per vertex, `.bss`); the
//! contact state (`ContactSolution`) and the LDLᵀ matrices live on the stack
//! for one step.

use core::fmt::Write;

use cortex_m_semihosting::hio;
use palpate_kernel::{ContactSolution, MAX_CONTACTS, PrecomputedModel, PrecomputedTable};

/// The f32 table built by `palpate tables build` from `mesh/box.node`
/// (`build.rs` copies it from `PALPATE_TABLE`), 16-byte aligned in flash as
/// `PrecomputedTable::load` requires.
static TABLE: &[u8] = palpate_kernel::include_table!(concat!(env!("OUT_DIR"), "/table.bin"));
/// The scripted contact sequence (syntax: `palpate-script`), in flash:
/// `sequence.txt`, or the file `PALPATE_SEQUENCE` names (`build.rs`).
static SEQUENCE: &str = include_str!(concat!(env!("OUT_DIR"), "/sequence.txt"));
// `VERTICES`: the vertices of the table's mesh, 64 for `mesh/box.node`
// (4 × 4 × 4) or `PALPATE_VERTICES` (`build.rs`): the length of the
// displacement buffer. `palpate_script::replay` checks it against the
// table's `vertex_count` and refuses a mismatch (printed as
// `# replay failed: ...`).
include!(concat!(env!("OUT_DIR"), "/vertices.rs"));

/// Loads the table, reports its figures on a `#` line, and replays the
/// sequence to semihosting stdout. Any failure is printed on a `#` line.
pub fn run() -> Result<(), ()> {
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
