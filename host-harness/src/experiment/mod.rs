//! Experiments that reproduce the papers' figures through the kernel.

pub mod relax;
pub mod scenes;
pub mod volume_bend;
