//! Per-tick instruction counts of the pre-computed models' haptic tick
//! (`palpate chart`'s cost in instructions, as `palpate budget` measures
//! them: [`crate::budget::measure`], callgrind collecting inside
//! [`crate::budget::budget_tick`] only).
//!
//! The haptic tick needs a scene (a surface, a tool, a trajectory): the
//! built-in block scene `palpate budget built-in` measures, with 1 to
//! [`MAX_TOOL_POINTS`] probes held pressed on their own sites (the
//! generated `press-hold` trajectory, so `P` probes make `P` simultaneous
//! contacts), with the linear pre-computed tissue and the same tissue made
//! quasi-non-linear by the chart's fitted remap (its coefficients change no
//! instruction count: one polynomial of fixed degree per contact and per
//! displaced vertex). The counts are deterministic for one binary.

use std::path::Path;
use std::process::Command;

use anyhow::Context;
use palpate_kernel::precomputed::{QuasiNonLinear, REMAP_DEGREE, Remap};
use serde::Serialize;

use super::{Model, Progress};
use crate::budget::{HOST_IR, budget_table, chosen_trajectories, measure, probe_remapped};
use crate::session::model::{SceneModel, SceneTables};
use crate::session::scene::{MAX_TOOL_POINTS, ToolSpec};
use crate::session::{Scene, Trajectory};

/// The scene of the counts (`palpate budget`'s).
pub const TICK_SCENE: &str = "built-in";
/// Its trajectory: every probe pressed and held.
pub const TICK_TRAJECTORY: &str = "press-hold";

/// One model's tick with `contacts` probes.
#[derive(Clone, Debug, Serialize)]
pub struct TickCount {
    /// The model (pre-computed linear or quasi-non-linear).
    pub model: Model,
    /// Probes, each making one contact while held.
    pub contacts: usize,
    /// Ticks measured.
    pub ticks: usize,
    /// Mean instructions per tick.
    pub mean_ir: f64,
    /// Largest instructions of a tick.
    pub max_ir: u64,
}

/// The counts, or why there are none.
#[derive(Clone, Debug, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum TickCounts {
    /// Measured.
    Measured {
        /// The scene's mesh, "V vertices, T tets".
        mesh: String,
        /// One per model and contact count.
        counts: Vec<TickCount>,
    },
    /// Not measured, and why.
    Skipped {
        /// The reason.
        reason: String,
    },
}

/// Runs of [`measure_ticks`]: two models × 1..=[`MAX_TOOL_POINTS`] probes.
pub const TICK_RUNS: usize = 2 * MAX_TOOL_POINTS;

/// Whether `valgrind --version` runs here.
pub fn valgrind_available() -> bool {
    Command::new("valgrind")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success())
}

/// The built-in scene with `points` probes.
fn scene_with(points: usize) -> anyhow::Result<Scene> {
    let mut scene = Scene::named(TICK_SCENE)?;
    scene.tool = ToolSpec::probes(points, scene.tool.radius_m);
    Ok(scene)
}

/// `remap` as the command-line word of [`probe_child`]: `φ`'s then `ψ`'s
/// coefficients and range end, comma-separated (`linear` for none).
pub fn remap_word(remap: Option<&QuasiNonLinear<f64>>) -> String {
    let Some(q) = remap else {
        return "linear".into();
    };
    [&q.radial, &q.force]
        .iter()
        .flat_map(|r| r.coefficients().iter().copied().chain([r.x_max()]))
        .map(|x| x.to_string())
        .collect::<Vec<_>>()
        .join(",")
}

/// The inverse of [`remap_word`], in f32 (the haptic tick's precision).
fn parse_remap(word: &str) -> anyhow::Result<Option<QuasiNonLinear<f32>>> {
    if word == "linear" {
        return Ok(None);
    }
    let values: Vec<f32> = word
        .split(',')
        .map(|x| x.parse::<f64>().map(|x| x as f32))
        .collect::<Result<_, _>>()
        .context("remap: not numbers")?;
    anyhow::ensure!(
        values.len() == 2 * (REMAP_DEGREE + 1),
        "remap: {} numbers, expected {}",
        values.len(),
        2 * (REMAP_DEGREE + 1)
    );
    let remap = |v: &[f32]| -> anyhow::Result<Remap<f32>> {
        let mut c = [0.0f32; REMAP_DEGREE];
        c.copy_from_slice(&v[..REMAP_DEGREE]);
        Remap::new(c, v[REMAP_DEGREE]).map_err(|e| anyhow::anyhow!("remap: {e}"))
    };
    let (radial, force) = values.split_at(REMAP_DEGREE + 1);
    Ok(Some(QuasiNonLinear {
        radial: remap(radial)?,
        force: remap(force)?,
    }))
}

