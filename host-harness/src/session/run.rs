//! `palpate session run`: drives the kernel's haptic loop
//! ([`palpate_kernel::haptic::HapticLoop`]) tick by tick from a
//! trajectory and writes one CSV line per tick, `t,fx,fy,fz,contacts,status`
//! (s, N, N, N, count, `ok` | `clamped` | `faulted:<reason>`).
//!
//! The table is built in memory from the scene (f32, the firmware
//! precision), pre-computed or tensor-mass by the scene's model. The force
//! is computed every tick (see the loop's docs); every `physics_every`
//! ticks comes the physics update: for the pre-computed model the
//! deformation field from the last contact solution, for the dynamic model
//! a [`DynamicLoop::physics_update`] (steps, held forces, re-binning). With
//! `--vtk` each update's field is written as a VTK frame.

use std::io::Write;
use std::path::Path;

use anyhow::{Context, bail};
use nalgebra::Vector3;
use palpate_kernel::PrecomputedTable;
use palpate_kernel::haptic::{
    DynamicLoop, ForceOutput, LoopConfig, OutputStatus, PrecomputedLoop, SafetyLimits,
};
use palpate_kernel::precomputed::PrecomputedTissue;
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::tensor_mass::{
    DynamicParams, DynamicTissue, ElasticLaw, PhysicsConfig, StvkForm, TensorMassModel,
};

use super::tool_points::{ForToolPoints, with_tool_points};
use super::{DynamicSpec, ModelSpec, Scene, Trajectory};
use crate::fix::fixed_vertices;
use crate::limits::{
    MAX_HAPTIC_HZ, MAX_SESSION_TICKS, MAX_TRAJECTORY_SPAN_S, MAX_VTK_SERIES_BYTES, vtk_frame_bytes,
};
use crate::mesh::{MeshReport, TetMesh, boundary_surface};
use crate::output::atomic::{self, AtomicFile, SeriesDir};
use crate::output::vtk;
use crate::table::build::{BuildOptions, build};
use crate::table::compliance::Solver;
use crate::table::estimate::{SizeLimits, TableEstimate};
use crate::table::file::Precision;
use crate::table::load::TableFile;
use crate::tensor_mass::run::diagonal;
use crate::tensor_mass::{OwnedState, OwnedSurface};

/// The build options of `scene`'s table, by its model: its material and
/// supports, f32 (the firmware precision), quiet; a pre-computed table
/// solved by sparse Cholesky, a tensor-mass table of the scene's density.
pub fn table_options(scene: &Scene) -> anyhow::Result<BuildOptions> {
    let material = scene.elastic_material()?;
    let fix = scene.fix.clone();
    Ok(match scene.model {
        ModelSpec::Precomputed => {
            BuildOptions::precomputed(material, fix, Solver::Cholesky, Precision::F32)
        }
        ModelSpec::Dynamic(_) => {
            BuildOptions::tensor_mass(material, scene.material.density_kg_m3, fix, Precision::F32)
        }
    })
}

/// The f32 table of `scene` (pre-computed or tensor-mass, by its model),
/// built in memory with the same pipeline as `palpate tables build`.
pub fn scene_table(scene: &Scene, mesh: &TetMesh, report: &MeshReport) -> anyhow::Result<Vec<u8>> {
    let options = table_options(scene)?;
    Ok(build(mesh, report, &options)
        .with_context(|| scene.source.clone())?
        .bytes)
}

/// Checks that `scene`'s table on `mesh` fits the limits every build
/// applies ([`SizeLimits::system`]: the largest table file, the memory
/// available), from the estimate of its size, without building it (linear
/// in the mesh): for a command that builds several tables, before the
/// first. Returns the estimate.
pub fn check_scene_table(
    scene: &Scene,
    mesh: &TetMesh,
    report: &MeshReport,
) -> anyhow::Result<TableEstimate> {
    let options = table_options(scene)?;
    let (fixed, _) = fixed_vertices(&mesh.positions, &options.fix, &report.unreferenced_vertices);
    let surface = boundary_surface(mesh);
    let estimate = TableEstimate::of_build(mesh, report, &options, &fixed, &surface);
    SizeLimits::system().check(&estimate, &report.source)?;
    Ok(estimate)
}

