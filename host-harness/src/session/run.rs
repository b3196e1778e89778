//! `palpate session run`: drives the kernel's haptic loop
//! ([`palpate_kernel::haptic::HapticLoop`]) tick by tick from a
//! trajectory and writes one CSV line per tick, `t,fx,fy,fz,contacts,status`
//! (s, N, N, N, count, `ok` | `clamped` | `faulted:<reason>` |
//! `cut-refused`: an enabled blade touched tissue the model cannot cut, the
//! pre-computed model; the force is the probe's, unclamped |
//! `tool-inside`: a tool point's centre is inside the body with no contact,
//! it adds no force, [`OutputStatus::ToolInside`]).
//!
//! The scene's tools ([`super::tools`]): probes, graspers (two jaws that
//! hold what they touch once closed) and cutters (a blade that removes the
//! tets it touches at each physics update of the dynamic model), from the
//! trajectory's positions, `jaw_m` and `cut` columns. With a cutter or
//! `[tearing]`, the tets each physics update removed are written, in
//! removal order, as `t,tet` lines (s, tet index of the mesh) to a side
//! file ([`removed_path`]): what a replay needs to repeat the cuts exactly.
//!
//! The table is built in memory from the scene (f32, the firmware
//! precision), pre-computed or tensor-mass by the scene's model. The force
//! is computed every tick (see the loop's docs); every `physics_every`
//! ticks comes the physics update: for the pre-computed model the
//! deformation field from the last contact solution, for the dynamic model
//! a `DynamicLoop::physics_update` (cuts, steps, tearing, held forces,
//! re-binning). With `--vtk` each update's field is written as a VTK frame
//! of the live tets (a cut shows as the tets gone, its faces as surface).

use std::io::Write;
use std::path::Path;

use anyhow::{Context, bail};
use nalgebra::Vector3;
use palpate_kernel::PrecomputedTable;
use palpate_kernel::haptic::{
    ForceOutput, HapticLoop, LoopConfig, OutputStatus, PhysicsTissue, PrecomputedLoop, ToolInput,
};
use palpate_kernel::math::{Dispatch, Portable};
use palpate_kernel::precomputed::PrecomputedTissue;
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::tensor_mass::DynamicTissue;

use super::hybrid::HybridSetup;
use super::model::{SceneModel, SceneTables};
use super::setup::{DynamicSetup, PhysicsView, loop_config};
use super::stability::check_stable_step;
use super::tool_points::{ForToolPoints, with_tool_points};
use super::tools::kernel_tools;
use crate::dispatch::HostDispatch;
use crate::limits::{
    MAX_HAPTIC_HZ, MAX_SESSION_TICKS, MAX_TRAJECTORY_SPAN_S, MAX_VTK_SERIES_BYTES, vtk_frame_bytes,
};
use crate::mesh::TetMesh;
use crate::output::atomic::{self, AtomicFile, SeriesDir};
use crate::output::number::time_s;
use crate::output::vtk;
use crate::scene::{ModelSpec, Scene, ToolKind, ToolSpec, ToolState, Trajectory};
use crate::threads::{Threaded, default_threads};

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

/// The ticks of `trajectory` at period `tick_s`: `(t_s, kernel tool
/// points)` for `t = start + k·tick_s` up to the end, [`tick_count`] of them
/// (its error if the count is out of range), each trajectory tool point
/// expanded by its kind in `tools` ([`kernel_tools`]); a tool point the
/// trajectory lacks is NaN (the loop faults on it).
pub fn ticks<'a, const P: usize>(
    trajectory: &'a Trajectory,
    tick_s: f64,
    tools: &'a ToolSpec,
) -> anyhow::Result<impl Iterator<Item = (f64, [ToolInput<f32>; P])> + 'a> {
    let start = trajectory.start_s();
    let count = tick_count(trajectory, tick_s)?;
    let idle = ToolState {
        position_m: [f64::NAN; 3],
        jaw_m: 0.0,
        cut: false,
    };
    let mut states = vec![idle; trajectory.tool_count()];
    Ok((0..count).map(move |k| {
        let t = start + k as f64 * tick_s;
        trajectory.tools_at_into(t, &mut states);
        (t, kernel_tools(tools, &states))
    }))
}

