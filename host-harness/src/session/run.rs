//! `palpate session run`: drives the kernel's haptic loop
//! ([`palpate_kernel::haptic::haptic_loop::HapticLoop`]) tick by tick from a
//! trajectory and writes one CSV line per tick, `t,fx,fy,fz,contacts,status`
//! (s, N, N, N, count, `ok` | `clamped` | `faulted:<reason>`).
//!
//! The table is built in memory from the scene (f32, the firmware
//! precision). Every `physics_every` ticks the deformation field is updated
//! from the last contact solution (and written as a VTK frame with
//! `--vtk`); the force is computed every tick (see the loop's docs).
//! Only the pre-computed model is driven here; a dynamic scene is refused.

use std::io::Write;
use std::path::Path;

use anyhow::{Context, bail};
use nalgebra::Vector3;
use palpate_kernel::PrecomputedTable;
use palpate_kernel::haptic::haptic_loop::{LoopConfig, PrecomputedLoop};
use palpate_kernel::haptic::safety::{OutputStatus, SafetyLimits};
use palpate_kernel::haptic::tissue::PrecomputedTissue;

use super::{ModelSpec, Scene, Trajectory};
use crate::mesh::{MeshReport, TetMesh};
use crate::output::vtk;
use crate::tables::build::{BuildOptions, build_table};
use crate::tables::compliance::Solver;
use crate::tables::file::Precision;
use crate::tables::load::TableFile;

/// The f32 pre-computed table of `scene` (the firmware precision), built
/// in memory with the same pipeline as `palpate tables build`.
pub fn precomputed_table(
    scene: &Scene,
    mesh: &TetMesh,
    report: &MeshReport,
) -> anyhow::Result<Vec<u8>> {
    let options = BuildOptions {
        material: scene.elastic_material()?,
        fix: scene.fix.clone(),
        solver: Solver::Cholesky,
        precision: Precision::F32,
        progress: false,
    };
    Ok(build_table(mesh, report, &options)
        .with_context(|| scene.source.clone())?
        .bytes)
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

/// The ticks of `trajectory` at period `tick_s`: `(t_s, tool positions)`
/// for `t = start + k·tick_s` up to the end; a tool point the trajectory
/// lacks is NaN (the loop faults on it).
pub fn ticks<const P: usize>(
    trajectory: &Trajectory,
    tick_s: f64,
) -> impl Iterator<Item = (f64, [Vector3<f32>; P])> + '_ {
    let start = trajectory.start_s();
    let count = ((trajectory.end_s() - start) / tick_s + 1e-9).floor() as usize + 1;
    let mut positions = vec![[0.0; 3]; trajectory.tool_count()];
    (0..count).map(move |k| {
        let t = start + k as f64 * tick_s;
        trajectory.positions_at_into(t, &mut positions);
        let tool = core::array::from_fn(|p| {
            let x = positions.get(p).copied().unwrap_or([f64::NAN; 3]);
            Vector3::new(x[0] as f32, x[1] as f32, x[2] as f32)
        });
        (t, tool)
    })
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
}

/// Runs `trajectory` through the haptic loop of `scene`, writing the CSV to
/// `out` and, with `vtk_dir`, a VTK frame per physics update and a `.pvd`.
pub fn run_session(
    scene: &Scene,
    trajectory: &Trajectory,
    out: &mut dyn Write,
    vtk_dir: Option<&Path>,
) -> anyhow::Result<SessionSummary> {
    if !matches!(scene.model, ModelSpec::Precomputed) {
        bail!(
            "{}: session run drives the pre-computed model only (model.kind = \"precomputed\")",
            scene.source
        );
    }
    let (mesh, report) = scene.load_mesh()?;
    let file = TableFile::from_bytes(&precomputed_table(scene, &mesh, &report)?);
    let table = PrecomputedTable::<f32>::load(file.bytes()).context("session table")?;
    let config = loop_config(scene);
    let field = FieldOutput {
        rest: &mesh.positions,
        tets: &mesh.tets,
        dir: vtk_dir,
        every: scene.rates.physics_every.max(1) as usize,
    };
    let run = Runner {
        table: &table,
        config,
        trajectory,
        tick_s: scene.tick_s(),
        field,
    };
    match scene.tool.points {
        1 => run.go::<1>(out),
        2 => run.go::<2>(out),
        3 => run.go::<3>(out),
        _ => run.go::<4>(out),
    }
}

/// Where the deformation field goes.
struct FieldOutput<'m> {
    rest: &'m [[f64; 3]],
    tets: &'m [[u32; 4]],
    dir: Option<&'m Path>,
    every: usize,
}

struct Runner<'r, 't> {
    table: &'r PrecomputedTable<'t, f32>,
    config: LoopConfig<f32>,
    trajectory: &'r Trajectory,
    tick_s: f64,
    field: FieldOutput<'r>,
}

impl Runner<'_, '_> {
    fn go<const P: usize>(&self, out: &mut dyn Write) -> anyhow::Result<SessionSummary> {
        let mut haptic =
            PrecomputedLoop::<f32, P, P>::new(PrecomputedTissue::new(self.table), self.config)
                .map_err(|e| anyhow::anyhow!("haptic loop: {e}"))?;
        let model = *haptic.tissue().model();
        let mut summary = SessionSummary::default();
        let mut field = vec![[0.0f32; 3]; self.field.rest.len()];
        let mut frames = Vec::new();
        let mut last = Vector3::<f32>::zeros();
        writeln!(out, "t,fx,fy,fz,contacts,status")?;
        for (k, (t, tool)) in ticks::<P>(self.trajectory, self.tick_s).enumerate() {
            let output = haptic.tick(&tool);
            let f = output.force_n;
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
            writeln!(
                out,
                "{t},{},{},{},{},{status}",
                f.x, f.y, f.z, output.contacts
            )?;
            summary.ticks += 1;
            summary.ticks_in_contact += usize::from(output.contacts > 0);
            summary.max_force_n = summary.max_force_n.max(f64::from(f.norm()));
            summary.max_jump_n = summary.max_jump_n.max(f64::from((f - last).norm()));
            last = f;
            if let (Some(dir), true) = (self.field.dir, k % self.field.every == 0) {
                if let Some(solution) = haptic.solution() {
                    model
                        .displacements(solution, &mut field)
                        .map_err(|e| anyhow::anyhow!("displacements: {e}"))?;
                } else {
                    field.fill([0.0; 3]);
                }
                let u: Vec<[f64; 3]> = field.iter().map(|d| d.map(f64::from)).collect();
                let path = dir.join(format!("frame_{:06}.vtk", frames.len()));
                vtk::write_frame(&path, self.field.rest, self.field.tets, &u)?;
                frames.push((t, path));
            }
        }
        if let Some(dir) = self.field.dir {
            vtk::write_collection(&dir.join("session.pvd"), &frames)?;
        }
        summary.frames = frames.len();
        Ok(summary)
    }
}
