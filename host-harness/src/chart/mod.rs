//! `palpate chart`: the speed/accuracy study. Every model of the harness is
//! run on the same loaded body at several refinements and loads, measured
//! against the Newton St Venant-Kirchhoff equilibrium on the finest mesh
//! ([`crate::fem::newton`]) and timed; [`plot`] draws the charts, [`report`]
//! writes the report.
//!
//! The body: the generated cylinder ([`cylinder_mesh`], height
//! [`HEIGHT_M`], radius `H/5`, E = 5 kPa, ν = 0.4), base fixed, loaded on its
//! top face by dead loads (one force per top vertex):
//! - **press**: equal shares of an axial force `−F ẑ`, each with the
//!   lateral imperfection [`PRESS_IMPERFECTION`] (so past the buckling
//!   load every model bends the same way);
//! - **bend**: equal shares of a lateral force `F x̂`;
//! - **twist**: tangential forces `T (ẑ × r_v)/Σ|r_v|²` (a torque `T` about
//!   the axis, `r_v` the vertex's distance vector from it).
//!
//! Each load has three levels: the force for which the linear FEM solution
//! on the finest mesh has a top-face displacement ([`tip_m`]) of 1 %, 5 %
//! and 20 % of the height.
//!
//! Models: the pre-computed linear model (the linear FEM solution of the
//! load, `fem::static_solve`; its step is the compliance product `u = C f`
//! the kernel's pre-computed update does), the same with the
//! quasi-non-linear remap (Cotin 1999 TVCG §3, fitted by
//! [`crate::remap::fit`] on the St Venant-Kirchhoff compression sample of
//! the same material and aspect), and the tensor-mass models (linear, St
//! Venant-Kirchhoff, St Venant-Kirchhoff + incompressibility penalty)
//! relaxed to rest by [`crate::experiment::relax`].
//!
//! Bounded: at most [`FULL_MESHES`] × 3 loads × [`LEVELS`] × 5 models
//! (135) static runs of at most [`MAX_RELAX_STEPS`] steps each, and the
//! stability map's [`stability`] trials.

pub mod plot;
pub mod report;
pub mod select;
pub mod series;
pub mod stability;
pub mod svg_text;
pub mod ticks;
pub mod trajectory;

use std::path::Path;

use anyhow::Context;
use faer::Mat;
use nalgebra::Vector3;
use palpate_kernel::precomputed::QuasiNonLinear;
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::tensor_mass::{
    DynamicParams, ElasticLaw, Integrator, StvkForm, TensorMassModel,
};
use serde::Serialize;

use crate::bench::measure::{Sampling, time};
use crate::dispatch::HostDispatch;
use crate::experiment::relax::relax;
use crate::experiment::scenes::tissue;
use crate::experiment::volume_bend::inverted_tets;
use crate::fem::assembly::assemble_restricted;
use crate::fem::llt::SparseLlt;
use crate::fem::material::{Material, TetMaterials};
use crate::fem::newton::{NewtonOptions, StaticProblem, solve_stvk};
use crate::fem::penalty::penalty_n;
use crate::fem::static_solve::solve_loaded;
use crate::fix::{FixPredicate, fixed_vertices};
use crate::hybrid::owned::with_hybrid;
use crate::hybrid::{HybridOptions, HybridTables, build_hybrid, check_hybrid};
use crate::mesh::generate::cylinder_mesh;
use crate::mesh::{MeshReport, TetMesh};
use crate::remap::fit::{FittedModel, fit_curves};
use crate::remap::sample::{Sample, linear_response, stvk_curves};
use crate::table::file::Precision;
use crate::table::tensor_mass::{TensorMassArrays, static_study_table, write_tensor_mass_table};
use crate::tensor_mass::OwnedState;
use crate::tensor_mass::run::{diagonal, volume_change};
use crate::tensor_mass::stability::omega_max;
use palpate_kernel::hybrid::HybridModel;

/// Cylinder height, m.
pub const HEIGHT_M: f64 = 0.1;
/// The refinements of the full run, (radial, height) cells of
/// [`cylinder_mesh`]; the last is the reference's.
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
/// Steps of one relaxation at most in `--quick`.
pub const QUICK_RELAX_STEPS: usize = 20_000;
/// Relaxation tolerance: largest residual force over the largest load on
/// a vertex. At 1e-3 the St Venant-Kirchhoff tip under the 20 % twist on
/// 3×15 was 7e-4 (relative) from its converged value, a bias visible at
/// the 1 % bound; at 1e-5 it is within 1e-5 of it (measured against a
/// relaxation to 1e-7).
pub const RELAX_TOLERANCE: f64 = 1e-5;
/// Newton load increments of the reference per 1 % of tip displacement
/// (at least one).
const NEWTON_STEPS_PER_PERCENT: f64 = 0.5;
/// The press's lateral imperfection: every loaded vertex's share of the
/// axial force carries this fraction of it along [`Body::lateral`] (the
/// bend's direction), for every model and the reference alike, so beyond
/// the buckling load every model solves the same problem with one bend
/// direction (the symmetric mesh and load leave it undecided: without it
/// the relaxations stay on the unstable straight state). Small enough
/// that the press-1 % reference's tip moves by 5e-5 (relative; 3×15:
/// 1.01620 → 1.01625 mm) and its figures in the report not at all.
pub const PRESS_IMPERFECTION: f64 = 1e-3;
/// Density of the tensor-mass tables, kg/m³ (the static studies').
const DENSITY_KG_M3: f64 = 1000.0;
/// The hybrid's tensor-mass region: this fraction of the body's length at
/// its loaded end ([`Body::hybrid_dynamic_tets`]).
pub const HYBRID_DYNAMIC_FRACTION: f64 = 1.0 / 3.0;
/// How a run's time per step is measured ([`crate::bench::measure`], the
/// library of `palpate bench`): one warm-up and 7 kept samples of 2 ms,
/// the median reported. Short, as the matrix times some 300 steps; the
/// spread is `palpate bench`'s to show.
const STEP_SAMPLING: Sampling = Sampling {
    warmup: 1,
    samples: 7,
    sample_s: 2e-3,
};

/// Which loads.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Load {
    /// Axial compression of the top face.
    Press,
    /// Lateral dead load on the top face.
    Bend,
    /// Torque as tangential loads on the top face.
    Twist,
}

