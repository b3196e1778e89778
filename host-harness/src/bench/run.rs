//! `palpate bench`'s run: the measurements it makes on one mesh, their
//! estimated duration (checked against [`MAX_BENCH_ESTIMATE_S`] before any
//! table is built), and one [`Record`] per measurement.

use std::collections::BTreeMap;

use anyhow::{anyhow, bail};
use palpate_kernel::tensor_mass::{ElasticLaw, Integrator, StvkForm};
use serde::Serialize;

use super::measure::{Sampling, Timing, estimated_seconds, time_copy};
use super::precomputed::PrecomputedBench;
use super::tensor_mass::{StepConfig, StepCounts, TensorMassBench};
use crate::dispatch::HostDispatch;
use crate::fem::material::Material;
use crate::fem::penalty::penalty_n;
use crate::fix::FixPredicate;
use crate::limits::{MAX_BENCH_ESTIMATE_S, MAX_BENCH_SAMPLE_S, MAX_BENCH_SAMPLES};
use crate::mesh::{MeshReport, TetMesh};
use crate::output::number::shown;
use crate::output::stderr;
use crate::table::build::BuildOptions;
use crate::table::compliance::Solver;
use crate::table::estimate::SizeLimits;
use crate::table::file::Precision;

/// A model `palpate bench --models` names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, clap::ValueEnum)]
pub enum BenchModel {
    /// The pre-computed model: force path, displacement update, haptic tick.
    Precomputed,
    /// Tensor-mass, linear.
    Linear,
    /// St Venant-Kirchhoff per tet.
    Stvk,
    /// St Venant-Kirchhoff by Picinbono's split terms.
    StvkTensors,
    /// St Venant-Kirchhoff per tet with the incompressibility penalty.
    StvkIncompressible,
    /// St Venant-Kirchhoff split terms with the incompressibility penalty.
    StvkTensorsIncompressible,
    /// Co-rotational linear, per tet.
    Corotational,
    /// Neo-Hookean, per tet.
    NeoHookean,
}

impl BenchModel {
    /// Every model, in the order a run measures them.
    pub const ALL: [BenchModel; 8] = [
        BenchModel::Precomputed,
        BenchModel::Linear,
        BenchModel::Stvk,
        BenchModel::StvkTensors,
        BenchModel::StvkIncompressible,
        BenchModel::StvkTensorsIncompressible,
        BenchModel::Corotational,
        BenchModel::NeoHookean,
    ];

    /// The tensor-mass law and whether the penalty is on; `None` for the
    /// pre-computed model.
    fn law(self) -> Option<(ElasticLaw, bool)> {
        let stvk = |form| ElasticLaw::StVenantKirchhoff(form);
        match self {
            BenchModel::Precomputed => None,
            BenchModel::Linear => Some((ElasticLaw::Linear, false)),
            BenchModel::Stvk => Some((stvk(StvkForm::PerTet), false)),
            BenchModel::StvkTensors => Some((stvk(StvkForm::Tensors), false)),
            BenchModel::StvkIncompressible => Some((stvk(StvkForm::PerTet), true)),
            BenchModel::StvkTensorsIncompressible => Some((stvk(StvkForm::Tensors), true)),
            BenchModel::Corotational => Some((ElasticLaw::Corotational, false)),
            BenchModel::NeoHookean => Some((ElasticLaw::NeoHookean, false)),
        }
    }
}

/// What `palpate bench` measures and how.
#[derive(Clone, Debug)]
pub struct BenchOptions {
    /// The tissue's material.
    pub material: Material,
    /// Mass density, kg/m³ (the tensor-mass model's masses).
    pub density_kg_m3: f64,
    /// Fixed-vertex predicates.
    pub fix: Vec<FixPredicate>,
    /// The models, each measured in full (deduplicated, in [`BenchModel::ALL`]'s order).
    pub models: Vec<BenchModel>,
    /// The integrators of the tensor-mass steps.
    pub integrators: Vec<Integrator>,
    /// The precisions, each measured.
    pub precisions: Vec<Precision>,
    /// Where the dispatched passes (steps, displacement update) run; each
    /// is measured.
    pub dispatches: Vec<HostDispatch>,
    /// How each measurement is sampled.
    pub sampling: Sampling,
}

