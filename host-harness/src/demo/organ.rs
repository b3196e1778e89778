//! Part two of the demo: the built-in hybrid organ
//! ([`Scene::built_in_hybrid`]) in a generated surgery
//! ([`hepatectomy`], `session generate hepatectomy`): the grasper (tool 0)
//! holds the right lobe, pre-computed tissue, and pulls it up while the
//! cutter (tool 1) cuts the left lobe through across its width, 4.5 cm
//! from its tip, in the cut zone, tensor-mass tissue, so that the tip
//! comes off; the pre-computed and tensor-mass regions are coupled at
//! their connection nodes (the hybrid model, MODELS.md §5).
//!
//! The session runs as `palpate session run built-in-hybrid` runs it (the
//! same tables, loop and ticks, [`crate::session::run`]), with each haptic
//! tick and each physics update timed, the device force summed up per
//! phase of the tools, and a VTK frame of the live tets every
//! [`FRAME_EVERY_S`] of simulated time.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, bail};
use nalgebra::Vector3;
use palpate_kernel::haptic::{ForceOutput, HybridLoop, OutputStatus};
use palpate_kernel::math::Portable;

use super::timing::Costs;
use crate::mesh::TetMesh;
use crate::output::vtk;
use crate::scene::generate::hepatectomy;
use crate::scene::{HEPATECTOMY_ZONE_PAST_CUT_M, Scene, ToolKind, ToolSpec, ToolState, Trajectory};
use crate::session::hybrid::HybridSetup;
use crate::session::model::{SceneModel, SceneTables};
use crate::session::run::{tick_count, ticks};
use crate::session::setup::PhysicsView;
use crate::session::tool_points::{ForToolPoints, with_tool_points};

/// The organ's ParaView collection in the demo's folder (the frames
/// `organ_NNNN.vtk` beside it).
pub const COLLECTION: &str = "organ.pvd";
/// Simulated time between two VTK frames of the organ, s.
pub const FRAME_EVERY_S: f64 = 0.1;

/// What part two measured.
#[derive(Clone, Debug, Default)]
pub struct OrganRun {
    /// Each haptic tick (contact search, grasp, force solve, supervisor)
    /// and each physics update (tensor-mass steps, cuts, coupling).
    pub costs: Costs,
    /// Tets removed: by the blade, and by the tearing its cut caused.
    pub removed_tets: usize,
    /// Ticks with at least one contact.
    pub ticks_in_contact: usize,
    /// Ticks whose force the supervisor clamped.
    pub clamped: usize,
    /// Ticks with a latched fault (zero force).
    pub faulted: usize,
}