/// The haptic loop configuration of `scene` (f32).
pub fn loop_config(scene: &Scene) -> LoopConfig<f32> {
    LoopConfig {
        radius_m: scene.tool.radius_m as f32,
        dt_s: scene.tick_s() as f32,
        limits: SafetyLimits {
            max_force_n: scene.safety.max_force_n as f32,
            max_slew_n_per_s: scene.safety.max_slew_n_per_s as f32,
        },
    }
}

/// The number of ticks of `trajectory` at period `tick_s` (s): one at its
/// start, then one every `tick_s` up to its end,
/// `⌊(end − start)/tick_s + 10⁻⁹⌋ + 1`. Checked: a period that is not finite
/// and > 0, or a count above [`MAX_SESSION_TICKS`] (one hour at 10 kHz), is
/// an error, never a count that wraps or saturates. A validated scene and a
/// trajectory read by the readers never exceed it (their own limits,
/// [`crate::limits`]).
pub fn tick_count(trajectory: &Trajectory, tick_s: f64) -> anyhow::Result<usize> {
    if !(tick_s.is_finite() && tick_s > 0.0) {
        bail!("tick period {tick_s} s: must be finite and > 0 s");
    }
    let span_s = trajectory.end_s() - trajectory.start_s();
    let periods = (span_s / tick_s + 1e-9).floor();
    // NaN and infinities fail the comparison.
    if !(periods >= 0.0 && periods < MAX_SESSION_TICKS as f64) {
        bail!(
            "the trajectory spans {span_s} s: {periods:e} ticks of {tick_s} s, above the limit of {MAX_SESSION_TICKS} ticks (MAX_SESSION_TICKS: {MAX_TRAJECTORY_SPAN_S} s at {MAX_HAPTIC_HZ} Hz)"
        );
    }
    // A whole number in 0..MAX_SESSION_TICKS: exact as an integer.
    Ok(periods as usize + 1)
}

/// The ticks of `trajectory` at period `tick_s`: `(t_s, tool positions)`
/// for `t = start + k·tick_s` up to the end, [`tick_count`] of them (its
/// error if the count is out of range); a tool point the trajectory lacks is
/// NaN (the loop faults on it).
pub fn ticks<const P: usize>(
    trajectory: &Trajectory,
    tick_s: f64,
) -> anyhow::Result<impl Iterator<Item = (f64, [Vector3<f32>; P])> + '_> {
    let start = trajectory.start_s();
    let count = tick_count(trajectory, tick_s)?;
    let mut positions = vec![[0.0; 3]; trajectory.tool_count()];
    Ok((0..count).map(move |k| {
        let t = start + k as f64 * tick_s;
        trajectory.positions_at_into(t, &mut positions);
        let tool = core::array::from_fn(|p| {
            let x = positions.get(p).copied().unwrap_or([f64::NAN; 3]);
            Vector3::new(x[0] as f32, x[1] as f32, x[2] as f32)
        });
        (t, tool)
    }))
}

/// What a session did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SessionSummary {
    /// Ticks run.
    pub ticks: usize,
    /// Ticks with at least one contact.
    pub ticks_in_contact: usize,
    /// Ticks whose force was clamped by the supervisor.
    pub clamped: usize,
    /// Ticks with a latched fault (zero force).
    pub faulted: usize,
    /// Largest device force magnitude, N.
    pub max_force_n: f64,
    /// Largest change of the force vector between consecutive ticks, N.
    pub max_jump_n: f64,
    /// VTK frames written.
    pub frames: usize,
    /// The first failed physics update of a dynamic model (the loop
    /// faulted from the next tick on).
    pub physics_error: Option<String>,
}