/// What a measurement times.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct What {
    /// `force-path`, `displacement-update`, `haptic-tick` or `step`.
    pub group: &'static str,
    /// `precomputed`, or the tensor-mass law (`linear`, `stvk`,
    /// `stvk-tensors`, `stvk-incompressible`, `stvk-tensors-incompressible`,
    /// `corotational`, `neo-hookean`).
    pub model: &'static str,
    /// The step's integrator (`euler`, `symplectic`, `rk4`, `central`),
    /// `null` for the pre-computed model.
    pub integrator: Option<&'static str>,
    /// Contacts (force path, update) or tool points (tick), `null` for a
    /// step.
    pub contacts: Option<usize>,
    /// `f32` or `f64`.
    pub precision: &'static str,
    /// Where the measured passes ran: `portable`, `avx2+fma` or `avx512`
    /// (`portable` for the force path and the tick, which are not
    /// dispatched).
    pub dispatch: &'static str,
}

impl What {
    /// `step stvk/symplectic` or `haptic-tick m=2`, for the text table.
    pub fn label(&self) -> String {
        match (self.integrator, self.contacts) {
            (Some(integrator), _) => format!("step {}/{integrator}", self.model),
            (None, Some(m)) => format!("{} m={m}", self.group),
            (None, None) => self.group.to_string(),
        }
    }
}

/// One measurement: what `--json` prints, one object per line.
#[derive(Clone, Debug, Serialize)]
pub struct Record {
    /// The mesh (file name as given).
    pub mesh: String,
    /// Its vertex count.
    pub vertices: usize,
    /// Its tet count.
    pub tets: usize,
    /// What was timed.
    #[serde(flatten)]
    pub what: What,
    /// Time per call, s, and how it was sampled.
    #[serde(flatten)]
    pub timing: Timing,
    /// Bytes one call reads (step, update), `null` otherwise.
    pub bytes_read: Option<u64>,
    /// The median of a memory copy of `bytes_read` bytes, s.
    pub copy_median_s: Option<f64>,
    /// `median_s / copy_median_s`.
    pub ratio_to_copy: Option<f64>,
    /// Steps that faulted while timed (0 expected), `null` for the
    /// pre-computed model.
    pub faults: Option<u64>,
}

/// One planned measurement.
#[derive(Clone, Copy, Debug)]
enum Item {
    ForcePath(usize),
    Update(usize, HostDispatch),
    Tick(usize),
    Step(StepConfig, HostDispatch),
}

impl Item {
    fn what(&self, precision: Precision) -> What {
        let (group, model, integrator, contacts, dispatch) = match *self {
            Item::ForcePath(m) => ("force-path", "precomputed", None, Some(m), "portable"),
            Item::Update(m, d) => (
                "displacement-update",
                "precomputed",
                None,
                Some(m),
                d.name(),
            ),
            Item::Tick(m) => ("haptic-tick", "precomputed", None, Some(m), "portable"),
            Item::Step(config, d) => {
                let integrator = Some(config.integrator.name());
                ("step", config.model_name(), integrator, None, d.name())
            }
        };
        What {
            group,
            model,
            integrator,
            contacts,
            precision: precision_name(precision),
            dispatch,
        }
    }
}

/// The measurements of a run, in order, each with its precision.
fn plan(options: &BenchOptions, penalty: f64) -> Vec<(Item, Precision)> {
    let mut items = Vec::new();
    let mut models = options.models.clone();
    models.sort();
    models.dedup();
    let contacts = 1..=palpate_kernel::MAX_CONTACTS;
    for model in models {
        match model.law() {
            None => {
                for &p in &options.precisions {
                    items.extend(contacts.clone().map(|m| (Item::ForcePath(m), p)));
                }
                for &p in &options.precisions {
                    for m in contacts.clone() {
                        items.extend(options.dispatches.iter().map(|&d| (Item::Update(m, d), p)));
                    }
                }
                for &p in &options.precisions {
                    items.extend(contacts.clone().map(|m| (Item::Tick(m), p)));
                }
            }
            Some((law, with_penalty)) => {
                for &integrator in &options.integrators {
                    let config = StepConfig {
                        law,
                        incompressibility_n: with_penalty.then_some(penalty),
                        integrator,
                    };
                    for &p in &options.precisions {
                        items.extend(
                            options
                                .dispatches
                                .iter()
                                .map(|&d| (Item::Step(config, d), p)),
                        );
                    }
                }
            }
        }
    }
    items
}

/// Seconds per byte a dispatched pass is assumed to take in the run's
/// estimate: 1 ns, about three times the slowest pass measured on the
/// development machine (St Venant-Kirchhoff by split terms, portable f64:
/// 0.3 ns per byte read), so the estimate is an upper bound on ordinary
/// hardware.
pub const ESTIMATE_SECONDS_PER_BYTE: f64 = 1e-9;