/// Refuses a trajectory without the `jaw_m,cut` columns for a scene with a
/// grasper or a cutter (they would never close or cut).
pub fn check_tool_columns(scene: &Scene, trajectory: &Trajectory) -> anyhow::Result<()> {
    if let Some(kind) = scene.tool.kinds.iter().find(|k| **k != ToolKind::Probe)
        && !trajectory.has_tool_columns()
    {
        bail!(
            "{}: [tool] kind has a {}: the trajectory needs the header t,tool,x,y,z,jaw_m,cut \
             (jaw opening in m, cut 0 or 1), not t,tool,x,y,z",
            scene.source,
            kind.name()
        );
    }
    Ok(())
}

/// Where `session run --out OUT` writes the removed tets of a scene that
/// can cut or tear: `OUT` with its extension replaced by `removed.csv`
/// (`session.csv` → `session.removed.csv`).
pub fn removed_path(out: &Path) -> std::path::PathBuf {
    out.with_extension("removed.csv")
}

/// `true` for a dynamic scene with a cutter or tearing: its session
/// removes tets.
pub fn removes_tets(scene: &Scene) -> bool {
    let dynamic = matches!(scene.model, ModelSpec::Dynamic(_)) || !scene.zones.is_empty();
    dynamic && (scene.tool.kinds.contains(&ToolKind::Cutter) || scene.tearing.is_some())
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
    /// Tets removed by cutting and tearing.
    pub removed_tets: usize,
    /// Ticks whose blade touched tissue that cannot be cut.
    pub cut_refused: usize,
    /// Ticks with a tool point inside the body and no contact (status
    /// `tool-inside`: it adds no force).
    pub tool_inside: usize,
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
    run_session_to_files_threads(scene, trajectory, out, vtk, default_threads())
}

/// [`run_session_to_files`] with the tensor-mass steps' per-tet force pass
/// on `threads` threads ([`run_session_threads`]).
pub fn run_session_to_files_threads(
    scene: &Scene,
    trajectory: &Trajectory,
    out: &Path,
    vtk: Option<&Path>,
    threads: usize,
) -> anyhow::Result<SessionSummary> {
    if let Some(dir) = vtk {
        atomic::refuse_inside(("--vtk", dir), &[("--out", out)])?;
    }
    let mut csv = AtomicFile::create(out)?;
    let mut removed = removes_tets(scene)
        .then(|| AtomicFile::create(&removed_path(out)))
        .transpose()?;
    let series = vtk.map(SeriesDir::create).transpose()?;
    let summary = run_session_threads(
        scene,
        trajectory,
        SessionOutputs {
            csv: &mut csv,
            removed: removed.as_mut().map(|f| f as &mut dyn Write),
            vtk_dir: series.as_ref().map(SeriesDir::dir),
            vtk_name: series.as_ref().map(SeriesDir::path),
        },
        threads,
    )?;
    // The CSVs are complete and synced before the series replaces the old
    // one: after the swap only the CSVs' renames are left to fail.
    csv.prepare()?;
    if let Some(removed) = &mut removed {
        removed.prepare()?;
    }
    if let Some(series) = series {
        series.commit()?;
    }
    if let Some(removed) = removed {
        removed.commit()?;
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
    run_session_into(
        scene,
        trajectory,
        SessionOutputs {
            csv: out,
            removed: None,
            vtk_dir,
            vtk_name: None,
        },
    )
}

/// Where a session writes.
pub struct SessionOutputs<'o> {
    /// The per-tick CSV.
    pub csv: &'o mut dyn Write,
    /// The removed tets, `t,tet` lines (module docs), if wanted.
    pub removed: Option<&'o mut dyn Write>,
    /// The VTK series folder (see [`run_session`]), if wanted.
    pub vtk_dir: Option<&'o Path>,
    /// The VTK folder as the user named it, for messages, when `vtk_dir`
    /// is a hidden temporary one ([`SeriesDir::dir`]); `None`: `vtk_dir`.
    pub vtk_name: Option<&'o Path>,
}

/// [`run_session`] into `outputs`. Before any work: the tick count, the
/// trajectory's tool columns for the scene's tools, and, for a dynamic
/// scene, its step against the mesh's stable step ([`check_stable_step`]).
pub fn run_session_into(
    scene: &Scene,
    trajectory: &Trajectory,
    outputs: SessionOutputs<'_>,
) -> anyhow::Result<SessionSummary> {
    run_session_threads(scene, trajectory, outputs, default_threads())
}