/// [`run_session`] into files, as `palpate session run` does: the CSV to the
/// file `out` and, with `vtk`, the VTK series to that folder, each written
/// whole or not at all ([`AtomicFile`], [`SeriesDir`]): nothing at `out` or
/// `vtk` changes until the run has succeeded, and on any error both keep
/// their previous contents. A `vtk` folder that exists must be one a
/// previous run wrote (or empty), and `out` must not lie inside it; both
/// are checked before the mesh is read.
pub fn run_session_to_files(
    scene: &Scene,
    trajectory: &Trajectory,
    out: &Path,
    vtk: Option<&Path>,
) -> anyhow::Result<SessionSummary> {
    if let Some(dir) = vtk {
        atomic::refuse_inside(("--vtk", dir), &[("--out", out)])?;
    }
    let mut csv = AtomicFile::create(out)?;
    let series = vtk.map(SeriesDir::create).transpose()?;
    let summary = run_session(
        scene,
        trajectory,
        &mut csv,
        series.as_ref().map(SeriesDir::dir),
    )?;
    // The CSV is complete and synced before the series replaces the old
    // one: after the swap only the CSV's rename is left to fail.
    csv.prepare()?;
    if let Some(series) = series {
        series.commit()?;
    }
    csv.commit()?;
    Ok(summary)
}

/// Refuses a VTK series above [`MAX_VTK_SERIES_BYTES`], before the table build: a frame per
/// physics update (every `physics_every` of `ticks`) of at most [`vtk_frame_bytes`].
fn check_series_size(
    scene: &Scene,
    ticks: usize,
    mesh: &TetMesh,
    dir: &Path,
) -> anyhow::Result<()> {
    let every = scene.rates.physics_every.max(1) as usize;
    let frames = ticks.div_ceil(every) as u64 + 1;
    let bytes = frames.saturating_mul(vtk_frame_bytes(mesh.positions.len(), mesh.tets.len()));
    if bytes > MAX_VTK_SERIES_BYTES {
        bail!(
            "--vtk {}: {frames} frames of up to {:.1} MB would write up to {:.1} GB, above the \
             {} GiB limit of a VTK series; raise [rates] physics_every, shorten the trajectory \
             or leave out --vtk",
            dir.display(),
            vtk_frame_bytes(mesh.positions.len(), mesh.tets.len()) as f64 / 1e6,
            bytes as f64 / 1e9,
            MAX_VTK_SERIES_BYTES >> 30
        );
    }
    Ok(())
}

/// Runs `trajectory` through the haptic loop of `scene`, writing the CSV to
/// `out` and, with `vtk_dir`, a VTK frame per physics update and a `.pvd`
/// (last) into that folder, which should be a fresh one ([`SeriesDir::dir`]:
/// frames of an earlier run would stay beside the new ones).
pub fn run_session(
    scene: &Scene,
    trajectory: &Trajectory,
    out: &mut dyn Write,
    vtk_dir: Option<&Path>,
) -> anyhow::Result<SessionSummary> {
    // Bounded before any work: the table build can take minutes.
    let tick_total =
        tick_count(trajectory, scene.tick_s()).with_context(|| scene.source.clone())?;
    let (mesh, report) = scene.load_mesh()?;
    if let Some(dir) = vtk_dir {
        check_series_size(scene, tick_total, &mesh, dir)?;
    }
    let mut session = Session {
        out,
        summary: SessionSummary::default(),
        last: Vector3::zeros(),
        rest: &mesh.positions,
        tets: &mesh.tets,
        dir: vtk_dir,
        frames: Vec::new(),
    };
    writeln!(session.out, "t,fx,fy,fz,contacts,status")?;
    let ticks = Ticks {
        trajectory,
        tick_s: scene.tick_s(),
        every: scene.rates.physics_every.max(1) as usize,
    };
    let file = TableFile::from_bytes(&scene_table(scene, &mesh, &report)?);
    let tissue = match scene.model {
        ModelSpec::Precomputed => SessionTissue::Precomputed(
            PrecomputedTable::<f32>::load(file.bytes()).context("session table")?,
            loop_config(scene),
        ),
        ModelSpec::Dynamic(spec) => {
            let table = TensorMassTable::<f32>::load(file.bytes()).context("session table")?;
            SessionTissue::Dynamic(DynamicSetup::of(scene, &spec, table)?)
        }
    };
    with_tool_points(
        scene.tool.points,
        SessionTicks {
            ticks: &ticks,
            tissue: &tissue,
            session: &mut session,
        },
    )?;
    session.finish()
}

