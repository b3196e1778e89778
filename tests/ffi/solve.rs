//! The scripted solve through the C ABI (`ffi/src/solve.rs`): every step of
//! the firmware's sequence (`tools/firmware-m4f/sequence.txt`, refusals
//! included) gives bit for bit the kernel's own `contact_forces` and
//! `displacements` on the same f32 table, and the kernel's message for each
//! refusal.

use palpate_ffi::error::{Detail, Error, palpate_error_message};
use palpate_ffi::solve::{
    Contact, ContactKind, Solution, palpate_precomputed_displacements, palpate_precomputed_solve,
};
use palpate_ffi::status::Status;
use palpate_kernel::precomputed::{AsConstraint, ContactPoint};
use palpate_kernel::{MAX_CONTACTS, PrecomputedModel, PrecomputedTable};
use palpate_tests::firmware_box_tables;

/// The C contact of a scripted constraint.
fn c_contact(c: &impl AsConstraint<f32>) -> Contact {
    let displacement_m = c.displacement_m().into();
    match c.point() {
        ContactPoint::Vertex(v) => Contact {
            kind: ContactKind::Vertex as u32,
            vertices: [v, 0, 0],
            weights: [0.0; 3],
            displacement_m,
        },
        ContactPoint::Triangle { vertices, weights } => Contact {
            kind: ContactKind::Triangle as u32,
            vertices,
            weights,
            displacement_m,
        },
    }
}

fn bits(v: &[[f32; 3]]) -> Vec<u32> {
    v.iter().flatten().map(|x| x.to_bits()).collect()
}

#[test]
fn abi_solve_is_the_kernel_solve_bit_for_bit() {
    let bytes = firmware_box_tables().precomputed.bytes();
    let table = super::table::precomputed();
    let model = PrecomputedModel::new(PrecomputedTable::<f32>::load(bytes).unwrap());
    let sequence = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tools/firmware-m4f/sequence.txt"),
    )
    .unwrap();
    let (mut solved, mut refused) = (0, 0);
    for (line, step) in palpate_script::steps::<f32>(&sequence) {
        let step = step.unwrap();
        let contacts: Vec<Contact> = step.iter().map(c_contact).collect();
        let mut solution = Solution::default();
        let mut error = Error::default();
        // SAFETY: live handles; `contacts` readable for its length.
        let status = unsafe {
            palpate_precomputed_solve(
                &*table,
                contacts.as_ptr(),
                contacts.len(),
                &mut solution,
                &mut error,
            )
        };
        match model.contact_forces::<MAX_CONTACTS>(&step) {
            Err(e) => {
                refused += 1;
                assert_eq!(status, Status::from(e), "line {line}");
                let mut text = [0u8; 200];
                // SAFETY: a live error; 200 writable bytes.
                let len = unsafe { palpate_error_message(&error, text.as_mut_ptr().cast(), 200) };
                assert_eq!(&text[..len], e.to_string().as_bytes(), "line {line}");
                assert_eq!(Detail::Contact(e).status(), status);
            }
            Ok(kernel) => {
                solved += 1;
                assert_eq!(status, Status::Ok, "line {line}");
                let forces: Vec<[f32; 3]> = kernel
                    .contact_forces_n()
                    .iter()
                    .map(|g| (*g).into())
                    .collect();
                assert_eq!(solution.count as usize, forces.len());
                assert_eq!(
                    bits(&solution.contact_forces_n[..forces.len()]),
                    bits(&forces),
                    "line {line}"
                );
                assert_eq!(
                    bits(&[solution.device_force_n]),
                    bits(&[kernel.device_force_n().into()])
                );
                let mut ours = vec![[0.0f32; 3]; 64];
                let mut theirs = vec![[0.0f32; 3]; 64];
                // SAFETY: live handles; 64 writable vertices.
                let status = unsafe {
                    palpate_precomputed_displacements(
                        &*table,
                        &solution,
                        ours.as_mut_ptr(),
                        64,
                        core::ptr::null_mut(),
                    )
                };
                assert_eq!(status, Status::Ok);
                model.displacements(&kernel, &mut theirs).unwrap();
                assert_eq!(bits(&ours), bits(&theirs), "line {line}");
            }
        }
    }
    // The sequence's 24 solved steps and 6 refusals.
    assert_eq!((solved, refused), (24, 6));
}