impl Load {
    /// Every load.
    pub const ALL: [Load; 3] = [Load::Press, Load::Bend, Load::Twist];

    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            Load::Press => "press",
            Load::Bend => "bend",
            Load::Twist => "twist",
        }
    }
}

/// The models compared.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Model {
    /// Pre-computed linear (linear FEM).
    PrecomputedLinear,
    /// Pre-computed with the quasi-non-linear remap.
    PrecomputedQuasi,
    /// Tensor-mass, linear law.
    TensorMassLinear,
    /// Tensor-mass, St Venant-Kirchhoff.
    Stvk,
    /// Tensor-mass, St Venant-Kirchhoff + incompressibility penalty.
    StvkPenalty,
    /// The hybrid (RR-3510 §6.2): St Venant-Kirchhoff tensor-mass in the
    /// region at the loaded end ([`Body::hybrid_dynamic_tets`]), the rest
    /// pre-computed linear, condensed onto the connection nodes.
    Hybrid,
}

impl Model {
    /// Every model, cheapest family first.
    pub const ALL: [Model; 6] = [
        Model::PrecomputedLinear,
        Model::PrecomputedQuasi,
        Model::TensorMassLinear,
        Model::Stvk,
        Model::StvkPenalty,
        Model::Hybrid,
    ];

    /// The tensor-mass law and incompressibility penalty (N) of the model
    /// on `body`; `None` for the pre-computed models and the hybrid.
    pub fn tensor_mass(self, body: &Body) -> Option<(ElasticLaw, Option<f64>)> {
        let stvk = ElasticLaw::StVenantKirchhoff(StvkForm::PerTet);
        match self {
            Model::PrecomputedLinear | Model::PrecomputedQuasi | Model::Hybrid => None,
            Model::TensorMassLinear => Some((ElasticLaw::Linear, None)),
            Model::Stvk => Some((stvk, None)),
            Model::StvkPenalty => Some((stvk, Some(penalty_n(&body.mesh, &body.material)))),
        }
    }

    /// A tensor-mass model (relaxed, integrated), not a pre-computed one
    /// nor the hybrid.
    pub fn is_tensor_mass(self) -> bool {
        matches!(
            self,
            Model::TensorMassLinear | Model::Stvk | Model::StvkPenalty
        )
    }

    /// A stepped model: tensor-mass, or the hybrid.
    pub fn is_dynamic(self) -> bool {
        self.is_tensor_mass() || self == Model::Hybrid
    }

    /// The law and penalty (N) of the stepped tensor-mass model: the
    /// model's own ([`Model::tensor_mass`]), the hybrid's region's
    /// ([`HYBRID_LAW`]); `None` for the pre-computed models.
    pub fn dynamic_law(self, body: &Body) -> Option<(ElasticLaw, Option<f64>)> {
        match self {
            Model::Hybrid => Some((HYBRID_LAW, None)),
            _ => self.tensor_mass(body),
        }
    }

    /// Name used in the JSON, the charts and the report.
    pub fn name(self) -> &'static str {
        match self {
            Model::PrecomputedLinear => "precomputed-linear",
            Model::PrecomputedQuasi => "precomputed-quasi",
            Model::TensorMassLinear => "tensor-mass-linear",
            Model::Stvk => "stvk",
            Model::StvkPenalty => "stvk-penalty",
            Model::Hybrid => "hybrid",
        }
    }
}

/// How many of [`Model::ALL`] are stepped (relaxed to rest, integrated
/// in the trajectories): the tensor-mass models and the hybrid (whose
/// tensor-mass region has at most the mesh's tets).
fn relaxed_models() -> usize {
    Model::ALL.iter().filter(|m| m.is_dynamic()).count()
}

/// A user's mesh for the study (`palpate chart --mesh`): run at its own
/// resolution only (no refinement series).
#[derive(Clone, Debug)]
pub struct GivenMesh {
    /// The file name, the mesh's label in the study.
    pub label: String,
    /// The rest mesh, m.
    pub mesh: TetMesh,
    /// Its reader report.
    pub report: MeshReport,
    /// The supports.
    pub fix: Vec<FixPredicate>,
    /// The loaded vertices (any predicate matching); empty: the face
    /// farthest from the supports ([`GivenMesh::loaded_vertices`]).
    pub load_on: Vec<FixPredicate>,
    /// Material.
    pub material: Material,
}

/// Of the extent along the axis, the depth of the face loaded by default.
pub const LOADED_FACE_DEPTH: f64 = 1e-3;