/// The child process callgrind runs: the ticks of the trajectory file
/// `trajectory` on the table `table` of the built-in scene with `points`
/// probes, the tissue remapped by `remap` ([`remap_word`]).
pub fn probe_child(
    table: &Path,
    trajectory: &Path,
    points: usize,
    remap: &str,
) -> anyhow::Result<()> {
    let scene = scene_with(points)?;
    let (mesh, report) = scene.load_mesh()?;
    let tables = SceneTables::read(SceneModel::of(&scene, &mesh, &report)?, table)?;
    let trajectory = Trajectory::read(trajectory, points)?;
    probe_remapped(&tables, &scene, &trajectory, parse_remap(remap)?)?;
    Ok(())
}

/// Measures the per-tick instructions of both pre-computed models with 1
/// to [`MAX_TOOL_POINTS`] probes under callgrind: `exe` (this binary) runs
/// [`probe_child`] through `child_args(table, trajectory, points, remap)`,
/// its files under `work_dir`. Skipped, with the reason, when valgrind is
/// not installed.
pub fn measure_ticks(
    exe: &Path,
    child_args: impl Fn(&Path, &Path, usize, &str) -> Vec<String>,
    work_dir: &Path,
    remap: &QuasiNonLinear<f64>,
    progress: &mut dyn Progress,
) -> anyhow::Result<TickCounts> {
    if !valgrind_available() {
        return Ok(TickCounts::Skipped {
            reason: "valgrind is not installed (tools/setup.sh installs it)".into(),
        });
    }
    std::fs::create_dir_all(work_dir).with_context(|| work_dir.display().to_string())?;
    // One table for every probe count (the tool changes only the bound).
    let scene = scene_with(1)?;
    let (mesh, report) = scene.load_mesh()?;
    let mesh_size = format!(
        "{} vertices, {} tets",
        mesh.positions.len(),
        mesh.tets.len()
    );
    let (tables, _) = budget_table(&scene, &mesh, &report, &HOST_IR, None)?;
    let table = work_dir.join("table.bin");
    tables.write(&table)?;
    let mut counts = Vec::new();
    for points in 1..=MAX_TOOL_POINTS {
        let scene = scene_with(points)?;
        let (_, trajectory) = chosen_trajectories(&scene, &[TICK_TRAJECTORY.into()])?
            .into_iter()
            .next()
            .context("no press-hold trajectory")?;
        let csv = work_dir.join(format!("{TICK_TRAJECTORY}-{points}.csv"));
        trajectory.write_csv_file(&csv)?;
        for (model, word) in [
            (Model::PrecomputedLinear, remap_word(None)),
            (Model::PrecomputedQuasi, remap_word(Some(remap))),
        ] {
            let args = child_args(&table, &csv, points, &word);
            let dumps = work_dir.join(format!("cg-{}-{points}", model.name()));
            let irs = measure(exe, &args, &dumps)?;
            anyhow::ensure!(!irs.is_empty(), "callgrind counted no tick");
            counts.push(TickCount {
                model,
                contacts: points,
                ticks: irs.len(),
                mean_ir: irs.iter().sum::<u64>() as f64 / irs.len() as f64,
                max_ir: irs.iter().copied().max().unwrap_or(0),
            });
            progress.tick(&format!(
                "callgrind {} {points} contact(s): max {} Ir per tick",
                model.name(),
                counts.last().map_or(0, |c| c.max_ir)
            ));
        }
    }
    Ok(TickCounts::Measured {
        mesh: mesh_size,
        counts,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The command-line word carries the remap exactly (f64 → text → f64,
    /// then f32, as the tick runs it).
    #[test]
    fn remap_word_round_trips() {
        let c = [0.9, 0.5, -0.1, 0.0, 0.0];
        let q = QuasiNonLinear {
            radial: Remap::new(c, 0.01).unwrap(),
            force: Remap::new([1.2, 3.0, 0.0, 0.0, 0.0], 2.5).unwrap(),
        };
        let back = parse_remap(&remap_word(Some(&q))).unwrap().unwrap();
        assert_eq!(back.radial.coefficients(), &c.map(|x| x as f32));
        assert_eq!(back.radial.x_max(), 0.01f32);
        assert_eq!(back.force.coefficients()[1], 3.0f32);
        assert_eq!(back.force.x_max(), 2.5f32);
        assert!(parse_remap("linear").unwrap().is_none());
        assert!(parse_remap("1,2").is_err());
    }
}
