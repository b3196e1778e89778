//! Link-time proof that the kernel's step path cannot panic.
//!
//! The panic handler calls `palpate_step_path_can_panic`, a symbol defined
//! nowhere. With `panic = "abort"`, LTO and optimisation, the linker keeps the
//! handler only if some panic is reachable from `main`; then the link fails
//! with "undefined symbol: palpate_step_path_can_panic". A successful link
//! proves that no panic is reachable in what `main` calls: table validation
//! (`PrecomputedTable::load`), the haptic force path
//! (`PrecomputedModel::contact_forces`) and the displacement updates
//! (`PrecomputedModel::free_displacements`, `displacements`), on inputs the optimiser cannot see
//! (`core::hint::black_box`).
#![no_std]
#![no_main]
// The only unsafe code: the call to the undefined symbol.
#![allow(unsafe_code)]

use core::hint::black_box;

use cortex_m_rt::entry;
use palpate_kernel::precomputed::Contact;
use palpate_kernel::{MAX_CONTACTS, PrecomputedModel, PrecomputedTable};

static TABLE: &[u8] = palpate_kernel::include_table!(concat!(env!("OUT_DIR"), "/table.bin"));

/// Upper bound of vertices of the checked table (the firmware's box has 64).
const VERTICES: usize = 64;

#[entry]
fn main() -> ! {
    let mut displacements = [[0.0f32; 3]; VERTICES];
    loop {
        let Ok(table) = PrecomputedTable::<f32>::load(black_box(TABLE)) else {
            continue;
        };
        let model = PrecomputedModel::new(table);
        // Contacts of any kind, count and value the optimiser cannot predict.
        let mut contacts = [Contact::at_vertex(0, [0.0f32; 3].into()); MAX_CONTACTS + 1];
        for contact in &mut contacts {
            let vertices: [u32; 3] = black_box([0; 3]);
            let weights: [f32; 3] = black_box([0.0; 3]);
            let d: [f32; 3] = black_box([0.0; 3]);
            *contact = if black_box(false) {
                Contact::on_triangle(vertices, weights, d.into())
            } else {
                Contact::at_vertex(vertices[0], d.into())
            };
        }
        let count = black_box(MAX_CONTACTS + 1).min(contacts.len());
        let set = contacts.get(..count).unwrap_or(&[]);
        if let Ok(solution) = model.contact_forces::<MAX_CONTACTS>(set) {
            black_box(solution.device_force_n());
            let len = black_box(VERTICES).min(displacements.len());
            if let Some(out) = displacements.get_mut(..len) {
                black_box(model.displacements(&solution, out).is_ok());
                black_box(model.free_displacements(&solution, out).is_ok());
            }
            black_box(&displacements);
        }
    }
}

unsafe extern "C" {
    /// Defined nowhere: referencing it fails the link.
    fn palpate_step_path_can_panic() -> !;
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo<'_>) -> ! {
    // SAFETY: never executed; the link fails if this handler is reachable.
    unsafe { palpate_step_path_can_panic() }
}
