//! Palpate kernel: the `no_std`, allocation-free part of a real-time soft-tissue
//! simulator for haptic surgery training.
//!
//! Layers, each depending only on those above it in this list:
//! - [`math`]: the scalar, the P1 element, the small dense LDLᵀ of the contact solve;
//! - [`table`]: the byte format and the validated views (pre-computed,
//!   tensor-mass, interface, collision index), checked once at load;
//! - [`contact`]: the collision grid builder, detection and tracking, the one
//!   [`contact::Contact`] type and its bounded set, the [`contact::Tissue`]
//!   trait;
//! - [`precomputed`] and [`tensor_mass`]: the two models, each with its
//!   tissue adapter for the haptic loop;
//! - [`hybrid`]: the two joined at connection nodes (RR-3510 §6.2), the
//!   pre-computed region condensed onto them, and its tissue adapter;
//! - [`haptic`]: the fixed-timestep loop and the safety supervisor;
//! - [`link`]: the haptic loop on a controller, the physics on a host: the
//!   framed wire format between them and the controller's side.
//!
//! Data flow: table bytes (built offline by the host harness, linked into
//! flash or read from a file) → [`table::PrecomputedTable::load`] validates them
//! once → [`precomputed::PrecomputedModel`] answers contact queries in bounded
//! time: the contact forces the haptic device needs ([`precomputed::PrecomputedModel::contact_forces`])
//! and, separately, the displacement of every vertex
//! ([`precomputed::PrecomputedModel::displacements`]); tool positions at the
//! haptic rate → [`haptic::HapticLoop::tick`] → a clamped device force.
//!
//! The physics is `docs/MODELS.md` in the repository (cited as `MODELS.md §n`
//! throughout the kernel); the sources, in `docs/papers/`, are Cotin,
//! Delingette and Ayache, *Efficient linear elastic models of soft tissues for
//! real-time surgery simulation*, INRIA RR-3510 (1998), the same authors'
//! TVCG 1999 paper on pre-computed real-time deformation and contact, and
//! Picinbono, Delingette and Ayache (2001) on St Venant-Kirchhoff.
//!
//! Guarantees of the step path (everything after `load`): no allocation, no
//! panic path (proven at link time by `tools/nopanic-check`), and every loop
//! bounded by a compile-time capacity or a count validated at load.
//!
//! Lints (`forbid(unsafe_code)`, `deny(missing_docs)`, and the clippy
//! lints against panics) are set in the `[lints]` tables of `Cargo.toml`.
#![no_std]

pub mod contact;
pub mod haptic;
pub mod hybrid;
pub mod link;
pub mod math;
pub mod precomputed;
pub mod table;
pub mod tensor_mass;

pub use math::Real;
pub use precomputed::{
    AsConstraint, Constraint, ContactError, ContactPoint, ContactSolution, PrecomputedModel,
};
pub use table::{LoadError, PrecomputedTable};

/// Default compile-time capacity of simultaneous contacts (`M` of the
/// haptic loop and of [`precomputed::PrecomputedTissue`]): a probe tip and a
/// grasper's two jaws with one spare.
pub const MAX_CONTACTS: usize = 4;

/// Largest capacity `M` the pre-computed solve
/// ([`precomputed::PrecomputedModel::contact_forces`]) accepts: its
/// `3M × 3M` system lives on the stack as `M²` 3×3 blocks, and its work
/// grows as `M³`.
pub const MAX_CONTACT_CAPACITY: usize = 16;
