//! The dynamic tensor-mass model on the host: heap-owned state buffers for
//! the kernel's [`palpate_kernel::tensor_mass::TensorMassModel`].

mod owned;

pub use owned::OwnedState;
