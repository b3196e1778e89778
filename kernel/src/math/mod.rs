//! The bottom layer: the scalar the kernel computes in ([`Real`]), the P1
//! tetrahedron ([`element`]: Lamé coefficients and the stiffness block
//! `K_jk`, MODELS.md §1) and the small dense block Cholesky the contact solve
//! runs on the stack ([`cholesky`], MODELS.md §2), and the dense row kernels
//! of the hybrid model's interface ([`dense`]). Depends on nothing else in the
//! crate.

pub(crate) mod cholesky;
pub mod dense;
pub mod element;
mod scalar;

pub use scalar::Real;