impl GivenMesh {
    /// The loaded vertices: those matching [`GivenMesh::load_on`], or by
    /// default the face farthest from the supports: the vertices within
    /// [`LOADED_FACE_DEPTH`] of the mesh's extent of the farthest one along
    /// the direction from the supports' centroid to the mesh's vertex
    /// centroid. Fixed and unreferenced vertices are never loaded.
    pub fn loaded_vertices(&self) -> anyhow::Result<Vec<u32>> {
        let positions = &self.mesh.positions;
        let (fixed, _) = fixed_vertices(positions, &self.fix, &self.report.unreferenced_vertices);
        let candidates = (0..positions.len() as u32).filter(|&v| !fixed[v as usize]);
        if !self.load_on.is_empty() {
            let p = |v: u32| positions[v as usize];
            let loaded: Vec<u32> = candidates
                .filter(|&v| self.load_on.iter().any(|f| f.matches(&p(v))))
                .collect();
            anyhow::ensure!(!loaded.is_empty(), "--load-on matches no free vertex");
            return Ok(loaded);
        }
        let supports = centroid(positions, (0..positions.len()).filter(|&v| fixed[v]))
            .context("no vertex matches the supports (--fix)")?;
        let all = centroid(positions, 0..positions.len()).context("an empty mesh")?;
        let direction = (all - supports)
            .try_normalize(1e-12)
            .context("the supports are centred on the mesh: give the loaded face with --load-on")?;
        let along = |v: u32| (Vector3::from(positions[v as usize]) - supports).dot(&direction);
        let (lo, hi) = (0..positions.len() as u32)
            .map(along)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                (lo.min(x), hi.max(x))
            });
        let depth = LOADED_FACE_DEPTH * (hi - lo);
        Ok(candidates.filter(|&v| along(v) >= hi - depth).collect())
    }

    /// The study's body.
    pub fn body(&self) -> anyhow::Result<Body> {
        Body::with_loaded_vertices(
            self.label.clone(),
            self.mesh.clone(),
            self.report.clone(),
            self.fix.clone(),
            self.loaded_vertices()?,
            self.material,
        )
    }
}

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
    /// ([`ticks`]).
    pub tick_counts: bool,
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
        }
    }

    /// Static runs: one per mesh, load, level and model, plus one Newton
    /// reference per load and level.
    pub fn static_runs(&self) -> usize {
        let cases = self.loads.len() * self.levels.len();
        cases * (self.mesh_count() * Model::ALL.len() + 1)
    }

    /// The same study on `given` instead of the cylinders.
    pub fn on(self, given: GivenMesh) -> Self {
        Self {
            given: Some(given),
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
            None => Ok(self.meshes.iter().map(|&m| Body::cylinder(m)).collect()),
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
            * relaxed_models()
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
                * relaxed_models() as u64
                * evaluations
                * steps;
        }
        Ok(relaxations + maps + trajectories)
    }
}

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
    /// Top-face displacement [`tip_m`], m.
    pub tip_m: f64,
    /// `|tip − tip_ref| / |tip_ref|` against the reference (`null` without one).
    pub tip_error: Option<f64>,
    /// Error of the force the model needs for the reference's tip
    /// displacement (its secant stiffness at the tool): `|tip_ref/tip − 1|`.
    pub force_error: Option<f64>,
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
    /// Every run.
    pub runs: Vec<Run>,
    /// The quasi-non-linear fit used.
    pub remap: FittedModel,
    /// The stability maps.
    pub stability: Vec<stability::Map>,
    /// The dynamic runs' trajectory errors.
    pub trajectories: Vec<trajectory::Trajectory>,
    /// Per-tick instructions of the pre-computed models' haptic tick
    /// ([`ticks`]; measured by the command, after [`run`]).
    pub ticks: ticks::TickCounts,
}

/// The mean rest position of `vertices`, m; `None` for none.
fn centroid(positions: &[[f64; 3]], vertices: impl Iterator<Item = usize>) -> Option<Vector3<f64>> {
    let (mut sum, mut count) = (Vector3::zeros(), 0usize);
    for v in vertices {
        sum += Vector3::from(positions[v]);
        count += 1;
    }
    (count > 0).then(|| sum / count as f64)
}

/// The predicates `fix`, comma-separated.
fn list(fix: &[FixPredicate]) -> String {
    fix.iter()
        .map(|f| f.to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

/// A mesh of the study with its boundary sets and load geometry.
pub struct Body {
    /// `"RxH"` for a cylinder, the file name for a given mesh.
    pub label: String,
    /// The rest mesh.
    pub mesh: TetMesh,
    /// The mesh's reader report (the hybrid's tables are built from it).
    pub report: MeshReport,
    /// The support predicates ([`Body::fixed`] is what they match).
    pub fix: Vec<FixPredicate>,
    /// Fixed vertices.
    pub fixed: Vec<bool>,
    /// The loaded vertices (the cylinder's top face).
    pub top: Vec<u32>,
    /// Material.
    pub material: Material,
    /// Unit vector from the supports to the loaded end (the press pushes
    /// along `−axis`, the twist turns about it).
    pub axis: Vector3<f64>,
    /// Unit vector orthogonal to `axis`: the bend's direction.
    pub lateral: Vector3<f64>,
    /// Centroid of the loaded vertices, m (the twist's axis passes through it).
    pub centre: Vector3<f64>,
    /// Extent of the mesh along `axis`, m: the length the levels are
    /// fractions of.
    pub length_m: f64,
    /// Largest distance of a loaded vertex from the axis through
    /// [`Body::centre`], m: the remap sample's radius.
    pub radius_m: f64,
}

impl Body {
    /// The cylinder of `(radial, height)` cells.
    pub fn cylinder((radial, height): (usize, usize)) -> Self {
        let mesh = cylinder_mesh(HEIGHT_M, radial, height);
        let label = format!("{radial}x{height}");
        let fix = vec!["z<=0".parse().expect("a valid predicate")];
        let top = (0..mesh.positions.len() as u32)
            .filter(|&v| mesh.positions[v as usize][2] == HEIGHT_M)
            .collect();
        let report = MeshReport {
            source: format!("generated cylinder {label}"),
            ..MeshReport::default()
        };
        let body = Self::with_loaded_vertices(label, mesh, report, fix, top, tissue())
            .expect("the cylinder is fixed at its base and loaded on its top");
        // The exact axes (the centroids agree with them to rounding).
        Self {
            axis: Vector3::z(),
            lateral: Vector3::x(),
            centre: Vector3::new(0.0, 0.0, HEIGHT_M),
            radius_m: HEIGHT_M / 5.0,
            ..body
        }
    }

    /// A given mesh with its supports `fix`, its loaded vertices `top`
    /// (not all fixed) and `material`. The axis runs from the fixed
    /// vertices' centroid to the loaded ones'; the bend is along the
    /// coordinate axis most orthogonal to it, made orthogonal.
    pub fn with_loaded_vertices(
        label: String,
        mesh: TetMesh,
        report: MeshReport,
        fix: Vec<FixPredicate>,
        top: Vec<u32>,
        material: Material,
    ) -> anyhow::Result<Self> {
        let (fixed, _) = fixed_vertices(&mesh.positions, &fix, &report.unreferenced_vertices);
        let supports = centroid(&mesh.positions, (0..fixed.len()).filter(|&v| fixed[v]))
            .context("no vertex matches the supports (--fix)")?;
        let loaded: Vec<u32> = top.into_iter().filter(|&v| !fixed[v as usize]).collect();
        let centre = centroid(&mesh.positions, loaded.iter().map(|&v| v as usize))
            .context("no free vertex to load")?;
        let axis = (centre - supports)
            .try_normalize(1e-12)
            .context("the loaded vertices' centroid is the supports' centroid: no axis")?;
        let least = (0..3)
            .min_by(|&a, &b| axis[a].abs().total_cmp(&axis[b].abs()))
            .unwrap_or(0);
        let lateral = (Vector3::ith(least, 1.0) - axis * axis[least]).normalize();
        let along = mesh.positions.iter().map(|p| Vector3::from(*p).dot(&axis));
        let (lo, hi) = along.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
            (lo.min(x), hi.max(x))
        });
        let radius_m = loaded
            .iter()
            .map(|&v| {
                let r = Vector3::from(mesh.positions[v as usize]) - centre;
                (r - axis * r.dot(&axis)).norm()
            })
            .fold(0.0, f64::max);
        Ok(Self {
            radius_m,
            label,
            mesh,
            report,
            fix,
            fixed,
            top: loaded,
            material,
            axis,
            lateral,
            centre,
            length_m: hi - lo,
        })
    }

    /// Nodal loads of `load` with total force (press, bend) or torque
    /// (twist) `magnitude`, N or N·m.
    pub fn loads(&self, load: Load, magnitude: f64) -> Vec<[f64; 3]> {
        let mut f = vec![[0.0; 3]; self.mesh.positions.len()];
        let share = magnitude / self.top.len() as f64;
        let arm = |v: u32| {
            let r = Vector3::from(self.mesh.positions[v as usize]) - self.centre;
            r - self.axis * r.dot(&self.axis)
        };
        let polar: f64 = self.top.iter().map(|&v| arm(v).norm_squared()).sum();
        for &v in &self.top {
            f[v as usize] = match load {
                Load::Press => (share * (PRESS_IMPERFECTION * self.lateral - self.axis)).into(),
                Load::Bend => (share * self.lateral).into(),
                Load::Twist => (self.axis.cross(&arm(v)) * (magnitude / polar)).into(),
            };
        }
        f
    }

    /// The hybrid's tensor-mass region: the tets whose centroid lies in the
    /// [`HYBRID_DYNAMIC_FRACTION`] of the length nearest the loaded end,
    /// and every tet with a loaded vertex (so the load acts on the
    /// tensor-mass region). That is where the rotations of the bend and the
    /// twist are largest (they grow from the supports to the loaded end)
    /// and where a tool would touch and cut.
    pub fn hybrid_dynamic_tets(&self) -> Vec<bool> {
        let end = self.centre.dot(&self.axis);
        let from = end - HYBRID_DYNAMIC_FRACTION * self.length_m;
        let mut loaded = vec![false; self.mesh.positions.len()];
        for &v in &self.top {
            loaded[v as usize] = true;
        }
        self.mesh
            .tets
            .iter()
            .map(|tet| {
                let centroid: Vector3<f64> = tet
                    .iter()
                    .map(|&v| Vector3::from(self.mesh.positions[v as usize]))
                    .sum::<Vector3<f64>>()
                    / 4.0;
                centroid.dot(&self.axis) >= from || tet.iter().any(|&v| loaded[v as usize])
            })
            .collect()
    }

    /// Every tet's material (the body is homogeneous).
    pub fn materials(&self) -> TetMaterials {
        TetMaterials::uniform(self.material, self.mesh.tets.len())
    }

    /// The linear FEM tip displacement ([`tip_m`]) per newton of `load`,
    /// m/N: what scales a load level to its magnitude.
    pub fn tip_per_newton_m(&self, load: Load) -> anyhow::Result<f64> {
        let unit = self.loads(load, 1.0);
        let (u_unit, _) = solve_loaded(
            &self.mesh.positions,
            &self.mesh.tets,
            &self.materials(),
            &self.fixed,
            &[],
            &unit,
        )?;
        Ok(tip_m(&unit, &u_unit))
    }

    /// The static problem of the body under `loads_n` (N per vertex).
    pub fn static_problem<'b>(
        &'b self,
        materials: &'b TetMaterials,
        loads_n: &'b [[f64; 3]],
    ) -> StaticProblem<'b> {
        StaticProblem {
            positions: &self.mesh.positions,
            tets: &self.mesh.tets,
            materials,
            fixed: &self.fixed,
            prescribed: &[],
            loads_n,
        }
    }
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

