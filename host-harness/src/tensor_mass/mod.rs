//! The dynamic tensor-mass model on the host: heap-owned state buffers for
//! the kernel's [`palpate_kernel::tensor_mass::TensorMassModel`] and the
//! `dynamic run`, `dynamic critical-dt` and `stvk forces` commands.

pub mod evaluate;
mod owned;
pub mod run;
pub mod stability;

pub use owned::{OwnedState, OwnedSurface};
