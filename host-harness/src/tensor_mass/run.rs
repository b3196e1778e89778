//! `palpate dynamic run`: a tensor-mass table built in memory (f64, or f32
//! with `--precision f32`), a scripted load, `N` steps of one integrator
//! through the kernel (its passes dispatched to the CPU's features,
//! [`crate::dispatch`]), a JSON report.

use anyhow::{Context, bail};
use nalgebra::Vector3;
use palpate_kernel::Real;
use palpate_kernel::math::Dispatch;
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::tensor_mass::{
    DynamicParams, ElasticLaw, Integrator, StepError, StepReport, TensorMassModel,
};
use serde::Serialize;

use super::OwnedState;
use crate::dispatch::HostDispatch;
use crate::fem::element::shape_gradients;
use crate::mesh::{MeshReport, TetMesh};
use crate::output::number::shown;
use crate::table::build::{BuildOptions, build};
use crate::table::file::Precision;
use crate::table::load::TableFile;
use crate::threads::{Threaded, default_threads, split_model};

/// A scripted dynamic run.
#[derive(Clone, Debug)]
pub struct RunOptions {
    /// The tensor-mass table: material, density, fixed vertices (its
    /// precision is replaced by [`Self::precision`]).
    pub table: BuildOptions,
    /// What the table stores and the model computes in: f64 (the default of
    /// `dynamic run`) or f32 (the firmware's). The output is f64 either way.
    pub precision: Precision,
    /// Mass-proportional damping, 1/s.
    pub damping_per_s: f64,
    /// The elastic force.
    pub law: ElasticLaw,
    /// Incompressibility penalty `γ`, N (`None`: off).
    pub incompressibility_n: Option<f64>,
    /// Constant external forces `(vertex, N)`.
    pub loads: Vec<(u32, [f64; 3])>,
    /// Gravity, m/s².
    pub gravity_m_s2: [f64; 3],
    /// The integrator.
    pub integrator: Integrator,
    /// Time step, s.
    pub dt_s: f64,
    /// Steps to run.
    pub steps: usize,
    /// Tets removed before the first step.
    pub cut_tets: Vec<u32>,
}

/// The JSON object `dynamic run --json` prints (a CLI contract).
#[derive(Serialize, Debug)]
pub struct RunOutput {
    /// Displacement of every vertex after the last good step, m.
    pub displacements: Vec<[f64; 3]>,
    /// Kinetic energy after the last good step, J.
    pub kinetic_energy: f64,
    /// `(V − V₀)/V₀` over the live tets after the last good step.
    pub volume_change: f64,
    /// `null`, or why the model faulted (it stops there).
    pub fault: Option<String>,
    /// Removed tets (cut and left hanging), ascending.
    pub removed_tets: Vec<u32>,
}

/// Runs `options` on `mesh`, the step's passes on the best this CPU runs
/// ([`HostDispatch::detect`]), the per-tet force pass on
/// [`default_threads`] threads (the same results on any number). Divergence bound: a displacement larger than
/// the mesh's bounding-box diagonal (a body that moves more than its own
/// size has diverged); the kinetic energy is not bounded.
pub fn run(mesh: &TetMesh, report: &MeshReport, options: &RunOptions) -> anyhow::Result<RunOutput> {
    let dispatch = Threaded::new(HostDispatch::detect(), default_threads());
    run_with(mesh, report, options, dispatch)
}

/// [`run`] with the step's passes run through `dispatch`, the per-tet
/// force pass split into `dispatch.parts()` ([`crate::threads`]).
pub fn run_with(
    mesh: &TetMesh,
    report: &MeshReport,
    options: &RunOptions,
    dispatch: impl Dispatch,
) -> anyhow::Result<RunOutput> {
    check_run_steps(mesh, options)?;
    let table = BuildOptions {
        precision: options.precision,
        ..options.table.clone()
    };
    let file = TableFile::from_bytes(&build(mesh, report, &table)?.bytes);
    match options.precision {
        Precision::F32 => run_in::<f32>(mesh, &file, options, dispatch),
        Precision::F64 => run_in::<f64>(mesh, &file, options, dispatch),
    }
}

