//! The bottom layer: the scalar the kernel computes in ([`Real`]), the P1
//! tetrahedron ([`element`]: Lamé coefficients and the stiffness block
//! `K_jk`, MODELS.md §1) and the small dense LDLᵀ the contact solve
//! runs on the stack (`ldlt`, MODELS.md §2), the 3×3 block products of
//! scalars or vector lanes (`block`), the dense row kernels
//! of the hybrid model's interface ([`dense`]), and the hook through which a
//! host runs the step's hot loops compiled for its CPU ([`dispatch`]), and
//! the closest rotation of a 3×3 matrix ([`polar`], the co-rotational law).
//! Depends on nothing else in the crate.

pub(crate) mod block;
pub mod dense;
pub mod dispatch;
pub mod element;
pub(crate) mod ldlt;
pub mod polar;
mod scalar;

pub use dispatch::{Dispatch, MAX_PARTS, Portable};
pub use scalar::Real;
