//! The input of haptic sessions: what is simulated (a scene file, [`Scene`]), where the tool
//! goes ([`trajectory`]), and generated tool paths ([`generate`]).
//!
//! Data flow: a scene file (TOML) → [`Scene`] (mesh, fixed vertices, material, model, tool,
//! rates, safety limits, zones) → the partition ([`crate::partition`]), the table build and the
//! session ([`crate::session`]); a trajectory file (CSV) or a [`generate::Generator`] →
//! [`Trajectory`] → every tool point's position (and jaw opening and blade) at each tick
//! ([`Trajectory::positions_at`], [`Trajectory::tools_at`]).
//!
//! A leaf of the harness: it reads meshes ([`crate::mesh`]), materials ([`crate::fem`]), the
//! fixed-vertex predicate ([`crate::fix`]) and the limits, and imports nothing that uses it.

pub mod generate;
pub mod materials;
pub mod spec;
pub mod trajectory;
pub mod zones;

pub use generate::{
    CutLine, GenerateError, Generator, GraspPull, Keyframe, Pinch, Poke, Press, PressHold, Slide,
    Strike, sample_keyframes, sample_keyframes_with_tool_columns,
};
pub use materials::RegionSpec;
pub use spec::*;
pub use trajectory::{FileProblem, LineProblem, Sample, ToolState, Trajectory, TrajectoryError};
pub use zones::{PartitionSpec, Zone, ZoneKind, ZoneShape};
