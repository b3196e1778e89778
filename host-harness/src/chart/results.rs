//! The study's results, as `study.json` holds them: one [`Run`] per model,
//! mesh, load and level, one [`Reference`] per load and level, and the
//! [`Study`] that gathers them with the stability maps, the trajectories,
//! the memory chart's tables and the tick counts.

use serde::Serialize;

use super::body::Load;
use super::model::Model;
use super::{memory, stability, ticks, trajectory};
use crate::remap::fit::FittedModel;

/// One model's run on one mesh at one load.
#[derive(Clone, Debug, Serialize)]
pub struct Run {
    /// `"RxH"` cells of the mesh.
    pub mesh: String,
    /// Vertices of the mesh.
    pub vertices: usize,
    /// Tets of the mesh.
    pub tets: usize,
    /// The load.
    pub load: Load,
    /// The level (fraction of the height).
    pub level: f64,
    /// The model.
    pub model: Model,
    /// `null`, or why the run has no equilibrium (divergence, refusal).
    pub fault: Option<String>,
    /// Top-face displacement `tip_m`, m.
    pub tip_m: f64,
    /// `|tip − tip_ref| / |tip_ref|` against the reference (`null` without one).
    pub tip_error: Option<f64>,
    /// Error of the force the model needs for the reference's tip
    /// displacement (its secant stiffness at the tool): `|tip_ref/tip − 1|`.
    pub force_error: Option<f64>,
    /// `|tip − tip_truth| / |tip_truth|` against the neo-Hookean truth
    /// (`null` without one): the error the Pareto fronts and the
    /// "cheapest within" tables use.
    pub truth_tip_error: Option<f64>,
    /// `|tip_truth/tip − 1|` against the neo-Hookean truth.
    pub truth_force_error: Option<f64>,
    /// On the reference's mesh: `‖u − u_ref‖₂ / ‖u_ref‖₂` over all vertices.
    pub l2_error: Option<f64>,
    /// On the reference's mesh: largest `|u_v − u_ref,v|`, m.
    pub max_error_m: Option<f64>,
    /// `(V − V₀)/V₀`.
    pub volume_change: f64,
    /// Tets with negative volume.
    pub inverted_tets: usize,
    /// Median time of one step, f64, s.
    pub step_s: f64,
    /// The same in f32, s.
    pub step_f32_s: Option<f64>,
    /// Steps to reach the equilibrium (1 for the pre-computed models).
    pub steps_to_settle: usize,
    /// `steps_to_settle × step_s`, s.
    pub settle_s: f64,
}

/// The reference of one load and level.
#[derive(Clone, Debug, Serialize)]
pub struct Reference {
    /// The load.
    pub load: Load,
    /// The level.
    pub level: f64,
    /// Total force (N) or torque (N·m) of the load.
    pub magnitude: f64,
    /// `null`, or why Newton failed (St Venant-Kirchhoff's collapse).
    pub fault: Option<String>,
    /// Newton iterations.
    pub iterations: usize,
    /// Tip displacement, m.
    pub tip_m: f64,
    /// `(V − V₀)/V₀`.
    pub volume_change: f64,
    /// Tets with negative volume (St Venant-Kirchhoff's collapse).
    pub inverted_tets: usize,
}

/// The study's results.
#[derive(Clone, Debug, Serialize)]
pub struct Study {
    /// What the body is (the report's first line).
    pub body: String,
    /// Per mesh, the hybrid's tensor-mass region: `(mesh, its tets, all tets)`.
    pub hybrid_region: Vec<(String, usize, usize)>,
    /// Height of the body, m.
    pub height_m: f64,
    /// Young's modulus, Pa, and Poisson ratio.
    pub material: (f64, f64),
    /// The reference mesh, `"RxH"`.
    pub reference_mesh: String,
    /// One per load and level.
    pub references: Vec<Reference>,
    /// The neo-Hookean truth, one per load and level.
    pub truths: Vec<super::truth::Truth>,
    /// Which truth levels were solved and why (the full run's, or the
    /// cheaper one of `--quick`).
    pub truth_levels: String,
    /// Every run.
    pub runs: Vec<Run>,
    /// The quasi-non-linear fit used.
    pub remap: FittedModel,
    /// The stability maps.
    pub stability: Vec<stability::Map>,
    /// The dynamic runs' trajectory errors.
    pub trajectories: Vec<trajectory::Trajectory>,
    /// The memory/accuracy chart's tables (also `memory.json`).
    pub memory: Vec<memory::MemoryPoint>,
    /// Per-tick instructions of the pre-computed models' haptic tick
    /// ([`ticks`]; measured by the command, after [`run`](super::run)).
    pub ticks: ticks::TickCounts,
}