/// The top-face displacement measured for a load: the work-conjugate mean
/// `Σ f_v·u_v / Σ |f_v|` over the loaded vertices (m): the mean axial
/// shortening under press, the mean lateral deflection under bend, the
/// force-weighted mean tangential displacement under twist.
pub fn tip_m(loads: &[[f64; 3]], u: &[[f64; 3]]) -> f64 {
    let (mut work, mut total) = (0.0, 0.0);
    for (f, d) in loads.iter().zip(u) {
        let f = Vector3::from(*f);
        work += f.dot(&Vector3::from(*d));
        total += f.norm();
    }
    if total > 0.0 { work / total } else { 0.0 }
}

/// The study's progress: one tick per run, and a message.
pub trait Progress {
    /// One run done.
    fn tick(&mut self, message: &str);
}

impl<F: FnMut(&str)> Progress for F {
    fn tick(&mut self, message: &str) {
        self(message);
    }
}

/// Runs the static part and the stability maps of `matrix`.
pub fn run(matrix: &Matrix, progress: &mut dyn Progress) -> anyhow::Result<Study> {
    anyhow::ensure!(matrix.mesh_count() > 0, "no mesh in the matrix");
    let bodies = matrix.bodies()?;
    let finest = bodies.last().context("no mesh")?;
    let material = finest.material;
    let height_m = finest.length_m;

    // The quasi-non-linear fit: the compression sample of the body's
    // aspect (radius H/5) and material, 25 % compression in 8 steps, cubic
    // (the `palpate remap fit` defaults).
    let sample = Sample::new(finest.length_m, finest.radius_m, material)?;
    let curves = stvk_curves(&sample, 0.25, 8).context("remap sample curves")?;
    let remap = fit_curves(&curves, &linear_response(&sample)?, 3)?;
    let quasi = (remap.kernel::<f64>()?, remap.kernel::<f32>()?);

    let mut references = Vec::new();
    let mut runs = Vec::new();
    let mut trajectory_loads = Vec::new();
    for &load in &matrix.loads {
        // Unit-load linear response on the finest mesh: scales the levels.
        let tip_per_unit = finest.tip_per_newton_m(load)?;
        trajectory_loads.push((load, matrix.trajectory.level * height_m / tip_per_unit));
        for &level in &matrix.levels {
            let magnitude = level * height_m / tip_per_unit;
            let reference = reference(finest, load, level, magnitude);
            progress.tick(&format!(
                "reference {} {:.0} %: {}",
                load.name(),
                100.0 * level,
                reference
                    .0
                    .fault
                    .clone()
                    .unwrap_or_else(|| format!("{} Newton iterations", reference.0.iterations))
            ));
            for body in &bodies {
                let same_mesh = core::ptr::eq(body, finest);
                for model in Model::ALL {
                    let (mut run, u) = run_model(
                        body,
                        model,
                        load,
                        (level, magnitude),
                        &quasi,
                        matrix.max_relax_steps,
                    )
                    .with_context(|| {
                        format!("{} on {} {}", model.name(), body.label, load.name())
                    })?;
                    score(&mut run, &u, &reference, same_mesh);
                    progress.tick(&format!(
                        "{} {} {:.0} % {}",
                        body.label,
                        load.name(),
                        100.0 * level,
                        model.name()
                    ));
                    runs.push(run);
                }
            }
            references.push(reference.0);
        }
    }
    let stability = stability::maps(&bodies[0], &matrix.stability, progress)?;
    let trajectories =
        trajectory::trajectories(&bodies, &trajectory_loads, &matrix.trajectory, progress)?;
    let hybrid_region = bodies
        .iter()
        .map(|b| {
            let tets = b.hybrid_dynamic_tets();
            let dynamic = tets.iter().filter(|&&d| d).count();
            (b.label.clone(), dynamic, tets.len())
        })
        .collect();
    Ok(Study {
        body: matrix.description(),
        hybrid_region,
        height_m,
        material: (material.young_pa, material.poisson),
        reference_mesh: finest.label.clone(),
        references,
        runs,
        remap,
        stability,
        trajectories,
        ticks: ticks::TickCounts::Skipped {
            reason: "not measured".into(),
        },
    })
}

