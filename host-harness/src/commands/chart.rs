//! `palpate chart`: the speed/accuracy study ([`palpate::chart`]): runs the
//! matrix with a progress bar, writes the charts, `report.md`,
//! `index.html` and `study.json` into `--out`, prints the summary (or the
//! JSON).

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use palpate::chart::{self, Matrix, plot, report};
use palpate::experiment::scenes;
use palpate::experiment::volume_bend::{self, Protocol};
use palpate::limits::MAX_CHART_TET_STEPS;
use palpate::output::atomic::write_file;

use super::stdout;

/// `palpate chart` arguments.
#[derive(Args)]
pub struct ChartArgs {
    /// The reduced matrix (two meshes, press and bend at 1 % and 5 %, a
    /// small stability grid, the small volume cylinder): under a minute.
    #[arg(long)]
    quick: bool,
    /// Output folder (created; files in it replaced atomically).
    #[arg(long, default_value = "chart-out")]
    out: PathBuf,
    /// Print the study as one JSON object instead of the summary.
    #[arg(long)]
    json: bool,
}

/// Runs `palpate chart`.
pub fn run(args: &ChartArgs) -> anyhow::Result<()> {
    let matrix = if args.quick {
        Matrix::quick()
    } else {
        Matrix::full()
    };
    let protocols = [Protocol::PaperLoads, Protocol::Tilt];
    // Picinbono's table 2 on the bent cylinder: the small one in --quick;
    // its relaxations capped as the study's.
    let scene = if args.quick {
        scenes::cylinder(2, 8)
    } else {
        scenes::default_cylinder()
    };
    let controls = volume_bend::Controls {
        max_steps: matrix.max_relax_steps,
        ..volume_bend::Controls::default()
    };
    let trials = 4 * matrix.stability.trials();
    let total = matrix.static_runs() + trials + matrix.trajectories() + protocols.len();
    eprintln!(
        "chart: {} meshes × {} loads × {} levels × {} models = {} static runs (+ {} Newton \
         references), {} stability trials, {} trajectories (each against its Δt/{}), {} volume \
         experiments: {total} steps of progress",
        matrix.meshes.len(),
        matrix.loads.len(),
        matrix.levels.len(),
        chart::Model::ALL.len(),
        matrix.static_runs() - matrix.loads.len() * matrix.levels.len(),
        matrix.loads.len() * matrix.levels.len(),
        trials,
        matrix.trajectories(),
        chart::trajectory::REFINEMENT,
        protocols.len(),
    );
    // The work bound, checked before anything runs, and its time here.
    let bodies = matrix.bodies();
    let volume_relaxations: usize = protocols
        .iter()
        .map(|&p| volume_bend::relaxations_bound(&scene, p, &controls))
        .sum();
    let bound = matrix.tet_step_bound(&bodies)?
        + (volume_relaxations * controls.max_steps * scene.mesh.tets.len()) as u64;
    anyhow::ensure!(
        bound <= MAX_CHART_TET_STEPS,
        "the study's work bound, {bound:.3e} tet-steps, exceeds the limit of {MAX_CHART_TET_STEPS:.0e}"
    );
    let finest = bodies.last().context("no mesh")?;
    let per_tet_step_s = chart::seconds_per_tet_step(finest)?;
    eprintln!(
        "chart: at most {bound:.2e} tet-steps (every relaxation at its {}-step cap; limit \
         {MAX_CHART_TET_STEPS:.0e}), at most {:.0} s at {:.0} ns per tet-step measured here \
         (St Venant-Kirchhoff + penalty on {}), plus the Newton references and the timing; \
         the relaxations settle far below their cap",
        matrix.max_relax_steps,
        bound as f64 * per_tet_step_s,
        1e9 * per_tet_step_s,
        finest.label,
    );
    let bar = ProgressBar::new(total as u64);
    if let Ok(style) = ProgressStyle::with_template("chart {bar:40} {pos}/{len} ({eta}) {msg}") {
        bar.set_style(style);
    }
    // Without a terminal (CI, a redirected run) the bar is hidden: one line
    // per step instead, with the time since the start.
    let lines = bar.is_hidden();
    let start = std::time::Instant::now();
    let mut tick = |message: &str| {
        bar.inc(1);
        if lines {
            eprintln!(
                "chart {}/{total} {:7.1} s {message}",
                bar.position(),
                start.elapsed().as_secs_f64()
            );
        } else {
            bar.set_message(message.to_string());
        }
    };
    let study = chart::run(&matrix, &mut tick)?;
    let mut volume = Vec::new();
    for protocol in protocols {
        volume.push(volume_bend::run_scene(&scene, protocol, &controls, |_| {})?);
        tick(&format!("volume {protocol:?}"));
    }
    bar.finish_and_clear();

    std::fs::create_dir_all(&args.out)?;
    let charts = plot::draw_all(&study, &volume, &args.out, &matrix.loads, &matrix.levels)?;
    let volume_table: String = volume
        .iter()
        .map(|r| volume_bend::table(core::slice::from_ref(r)))
        .collect::<Vec<_>>()
        .join("\n");
    let markdown = report::markdown(
        &study,
        &matrix.loads,
        &matrix.levels,
        &charts,
        &volume_table,
    );
    write_file(&args.out.join("report.md"), markdown.as_bytes())?;
    write_file(
        &args.out.join("index.html"),
        report::html(&markdown, &charts).as_bytes(),
    )?;
    let mut summary = serde_json::Map::new();
    for &load in &matrix.loads {
        for &level in &matrix.levels {
            let key = format!("{}-{:.0}", load.name(), 100.0 * level);
            let within: serde_json::Map<String, serde_json::Value> = report::BOUNDS
                .iter()
                .map(|&b| {
                    (
                        format!("{:.0}", 100.0 * b),
                        report::cheapest(&study, load, level, b).into(),
                    )
                })
                .collect();
            summary.insert(
                key,
                serde_json::json!({
                    "pareto": report::pareto_members(&study, load, level),
                    "cheapest_within_percent": within,
                }),
            );
        }
    }
    let json = serde_json::json!({
        "summary": summary,
        "study": study,
        "volume": volume,
        "charts": charts,
    });
    write_file(&args.out.join("study.json"), json.to_string().as_bytes())?;
    if args.json {
        stdout::println(&json.to_string())?;
    } else {
        stdout::print(&markdown)?;
    }
    Ok(())
}