/// [`run_with`] on the built table `file`, in `T`.
fn run_in<T: Real>(
    mesh: &TetMesh,
    file: &TableFile,
    options: &RunOptions,
    dispatch: impl Dispatch,
) -> anyhow::Result<RunOutput> {
    let table = TensorMassTable::<T>::load(file.bytes()).context("tensor-mass table")?;
    let mut state = OwnedState::for_table(&table);
    let mut split = None;
    let params = host_params(&mesh.positions, options.damping_per_s)
        .with_law(options.law)
        .with_incompressibility(options.incompressibility_n.map(T::of_f64))
        .with_gravity(vector(options.gravity_m_s2));
    let model = TensorMassModel::new(table, state.buffers(), params)?;
    let mut model = split_model(model, &mut split, dispatch.parts())?;
    for &tet in &options.cut_tets {
        model
            .remove_tet(tet)
            .with_context(|| format!("--cut-tets {tet}"))?;
    }
    for &(vertex, force) in &options.loads {
        model
            .set_external_force(vertex, vector(force))
            .with_context(|| format!("--load {vertex}"))?;
    }
    if !(options.dt_s.is_finite() && options.dt_s > 0.0) {
        bail!("--dt must be finite and > 0 s, got {}", shown(options.dt_s));
    }
    let dt_s = T::of_f64(options.dt_s);
    let first = model.displacements_m()?.to_vec();
    let (last, kinetic_energy, fault) = run_steps(options.steps, first, |last| {
        let report = model.step_with(dispatch, options.integrator, dt_s)?;
        last.copy_from_slice(model.displacements_m().map_err(StepError::Faulted)?);
        Ok(report)
    })?;
    let last: Vec<[f64; 3]> = last.iter().map(|u| u.map(T::as_f64)).collect();
    let alive = model.tet_alive();
    Ok(RunOutput {
        volume_change: volume_change(mesh, &last, alive),
        displacements: last,
        kinetic_energy: kinetic_energy.as_f64(),
        fault,
        removed_tets: (0..alive.len() as u32)
            .filter(|&t| !alive[t as usize])
            .collect(),
    })
}

/// An f64 triple in `T` (rounded to nearest for f32).
fn vector<T: Real>(v: [f64; 3]) -> Vector3<T> {
    Vector3::from(v.map(T::of_f64))
}

/// Checks `options.steps` on `mesh` against the offline runs' work limit
/// ([`crate::limits::check_tet_steps`]) before anything is built.
pub fn check_run_steps(mesh: &TetMesh, options: &RunOptions) -> anyhow::Result<()> {
    crate::limits::check_tet_steps(
        "dynamic run",
        mesh.tets.len() as u64,
        u64::try_from(options.steps).unwrap_or(u64::MAX),
        "give fewer --steps or use a coarser mesh",
    )
}

/// Steps `steps` times with `step`, which steps and, on success, writes
/// the field into its argument; stops at a fault. Returns the last good
/// field (starting from `last`), its kinetic energy (J) and the fault, if
/// any: the step loop of `dynamic run`, for the tensor-mass and the hybrid
/// model. One copy of the field per step (the step's own, into a buffer
/// swapped with the last good one).
pub fn run_steps<T: Real, E: Clone>(
    steps: usize,
    mut last: Vec<E>,
    mut step: impl FnMut(&mut Vec<E>) -> Result<StepReport<T>, StepError>,
) -> anyhow::Result<(Vec<E>, T, Option<String>)> {
    let mut kinetic_energy = T::zero();
    let mut field = last.clone();
    for _ in 0..steps {
        match step(&mut field) {
            Ok(report) => {
                kinetic_energy = report.kinetic_energy_j;
                core::mem::swap(&mut last, &mut field);
            }
            Err(StepError::Faulted(f)) => return Ok((last, kinetic_energy, Some(f.to_string()))),
            Err(e) => bail!("{e}"),
        }
    }
    Ok((last, kinetic_energy, None))
}

/// The table of `mesh` that `options` describe (a tensor-mass kind) in f64:
/// host runs verify in f64.
pub fn f64_table(
    mesh: &TetMesh,
    report: &MeshReport,
    options: &BuildOptions,
) -> anyhow::Result<TableFile> {
    let options = BuildOptions {
        precision: Precision::F64,
        ..options.clone()
    };
    Ok(TableFile::from_bytes(&build(mesh, report, &options)?.bytes))
}

/// The host commands' parameters: the linear law without penalty, damping
/// `damping_per_s` (1/s), no gravity,
/// divergence when a displacement exceeds the bounding-box diagonal of
/// `positions` (m), kinetic energy unbounded.
pub fn host_params<T: Real>(positions: &[[f64; 3]], damping_per_s: f64) -> DynamicParams<T> {
    DynamicParams::linear(T::of_f64(damping_per_s), T::of_f64(diagonal(positions)))
}

/// Bounding-box diagonal, m.
pub fn diagonal(positions: &[[f64; 3]]) -> f64 {
    let (lo, hi) = positions.iter().fold(
        ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
        |(lo, hi), p| {
            (
                core::array::from_fn(|i| lo[i].min(p[i])),
                core::array::from_fn(|i| hi[i].max(p[i])),
            )
        },
    );
    Vector3::from(hi).metric_distance(&Vector3::from(lo))
}

/// `(Σ V − Σ V₀) / Σ V₀` over the live tets, `V` at rest + `u` (MODELS.md §3:
/// the linear model's volume is not conserved under large motion).
pub fn volume_change(mesh: &TetMesh, u: &[[f64; 3]], alive: &[bool]) -> f64 {
    let (mut rest, mut now) = (0.0, 0.0);
    for (tet, _) in mesh.tets.iter().zip(alive).filter(|(_, a)| **a) {
        let p0 = tet.map(|v| mesh.positions[v as usize]);
        let p = tet.map(|v| {
            let (x, d) = (mesh.positions[v as usize], u[v as usize]);
            [x[0] + d[0], x[1] + d[1], x[2] + d[2]]
        });
        rest += shape_gradients(&p0).1;
        now += shape_gradients(&p).1;
    }
    (now - rest) / rest
}
