//! Per-tick instruction counts of every model's haptic tick (`palpate
//! chart`'s cost in instructions, as `palpate budget` measures them:
//! [`crate::budget::measure`], callgrind collecting inside
//! [`crate::budget::budget_tick`] only).
//!
//! The haptic tick needs a scene (a surface, a tool, a trajectory), the
//! one `palpate budget` measures for the model ([`tick_scene`]), with 1 to
//! [`MAX_TOOL_POINTS`] probes held pressed on their own sites (the
//! generated `press-hold` trajectory, so `P` probes make `P` simultaneous
//! contacts):
//! - the pre-computed models on the built-in block scene (`built-in`): the
//!   linear tissue and the same tissue made quasi-non-linear by the chart's
//!   fitted remap (its coefficients change no instruction count: one
//!   polynomial of fixed degree per contact and per displaced vertex);
//! - the tensor-mass models on the same block, dynamic
//!   (`built-in-dynamic`), with the model's law: linear, St
//!   Venant-Kirchhoff, St Venant-Kirchhoff + the penalty
//!   ([`crate::fem::penalty::penalty_n`] of the block);
//! - the hybrid on the built-in hybrid organ (`built-in-hybrid`, probes in
//!   place of its grasper and cutter), its tensor-mass region St
//!   Venant-Kirchhoff as the chart's ([`HYBRID_LAW`]).
//!
//! The dynamic scenes' physics updates (the law's force evaluations) run
//! every 10th tick outside the measured function, as in `palpate budget`:
//! a tick's count is the contact work (detection on the deformed surface,
//! solve), the step's cost is the chart's step time. The counts are
//! deterministic for one binary.

use std::path::Path;
use std::process::Command;

use anyhow::Context;
use palpate_kernel::precomputed::{QuasiNonLinear, REMAP_DEGREE, Remap};
use serde::Serialize;

use super::model::{HYBRID_LAW, Model};
use super::progress::Progress;
use crate::budget::{HOST_IR, budget_table, chosen_trajectories, measure, probe_remapped};
use crate::fem::penalty::penalty_n;
use crate::scene::ModelSpec;
use crate::scene::{MAX_TOOL_POINTS, ToolSpec};
use crate::scene::{Scene, Trajectory};
use crate::session::model::{SceneModel, SceneTables};
use palpate_kernel::tensor_mass::ElasticLaw;

/// The trajectory of the counts: every probe pressed and held.
pub const TICK_TRAJECTORY: &str = "press-hold";

/// The scene `palpate budget` measures for `model`, with `points` probes
/// and the model's law (module documentation).
pub fn tick_scene(model: Model, points: usize) -> anyhow::Result<Scene> {
    let name = match model {
        Model::PrecomputedLinear | Model::PrecomputedQuasi => "built-in",
        Model::Hybrid => "built-in-hybrid",
        Model::TensorMassLinear
        | Model::Stvk
        | Model::StvkPenalty
        | Model::Corotational
        | Model::NeoHookean => "built-in-dynamic",
    };
    let mut scene = Scene::named(name)?;
    scene.tool = ToolSpec::probes(points, scene.tool.radius_m);
    let (law, penalty) = match model {
        Model::TensorMassLinear => (ElasticLaw::Linear, None),
        Model::Corotational => (ElasticLaw::Corotational, None),
        Model::NeoHookean => (ElasticLaw::NeoHookean, None),
        Model::StvkPenalty => {
            let (mesh, _) = scene.load_mesh()?;
            (HYBRID_LAW, Some(penalty_n(&mesh, &scene.material.elastic)))
        }
        _ => (HYBRID_LAW, None),
    };
    if let ModelSpec::Dynamic(spec) = &mut scene.model {
        spec.law = law;
        spec.incompressibility_n = penalty;
    }
    Ok(scene)
}

/// One model's tick with `contacts` probes.
#[derive(Clone, Debug, Serialize)]
pub struct TickCount {
    /// The model.
    pub model: Model,
    /// Its scene: name, vertices and tets.
    pub scene: String,
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
        /// One per model and contact count.
        counts: Vec<TickCount>,
    },
    /// Not measured, and why.
    Skipped {
        /// The reason.
        reason: String,
    },
}

