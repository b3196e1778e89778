//! The input of haptic sessions: what is simulated ([`scene`]), where the tool goes
//! ([`trajectory`]), and generated tool paths ([`generate`]).
//!
//! Data flow: a scene file (TOML) → [`Scene`] (mesh, fixed vertices, material, model, tool,
//! rates, safety limits) → the table build and the kernel's haptic loop; a trajectory file (CSV)
//! or a [`generate::Generator`] → [`Trajectory`] → every tool point's position (and jaw opening
//! and blade) at each tick ([`Trajectory::positions_at`], [`Trajectory::tools_at`]).
//! [`tools`] expands each tick's tool states into the kernel's tool points (a grasper is two
//! jaws), and [`tool_points`] turns their count into the kernel's const generic.

pub mod generate;
pub mod hybrid;
pub mod materials;
pub mod model;
pub mod run;
pub mod scene;
pub mod stability;
pub mod tool_points;
pub mod tools;
pub mod trajectory;
pub mod zones;

pub use generate::{
    CutLine, GenerateError, Generator, GraspPull, Keyframe, Pinch, Poke, Press, PressHold, Slide,
    Strike, sample_keyframes, sample_keyframes_with_tool_columns,
};
pub use materials::RegionSpec;
pub use scene::{
    DynamicSpec, MAX_TOOL_POINTS, MaterialSpec, MeshSource, ModelSpec, Rates, Scene, SceneError,
    ToolSpec,
};
pub use trajectory::{FileProblem, LineProblem, Sample, ToolState, Trajectory, TrajectoryError};
pub use zones::{PartitionSpec, Zone, ZoneKind, ZoneShape};
