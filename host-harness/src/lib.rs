//! Palpate host harness: mesh input, offline tables, scripted runs, reports.
//!
//! Data flow: [`mesh`] (read and validate a tetrahedral mesh) → [`fem`]
//! (P1 stiffness) → [`table`] (one build pipeline for both kinds of table:
//! compliance or tensor-mass arrays, the table file) → the kernel
//! (`palpate_kernel`) → [`precomputed`] / [`tensor_mass`] / [`session`] (on a
//! [`scene`]) / [`demo`] / [`replay`] (runs and reports). The host modules are named after
//! the kernel's (`palpate_kernel::table`, `palpate_kernel::tensor_mass`).

pub mod bench;
pub mod budget;
pub mod callgrind;
pub mod chart;
pub mod demo;
pub mod dispatch;
pub mod experiment;
pub mod fem;
pub mod fix;
pub mod hybrid;
pub mod limits;
pub mod mesh;
pub mod output;
pub mod partition;
pub mod precomputed;
pub mod remap;
pub mod replay;
pub mod scene;
pub mod session;
pub mod table;
pub mod tensor_mass;
pub mod threads;
