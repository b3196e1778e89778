//! Palpate kernel: the `no_std`, allocation-free part of a real-time soft-tissue
//! simulator for haptic surgery training.
//!
//! Data flow: table bytes (built offline by the host harness, linked into
//! flash or read from a file) → [`table::PrecomputedTable::load`] validates them
//! once → [`precomputed::PrecomputedModel`] answers contact queries in bounded
//! time: the contact forces the haptic device needs ([`precomputed::PrecomputedModel::contact_forces`])
//! and, separately, the displacement of every vertex
//! ([`precomputed::PrecomputedModel::displacements`]).
//!
//! The physics is `MODELS.md` sections 1, 2 and 6; the source is Cotin,
//! Delingette and Ayache, *Efficient linear elastic models of soft tissues for
//! real-time surgery simulation*, INRIA RR-3510 (1998), §4.
//!
//! Guarantees of the step path (everything after `load`): no allocation, no
//! panic path (proven at link time by `tools/nopanic-check`), and every loop
//! bounded by a compile-time capacity or a count validated at load.
#![no_std]
#![forbid(unsafe_code)]
#![deny(missing_docs)]
#![warn(
    clippy::panic,
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing
)]

pub mod element;
pub mod haptic;
pub mod precomputed;
pub mod scalar;
pub mod table;
pub mod tensor_mass;

pub use precomputed::{Contact, ContactError, ContactPoint, ContactSolution, PrecomputedModel};
pub use scalar::Real;
pub use table::{LoadError, PrecomputedTable};

/// Default compile-time capacity of simultaneous contacts (`M` in
/// [`precomputed::PrecomputedModel::contact_forces`]): a probe tip and a
/// grasper's two jaws with one spare. The solver accepts any `1..=16`.
pub const MAX_CONTACTS: usize = 4;
