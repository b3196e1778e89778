//! `palpate chart`: the speed/accuracy study ([`palpate::chart`]): runs the
//! matrix with a progress bar, writes the charts, `report.md`,
//! `index.html` and `study.json` into `--out` (built in a hidden sibling
//! folder and renamed into place whole: `palpate::output::atomic`'s
//! `SeriesDir`, which refuses a folder palpate did not write), prints the
//! summary (or the JSON).

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use palpate::chart::{self, GivenMesh, Matrix, plot, report, ticks};
use palpate::experiment::scenes;
use palpate::experiment::volume_bend::{self, Protocol};
use palpate::fix::FixPredicate;
use palpate::limits::MAX_CHART_TET_STEPS;
use palpate::mesh::read_mesh;
use palpate::output::atomic::{self, FolderKind, SeriesDir, write_file};
use palpate::output::stderr;

use super::args::{MaterialArgs, parse_fix};
use super::stdout;

/// `palpate chart` arguments.
#[derive(Args)]
pub struct ChartArgs {
    /// The reduced matrix (two meshes, press and bend at 1 % and 5 %, a
    /// small stability grid, the small volume cylinder): under a minute.
    #[arg(long)]
    quick: bool,
    /// Output folder: created, or replaced as a whole if a previous run
    /// wrote it (anything else is refused).
    #[arg(long, default_value = "chart-out")]
    out: PathBuf,
    /// Count the haptic tick's instructions under callgrind in `--quick`
    /// too (the full run always does, when valgrind is installed).
    #[arg(long)]
    tick_counts: bool,
    /// Print the study as one JSON object instead of the summary.
    #[arg(long)]
    json: bool,
    /// Run the matrix on this mesh (m; any format the mesh readers take) at
    /// its own resolution, instead of the cylinder's refinements.
    #[arg(long, requires_all = ["young", "poisson", "fix"])]
    mesh: Option<PathBuf>,
    /// Young's modulus of `--mesh`, Pa.
    #[arg(long, requires = "mesh", allow_negative_numbers = true)]
    young: Option<f64>,
    /// Poisson ratio of `--mesh`, in [0, 0.4999].
    #[arg(long, requires = "mesh", allow_negative_numbers = true)]
    poisson: Option<f64>,
    /// Fixed vertices of `--mesh`: x|y|z then <, <=, > or >= then a number in mesh units (repeatable).
    #[arg(long = "fix", requires = "mesh", value_parser = parse_fix, allow_hyphen_values = true)]
    fix: Vec<FixPredicate>,
    /// Loaded vertices of `--mesh`, same syntax (repeatable; default: the
    /// face farthest from the supports).
    #[arg(long = "load-on", requires = "mesh", value_parser = parse_fix, allow_hyphen_values = true)]
    load_on: Vec<FixPredicate>,
    /// Internal: run the haptic ticks of this trajectory on this table of
    /// MODEL's scene (`chart::ticks::tick_scene`) with POINTS probes, REMAP
    /// the quasi-non-linear remap or `linear` (the process callgrind
    /// measures).
    #[arg(long, hide = true, num_args = 5, value_names = ["MODEL", "TABLE", "TRAJECTORY", "POINTS", "REMAP"])]
    tick_probe: Option<Vec<String>>,
}

impl ChartArgs {
    /// The user's mesh of `--mesh`, if given.
    fn given(&self) -> anyhow::Result<Option<GivenMesh>> {
        let Some(path) = &self.mesh else {
            return Ok(None);
        };
        let (mesh, report) = read_mesh(path)?;
        let material = MaterialArgs {
            young: self.young.context("--young")?,
            poisson: self.poisson.context("--poisson")?,
        }
        .material()?;
        Ok(Some(GivenMesh {
            label: path.file_name().map_or_else(
                || path.display().to_string(),
                |f| f.to_string_lossy().into(),
            ),
            mesh,
            report,
            fix: self.fix.clone(),
            load_on: self.load_on.clone(),
            material,
        }))
    }
}

