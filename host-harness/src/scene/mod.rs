//! The input of haptic sessions: what is simulated (a scene file, [`Scene`]), where the tool
//! goes ([`trajectory`]), and generated tool paths ([`generate`]).
//!
//! Data flow: a scene file (TOML, `file`) → [`Scene`] ([`spec`]: mesh source, fixed
//! vertices, material and [`materials`] per region, model, [`tool`], rates, safety limits,
//! [`zones`]), checked by [`validate`] → the partition ([`crate::partition`]), the table build
//! and the session ([`crate::session`]); a trajectory file (CSV) or a [`generate::Generator`] →
//! [`Trajectory`] → every tool point's position (and jaw opening and blade) at each tick
//! ([`Trajectory::positions_at`], [`Trajectory::tools_at`]). [`built_in`]: the built-in scenes.
//!
//! A leaf of the harness: it reads meshes ([`crate::mesh`]), materials ([`crate::fem`]), the
//! fixed-vertex predicate ([`crate::fix`]) and the limits, and imports nothing that uses it.

pub mod built_in;
pub mod error;
pub(crate) mod exact;
pub mod file;
pub mod generate;
pub mod materials;
pub mod mesh;
pub mod spec;
pub mod tables;
pub mod tool;
pub mod trajectory;
pub mod validate;
pub mod zones;

pub use built_in::{
    HEPATECTOMY_BLADE_M, HEPATECTOMY_DT_S, HEPATECTOMY_ZONE_PAST_CUT_M, HepatectomySites,
};
pub use error::SceneError;
pub use generate::{
    CutLine, GenerateError, Generator, GraspPull, Keyframe, Pinch, Poke, Press, PressHold, Slide,
    Strike, sample_keyframes, sample_keyframes_with_tool_columns,
};
pub use materials::{DEFAULT_DENSITY_KG_M3, MaterialSpec, RegionSpec};
pub use mesh::{MAX_GENERATED_VERTICES, MeshSource};
pub use spec::{
    CuttingSpec, DEFAULT_CAPACITY_TETS, DEFAULT_CUT_FORCE_N, DEFAULT_HAPTIC_HZ,
    DEFAULT_MAX_FORCE_N, DEFAULT_MAX_SLEW_N_PER_S, DEFAULT_PHYSICS_EVERY, DynamicSpec,
    MAX_CAPACITY_TETS, MAX_SUBSTEPS, ModelSpec, Rates, Scene, TearingSpec,
};
pub use tables::{TableCode, TablesSpec};
pub use tool::{
    DEFAULT_BLADE_M, DEFAULT_GRIP_OPENING_RADII, DEFAULT_JAW_AXIS, DEFAULT_TOOL_POINTS,
    DEFAULT_TOOL_RADIUS_M, MAX_BLADE_M, MAX_TOOL_POINTS, MAX_TOOL_RADIUS_FRACTION, ToolKind,
    ToolSpec,
};
pub use trajectory::{FileProblem, LineProblem, Sample, ToolState, Trajectory, TrajectoryError};
pub use zones::{PartitionSpec, Zone, ZoneKind, ZoneShape};