/// [`run_session_into`] with the tensor-mass steps' per-tet force pass on
/// `threads` threads (dynamic and hybrid scenes; the results are the same
/// bits for any count, [`crate::threads`]).
pub fn run_session_threads(
    scene: &Scene,
    trajectory: &Trajectory,
    outputs: SessionOutputs<'_>,
    threads: usize,
) -> anyhow::Result<SessionSummary> {
    let SessionOutputs {
        csv: out,
        mut removed,
        vtk_dir,
        vtk_name,
    } = outputs;
    // Bounded before any work: the table build can take minutes.
    let tick_total =
        tick_count(trajectory, scene.tick_s()).with_context(|| scene.source.clone())?;
    check_tool_columns(scene, trajectory)?;
    let (mesh, report) = scene.load_mesh()?;
    check_stable_step(scene, &mesh, &report)?;
    if let Some(dir) = vtk_dir {
        check_series_size(scene, tick_total, &mesh, vtk_name.unwrap_or(dir))?;
    }
    if let Some(removed) = removed.as_mut() {
        writeln!(removed, "t,tet")?;
    }
    let mut session = Session {
        out,
        removed,
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
        tools: &scene.tool,
        tick_s: scene.tick_s(),
        every: scene.rates.physics_every.max(1) as usize,
        threads,
    };
    let tables = SceneModel::of(scene, &mesh, &report)?.tables(scene, &mesh, &report, None)?;
    let load = |e| anyhow::anyhow!("session table: {e}");
    let tissue = match &tables {
        SceneTables::Precomputed(file) => SessionTissue::Precomputed(
            PrecomputedTable::<f32>::load(file.bytes()).map_err(load)?,
            loop_config(scene),
        ),
        SceneTables::Dynamic(file, spec) => {
            let table = TensorMassTable::<f32>::load(file.bytes()).map_err(load)?;
            SessionTissue::Dynamic(DynamicSetup::of(scene, spec, table)?)
        }
        SceneTables::Hybrid(tables, spec) => {
            SessionTissue::Hybrid(Box::new(HybridSetup::of(scene, spec, tables)?))
        }
    };
    with_tool_points(
        scene.tool.kernel_points(),
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
    Hybrid(Box<HybridSetup<'t>>),
}

/// A session's ticks on its tissue, run with the scene's tool points.
struct SessionTicks<'a, 't, 'o, 'm> {
    ticks: &'a Ticks<'a>,
    tissue: &'a SessionTissue<'t>,
    session: &'a mut Session<'o, 'm>,
}

impl ForToolPoints for SessionTicks<'_, '_, '_, '_> {
    type Output = anyhow::Result<()>;

    fn call<const P: usize>(self) -> anyhow::Result<()> {
        match self.tissue {
            SessionTissue::Precomputed(table, config) => {
                self.ticks.precomputed::<P>(table, *config, self.session)
            }
            SessionTissue::Dynamic(setup) => self.ticks.dynamic::<P>(setup, self.session),
            SessionTissue::Hybrid(setup) => self.ticks.hybrid::<P>(setup, self.session),
        }
    }
}

/// The trajectory's ticks, the tools, the physics period in ticks and the
/// threads of the tensor-mass steps' per-tet pass.
struct Ticks<'r> {
    trajectory: &'r Trajectory,
    tools: &'r ToolSpec,
    tick_s: f64,
    every: usize,
    threads: usize,
}

impl Ticks<'_> {
    fn precomputed<const P: usize>(
        &self,
        table: &PrecomputedTable<'_, f32>,
        config: LoopConfig<f32>,
        session: &mut Session<'_, '_>,
    ) -> anyhow::Result<()> {
        let mut haptic = PrecomputedLoop::<f32, P, P>::new(PrecomputedTissue::new(table), config)
            .map_err(|e| anyhow::anyhow!("haptic loop: {e}"))?;
        let model = *haptic.tissue().model();
        let mut field = vec![[0.0f32; 3]; session.rest.len()];
        for (k, (t, tool)) in ticks::<P>(self.trajectory, self.tick_s, self.tools)?.enumerate() {
            session.record(t, &haptic.tick_tools(&tool))?;
            if session.dir.is_some() && k % self.every == 0 {
                match haptic.solution() {
                    Some(solution) => model
                        .displacements(solution, &mut field)
                        .map_err(|e| anyhow::anyhow!("displacements: {e}"))?,
                    None => field.fill([0.0; 3]),
                }
                session.frame(t, &field, None)?;
            }
        }
        Ok(())
    }

    fn dynamic<const P: usize>(
        &self,
        setup: &DynamicSetup<'_>,
        session: &mut Session<'_, '_>,
    ) -> anyhow::Result<()> {
        let dispatch = Threaded::new(HostDispatch::detect(), self.threads);
        setup.with_loop::<P, _, _>(dispatch, |haptic| {
            self.physics_ticks(haptic, session, &DynamicView)
        })
    }

    fn hybrid<const P: usize>(
        &self,
        setup: &HybridSetup<'_>,
        session: &mut Session<'_, '_>,
    ) -> anyhow::Result<()> {
        let view = setup.view();
        let dispatch = Threaded::new(Portable, self.threads);
        setup.with_loop::<P, _, _>(dispatch, |haptic| {
            self.physics_ticks(haptic, session, &view)
        })
    }

    /// The ticks of a tissue stepped at the physics rate: a physics update
    /// every `every` ticks, its removed tets and VTK frame through `view`.
    fn physics_ticks<const P: usize, B: PhysicsTissue<f32, P>>(
        &self,
        haptic: &mut HapticLoop<f32, B, P, P>,
        session: &mut Session<'_, '_>,
        view: &impl PhysicsView<B>,
    ) -> anyhow::Result<()> {
        for (k, (t, tool)) in ticks::<P>(self.trajectory, self.tick_s, self.tools)?.enumerate() {
            session.record(t, &haptic.tick_tools(&tool))?;
            if (k + 1) % self.every != 0 {
                continue;
            }
            if let Err(e) = haptic.physics_update()
                && session.summary.physics_error.is_none()
            {
                session.summary.physics_error = Some(format!("t = {} s: {e}", time_s(t)));
            }
            session.removed(t, &view.removed(haptic.tissue()))?;
            if session.dir.is_some() {
                let (u, alive) = view.frame(haptic.tissue())?;
                session.frame(t, &u, Some(&alive))?;
            }
        }
        Ok(())
    }
}

