//! The dynamic tensor-mass model on the host: heap-owned state buffers for
//! the kernel's [`palpate_kernel::tensor_mass::TensorMassModel`] and the
//! `dynamic run` command.

mod owned;
pub mod run;

pub use owned::OwnedState;
