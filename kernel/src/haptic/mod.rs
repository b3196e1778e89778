//! The fixed-timestep haptic loop and its safety supervisor (Cotin 1999 §4;
//! MODELS.md §6), the top layer: each tick reads the tool points, detects
//! and tracks contacts ([`crate::contact`]), has the tissue model
//! ([`crate::precomputed::PrecomputedTissue`] or
//! [`crate::tensor_mass::DynamicTissue`]) solve the contact set, and passes
//! the device force through the [`Supervisor`].

mod haptic_loop;
mod safety;
mod tool;

pub use haptic_loop::{
    DynamicLoop, ForceOutput, HapticLoop, HybridLoop, LoopConfig, LoopError, PhysicsTissue,
    PrecomputedLoop, TickCounters,
};
pub use safety::{BadLimits, OutputStatus, SafetyFault, SafetyLimits, Supervisor};
pub use tool::{ToolAction, ToolInput};