/// The Newton St Venant-Kirchhoff equilibrium of `load` at `magnitude` on
/// `body`, and its displacement field (`None` when Newton failed).
///
/// Past a loss of stability Newton follows the stable equilibria
/// ([`NewtonOptions::descent`]: each load increment minimizes the total
/// potential energy from the previous equilibrium, and the end state's
/// tangent must be positive definite). That is what the press beyond
/// ~2.7 % needs: the free-top column's Euler load (`π²EI/4L²`, 2.5 % of
/// `EA` here) is passed, and the press's lateral imperfection
/// ([`PRESS_IMPERFECTION`]) picks the bend direction. Measured on 3×15
/// (`NEWTON_STEPS_PER_PERCENT` increments): plain load-stepped Newton fails
/// there with or without the imperfection (1e-3, 1e-2, 3e-2 of the axial
/// force; up to 640 increments at 5 %: no convergence near 2.7 %, a limit
/// point), because St Venant-Kirchhoff's post-buckling branch is unstable:
/// the bending strains of the buckled column at the base exceed the ~42 %
/// compression where St Venant-Kirchhoff's stress peaks, and the column
/// snaps into its collapse. The stable equilibrium at 5 % and 20 % is that
/// collapse (tip 0.186 m and 0.214 m, past the base; 484 and 962 of 3240
/// tets inverted, ΔV/V₀ −29 % and −59 %): the reference of the law the
/// study compares against, which the models that do not buckle (linear,
/// pre-computed) or resist the collapse (the penalty) miss. The same state
/// at 3, 10 and 60 increments at 5 % (tip to 6 digits), within 0.3 % at 20 %
/// (3 against 10 and 60); with a 1e-2 imperfection the 5 % tip moves by
/// 0.07 %.
fn reference(
    body: &Body,
    load: Load,
    level: f64,
    magnitude: f64,
) -> (Reference, Option<Vec<[f64; 3]>>) {
    let loads = body.loads(load, magnitude);
    let materials = body.materials();
    let problem = body.static_problem(&materials, &loads);
    let options = NewtonOptions {
        load_steps: ((100.0 * level * NEWTON_STEPS_PER_PERCENT).ceil() as usize).max(1),
        max_iterations: 400,
        tolerance: 1e-10,
        descent: true,
    };
    let alive = vec![true; body.mesh.tets.len()];
    match solve_stvk(&problem, &options) {
        Ok(e) => (
            Reference {
                load,
                level,
                magnitude,
                fault: None,
                iterations: e.iterations,
                tip_m: tip_m(&loads, &e.u),
                volume_change: volume_change(&body.mesh, &e.u, &alive),
                inverted_tets: inverted_tets(&body.mesh, &e.u),
            },
            Some(e.u),
        ),
        Err(e) => (
            Reference {
                load,
                level,
                magnitude,
                fault: Some(format!("{e:#}")),
                iterations: 0,
                tip_m: f64::NAN,
                volume_change: f64::NAN,
                inverted_tets: 0,
            },
            None,
        ),
    }
}

/// Fills the errors of `run` (displacements `u`) against `reference`
/// (full fields when `same_mesh`, the reference's mesh).
fn score(
    run: &mut Run,
    u: &[[f64; 3]],
    reference: &(Reference, Option<Vec<[f64; 3]>>),
    same_mesh: bool,
) {
    let (reference, field) = reference;
    if run.fault.is_some() || reference.fault.is_some() || !run.tip_m.is_finite() {
        return;
    }
    run.tip_error = Some((run.tip_m - reference.tip_m).abs() / reference.tip_m.abs());
    run.force_error = Some((reference.tip_m / run.tip_m - 1.0).abs());
    if let (true, Some(field)) = (same_mesh, field) {
        let (mut diff, mut norm, mut max) = (0.0, 0.0, 0.0f64);
        for (a, b) in u.iter().zip(field) {
            let d = (Vector3::from(*a) - Vector3::from(*b)).norm();
            diff += d * d;
            norm += Vector3::from(*b).norm_squared();
            max = max.max(d);
        }
        run.l2_error = Some((diff / norm).sqrt());
        run.max_error_m = Some(max);
    }
}

