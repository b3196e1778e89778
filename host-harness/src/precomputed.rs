//! `palpate precomputed solve`: one contact set through the kernel's code path.

use nalgebra::Vector3;
use palpate_kernel::{Constraint, MAX_CONTACTS, PrecomputedModel, Real};
use serde::Serialize;

/// The JSON object `precomputed solve --json` prints (a CLI contract).
#[derive(Serialize)]
pub struct SolveOutput<T> {
    /// Displacement of every mesh vertex in input order, m.
    pub displacements: Vec<[T; 3]>,
    /// Force the tool applies to the tissue at each contact, argument order, N.
    pub contact_forces: Vec<[T; 3]>,
    /// Force rendered on the device, `-Σ g`, N.
    pub device_force: [T; 3],
}

/// Solves the contact set with capacity [`MAX_CONTACTS`] and computes every
/// vertex displacement, exactly as the kernel does on firmware.
pub fn solve<T: Real + Serialize>(
    model: &PrecomputedModel<'_, T>,
    contacts: &[Constraint<T>],
) -> anyhow::Result<SolveOutput<T>> {
    let solution = model.contact_forces::<MAX_CONTACTS>(contacts)?;
    let mut displacements = vec![[T::zero(); 3]; model.table().vertex_count()];
    model.displacements(&solution, &mut displacements)?;
    let array = |v: &Vector3<T>| [v.x, v.y, v.z];
    Ok(SolveOutput {
        displacements,
        contact_forces: solution.contact_forces_n().iter().map(array).collect(),
        device_force: array(&solution.device_force_n()),
    })
}