/// The tissue a session runs on: a pre-computed table and the loop
/// settings, or a dynamic scene's setup.
enum SessionTissue<'t> {
    Precomputed(PrecomputedTable<'t, f32>, LoopConfig<f32>),
    Dynamic(DynamicSetup<'t>),
}

/// A session's ticks on its tissue, run with the scene's tool points.
struct SessionTicks<'a, 't, 'o> {
    ticks: &'a Ticks<'a>,
    tissue: &'a SessionTissue<'t>,
    session: &'a mut Session<'o>,
}

impl ForToolPoints for SessionTicks<'_, '_, '_> {
    type Output = anyhow::Result<()>;

    fn call<const P: usize>(self) -> anyhow::Result<()> {
        match self.tissue {
            SessionTissue::Precomputed(table, config) => {
                self.ticks.precomputed::<P>(table, *config, self.session)
            }
            SessionTissue::Dynamic(setup) => self.ticks.dynamic::<P>(setup, self.session),
        }
    }
}

/// A dynamic scene's table and settings: everything to build its loop.
pub struct DynamicSetup<'t> {
    table: TensorMassTable<'t, f32>,
    params: DynamicParams<f32>,
    physics: PhysicsConfig<f32>,
    config: LoopConfig<f32>,
}

impl<'t> DynamicSetup<'t> {
    /// The settings of dynamic `scene` (model `spec`) over `table`: its law,
    /// penalty and damping, no gravity (the tissue rests in its meshed
    /// shape), divergence when a displacement exceeds the mesh's
    /// bounding-box diagonal; the physics period in steps of `dt_s`.
    pub fn of(
        scene: &Scene,
        spec: &DynamicSpec,
        table: TensorMassTable<'t, f32>,
    ) -> anyhow::Result<Self> {
        let rest: Vec<[f64; 3]> = table
            .rest_positions()
            .iter()
            .map(|p| p.map(f64::from))
            .collect();
        Ok(Self {
            table,
            params: DynamicParams::linear(spec.damping_per_s as f32, diagonal(&rest) as f32)
                .with_law(spec.law)
                .with_incompressibility(spec.incompressibility_n.map(|g| g as f32)),
            physics: PhysicsConfig {
                extrapolation: spec.extrapolation,
                integrator: spec.integrator,
                dt_s: spec.dt_s as f32,
                substeps: scene
                    .dynamic_substeps()
                    .context("physics period is not a whole number of dt_s")?,
                cut_capacity_tets: 8,
                tearing: None,
            },
            config: loop_config(scene),
        })
    }

    /// Builds the model, its surface and the loop at rest on heap buffers
    /// and runs `body` on the loop.
    pub fn with_loop<const P: usize, R>(
        &self,
        body: impl FnOnce(&mut DynamicLoop<'_, '_, f32, P, P>) -> anyhow::Result<R>,
    ) -> anyhow::Result<R> {
        // The split-term buffers only for the form that reads them.
        let state = OwnedState::for_table(&self.table);
        let mut state = if self.params.law == ElasticLaw::StVenantKirchhoff(StvkForm::Tensors) {
            state
        } else {
            state.without_split_terms()
        };
        let model = TensorMassModel::new(self.table, state.buffers(), self.params)
            .map_err(|e| anyhow::anyhow!("dynamic model: {e}"))?;
        let mut surface = OwnedSurface::for_model(&model);
        let (buffers, forces) = surface.buffers();
        let tissue = DynamicTissue::<f32, P>::new(model, buffers, forces, self.physics)
            .map_err(|e| anyhow::anyhow!("dynamic tissue: {e}"))?;
        let mut haptic = DynamicLoop::<f32, P, P>::new(tissue, self.config)
            .map_err(|e| anyhow::anyhow!("haptic loop: {e}"))?;
        body(&mut haptic)
    }
}

/// The trajectory's ticks and the physics period in ticks.
struct Ticks<'r> {
    trajectory: &'r Trajectory,
    tick_s: f64,
    every: usize,
}

