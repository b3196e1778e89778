//! Palpate host harness: mesh input, offline tables, scripted runs, reports.
//!
//! Data flow: [`mesh`] (read and validate a tetrahedral mesh) → [`fem`]
//! (P1 stiffness) → [`tables`] (compliance, table file) → the kernel
//! (`palpate_kernel`) → [`precomputed`] / [`demo`] / [`replay`] (runs and reports).

pub mod budget;
pub mod demo;
pub mod dynamic;
pub mod experiment;
pub mod fem;
pub mod fix;
pub mod mesh;
pub mod output;
pub mod precomputed;
pub mod replay;
pub mod session;
pub mod tables;