/// One model's run (errors filled by [`score`]) and its displacements, m.
fn run_model(
    body: &Body,
    model: Model,
    load: Load,
    (level, magnitude): (f64, f64),
    quasi: &(QuasiNonLinear<f64>, QuasiNonLinear<f32>),
    max_steps: usize,
) -> anyhow::Result<(Run, Vec<[f64; 3]>)> {
    let loads = body.loads(load, magnitude);
    let outcome = match (model, model.tensor_mass(body)) {
        (_, Some((law, penalty))) => dynamic(body, &loads, law, penalty, max_steps)?,
        (Model::PrecomputedQuasi, None) => precomputed(body, &loads, Some(quasi))?,
        (Model::Hybrid, None) => hybrid(body, &loads, max_steps)?,
        (_, None) => precomputed(body, &loads, None)?,
    };
    let alive = vec![true; body.mesh.tets.len()];
    let run = Run {
        mesh: body.label.clone(),
        vertices: body.mesh.positions.len(),
        tets: body.mesh.tets.len(),
        load,
        level,
        model,
        fault: outcome.fault,
        tip_m: tip_m(&loads, &outcome.u),
        tip_error: None,
        force_error: None,
        l2_error: None,
        max_error_m: None,
        volume_change: volume_change(&body.mesh, &outcome.u, &alive),
        inverted_tets: inverted_tets(&body.mesh, &outcome.u),
        step_s: outcome.step_s,
        step_f32_s: outcome.step_f32_s,
        steps_to_settle: outcome.steps,
        settle_s: outcome.steps as f64 * outcome.step_s,
    };
    Ok((run, outcome.u))
}

/// What a model's run gives.
struct Outcome {
    u: Vec<[f64; 3]>,
    fault: Option<String>,
    step_s: f64,
    step_f32_s: Option<f64>,
    steps: usize,
}

/// The pre-computed model under the nodal `loads`: the compliance columns
/// `C` of the loaded DOFs (one sparse Cholesky factorization, one solve per
/// column; the columns the pre-computed table stores), the step `u = C f`
/// over the free vertices, and with `quasi` the remap of each vertex's
/// displacement ([`quasi_displacements`]). Timed in f64 and f32.
fn precomputed(
    body: &Body,
    loads: &[[f64; 3]],
    quasi: Option<&(QuasiNonLinear<f64>, QuasiNonLinear<f32>)>,
) -> anyhow::Result<Outcome> {
    let n = body.mesh.positions.len();
    let mut slot = vec![None; n];
    let mut free = Vec::new();
    for (v, s) in slot.iter_mut().enumerate() {
        if !body.fixed[v] {
            *s = Some(free.len() as u32);
            free.push(v);
        }
    }
    let loaded: Vec<usize> = (0..n)
        .filter(|&v| loads[v].iter().any(|&x| x != 0.0))
        .collect();
    let k = assemble_restricted(
        &body.mesh.positions,
        &body.mesh.tets,
        &body.materials(),
        &slot,
        free.len(),
    );
    let llt = SparseLlt::new(k.as_ref()).context("stiffness of the free vertices")?;
    let rows = 3 * free.len();
    let mut columns = Mat::<f64>::zeros(rows, 3 * loaded.len());
    let mut weights = Vec::with_capacity(3 * loaded.len());
    for (j, &v) in loaded.iter().enumerate() {
        let s = slot[v].context("a loaded vertex is fixed")? as usize;
        for c in 0..3 {
            columns[(3 * s + c, 3 * j + c)] = 1.0;
            weights.push(loads[v][c]);
        }
    }
    llt.solve_in_place(columns.as_mut());
    // Column-major dense compliance, the kernel's layout of a column walk.
    let c64: Vec<f64> = (0..weights.len())
        .flat_map(|j| (0..rows).map(move |i| (i, j)))
        .map(|(i, j)| columns[(i, j)])
        .collect();
    let c32: Vec<f32> = c64.iter().map(|&x| x as f32).collect();
    let w32: Vec<f32> = weights.iter().map(|&x| x as f32).collect();
    let mut out64 = vec![0.0f64; rows];
    let mut out32 = vec![0.0f32; rows];
    let direction = quasi.and_then(|_| {
        let total: Vector3<f64> = loads.iter().map(|f| Vector3::from(*f)).sum();
        QuasiNonLinear::direction(&total)
    });
    let total = direction.map_or(0.0, |d| {
        loads.iter().map(|f| Vector3::from(*f).dot(&d)).sum::<f64>()
    });
    let direction32 = direction.map(|d| d.map(|x| x as f32));
    let step_s = median_s(|| {
        compliance_product(&c64, &weights, &mut out64);
        if let (Some((q, _)), Some(d)) = (quasi, &direction) {
            remap_rows(q, d, 1.0, &mut out64);
        }
        core::hint::black_box(&out64);
    });
    let step_f32_s = median_s(|| {
        compliance_product(&c32, &w32, &mut out32);
        if let (Some((_, q)), Some(d)) = (quasi, &direction32) {
            remap_rows(q, d, 1.0, &mut out32);
        }
        core::hint::black_box(&out32);
    });
    compliance_product(&c64, &weights, &mut out64);
    if let (Some((q, _)), Some(d)) = (quasi, &direction) {
        remap_rows(q, d, axial_scale(q, total), &mut out64);
    }
    let mut u = vec![[0.0; 3]; n];
    for (s, &v) in free.iter().enumerate() {
        u[v] = [out64[3 * s], out64[3 * s + 1], out64[3 * s + 2]];
    }
    Ok(Outcome {
        u,
        fault: None,
        step_s,
        step_f32_s: Some(step_f32_s),
        steps: 1,
    })
}

/// Median time of one call of `call`, s, sampled as [`STEP_SAMPLING`].
pub(crate) fn median_s(call: impl FnMut()) -> f64 {
    time(&STEP_SAMPLING, call).median_s
}

/// `out = Σ_j w_j C_j` over the columns `C_j` of the column-major `c`.
fn compliance_product<T: palpate_kernel::Real>(c: &[T], w: &[T], out: &mut [T]) {
    out.fill(T::zero());
    for (column, &wj) in c.chunks_exact(out.len()).zip(w) {
        for (o, &cij) in out.iter_mut().zip(column) {
            *o += cij * wj;
        }
    }
}

/// Each vertex's displacement of `rows` (xyz triples) scaled by `scale`,
/// then its part orthogonal to `direction` remapped by φ
/// ([`QuasiNonLinear::displacement`]).
fn remap_rows<T: palpate_kernel::Real>(
    quasi: &QuasiNonLinear<T>,
    direction: &Vector3<T>,
    scale: T,
    rows: &mut [T],
) {
    for r in rows.chunks_exact_mut(3) {
        let u = Vector3::new(r[0], r[1], r[2]) * scale;
        let q = quasi.displacement(direction, u);
        r.copy_from_slice(q.as_slice());
    }
}