/// Seconds a force-path solve or a haptic tick is assumed to take in the
/// estimate (measured: below 1 µs; independent of the mesh).
const ESTIMATE_TICK_S: f64 = 10e-6;

/// The run's counts, known before any table: vertices, edges (counted),
/// their groups of 4 (estimated as `⌈E / 4⌉`: the layout pads rows by about
/// 1 %), tets, every mesh face, and an upper bound on the free vertices.
fn counts_of(mesh: &TetMesh) -> StepCounts {
    let mut edges: Vec<[u32; 2]> = Vec::with_capacity(6 * mesh.tets.len());
    let mut faces: Vec<[u32; 3]> = Vec::with_capacity(4 * mesh.tets.len());
    for t in &mesh.tets {
        for pair in palpate_kernel::table::format::tet_edge_vertices(*t) {
            let mut e = pair;
            e.sort_unstable();
            edges.push(e);
        }
        for face in palpate_kernel::table::format::tet_face_vertices(*t) {
            let mut f = face;
            f.sort_unstable();
            faces.push(f);
        }
    }
    edges.sort_unstable();
    edges.dedup();
    faces.sort_unstable();
    faces.dedup();
    StepCounts {
        vertices: mesh.positions.len() as u64,
        edges: edges.len() as u64,
        edge_groups: edges.len().div_ceil(4) as u64,
        tets: mesh.tets.len() as u64,
        triangles: faces.len() as u64,
    }
}

/// The estimated duration of a run: the measurements, their calls
/// ([`ESTIMATE_SECONDS_PER_BYTE`] per byte read) and the roofline copies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RunEstimate {
    /// Measurements (copies not counted).
    pub measurements: usize,
    /// Estimated wall time, s.
    pub seconds: f64,
}

fn estimate(items: &[(Item, Precision)], counts: &StepCounts, sampling: &Sampling) -> RunEstimate {
    let vertices = counts.vertices;
    let mut seconds = 0.0;
    let mut copies = std::collections::BTreeSet::new();
    for &(item, precision) in items {
        let scalar = scalar_bytes(precision);
        let bytes = match item {
            Item::ForcePath(_) | Item::Tick(_) => None,
            // A free vertex per vertex: the column of every vertex.
            Item::Update(m, _) => Some(m as u64 * 9 * scalar * vertices + 3 * scalar * vertices),
            Item::Step(config, _) => Some(counts.step_bytes(&config, scalar)),
        };
        let call_s = bytes.map_or(ESTIMATE_TICK_S, |b| b as f64 * ESTIMATE_SECONDS_PER_BYTE);
        seconds += estimated_seconds(sampling, call_s);
        if let Some(b) = bytes
            && copies.insert(b)
        {
            seconds += estimated_seconds(sampling, b as f64 * ESTIMATE_SECONDS_PER_BYTE / 10.0);
        }
    }
    RunEstimate {
        measurements: items.len(),
        seconds,
    }
}

fn scalar_bytes(precision: Precision) -> u64 {
    match precision {
        Precision::F32 => 4,
        Precision::F64 => 8,
    }
}

fn precision_name(precision: Precision) -> &'static str {
    match precision {
        Precision::F32 => "f32",
        Precision::F64 => "f64",
    }
}

/// Checks the sampling against the limits ([`MAX_BENCH_SAMPLES`],
/// [`MAX_BENCH_SAMPLE_S`]) and the run's estimate against
/// [`MAX_BENCH_ESTIMATE_S`], before anything is built; returns the
/// estimate.
pub fn check(mesh: &TetMesh, options: &BenchOptions) -> anyhow::Result<RunEstimate> {
    let s = &options.sampling;
    check_sampling(s)?;
    let items = plan(options, 0.0);
    if items.is_empty() {
        bail!(
            "nothing to measure: --models, --integrators, --precision and --dispatch leave no measurement"
        );
    }
    let estimate = estimate(&items, &counts_of(mesh), s);
    if estimate.seconds > MAX_BENCH_ESTIMATE_S {
        bail!(
            "{} measurements estimated at {:.0} s, more than {MAX_BENCH_ESTIMATE_S} s (MAX_BENCH_ESTIMATE_S): \
             measure fewer --models, --integrators or precisions, or fewer --samples",
            estimate.measurements,
            estimate.seconds
        );
    }
    Ok(estimate)
}

