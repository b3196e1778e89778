//! The hybrid model's offline side (RR-3510 §6.2; the kernel's
//! `palpate_kernel::hybrid`): a mesh and the tets chosen dynamic →
//! [`split::RegionSplit`] (the two regions and their connection nodes) →
//! [`condense::condense`] (the pre-computed region condensed onto the
//! connection nodes; [`hmatrix`] stores it hierarchically when asked) →
//! [`build::build_hybrid`] (the three tables) →
//! [`owned::with_hybrid`] (the kernel model over heap buffers, for the
//! harness's runs) and [`stability::critical_dt_of_hybrid`] (its stable
//! step next to its tensor-mass region's alone).

pub mod build;
pub mod condense;
pub mod estimate;
pub mod hmatrix;
pub mod owned;
pub mod run;
pub mod split;
pub mod stability;

pub use build::{ConnectionMass, HybridOptions, HybridTables, build_hybrid, check_hybrid};
pub use split::RegionSplit;