/// Runs of [`measure_ticks`]: every model × 1..=[`MAX_TOOL_POINTS`] probes.
pub const TICK_RUNS: usize = Model::ALL.len() * MAX_TOOL_POINTS;

/// Whether `valgrind --version` runs here.
pub fn valgrind_available() -> bool {
    Command::new("valgrind")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success())
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
pub fn parse_remap(word: &str) -> anyhow::Result<Option<QuasiNonLinear<f32>>> {
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
/// `trajectory` on the tables `table` of `model`'s scene ([`tick_scene`])
/// with `points` probes, the pre-computed tissue remapped by `remap`
/// ([`remap_word`]).
pub fn probe_child(
    model: &str,
    table: &Path,
    trajectory: &Path,
    points: usize,
    remap: &str,
) -> anyhow::Result<()> {
    let model = Model::ALL
        .into_iter()
        .find(|m| m.name() == model)
        .with_context(|| format!("no model {model}"))?;
    let scene = tick_scene(model, points)?;
    let (mesh, report) = scene.load_mesh()?;
    let tables = SceneTables::read(SceneModel::of(&scene, &mesh, &report)?, table)?;
    let trajectory = Trajectory::read(trajectory, points)?;
    probe_remapped(&tables, &scene, &trajectory, parse_remap(remap)?)?;
    Ok(())
}

/// The arguments of [`probe_child`] for one run: model name, table,
/// trajectory, probes, remap word.
pub struct ChildArgs<'a> {
    /// The model.
    pub model: Model,
    /// Its tables (base path, [`SceneTables::write`]).
    pub table: &'a Path,
    /// The trajectory file.
    pub trajectory: &'a Path,
    /// Probes.
    pub points: usize,
    /// [`remap_word`].
    pub remap: &'a str,
}

/// Measures the per-tick instructions of every model with 1 to
/// [`MAX_TOOL_POINTS`] probes under callgrind: `exe` (this binary) runs
/// [`probe_child`] through `child_args`, its files under `work_dir`.
/// Skipped, with the reason, when valgrind is not installed.
pub fn measure_ticks(
    exe: &Path,
    child_args: impl Fn(&ChildArgs<'_>) -> Vec<String>,
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
    let mut counts = Vec::new();
    for model in Model::ALL {
        // One table for every probe count (the tool changes only the bound).
        let scene = tick_scene(model, 1)?;
        let (mesh, report) = scene.load_mesh()?;
        let scene_name = format!(
            "{} ({} vertices, {} tets)",
            scene.source,
            mesh.positions.len(),
            mesh.tets.len()
        );
        let (tables, _) = budget_table(&scene, &mesh, &report, &HOST_IR, None)?;
        let table = work_dir.join(format!("table-{}", model.name()));
        tables.write(&table)?;
        let word = match model {
            Model::PrecomputedQuasi => remap_word(Some(remap)),
            _ => remap_word(None),
        };
        for points in 1..=MAX_TOOL_POINTS {
            let scene = tick_scene(model, points)?;
            let (_, trajectory) = chosen_trajectories(&scene, &[TICK_TRAJECTORY.into()])?
                .into_iter()
                .next()
                .context("no press-hold trajectory")?;
            let csv = work_dir.join(format!("{TICK_TRAJECTORY}-{}-{points}.csv", model.name()));
            trajectory.write_csv_file(&csv)?;
            let args = child_args(&ChildArgs {
                model,
                table: &table,
                trajectory: &csv,
                points,
                remap: &word,
            });
            let dumps = work_dir.join(format!("cg-{}-{points}", model.name()));
            // Never empty: `measure` refuses a probe that counted no tick.
            let irs = measure(exe, &args, &dumps)?;
            counts.push(TickCount {
                model,
                scene: scene_name.clone(),
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
    Ok(TickCounts::Measured { counts })
}