/// The tensor-mass tissue is the whole mesh.
struct DynamicView;

impl<const P: usize, D: Dispatch> PhysicsView<DynamicTissue<'_, '_, f32, P, D>> for DynamicView {
    fn removed(&self, tissue: &DynamicTissue<'_, '_, f32, P, D>) -> Vec<u32> {
        tissue.removed().to_vec()
    }

    fn frame(
        &self,
        tissue: &DynamicTissue<'_, '_, f32, P, D>,
    ) -> anyhow::Result<(Vec<[f32; 3]>, Vec<bool>)> {
        let model = tissue.model();
        let u = model.displacements_m().unwrap_or(&[]).to_vec();
        Ok((u, model.tet_alive().to_vec()))
    }
}

/// The CSV, the summary and the VTK frames of a running session.
struct Session<'o, 'm> {
    out: &'o mut dyn Write,
    removed: Option<&'o mut dyn Write>,
    summary: SessionSummary,
    last: Vector3<f32>,
    rest: &'m [[f64; 3]],
    tets: &'m [[u32; 4]],
    dir: Option<&'o Path>,
    frames: Vec<(f64, std::path::PathBuf)>,
}

impl Session<'_, '_> {
    /// One tick's CSV line and its share of the summary.
    fn record(&mut self, t: f64, output: &ForceOutput<f32>) -> anyhow::Result<()> {
        let summary = &mut self.summary;
        let status = match output.status {
            OutputStatus::Ok if output.cut_refused => {
                summary.cut_refused += 1;
                "cut-refused".to_string()
            }
            OutputStatus::Ok => "ok".to_string(),
            OutputStatus::Clamped => {
                summary.clamped += 1;
                "clamped".to_string()
            }
            OutputStatus::ToolInside => {
                summary.tool_inside += 1;
                "tool-inside".to_string()
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

    /// The tets a physics update at `t` removed, one `t,tet` line each.
    fn removed(&mut self, t: f64, tets: &[u32]) -> anyhow::Result<()> {
        self.summary.removed_tets += tets.len();
        if let Some(out) = self.removed.as_mut() {
            for tet in tets {
                writeln!(out, "{t},{tet}")?;
            }
        }
        Ok(())
    }

    /// A VTK frame of displacement field `u` (m; zero where missing) at `t`,
    /// of the tets `alive` keeps (all without it).
    fn frame(&mut self, t: f64, u: &[[f32; 3]], alive: Option<&[bool]>) -> anyhow::Result<()> {
        let Some(dir) = self.dir else { return Ok(()) };
        let path = dir.join(format!("frame_{:06}.vtk", self.frames.len()));
        vtk::write_state_frame(&path, self.rest, self.tets, u, alive)?;
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
