//! The pre-computed model's scripted solve (RR-3510 §4, MODELS.md §2): a
//! contact set's forces, then the displacement of every vertex. What
//! `palpate precomputed replay` runs, step by step; the haptic loop
//! ([`crate::precomputed_loop`]) finds its contacts itself.

use core::ptr::addr_of_mut;

use nalgebra::Vector3;
use palpate_kernel::precomputed::{AsConstraint, ContactPoint};
use palpate_kernel::{ContactSolution, PrecomputedModel};

use crate::error::{Detail, Error, finish};
use crate::handle::{self, Handle};
use crate::status::Status;
use crate::table::{self, Table};
use crate::{M, PALPATE_MAX_CONTACTS};

/// Where a scripted contact acts (`palpate_contact::kind`).
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContactKind {
    /// A touchable vertex: `vertices[0]`.
    Vertex = 0,
    /// A point of a surface triangle: `vertices` with barycentric `weights`.
    Triangle = 1,
}

/// A scripted contact: a point of the surface and the displacement the
/// tool imposes on it.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    /// A `palpate_contact_kind` value.
    pub kind: u32,
    /// Mesh vertex indices (0-based): a vertex contact uses `vertices[0]`;
    /// a triangle contact its three vertices, a triangle of the table's
    /// boundary surface in any order.
    pub vertices: [u32; 3],
    /// A triangle contact's barycentric weights (each in `[0, 1]`, summing
    /// to 1); ignored for a vertex contact.
    pub weights: [f32; 3],
    /// Imposed displacement of the contact point from rest, m.
    pub displacement_m: [f32; 3],
}

impl AsConstraint<f32> for Contact {
    /// A kind other than `Vertex` is a triangle: the solve checks the kinds
    /// first (`check_kinds`).
    fn point(&self) -> ContactPoint<f32> {
        if self.kind == ContactKind::Vertex as u32 {
            let [v, _, _] = self.vertices;
            ContactPoint::Vertex(v)
        } else {
            ContactPoint::Triangle {
                vertices: self.vertices,
                weights: self.weights,
            }
        }
    }

    fn displacement_m(&self) -> Vector3<f32> {
        self.displacement_m.into()
    }
}

/// `Err(BadArgument)` if a contact's kind is not a `palpate_contact_kind`.
fn check_kinds(contacts: &[Contact]) -> Result<(), Status> {
    let known = |k: u32| k == ContactKind::Vertex as u32 || k == ContactKind::Triangle as u32;
    if contacts.iter().all(|c| known(c.kind)) {
        Ok(())
    } else {
        Err(Status::BadArgument)
    }
}

/// Words of a `palpate_solution_state`.
pub const PALPATE_SOLUTION_WORDS: usize = 32;

/// The kernel's contact solution inside a `palpate_solution` (opaque).
#[repr(C)]
pub struct SolutionState {
    opaque: [u64; PALPATE_SOLUTION_WORDS],
}

/// Zeroed, as C's static storage: not initialized until created.
impl Default for SolutionState {
    fn default() -> Self {
        Self {
            opaque: [0; PALPATE_SOLUTION_WORDS],
        }
    }
}

// SAFETY: `SolutionState` is a `#[repr(C)]` struct of `u64` words.
unsafe impl Handle for SolutionState {
    type Value = ContactSolution<f32, M>;
    const MAGIC: u32 = u32::from_le_bytes(*b"PSol");
}

/// A solved contact set (`palpate_precomputed_solve`).
#[repr(C)]
pub struct Solution {
    /// Contacts solved (0 to `PALPATE_MAX_CONTACTS`).
    pub count: u32,
    /// `-Σ g_p`: the force of the tissue on the tool, what the device
    /// renders, N (`+0` without contact).
    pub device_force_n: [f32; 3],
    /// `g_p`: the force the tool applies to the tissue at each contact, N,
    /// in the order given; zero from `count` on.
    pub contact_forces_n: [[f32; 3]; PALPATE_MAX_CONTACTS as usize],
    /// The kernel's solution, for `palpate_precomputed_displacements`.
    pub state: SolutionState,
}

/// No contact solved yet.
impl Default for Solution {
    fn default() -> Self {
        Self {
            count: 0,
            device_force_n: [0.0; 3],
            contact_forces_n: [[0.0; 3]; PALPATE_MAX_CONTACTS as usize],
            state: SolutionState::default(),
        }
    }
}

