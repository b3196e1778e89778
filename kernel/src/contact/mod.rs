//! Tool contact, between the tables and the tissue models (Cotin 1999 §4;
//! MODELS.md §6): the one allocation-free builder of the collision bucket
//! grid ([`grid`], used by the host's table writer and by the deforming
//! surface of the tensor-mass model), detection and tracking on a surface
//! ([`SurfaceGeometry`]), the one [`Contact`] type that flows from detection
//! to the tissue solve to the force, its bounded sets (the loop's records
//! lent to a solve, [`ContactRefs`]; copies for a physics update,
//! [`ContactSet`]), and the [`Tissue`] trait each model implements for the
//! haptic loop.
//!
//! Depends on [`crate::math`] and [`crate::table`] only.

mod geometry;
pub mod grid;
mod set;
mod tissue;

pub use geometry::{
    ContactWork, MAX_WALK_STEPS, PENETRATION_DEPTH_RADII, Supports, SurfaceGeometry,
};
pub use set::{Contact, ContactRefs, ContactSet, lend};
pub use tissue::{Refusal, Tissue};