/// Refuses `--samples` 0, `--samples` + `--warmup` above
/// [`MAX_BENCH_SAMPLES`] and a `--sample-ms` not in (0, [`MAX_BENCH_SAMPLE_S`]].
pub fn check_sampling(s: &Sampling) -> anyhow::Result<()> {
    if s.samples == 0 || s.samples.saturating_add(s.warmup) > MAX_BENCH_SAMPLES {
        bail!(
            "--samples must be at least 1 and --samples + --warmup at most {MAX_BENCH_SAMPLES} (MAX_BENCH_SAMPLES), got {} + {}",
            s.samples,
            s.warmup
        );
    }
    if !(s.sample_s > 0.0 && s.sample_s <= MAX_BENCH_SAMPLE_S) {
        bail!(
            "--sample-ms must be > 0 and at most {} ms (MAX_BENCH_SAMPLE_S), got {}",
            MAX_BENCH_SAMPLE_S * 1e3,
            shown(s.sample_s * 1e3)
        );
    }
    Ok(())
}

/// Runs the measurements of `options` on `mesh` (named `name`), after
/// [`check`]: builds the tables (the pre-computed one checked against
/// `table_limits` first), then times each measurement in turn, handing
/// each [`Record`] to `on_record` as it is made; `on_start` is called
/// with each measurement's label before it starts (a progress bar).
pub fn run(
    mesh: &TetMesh,
    report: &MeshReport,
    name: &str,
    options: &BenchOptions,
    table_limits: &SizeLimits,
    mut on_start: impl FnMut(&str),
    mut on_record: impl FnMut(&Record) -> anyhow::Result<()>,
) -> anyhow::Result<()> {
    let penalty = penalty_n(mesh, &options.material);
    let items = plan(options, penalty);
    let precomputed = if options.models.contains(&BenchModel::Precomputed) {
        on_start("pre-computed tables");
        let build = BuildOptions::precomputed(
            options.material,
            options.fix.clone(),
            Solver::Cholesky,
            Precision::F64,
        );
        Some(PrecomputedBench::new(
            mesh,
            report,
            &build,
            &options.precisions,
            table_limits,
        )?)
    } else {
        None
    };
    let tensor_mass = if options.models.iter().any(|m| m.law().is_some()) {
        on_start("tensor-mass tables");
        let build = BuildOptions::tensor_mass(
            options.material,
            options.density_kg_m3,
            options.fix.clone(),
            Precision::F64,
        );
        Some(TensorMassBench::new(
            mesh,
            report,
            &build,
            &options.precisions,
        )?)
    } else {
        None
    };
    let sampling = &options.sampling;
    let mut copies: BTreeMap<u64, Timing> = BTreeMap::new();
    let pre = || {
        precomputed
            .as_ref()
            .ok_or_else(|| anyhow!("internal: no pre-computed bench"))
    };
    for (item, precision) in items {
        let what = item.what(precision);
        on_start(&what.label());
        let (timing, bytes_read, faults) = match item {
            Item::ForcePath(m) | Item::Update(m, _) | Item::Tick(m)
                if m > pre()?.max_contacts() =>
            {
                continue;
            }
            Item::ForcePath(m) => (pre()?.time_force_path(m, precision, sampling)?, None, None),
            Item::Update(m, dispatch) => {
                let timed = pre()?.time_update(m, precision, dispatch, sampling)?;
                (timed.timing, Some(timed.bytes), None)
            }
            Item::Tick(m) => match pre()?.time_tick(m, precision, sampling) {
                Ok(timing) => (timing, None, None),
                Err(e) => {
                    stderr::line(&format!("warning: {}: {e:#}", what.label()));
                    continue;
                }
            },
            Item::Step(config, dispatch) => {
                let bench = tensor_mass
                    .as_ref()
                    .ok_or_else(|| anyhow!("internal: no tensor-mass bench"))?;
                let timed = bench.time_step(&config, precision, dispatch, sampling)?;
                (timed.timing, Some(timed.bytes), Some(timed.faults))
            }
        };
        let copy = bytes_read.map(|bytes| {
            *copies.entry(bytes).or_insert_with(|| {
                on_start(&format!("copy of {bytes} bytes"));
                time_copy(bytes as usize, sampling)
            })
        });
        on_record(&Record {
            mesh: name.to_string(),
            vertices: mesh.positions.len(),
            tets: mesh.tets.len(),
            what,
            timing,
            bytes_read,
            copy_median_s: copy.map(|c| c.median_s),
            ratio_to_copy: copy.map(|c| timing.median_s / c.median_s),
            faults,
        })?;
    }
    Ok(())
}
