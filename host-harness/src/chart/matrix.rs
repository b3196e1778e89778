//! The study's extent ([`Matrix`]: meshes, loads, levels, the stability
//! maps' and the trajectories' extents) and its work bound, with the time a
//! tet-step takes here ([`seconds_per_tet_step`]).

use anyhow::Context;
use palpate_kernel::tensor_mass::{DynamicParams, Integrator};

use super::body::{Body, GivenMesh, Load};
use super::measure::median_s;
use super::model::{Model, relaxed_models};
use super::truth::Discretization;
use super::{memory, stability, trajectory};
use crate::dispatch::HostDispatch;
use crate::experiment::scenes::tissue;
use crate::fem::material::Material;
use crate::fix::FixPredicate;
use crate::tensor_mass::run::diagonal;

/// The refinements of the full run, (radial, height) cells of
/// `cylinder_mesh`; the last is the reference's.
pub const FULL_MESHES: [(usize, usize); 3] = [(1, 5), (2, 10), (3, 15)];
/// The refinements of `--quick` (the reference on the last).
pub const QUICK_MESHES: [(usize, usize); 2] = [(1, 5), (2, 10)];
/// Load levels: the linear FEM tip displacement on the finest mesh as a
/// fraction of the height.
pub const LEVELS: [f64; 3] = [0.01, 0.05, 0.20];
/// Levels of `--quick`.
pub const QUICK_LEVELS: [f64; 2] = [0.01, 0.05];
/// Steps of one relaxation at most (full run and `--quick`); measured
/// need: 900–3600 steps on the 3×15 cylinder (twist and bend at 20 %).
pub const MAX_RELAX_STEPS: usize = 20_000;
/// The neo-Hookean truth's levels of the full run ([`super::truth`]): P1
/// on the finest chart mesh and on its refinement (edges halved), then P2
/// on it.
pub const FULL_TRUTH: [Discretization; 3] = [
    Discretization::p1(0),
    Discretization::p1(1),
    Discretization::p2(0),
];
/// The truth's levels of `--quick`: P1 and P2 on its finest mesh (0.6 s
/// for P2 on 2×10 under the 1 % bend; P2 on its refinement took 16.3 s
/// there on a loaded machine, and still changed the charted quantity by
/// 8.8e-3): a check of the truth's machinery, not a converged truth.
pub const QUICK_TRUTH: [Discretization; 2] = [Discretization::p1(0), Discretization::p2(0)];
/// Steps of one relaxation at most in `--quick`.
pub const QUICK_RELAX_STEPS: usize = 20_000;

/// The study's extent.
#[derive(Clone, Debug)]
pub struct Matrix {
    /// Refinements of the cylinder, coarsest first; the last one carries
    /// the reference. Ignored with [`Matrix::given`].
    pub meshes: Vec<(usize, usize)>,
    /// A user's mesh instead of the cylinders.
    pub given: Option<GivenMesh>,
    /// Loads.
    pub loads: Vec<Load>,
    /// Levels (fractions of the height).
    pub levels: Vec<f64>,
    /// The stability map's extent.
    pub stability: stability::MapExtent,
    /// Steps of one relaxation at most.
    pub max_relax_steps: usize,
    /// The trajectories' extent.
    pub trajectory: trajectory::TrajectoryExtent,
    /// Whether to count the haptic tick's instructions under callgrind
    /// (`ticks`).
    pub tick_counts: bool,
    /// The cylinders' material (a given mesh has its own).
    pub material: Material,
    /// The neo-Hookean truth's levels, coarsest first.
    pub truth: Vec<Discretization>,
    /// What the report says of the truth's levels beyond their list.
    pub truth_note: &'static str,
    /// The memory/accuracy chart's meshes (none on a given mesh).
    pub memory_meshes: Vec<memory::MemoryMesh>,
    /// The memory/accuracy chart's encodings.
    pub memory_encodings: Vec<memory::Encoding>,
}

impl Matrix {
    /// The full study.
    pub fn full() -> Self {
        Self {
            meshes: FULL_MESHES.to_vec(),
            given: None,
            loads: Load::ALL.to_vec(),
            levels: LEVELS.to_vec(),
            stability: stability::MapExtent::full(),
            max_relax_steps: MAX_RELAX_STEPS,
            trajectory: trajectory::TrajectoryExtent::full(),
            tick_counts: true,
            material: tissue(),
            truth: FULL_TRUTH.to_vec(),
            truth_note: "",
            memory_meshes: memory::FULL_MESHES.to_vec(),
            memory_encodings: memory::FULL_ENCODINGS.to_vec(),
        }
    }

    /// The reduced study of `--quick`: two meshes, press and bend, two levels.
    pub fn quick() -> Self {
        Self {
            meshes: QUICK_MESHES.to_vec(),
            given: None,
            loads: vec![Load::Press, Load::Bend],
            levels: QUICK_LEVELS.to_vec(),
            stability: stability::MapExtent::quick(),
            max_relax_steps: QUICK_RELAX_STEPS,
            trajectory: trajectory::TrajectoryExtent::quick(),
            tick_counts: false,
            material: tissue(),
            truth: QUICK_TRUTH.to_vec(),
            truth_note: " `--quick` solves P1 and P2 on its finest mesh only, no refinement: \
                         their change (P1 locks in bending) is far above the bound, so its cases \
                         have no converged truth and its selections are those against St \
                         Venant-Kirchhoff; the full run refines further",
            memory_meshes: memory::QUICK_MESHES.to_vec(),
            memory_encodings: memory::QUICK_ENCODINGS.to_vec(),
        }
    }

