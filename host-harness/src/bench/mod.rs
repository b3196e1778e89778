//! Timings a user reproduces on their own mesh (`palpate bench`): the
//! pre-computed model's force path, displacement update and haptic tick,
//! and one step of each tensor-mass law, form and integrator, each next to
//! a memory copy of the bytes it reads (the roofline), in f32 and f64, with
//! the kernel's hot passes dispatched to the CPU's features
//! ([`crate::dispatch`]) or portable.
//!
//! The criterion benches (`benches/`) are the project's reference figures
//! (fixed meshes, statistics, baselines); this module times a user's mesh
//! in one process. [`tensor_mass::TensorMassBench::time_step`] (or
//! [`tensor_mass::time_step_on_mesh`]) times one configuration on a mesh
//! and returns its median and spread ([`measure::Timing`]).
//! [`scene`] times a scene's own model stage by stage against its real-time
//! periods (`palpate bench --scene`).

pub mod measure;
pub mod precomputed;
pub mod run;
pub mod scene;
pub mod tensor_mass;
