//! The hybrid model's partition (MODELS.md §5, RR-3510 §6), chosen from a scene's intent: the
//! zones where cutting or large deformation may happen ([`crate::scene::zones`]) become
//! tensor-mass regions with a margin of element rings, the rest is pre-computed.
//!
//! Data flow: scene zones + mesh → [`geometry`] (which tets each zone takes) → [`mod@plan`]
//! ([`Partition`]: regions, connection nodes, laws, refusals) → [`cost`] (table sizes, timed
//! steps, stable steps) → [`report`] (`palpate scene plan`, text or JSON).
//!
//! From a scene: `Partition::of_scene(&scene, &mesh, &report)?`, then
//! `PlanReport::new(&scene, &mesh, &report, &partition)?`.

pub mod cost;
pub mod geometry;
pub mod plan;
pub mod report;

pub use plan::{
    INCOMPRESSIBLE_POISSON, Partition, PlanError, PlanInput, PlannedRegion, RegionModel, plan,
};
pub use report::PlanReport;
