//! The input of haptic sessions: what is simulated ([`scene`]), where the tool goes
//! ([`trajectory`]), and generated tool paths ([`generate`]).
//!
//! Data flow: a scene file (TOML) → [`Scene`] (mesh, fixed vertices, material, model, tool,
//! rates, safety limits) → the table build and the kernel's haptic loop; a trajectory file (CSV)
//! or a [`generate::Generator`] → [`Trajectory`] → every tool point's position at each tick
//! ([`Trajectory::positions_at`]). [`tool_points`] turns a scene's tool-point count into the
//! kernel's const generic.

pub mod generate;
pub mod run;
pub mod scene;
pub mod tool_points;
pub mod trajectory;

pub use generate::{
    GenerateError, Generator, Keyframe, Pinch, Poke, Press, PressHold, Slide, Strike,
    sample_keyframes,
};
pub use scene::{
    DynamicSpec, MAX_TOOL_POINTS, MaterialSpec, MeshSource, ModelSpec, Rates, Scene, SceneError,
    ToolSpec,
};
pub use trajectory::{FileProblem, LineProblem, Sample, Trajectory, TrajectoryError};