    /// Static runs: one per mesh, load, level and model, plus one Newton
    /// reference and one neo-Hookean truth per load and level.
    pub fn static_runs(&self) -> usize {
        let cases = self.loads.len() * self.levels.len();
        cases * (self.mesh_count() * Model::ALL.len() + 2)
    }

    /// Tables of the memory/accuracy chart.
    pub fn memory_tables(&self) -> usize {
        self.memory_meshes.len() * self.memory_encodings.len()
    }

    /// The same study on `given` instead of the cylinders, without the
    /// memory/accuracy chart (its meshes are its own: `palpate tables build
    /// --compress` measures a given mesh's tables).
    pub fn on(self, given: GivenMesh) -> Self {
        Self {
            given: Some(given),
            memory_meshes: Vec::new(),
            ..self
        }
    }

    /// Meshes in the study: the given one, or the cylinders.
    pub fn mesh_count(&self) -> usize {
        if self.given.is_some() {
            1
        } else {
            self.meshes.len()
        }
    }

    /// The bodies: the given mesh's, or the cylinders of [`Matrix::meshes`].
    pub fn bodies(&self) -> anyhow::Result<Vec<Body>> {
        match &self.given {
            Some(given) => Ok(vec![given.body()?]),
            None => Ok(self
                .meshes
                .iter()
                .map(|&m| Body::cylinder(m, self.material))
                .collect()),
        }
    }

    /// What the body is, for the report.
    pub fn description(&self) -> String {
        match &self.given {
            Some(g) => format!(
                "The given mesh {} ({} vertices, {} tets) at its own resolution (no refinement \
                 series), supports {}, loaded {}",
                g.label,
                g.mesh.positions.len(),
                g.mesh.tets.len(),
                list(&g.fix),
                if g.load_on.is_empty() {
                    "on the face farthest from the supports".to_string()
                } else {
                    format!("on {}", list(&g.load_on))
                }
            ),
            None => "Cylinder (radius H/5), base fixed, dead loads on the top face".into(),
        }
    }

    /// Trajectories: per trajectory mesh, load, tensor-mass model,
    /// integrator and time step.
    pub fn trajectories(&self) -> usize {
        self.mesh_count().min(self.trajectory.meshes)
            * self.loads.len()
            * trajectory::MODELS.len()
            * Integrator::ALL.len()
            * self.trajectory.dt_factors.len()
    }

    /// Upper bound on the tet-steps (one tet's force evaluation; a
    /// Runge-Kutta step is four) of the static runs, the stability maps and
    /// the trajectories: every relaxation at [`Matrix::max_relax_steps`],
    /// every trial and trajectory run to its end. Not counted: the Newton
    /// references, the `ω_max` estimates and the timing loops (each about
    /// 40 ms: `STEP_SAMPLING`).
    pub fn tet_step_bound(&self, bodies: &[Body]) -> anyhow::Result<u64> {
        let tets = |b: &Body| b.mesh.tets.len() as u64;
        let cases = (self.loads.len() * self.levels.len()) as u64;
        let relaxations: u64 = bodies
            .iter()
            .map(|b| tets(b) * cases * relaxed_models() as u64 * self.max_relax_steps as u64)
            .sum();
        let evaluations: u64 = Integrator::ALL
            .iter()
            .map(|&i| trajectory::evaluations(i) as u64)
            .sum();
        let coarsest = bodies.first().context("no mesh")?;
        let critical =
            crate::tensor_mass::stability::BISECTIONS * crate::tensor_mass::stability::TRIAL_STEPS;
        let trials = self.stability.trials() * stability::TRIAL_STEPS;
        let maps = stability::MAP_MODELS.len() as u64
            * tets(coarsest)
            * evaluations
            * (critical + trials) as u64;
        let mut trajectories = 0;
        for body in bodies.iter().take(self.trajectory.meshes) {
            let two_over_omega = trajectory::two_over_omega_s(body)?;
            let steps: u64 = self
                .trajectory
                .dt_factors
                .iter()
                .map(|&f| {
                    (1 + trajectory::REFINEMENT as u64)
                        * trajectory::steps(f * two_over_omega) as u64
                })
                .sum();
            trajectories += tets(body)
                * self.loads.len() as u64
                * trajectory::MODELS.len() as u64
                * evaluations
                * steps;
        }
        Ok(relaxations + maps + trajectories)
    }
}

/// The predicates `fix`, comma-separated.
fn list(fix: &[FixPredicate]) -> String {
    fix.iter()
        .map(|f| f.to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

/// Median time of one symplectic-Euler step of the costliest law per tet
/// (St Venant-Kirchhoff with the penalty, f64) on `body` from rest, over
/// its tet count: s per tet-step, to turn [`Matrix::tet_step_bound`] into
/// time.
pub fn seconds_per_tet_step(body: &Body) -> anyhow::Result<f64> {
    let (law, penalty) = Model::StvkPenalty
        .tensor_mass(body)
        .context("a tensor-mass model")?;
    let params = DynamicParams::linear(0.0, 100.0 * diagonal(&body.mesh.positions))
        .with_law(law)
        .with_incompressibility(penalty);
    let dt_s = 0.5 * trajectory::two_over_omega_s(body)?;
    let dispatch = HostDispatch::detect();
    let step_s = stability::with_params(body, body.material, params, |model| {
        Ok(median_s(|| {
            let _ =
                core::hint::black_box(model.step_with(dispatch, Integrator::SymplecticEuler, dt_s));
        }))
    })?;
    Ok(step_s / body.mesh.tets.len() as f64)
}