/// Runs part two for the surgery's first `length_s` seconds (`None`: all
/// of it), printing the scene, the tables, the surgery and the force per
/// phase to `out`, and writing the frames and [`COLLECTION`] into `dir`.
/// A failed physics update is an error.
pub fn run(dir: &Path, length_s: Option<f64>, out: &mut dyn Write) -> anyhow::Result<OrganRun> {
    let scene = Scene::built_in_hybrid();
    let trajectory = hepatectomy(&scene.tool).map_err(|e| anyhow::anyhow!("{e}"))?;
    let (mesh, report) = scene.load_mesh()?;
    let started = Instant::now();
    let model = SceneModel::of(&scene, &mesh, &report)?;
    let SceneModel::Hybrid { partition, .. } = &model else {
        bail!("the built-in hybrid scene is not a hybrid");
    };
    writeln!(
        out,
        "scene: organ, {} vertices, {} tets, E = {} Pa, nu = {}, underside fixed; tensor-mass \
         region: {} tets, the left lobe to {:.0} mm past the cut line, {} connection nodes to the \
         pre-computed rest",
        mesh.positions.len(),
        mesh.tets.len(),
        scene.material.elastic.young_pa,
        scene.material.elastic.poisson,
        partition.dynamic.iter().filter(|&&d| d).count(),
        HEPATECTOMY_ZONE_PAST_CUT_M * 1e3,
        partition.connection_nodes.len()
    )?;
    let SceneTables::Hybrid(files, spec) = model.tables(&scene, &mesh, &report, None)? else {
        bail!("the built-in hybrid scene's tables are not a hybrid's");
    };
    writeln!(
        out,
        "tables: pre-computed region, tensor-mass region and interface (f32), built in {:.3} s",
        started.elapsed().as_secs_f64()
    )?;
    let setup = HybridSetup::of(&scene, &spec, &files)?;
    let all = tick_count(&trajectory, scene.tick_s())?;
    let count = length_s.map_or(all, |s| all.min((s / scene.tick_s()).floor() as usize + 1));
    writeln!(
        out,
        "surgery (session generate hepatectomy): {:.3} of {:.3} s at {} Hz, physics every {} ticks; \
         the grasper holds the pre-computed lobe, the cutter cuts the tensor-mass zone",
        (count - 1) as f64 * scene.tick_s(),
        trajectory.end_s() - trajectory.start_s(),
        scene.rates.haptic_hz,
        scene.rates.physics_every
    )?;
    let surgery = Surgery {
        scene: &scene,
        trajectory: &trajectory,
        mesh: &mesh,
        setup: &setup,
        count,
        dir,
    };
    let (run, phases) = with_tool_points(scene.tool.kernel_points(), surgery)?;
    phases.print(out)?;
    writeln!(
        out,
        "ticks: {} ({} in contact, {} clamped, {} faulted); the cut removed {} tets (the blade's \
         and the tears it opened)",
        run.costs.ticks.len(),
        run.ticks_in_contact,
        run.clamped,
        run.faulted,
        run.removed_tets
    )?;
    Ok(run)
}

/// The surgery's first `count` ticks on the organ, frames into `dir`.
struct Surgery<'a> {
    scene: &'a Scene,
    trajectory: &'a Trajectory,
    mesh: &'a TetMesh,
    setup: &'a HybridSetup<'a>,
    count: usize,
    dir: &'a Path,
}

impl ForToolPoints for Surgery<'_> {
    type Output = anyhow::Result<(OrganRun, Phases)>;

    fn call<const P: usize>(self) -> Self::Output {
        self.setup
            .with_loop::<P, _, _>(Portable, |haptic| self.drive(haptic))
    }
}

impl Surgery<'_> {
    /// The ticks as `session run` runs them (a physics update every
    /// `physics_every` ticks), each timed; a frame every [`FRAME_EVERY_S`].
    fn drive<const P: usize>(
        &self,
        haptic: &mut HybridLoop<'_, '_, f32, P, P>,
    ) -> anyhow::Result<(OrganRun, Phases)> {
        let view = self.setup.view();
        let tick_s = self.scene.tick_s();
        let every = self.scene.rates.physics_every.max(1) as usize;
        let frame_every = every * ((FRAME_EVERY_S / tick_s / every as f64).round() as usize).max(1);
        let idle = ToolState {
            position_m: [f64::NAN; 3],
            jaw_m: 0.0,
            cut: false,
        };
        let mut states = vec![idle; self.trajectory.tool_count()];
        let mut run = OrganRun::default();
        let mut phases = Phases::default();
        let mut frames = Vec::new();
        let tool_ticks = ticks::<P>(self.trajectory, tick_s, &self.scene.tool)?;
        for (k, (t, tool)) in tool_ticks.take(self.count).enumerate() {
            let started = Instant::now();
            let output = haptic.tick_tools(&tool);
            run.costs.ticks.push(started.elapsed());
            run.count(&output);
            self.trajectory.tools_at_into(t, &mut states);
            phases.record(phase_name(&self.scene.tool, &states), t, &output);
            if (k + 1) % every != 0 {
                continue;
            }
            let started = Instant::now();
            let update = haptic.physics_update();
            run.costs.physics.push(started.elapsed());
            update.map_err(|e| anyhow::anyhow!("physics update at t = {t} s: {e}"))?;
            let removed = view.removed(haptic.tissue()).len();
            run.removed_tets += removed;
            phases.removed(removed);
            if (k + 1) % frame_every == 0 {
                let (u, alive) = view.frame(haptic.tissue())?;
                frames.push((t, self.frame(frames.len(), &u, &alive)?));
            }
        }
        vtk::write_collection(&self.dir.join(COLLECTION), &frames)?;
        run.costs.frames = frames.len();
        Ok((run, phases))
    }

    /// Writes frame `n`: displacement `u` (m, per mesh vertex; zero where
    /// missing) on the tets `alive` keeps.
    fn frame(&self, n: usize, u: &[[f32; 3]], alive: &[bool]) -> anyhow::Result<PathBuf> {
        let path = self.dir.join(format!("organ_{n:04}.vtk"));
        vtk::write_state_frame(&path, &self.mesh.positions, &self.mesh.tets, u, Some(alive))
            .with_context(|| format!("organ frame {n}"))?;
        Ok(path)
    }
}

