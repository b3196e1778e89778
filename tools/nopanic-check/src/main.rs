//! Link-time proof that the kernel's step path cannot panic.
//!
//! The panic handler calls `palpate_step_path_can_panic`, a symbol defined
//! nowhere. With `panic = "abort"`, LTO and optimisation, the linker keeps the
//! handler only if some panic is reachable from `main`; then the link fails
//! with "undefined symbol: palpate_step_path_can_panic". A successful link
//! proves that no panic is reachable in what `main` calls:
//! - table validation, `PrecomputedTable::load` (not the step path, but it runs
//!   on bytes from flash or a file, so it is checked too);
//! - the haptic force path, `PrecomputedModel::contact_forces::<MAX_CONTACTS>`;
//! - the displacement updates, `PrecomputedModel::free_displacements` and
//!   `PrecomputedModel::displacements`.
//!
//! Why the proof holds for every input, not just one: every input (the table
//! length, the contact count, each contact's kind, vertices, barycentric
//! weights and imposed displacement, the output buffer lengths) is read with
//! `core::ptr::read_volatile` from a `static mut` each time round the loop, so
//! the optimiser must assume any value (a debugger could write them). Every
//! result is written with `core::ptr::write_volatile`, so no computation can be
//! dropped as dead. `core::hint::black_box` is not used: its documentation
//! says it must not be relied on for correctness, and a too-weak barrier would
//! make this check pass vacuously.
//!
//! Never run; only linked. `tools/nopanic-check.sh` builds it.
#![no_std]
#![no_main]
// The only unsafe code: volatile access to the input/output statics and the
// call to the undefined symbol. The kernel itself stays `forbid(unsafe_code)`.
#![allow(unsafe_code)]

use core::ptr::{addr_of, addr_of_mut, read_volatile, write_volatile};

use cortex_m_rt::entry;
use palpate_kernel::precomputed::Contact;
use palpate_kernel::{MAX_CONTACTS, PrecomputedModel, PrecomputedTable};

/// The f32 table of the firmware example's box (64 vertices), 16-byte aligned
/// as `load` requires.
static TABLE: &[u8] = palpate_kernel::include_table!(concat!(env!("OUT_DIR"), "/table.bin"));

/// Capacity of the displacement buffers, vertices: the checked table has 64,
/// and the lengths actually passed are volatile inputs below that bound.
const VERTICES: usize = 64;

/// One more contact slot than the capacity, so that the "too many contacts"
/// refusal is reachable too.
const SLOTS: usize = MAX_CONTACTS + 1;

/// Everything the step path takes, opaque to the optimiser (see the crate
/// docs). Integers stand in for booleans so that any byte a debugger writes is
/// a valid value.
struct Inputs {
    /// Bytes of `TABLE` passed to `load` (clamped to the table length).
    table_len: usize,
    /// Contacts in the set (clamped to `SLOTS`).
    contact_count: usize,
    /// Non-zero: contact `p` is a triangle contact; zero: a vertex contact.
    on_triangle: [u8; SLOTS],
    /// Mesh vertex indices (a vertex contact uses the first).
    vertices: [[u32; 3]; SLOTS],
    /// Barycentric weights of a triangle contact, dimensionless.
    weights: [[f32; 3]; SLOTS],
    /// Imposed displacement of each contact point, m.
    displacement_m: [[f32; 3]; SLOTS],
    /// Entries passed to `displacements` (clamped to `VERTICES`).
    vertex_len: usize,
    /// Entries passed to `free_displacements` (clamped to `VERTICES`).
    free_len: usize,
}

/// The inputs, read with `read_volatile` only.
static mut INPUTS: Inputs = Inputs {
    table_len: usize::MAX,
    contact_count: 0,
    on_triangle: [0; SLOTS],
    vertices: [[0; 3]; SLOTS],
    weights: [[0.0; 3]; SLOTS],
    displacement_m: [[0.0; 3]; SLOTS],
    vertex_len: VERTICES,
    free_len: VERTICES,
};

/// Where the results go, written with `write_volatile` only: the device force
/// (N), each contact force (N), and the vertex displacements (m).
struct Outputs {
    /// `-Σ g_q`, N.
    device_force_n: [f32; 3],
    /// `g_q`, N.
    contact_forces_n: [[f32; 3]; MAX_CONTACTS],
    /// Displacements from the last update, m.
    displacements_m: [[f32; 3]; VERTICES],
    /// Which call refused, as a counter per outcome (keeps the `Err` arms live).
    refusals: u32,
}