/// Solves `count` contacts at `contacts` on pre-computed table `table`
/// (MODELS.md §2: the point compliances `C_pq`, a block Cholesky of the
/// `3m × 3m` system on the stack) and writes the forces to `solution`.
/// Bounded: `O(m³)` with `m ≤ PALPATE_MAX_CONTACTS`, independent of the
/// mesh. No contact gives zero force. Refused, with the kernel's reason
/// (`PALPATE_STATUS_CONTACT_*`, details in `error`): more than
/// `PALPATE_MAX_CONTACTS` contacts, a vertex out of range, fixed or not on
/// the surface, a triangle that is not one of the surface's, bad weights,
/// non-finite input, two contacts on one vertex, an ill-conditioned system.
///
/// # Safety
///
/// `table` is `NULL` or points to a `palpate_table`; `contacts` is
/// `NULL` or points to `count` readable `palpate_contact` (it may be
/// `NULL` when `count` is 0); `solution` is `NULL` or points to a writable
/// `palpate_solution`; `error` is `NULL` or points to a writable
/// `palpate_error`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn palpate_precomputed_solve(
    table: *const Table,
    contacts: *const Contact,
    count: usize,
    solution: *mut Solution,
    error: *mut Error,
) -> Status {
    let result = (|| -> Result<(), Detail> {
        // SAFETY: `table` is null or a table handle (contract).
        let model = PrecomputedModel::new(*unsafe { table::view(table) }?.precomputed()?);
        let contacts: &[Contact] = if count == 0 {
            &[]
        } else {
            // SAFETY: `count` readable contacts at `contacts` (contract);
            // every bit pattern is a valid `Contact`.
            unsafe { handle::slice(contacts, count) }?
        };
        handle::check(solution)?;
        check_kinds(contacts)?;
        let solved = model.contact_forces::<M>(contacts)?;
        let mut forces = [[0.0f32; 3]; M];
        for (out, g) in forces.iter_mut().zip(solved.contact_forces_n()) {
            *out = (*g).into();
        }
        // SAFETY: `solution` is non-null and aligned (checked) and writable
        // (contract); its state is a handle inside it.
        unsafe {
            handle::init(addr_of_mut!((*solution).state), solved)?;
            addr_of_mut!((*solution).count).write(u32::try_from(solved.len()).unwrap_or(0));
            addr_of_mut!((*solution).device_force_n).write(solved.device_force_n().into());
            addr_of_mut!((*solution).contact_forces_n).write(forces);
        }
        Ok(())
    })();
    // SAFETY: `error` is null or a writable error (contract).
    unsafe { finish(result, error) }
}

/// Writes the displacement of every vertex (m, mesh vertex order; fixed
/// vertices zero) for `solution` to `displacements_m`, which holds
/// `vertex_count` entries: the table's vertex count
/// (`PALPATE_STATUS_DISPLACEMENT_BUFFER` otherwise). MODELS.md §2:
/// `u_n = Σ_q Σ_b β^q_b C_{n v^q_b} g_q`. `table` is the table `solution`
/// was solved on. Not needed by the haptic path (a renderer's call).
///
/// # Safety
///
/// `table` and `solution` are `NULL` or point to a table and a solution;
/// `displacements_m` is `NULL` or points to `vertex_count` writable,
/// 4-byte-aligned `float[3]`; `error` is `NULL` or points to a writable
/// `palpate_error`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn palpate_precomputed_displacements(
    table: *const Table,
    solution: *const Solution,
    displacements_m: *mut [f32; 3],
    vertex_count: usize,
    error: *mut Error,
) -> Status {
    let result = (|| -> Result<(), Detail> {
        // SAFETY: `table` is null or a table handle (contract).
        let model = PrecomputedModel::new(*unsafe { table::view(table) }?.precomputed()?);
        handle::check(solution)?;
        // SAFETY: `solution` is non-null, aligned (checked) and readable
        // (contract); its state is a handle inside it.
        let solved = unsafe { handle::get(core::ptr::addr_of!((*solution).state)) }?;
        // SAFETY: `vertex_count` writable entries (contract).
        let out = unsafe { handle::slice_mut(displacements_m, vertex_count) }?;
        model.displacements(solved, out)?;
        Ok(())
    })();
    // SAFETY: `error` is null or a writable error (contract).
    unsafe { finish(result, error) }
}