/// The quasi-non-linear model under a dead load of total colinear force
/// `force_n`: the compression the remapped force law `ψ` needs to carry
/// it, over the linear one (`ψ⁻¹(F)/F`, by bisection on the monotone ψ);
/// 1 for no force.
fn axial_scale(quasi: &QuasiNonLinear<f64>, force_n: f64) -> f64 {
    if force_n == 0.0 {
        return 1.0;
    }
    let target = force_n.abs();
    let (mut lo, mut hi) = (0.0, target);
    for _ in 0..64 {
        if quasi.force.apply(hi) >= target {
            break;
        }
        (lo, hi) = (hi, 2.0 * hi);
    }
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if quasi.force.apply(mid) < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi / target
}

/// A tensor-mass model of `body` under the nodal `loads`, relaxed to rest
/// (symplectic Euler at `0.5/ω_max` with kinetic damping,
/// [`relax`]); time per step measured in f64 at the equilibrium and in f32
/// from rest, with the host's CPU-feature dispatch ([`HostDispatch`], as
/// `dynamic run` steps).
fn dynamic(
    body: &Body,
    loads: &[[f64; 3]],
    law: ElasticLaw,
    incompressibility_n: Option<f64>,
    max_steps: usize,
) -> anyhow::Result<Outcome> {
    let n = body.mesh.positions.len();
    let file = static_study_table(&body.mesh, &body.materials(), body.fixed.clone());
    let table = TensorMassTable::<f64>::load(file.bytes()).context("tensor-mass table")?;
    let mut state = OwnedState::for_table(&table);
    let bound = 100.0 * diagonal(&body.mesh.positions);
    let params = DynamicParams::linear(0.0, bound)
        .with_law(law)
        .with_incompressibility(incompressibility_n);
    let mut model = TensorMassModel::new(table, state.buffers(), params)?;
    let dt_s = 0.5 / omega_max(&mut model);
    model.reset();
    set_loads(&mut model, loads)?;
    let largest = loads
        .iter()
        .map(|f| Vector3::from(*f).norm())
        .fold(0.0, f64::max);
    let mut u = vec![[0.0; 3]; n];
    let (fault, steps) = relax_outcome(relax(
        &mut model,
        loads,
        dt_s,
        RELAX_TOLERANCE * largest,
        max_steps,
        &mut u,
    ));
    // Time per step: the law's step from the state reached (reset if it
    // faulted, so the step runs).
    if model.fault().is_some() {
        model.reset();
    }
    let dispatch = HostDispatch::detect();
    let step_s = median_s(|| {
        let _ = core::hint::black_box(model.step_with(dispatch, Integrator::SymplecticEuler, dt_s));
    });
    let step_f32_s = dynamic_f32_step(body, loads, law, incompressibility_n, dt_s)?;
    Ok(Outcome {
        u,
        fault,
        step_s,
        step_f32_s: Some(step_f32_s),
        steps,
    })
}

/// The hybrid of `body` ([`Model::Hybrid`]) under the nodal `loads` (all
/// on its tensor-mass region), relaxed to rest as [`dynamic`] relaxes the
/// tensor-mass models (the condensed region's force is part of every force
/// evaluation, so the residual is the whole body's); time per step of the
/// coupled step in f64 at the equilibrium and in f32 from rest.
fn hybrid(body: &Body, loads: &[[f64; 3]], max_steps: usize) -> anyhow::Result<Outcome> {
    let n = body.mesh.positions.len();
    // A mesh whose loaded end is all of it (or none) has no hybrid: a
    // fault of the run, not of the study.
    let tables = match hybrid_tables(body, body.material, Precision::F64) {
        Ok(tables) => tables,
        Err(e) => {
            return Ok(Outcome {
                u: vec![[0.0; 3]; n],
                fault: Some(format!("no hybrid of this mesh: {e:#}")),
                step_s: f64::NAN,
                step_f32_s: None,
                steps: 0,
            });
        }
    };
    let local = region_loads(&tables, loads)?;
    let largest = loads
        .iter()
        .map(|f| Vector3::from(*f).norm())
        .fold(0.0, f64::max);
    let bound = 100.0 * diagonal(&body.mesh.positions);
    let params = DynamicParams::linear(0.0, bound).with_law(HYBRID_LAW);
    let (u, fault, steps, step_s, dt_s) = with_hybrid(&tables, params, |h| {
        let dt_s = 0.5 / omega_max(h.dynamic_mut());
        h.reset();
        set_loads(h.dynamic_mut(), &local)?;
        let mut last = vec![[0.0; 3]; local.len()];
        let relaxed = relax(
            h.dynamic_mut(),
            &local,
            dt_s,
            RELAX_TOLERANCE * largest,
            max_steps,
            &mut last,
        );
        let (fault, steps) = relax_outcome(relaxed);
        let u = match fault {
            None => hybrid_field(h, n)?,
            Some(_) => vec![[0.0; 3]; n],
        };
        if h.dynamic().fault().is_some() {
            h.reset();
        }
        let step_s = median_s(|| {
            let _ = core::hint::black_box(h.step(Integrator::SymplecticEuler, dt_s));
        });
        anyhow::Ok((u, fault, steps, step_s, dt_s))
    })??;
    let tables32 = hybrid_tables(body, body.material, Precision::F32)?;
    let params32 = DynamicParams::linear(0.0f32, bound as f32).with_law(HYBRID_LAW);
    let step_f32_s = with_hybrid(&tables32, params32, |h| {
        set_loads(h.dynamic_mut(), &local)?;
        anyhow::Ok(median_s(|| {
            if h.dynamic().fault().is_some() {
                h.reset();
            }
            let _ = core::hint::black_box(h.step(Integrator::SymplecticEuler, dt_s as f32));
        }))
    })??;
    Ok(Outcome {
        u,
        fault,
        step_s,
        step_f32_s: Some(step_f32_s),
        steps,
    })
}