/// The outputs.
static mut OUTPUTS: Outputs = Outputs {
    device_force_n: [0.0; 3],
    contact_forces_n: [[0.0; 3]; MAX_CONTACTS],
    displacements_m: [[0.0; 3]; VERTICES],
    refusals: 0,
};

#[entry]
fn main() -> ! {
    let mut displacements = [[0.0f32; 3]; VERTICES];
    loop {
        // SAFETY: single-threaded, no interrupt touches INPUTS; a volatile
        // read of a plain-old-data static is always valid.
        let inputs = unsafe { read_volatile(addr_of!(INPUTS)) };
        step(&inputs, &mut displacements);
    }
}

/// One tick: load, contact forces, both displacement updates, on `inputs`.
fn step(inputs: &Inputs, displacements: &mut [[f32; 3]; VERTICES]) {
    let bytes = TABLE.get(..inputs.table_len).unwrap_or(TABLE);
    let Ok(table) = PrecomputedTable::<f32>::load(bytes) else {
        refused();
        return;
    };
    let model = PrecomputedModel::new(table);

    let mut contacts = [Contact::at_vertex(0, [0.0f32; 3].into()); SLOTS];
    for (p, contact) in contacts.iter_mut().enumerate() {
        let (Some(&kind), Some(&vertices), Some(&weights), Some(&d)) = (
            inputs.on_triangle.get(p),
            inputs.vertices.get(p),
            inputs.weights.get(p),
            inputs.displacement_m.get(p),
        ) else {
            continue;
        };
        *contact = if kind != 0 {
            Contact::on_triangle(vertices, weights, d.into())
        } else {
            Contact::at_vertex(vertices[0], d.into())
        };
    }
    let set = contacts
        .get(..inputs.contact_count)
        .unwrap_or(&contacts[..]);

    let Ok(solution) = model.contact_forces::<MAX_CONTACTS>(set) else {
        refused();
        return;
    };
    let out = addr_of_mut!(OUTPUTS);
    // SAFETY (all volatile writes below): single-threaded, `out` points to a
    // live static, every field is plain old data.
    unsafe {
        write_volatile(
            addr_of_mut!((*out).device_force_n),
            solution.device_force_n().into(),
        );
        for (g, o) in solution
            .contact_forces_n()
            .iter()
            .zip((*out).contact_forces_n.iter_mut())
        {
            write_volatile(o, (*g).into());
        }
    }

    let vertex_len = inputs.vertex_len.min(VERTICES);
    if model
        .displacements(&solution, &mut displacements[..vertex_len])
        .is_err()
    {
        refused();
    }
    publish(displacements);
    let free_len = inputs.free_len.min(VERTICES);
    if model
        .free_displacements(&solution, &mut displacements[..free_len])
        .is_err()
    {
        refused();
    }
    publish(displacements);
}

/// Counts a refusal (volatile, so the error arms are not dead code).
fn refused() {
    let out = addr_of_mut!(OUTPUTS);
    // SAFETY: single-threaded; plain-old-data field of a live static.
    unsafe {
        let n = read_volatile(addr_of!((*out).refusals));
        write_volatile(addr_of_mut!((*out).refusals), n.wrapping_add(1));
    }
}

/// Writes the displacement buffer to `OUTPUTS` (volatile, so the updates are
/// not dead code).
fn publish(displacements: &[[f32; 3]; VERTICES]) {
    let out = addr_of_mut!(OUTPUTS);
    // SAFETY: single-threaded; plain-old-data field of a live static.
    unsafe {
        for (u, o) in displacements.iter().zip((*out).displacements_m.iter_mut()) {
            write_volatile(o, *u);
        }
    }
}

#[cfg(not(feature = "locate"))]
unsafe extern "C" {
    /// Defined nowhere: referencing it fails the link.
    fn palpate_step_path_can_panic() -> !;
}

/// Reachable only if some panic is: then the link fails on the undefined
/// symbol, which is the point of this crate.
#[cfg(not(feature = "locate"))]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo<'_>) -> ! {
    // SAFETY: never executed; the link fails if this handler is reachable.
    unsafe { palpate_step_path_can_panic() }
}

/// With `--features locate` (used by `tools/nopanic-check.sh` after a failed
/// link) the handler is an ordinary loop, so the program links and its
/// disassembly shows which code calls into `core::panicking`.
#[cfg(feature = "locate")]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo<'_>) -> ! {
    loop {
        core::hint::spin_loop();
    }
}
