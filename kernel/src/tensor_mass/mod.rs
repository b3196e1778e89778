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

mod cut;
mod force;
mod integrator;
mod law;
mod model;
mod state;
mod stvk;
pub mod stvk_terms;

pub use cut::{CutReport, RemoveError, TearThresholds};
pub use integrator::Integrator;
pub use law::{ElasticLaw, StvkForm};
pub use model::{DynamicParams, InputError, Limits, StepError, StepReport, TensorMassModel};
pub use state::{Fault, StateBuffers, StateError, VertexMode};