/// Runs `palpate chart`.
pub fn run(args: &ChartArgs) -> anyhow::Result<()> {
    if let Some([model, table, trajectory, points, remap]) = args.tick_probe.as_deref() {
        let points: usize = points.parse().context("--tick-probe POINTS")?;
        return ticks::probe_child(model, table.as_ref(), trajectory.as_ref(), points, remap);
    }
    let matrix = if args.quick {
        Matrix::quick()
    } else {
        Matrix::full()
    };
    // The folder: one a previous run wrote (or new), checked before any
    // work; the files go to a hidden sibling put in place when complete.
    if let Some(mesh) = &args.mesh {
        atomic::refuse_inside(("--out", &args.out), &[("--mesh", mesh)])?;
    }
    let folder = SeriesDir::of_kind(&args.out, FolderKind::Chart)?;
    let dir = folder.dir();
    let mut matrix = match args.given()? {
        Some(given) => matrix.on(given),
        None => matrix,
    };
    matrix.tick_counts |= args.tick_counts;
    // Picinbono's table 2 is the cylinder's experiment: not run on a given mesh.
    let protocols: &[Protocol] = if matrix.given.is_some() {
        &[]
    } else {
        &[Protocol::PaperLoads, Protocol::Tilt]
    };
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
    let trials = chart::stability::map_count() * matrix.stability.trials();
    // The tick counts need valgrind: without it, skipped (said in the report).
    let tick_runs = if matrix.tick_counts && ticks::valgrind_available() {
        ticks::TICK_RUNS
    } else {
        0
    };
    let total = matrix.static_runs() + trials + matrix.trajectories() + protocols.len() + tick_runs;
    stderr::line(&format!(
        "chart: {} meshes × {} loads × {} levels × {} models = {} static runs (+ {} Newton \
         references), {} stability trials, {} trajectories (each against its Δt/{}), {} volume \
         experiments, {tick_runs} callgrind runs: {total} steps of progress",
        matrix.mesh_count(),
        matrix.loads.len(),
        matrix.levels.len(),
        chart::Model::ALL.len(),
        matrix.static_runs() - matrix.loads.len() * matrix.levels.len(),
        matrix.loads.len() * matrix.levels.len(),
        trials,
        matrix.trajectories(),
        chart::trajectory::REFINEMENT,
        protocols.len(),
    ));
    // The work bound, checked before anything runs, and its time here.
    let bodies = matrix.bodies()?;
    chart::preflight(&bodies, &args.out)?;
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
    stderr::line(&format!(
        "chart: at most {bound:.2e} tet-steps (every relaxation at its {}-step cap; limit \
         {MAX_CHART_TET_STEPS:.0e}), at most {:.0} s at {:.0} ns per tet-step measured here \
         (St Venant-Kirchhoff + penalty on {}), plus the Newton references and the timing; \
         the relaxations settle far below their cap",
        matrix.max_relax_steps,
        bound as f64 * per_tet_step_s,
        1e9 * per_tet_step_s,
        finest.label,
    ));
    let bar = stderr::progress_bar(
        total as u64,
        "chart {bar:40} {pos}/{len} ({eta}) {msg}",
        true,
    );
    // Without a terminal (CI, a redirected run) the bar is hidden: one line
    // per step instead, with the time since the start.
    let lines = bar.is_hidden();
    let start = std::time::Instant::now();
    let mut tick = |message: &str| {
        bar.inc(1);
        if lines {
            stderr::line(&format!(
                "chart {}/{total} {:7.1} s {message}",
                bar.position(),
                start.elapsed().as_secs_f64()
            ));
        } else {
            bar.set_message(message.to_string());
        }
    };
    let mut study = chart::run(&matrix, &mut tick)?;
    study.ticks = if !matrix.tick_counts {
        ticks::TickCounts::Skipped {
            reason: format!(
                "--quick ({} callgrind runs; `--tick-counts` measures them)",
                ticks::TICK_RUNS
            ),
        }
    } else {
        let exe = std::env::current_exe()?;
        let child = |a: &ticks::ChildArgs<'_>| {
            vec![
                "chart".into(),
                "--tick-probe".into(),
                a.model.name().into(),
                a.table.display().to_string(),
                a.trajectory.display().to_string(),
                a.points.to_string(),
                a.remap.into(),
            ]
        };
        let quasi = study.remap.kernel::<f64>()?;
        ticks::measure_ticks(&exe, child, &dir.join("ticks"), &quasi, &mut tick)?
    };
    let mut volume = Vec::new();
    for &protocol in protocols {
        volume.push(volume_bend::run_scene(&scene, protocol, &controls, |_| {})?);
        tick(&format!("volume {protocol:?}"));
    }
    bar.finish_and_clear();

    let charts = plot::draw_all(&study, &volume, dir, &matrix.loads, &matrix.levels)?;
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
    write_file(&dir.join("report.md"), markdown.as_bytes())?;
    write_file(
        &dir.join("index.html"),
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
    write_file(&dir.join("study.json"), json.to_string().as_bytes())?;
    folder.commit()?;
    if args.json {
        stdout::println(&json.to_string())?;
    } else {
        stdout::print(&markdown)?;
    }
    Ok(())
}