impl OrganRun {
    /// One tick's share of the counts.
    fn count(&mut self, output: &ForceOutput<f32>) {
        self.ticks_in_contact += usize::from(output.contacts > 0);
        match output.status {
            OutputStatus::Clamped => self.clamped += 1,
            OutputStatus::Faulted(_) => self.faulted += 1,
            _ => {}
        }
    }
}

/// What the tools do at one tick, by the trajectory's tool states: a
/// grasper's jaws closed (at or below the scene's grip opening) or open,
/// a cutter's blade cutting or off.
fn phase_name(tools: &ToolSpec, states: &[ToolState]) -> String {
    let parts: Vec<&str> = tools
        .kinds
        .iter()
        .zip(states)
        .map(|(kind, s)| match kind {
            ToolKind::Grasper if s.jaw_m <= tools.grip_opening_m => "grasper closed",
            ToolKind::Grasper => "grasper open",
            ToolKind::Cutter if s.cut => "blade cutting",
            ToolKind::Cutter => "blade off",
            ToolKind::Probe => "probe",
        })
        .collect();
    parts.join(", ")
}

/// The device force per phase: a phase runs while what the tools do
/// ([`phase_name`]) stays the same.
#[derive(Default)]
struct Phases {
    rows: Vec<Phase>,
}

struct Phase {
    name: String,
    from_s: f64,
    ticks: usize,
    last_n: Vector3<f32>,
    peak_n: f32,
    removed_tets: usize,
}

impl Phases {
    /// One tick at `t` (s) of phase `name` and its force.
    fn record(&mut self, name: String, t: f64, output: &ForceOutput<f32>) {
        if self.rows.last().is_none_or(|p| p.name != name) {
            self.rows.push(Phase {
                name,
                from_s: t,
                ticks: 0,
                last_n: Vector3::zeros(),
                peak_n: 0.0,
                removed_tets: 0,
            });
        }
        if let Some(p) = self.rows.last_mut() {
            p.ticks += 1;
            p.last_n = output.force_n;
            p.peak_n = p.peak_n.max(output.force_n.norm());
        }
    }

    /// Tets a physics update of the current phase removed.
    fn removed(&mut self, tets: usize) {
        if let Some(p) = self.rows.last_mut() {
            p.removed_tets += tets;
        }
    }

    fn print(&self, out: &mut dyn Write) -> anyhow::Result<()> {
        writeln!(
            out,
            "phase                          from (s)  ticks  device force at end (N)          |F| peak (N)  tets removed"
        )?;
        for p in &self.rows {
            let f = p.last_n;
            writeln!(
                out,
                "{:<30} {:>8.3} {:>6}  ({:+.4}, {:+.4}, {:+.4})  {:>11.4}  {:>12}",
                p.name, p.from_s, p.ticks, f.x, f.y, f.z, p.peak_n, p.removed_tets
            )?;
        }
        Ok(())
    }
}