impl Ticks<'_> {
    fn precomputed<const P: usize>(
        &self,
        table: &PrecomputedTable<'_, f32>,
        config: LoopConfig<f32>,
        session: &mut Session<'_>,
    ) -> anyhow::Result<()> {
        let mut haptic = PrecomputedLoop::<f32, P, P>::new(PrecomputedTissue::new(table), config)
            .map_err(|e| anyhow::anyhow!("haptic loop: {e}"))?;
        let model = *haptic.tissue().model();
        let mut field = vec![[0.0f32; 3]; session.rest.len()];
        for (k, (t, tool)) in ticks::<P>(self.trajectory, self.tick_s)?.enumerate() {
            session.record(t, &haptic.tick(&tool))?;
            if session.dir.is_some() && k % self.every == 0 {
                match haptic.solution() {
                    Some(solution) => model
                        .displacements(solution, &mut field)
                        .map_err(|e| anyhow::anyhow!("displacements: {e}"))?,
                    None => field.fill([0.0; 3]),
                }
                session.frame(t, &field)?;
            }
        }
        Ok(())
    }

    fn dynamic<const P: usize>(
        &self,
        setup: &DynamicSetup<'_>,
        session: &mut Session<'_>,
    ) -> anyhow::Result<()> {
        setup.with_loop::<P, _>(|haptic| self.dynamic_ticks(haptic, session))
    }

    fn dynamic_ticks<const P: usize>(
        &self,
        haptic: &mut DynamicLoop<'_, '_, f32, P, P>,
        session: &mut Session<'_>,
    ) -> anyhow::Result<()> {
        for (k, (t, tool)) in ticks::<P>(self.trajectory, self.tick_s)?.enumerate() {
            session.record(t, &haptic.tick(&tool))?;
            if (k + 1) % self.every != 0 {
                continue;
            }
            if let Err(e) = haptic.physics_update()
                && session.summary.physics_error.is_none()
            {
                session.summary.physics_error = Some(format!("t = {t} s: {e}"));
            }
            if session.dir.is_some() {
                let u = haptic.tissue().model().displacements_m().unwrap_or(&[]);
                session.frame(t, u)?;
            }
        }
        Ok(())
    }
}

/// The CSV, the summary and the VTK frames of a running session.
struct Session<'o> {
    out: &'o mut dyn Write,
    summary: SessionSummary,
    last: Vector3<f32>,
    rest: &'o [[f64; 3]],
    tets: &'o [[u32; 4]],
    dir: Option<&'o Path>,
    frames: Vec<(f64, std::path::PathBuf)>,
}

impl Session<'_> {
    /// One tick's CSV line and its share of the summary.
    fn record(&mut self, t: f64, output: &ForceOutput<f32>) -> anyhow::Result<()> {
        let summary = &mut self.summary;
        let status = match output.status {
            OutputStatus::Ok => "ok".to_string(),
            OutputStatus::Clamped => {
                summary.clamped += 1;
                "clamped".to_string()
            }
            OutputStatus::Faulted(reason) => {
                summary.faulted += 1;
                format!("faulted:{reason}")
            }
        };
        let f = output.force_n;
        writeln!(
            self.out,
            "{t},{},{},{},{},{status}",
            f.x, f.y, f.z, output.contacts
        )?;
        summary.ticks += 1;
        summary.ticks_in_contact += usize::from(output.contacts > 0);
        summary.max_force_n = summary.max_force_n.max(f64::from(f.norm()));
        summary.max_jump_n = summary.max_jump_n.max(f64::from((f - self.last).norm()));
        self.last = f;
        Ok(())
    }

    /// A VTK frame of displacement field `u` (m; zero where missing) at `t`.
    fn frame(&mut self, t: f64, u: &[[f32; 3]]) -> anyhow::Result<()> {
        let Some(dir) = self.dir else { return Ok(()) };
        let u: Vec<[f64; 3]> = (0..self.rest.len())
            .map(|v| u.get(v).map_or([0.0; 3], |d| d.map(f64::from)))
            .collect();
        let path = dir.join(format!("frame_{:06}.vtk", self.frames.len()));
        vtk::write_frame(&path, self.rest, self.tets, &u)?;
        self.frames.push((t, path));
        Ok(())
    }

    fn finish(mut self) -> anyhow::Result<SessionSummary> {
        if let Some(dir) = self.dir {
            vtk::write_collection(&dir.join("session.pvd"), &self.frames)?;
        }
        self.summary.frames = self.frames.len();
        Ok(self.summary)
    }
}