/// The checks of a study that would otherwise fail late, run before any work: `out` can be
/// written (the nearest folder that exists on its path takes a file; nothing is created or
/// left there), and every body has a hybrid ([`check_hybrid`] of its tables in f64 and f32:
/// its loaded end is neither none nor all of it, its pre-computed region has a free vertex,
/// its tables are within the limits). Each error is one line naming the path or the mesh.
pub fn preflight(bodies: &[Body], out: &Path) -> anyhow::Result<()> {
    let existing = out
        .ancestors()
        .find(|p| p.as_os_str().is_empty() || p.exists())
        .map(|p| {
            if p.as_os_str().is_empty() {
                Path::new(".")
            } else {
                p
            }
        })
        .unwrap_or(Path::new("."));
    if !existing.is_dir() {
        anyhow::bail!(
            "--out {}: {} is not a folder: refused before the study",
            out.display(),
            existing.display()
        );
    }
    let probe = existing.join(format!(".palpate-chart-probe-{}", std::process::id()));
    match std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
    {
        Ok(_) => std::fs::remove_file(&probe).with_context(|| {
            format!("--out {}: cannot remove {}", out.display(), probe.display())
        })?,
        Err(e) => anyhow::bail!(
            "--out {}: cannot write in {} ({e}): refused before the study",
            out.display(),
            existing.display()
        ),
    }
    for body in bodies {
        let dynamic = body.hybrid_dynamic_tets();
        for precision in [Precision::F64, Precision::F32] {
            let options =
                HybridOptions::new(body.material, DENSITY_KG_M3, body.fix.clone(), precision);
            check_hybrid(&body.mesh, &body.report, &dynamic, &options).with_context(|| {
                format!(
                    "mesh {}: no hybrid model of it for the study (its tensor-mass region is \
                     the loaded end, {} of its {} tets): refused before the study",
                    body.label,
                    dynamic.iter().filter(|&&d| d).count(),
                    dynamic.len()
                )
            })?;
        }
    }
    Ok(())
}

/// The hybrid's law on its tensor-mass region.
pub const HYBRID_LAW: ElasticLaw = ElasticLaw::StVenantKirchhoff(StvkForm::PerTet);

/// The hybrid's tables of `body` with `material` in `precision`: its
/// tensor-mass region [`Body::hybrid_dynamic_tets`], the rest pre-computed.
pub(crate) fn hybrid_tables(
    body: &Body,
    material: Material,
    precision: Precision,
) -> anyhow::Result<HybridTables> {
    let options = HybridOptions::new(material, DENSITY_KG_M3, body.fix.clone(), precision);
    build_hybrid(
        &body.mesh,
        &body.report,
        &body.hybrid_dynamic_tets(),
        &options,
    )
}

/// The nodal `loads` of the whole mesh on the hybrid's tensor-mass region
/// (its vertex numbering); every loaded vertex must lie in it.
pub(crate) fn region_loads(
    tables: &HybridTables,
    loads: &[[f64; 3]],
) -> anyhow::Result<Vec<[f64; 3]>> {
    let split = &tables.split;
    let mut local = vec![[0.0; 3]; split.dynamic_vertex.len()];
    for (v, f) in loads.iter().enumerate() {
        if f.iter().any(|&x| x != 0.0) {
            let l =
                split.dynamic_index[v].context("a loaded vertex outside the tensor-mass region")?;
            local[l as usize] = *f;
        }
    }
    Ok(local)
}

/// Sets the nonzero nodal `loads` (N, f64, converted to `T`) on `model`.
pub(crate) fn set_loads<T: palpate_kernel::Real>(
    model: &mut TensorMassModel<'_, '_, T>,
    loads: &[[f64; 3]],
) -> anyhow::Result<()> {
    for (v, f) in loads.iter().enumerate() {
        if f.iter().any(|&x| x != 0.0) {
            model.set_external_force(v as u32, Vector3::from(f.map(T::of_f64)))?;
        }
    }
    Ok(())
}

/// The hybrid's displacement field over the whole mesh of `n` vertices, m:
/// the pre-computed region's background brought up to date first.
pub(crate) fn hybrid_field(
    h: &mut HybridModel<'_, '_, f64>,
    n: usize,
) -> anyhow::Result<Vec<[f64; 3]>> {
    let mut u = vec![[0.0; 3]; n];
    h.update_background(usize::MAX)?;
    h.displacements::<1>(None, &mut u)?;
    Ok(u)
}

/// The fault (`None` when settled) and the steps of a relaxation.
fn relax_outcome(
    relaxed: Result<crate::experiment::relax::Relaxation, palpate_kernel::tensor_mass::StepError>,
) -> (Option<String>, usize) {
    match relaxed {
        Ok(r) if r.converged => (None, r.steps),
        Ok(r) => (
            Some(format!(
                "not settled in {} steps (residual {:.2e} N)",
                r.steps, r.residual_n
            )),
            r.steps,
        ),
        Err(e) => (Some(format!("diverged: {e}")), 0),
    }
}

/// Median time of one f32 symplectic-Euler step of the same model, s.
fn dynamic_f32_step(
    body: &Body,
    loads: &[[f64; 3]],
    law: ElasticLaw,
    incompressibility_n: Option<f64>,
    dt_s: f64,
) -> anyhow::Result<f64> {
    let arrays = TensorMassArrays::new(
        &body.mesh,
        &body.materials(),
        DENSITY_KG_M3,
        body.fixed.clone(),
    );
    let bytes = write_tensor_mass_table(
        &body.mesh,
        &crate::mesh::boundary_surface(&body.mesh).triangles,
        &arrays,
        Precision::F32,
    );
    let file = crate::table::load::TableFile::from_bytes(&bytes);
    let table = TensorMassTable::<f32>::load(file.bytes()).context("f32 tensor-mass table")?;
    let mut state = OwnedState::for_table(&table);
    let bound = 100.0 * diagonal(&body.mesh.positions);
    let params = DynamicParams::linear(0.0f32, bound as f32)
        .with_law(law)
        .with_incompressibility(incompressibility_n.map(|g| g as f32));
    let mut model = TensorMassModel::new(table, state.buffers(), params)?;
    set_loads(&mut model, loads)?;
    let dt = dt_s as f32;
    let dispatch = HostDispatch::detect();
    Ok(median_s(|| {
        if model.fault().is_some() {
            model.reset();
        }
        let _ = core::hint::black_box(model.step_with(dispatch, Integrator::SymplecticEuler, dt));
    }))
}
