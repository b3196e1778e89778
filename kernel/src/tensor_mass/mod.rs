//! The dynamic linear tensor-mass model (Cotin, Delingette, Ayache, RR-3510 §5;
//! MODELS.md §1 and §3): stiffness stored on vertices (`K_ii`) and edges
//! (`K_ij`), lumped masses, explicit time stepping, so that removing a tet is
//! a local update.
//!
//! Data flow: a [`crate::table::TensorMassTable`] (validated once) plus
//! caller-provided [`StateBuffers`] (static arrays on firmware) →
//! [`TensorMassModel`] → [`TensorMassModel::step`] with an [`Integrator`].
//!
//! Bounded work: a step is one pass over the `N` vertices and the `E` edges
//! per force evaluation (four for RK4); every loop runs over table-declared
//! counts. Nothing allocates and nothing panics; divergence puts the model in
//! a [`Fault`] state the caller sees instead of numbers.
//!
//! For the haptic loop: [`DeformingSurface`] (the surface at the current
//! positions, re-binned per physics update) and [`DynamicTissue`] (the
//! model as a tissue). Depends on [`crate::math`], [`crate::table`] and
//! [`crate::contact`].

mod corotational;
mod coupling;
mod cut;
mod edges;
mod force;
mod integrator;
mod law;
mod limits;
mod model;
mod neo_hookean;
mod split;
mod split_model;
mod state;
mod stvk;
pub mod stvk_terms;
mod surface;
mod tissue;

pub use cut::{CutReport, RemoveError, TearThresholds};
pub use edges::{EDGE_LANES, EdgeGroup};
pub use integrator::Integrator;
pub use law::{ElasticLaw, StvkForm};
pub use limits::Limits;
pub use model::{DynamicParams, InputError, StepError, StepReport, TensorMassModel};
pub use neo_hookean::NEO_HOOKEAN_J_FLOOR;
pub use split::SplitBuffers;
pub use state::{Fault, StateBuffers, StateError, VertexMode};
pub(crate) use surface::check_lengths;
pub use surface::{
    DeformingSurface, NonFinitePosition, SurfaceBufferError, SurfaceBuffers, SurfaceLengths,
};
pub use tissue::{
    Blade, Blades, DynamicTissue, DynamicTissueError, Extrapolation, HeldContact, LocalModel,
    MAX_REMOVAL_CAPACITY, MAX_REMOVED_PER_UPDATE, MAX_SUBSTEPS, MIN_MOVABLE_WEIGHT2, PhysicsConfig,
    PhysicsError, SECANT_MIN_MOTION_M, Tearing, correction_blend, penalty_on_hand,
};
