//! `palpate chart`: the speed/accuracy study ([`palpate::chart`]): runs the
//! matrix with a progress bar, writes the charts, `report.md`,
//! `index.html`, `study.json` and `memory.json` into `--out` (built in a hidden sibling
//! folder and renamed into place whole: `palpate::output::atomic`'s
//! `SeriesDir`, which refuses a folder palpate did not write), prints the
//! summary (or the JSON).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use clap::Args;
use indicatif::ProgressBar;
use palpate::chart::series::Against;
use palpate::chart::{self, GivenMesh, Matrix, Progress as _, plot, report, ticks};
use palpate::experiment::scenes;
use palpate::experiment::volume_bend::{self, Protocol, SceneResult};
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
    /// small stability grid, the small volume cylinder, the memory chart on
    /// two small boxes): under a minute.
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
    /// Young's modulus, Pa: of `--mesh` (required with it), or of the
    /// cylinders (default 5000).
    #[arg(long, allow_negative_numbers = true)]
    young: Option<f64>,
    /// Poisson ratio, in [0, 0.4999]: of `--mesh` (required with it), or of
    /// the cylinders (default 0.4; the neo-Hookean truth's study is run at
    /// 0.45 and 0.49).
    #[arg(long, allow_negative_numbers = true)]
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
        None => Matrix {
            material: MaterialArgs {
                young: args.young.unwrap_or(matrix.material.young_pa),
                poisson: args.poisson.unwrap_or(matrix.material.poisson),
            }
            .material()?,
            ..matrix
        },
    };
    matrix.tick_counts |= args.tick_counts;
    let volume_runs = VolumeRuns::of(&matrix, args.quick);
    let total = announce(&matrix, volume_runs.protocols.len());
    check_bound(&matrix, &args.out, &volume_runs)?;
    let mut progress = Bar::new(total);
    let mut study = chart::run(&matrix, &mut progress)?;
    study.ticks = tick_counts(&matrix, &study, dir, &mut progress)?;
    let volume = volume_runs.run(&mut progress)?;
    progress.bar.finish_and_clear();

    let (json, markdown) = write_outputs(&matrix, &study, &volume, dir)?;
    folder.commit()?;
    if args.json {
        stdout::println(&json.to_string())?;
    } else {
        stdout::print(&markdown)?;
    }
    Ok(())
}

/// The study's volume experiments: Picinbono's table 2 on the bent
/// cylinder (the small one in `--quick`), its relaxations capped as the
/// study's; none on a given mesh (table 2 is the cylinder's experiment).
struct VolumeRuns {
    protocols: &'static [Protocol],
    scene: volume_bend::Scene,
    controls: volume_bend::Controls,
}

impl VolumeRuns {
    /// The experiments of `matrix` (`quick`: the small cylinder).
    fn of(matrix: &Matrix, quick: bool) -> Self {
        let protocols: &[Protocol] = if matrix.given.is_some() {
            &[]
        } else {
            &[Protocol::PaperLoads, Protocol::Tilt]
        };
        let scene = if quick {
            scenes::cylinder(2, 8)
        } else {
            scenes::default_cylinder()
        };
        let controls = volume_bend::Controls {
            max_steps: matrix.max_relax_steps,
            ..volume_bend::Controls::default()
        };
        Self {
            protocols,
            scene,
            controls,
        }
    }

    /// Upper bound on their tet-steps: every relaxation at its step cap.
    fn tet_step_bound(&self) -> u64 {
        let relaxations: usize = self
            .protocols
            .iter()
            .map(|&p| volume_bend::relaxations_bound(&self.scene, p, &self.controls))
            .sum();
        (relaxations * self.controls.max_steps * self.scene.mesh.tets.len()) as u64
    }

    /// Runs them, one step of `progress` each.
    fn run(&self, progress: &mut Bar) -> anyhow::Result<Vec<SceneResult>> {
        let mut volume = Vec::new();
        for &protocol in self.protocols {
            volume.push(volume_bend::run_scene(
                &self.scene,
                protocol,
                &self.controls,
                |_| {},
            )?);
            progress.tick(&format!("volume {protocol:?}"));
        }
        Ok(volume)
    }
}

/// Prints the study's extent on standard error and returns its steps of
/// progress: the static runs, the stability trials, the trajectories, the
/// `volume_experiments` and the callgrind runs (none without valgrind:
/// the tick counts are then skipped, said in the report).
fn announce(matrix: &Matrix, volume_experiments: usize) -> usize {
    let trials = chart::stability::map_count() * matrix.stability.trials();
    let tick_runs = if matrix.tick_counts && ticks::valgrind_available() {
        ticks::TICK_RUNS
    } else {
        0
    };
    let total = matrix.static_runs()
        + trials
        + matrix.trajectories()
        + matrix.memory_tables()
        + volume_experiments
        + tick_runs;
    stderr::line(&format!(
        "chart: {} meshes × {} loads × {} levels × {} models = {} static runs (+ {} Newton \
         references and as many neo-Hookean truths of {} levels), {} stability trials, {} \
         trajectories (each against its Δt/{}), {} memory-chart tables, {} volume experiments, \
         {tick_runs} callgrind runs: {total} steps of progress",
        matrix.mesh_count(),
        matrix.loads.len(),
        matrix.levels.len(),
        chart::Model::ALL.len(),
        matrix.static_runs() - 2 * matrix.loads.len() * matrix.levels.len(),
        matrix.loads.len() * matrix.levels.len(),
        matrix.truth.len(),
        trials,
        matrix.trajectories(),
        chart::trajectory::REFINEMENT,
        matrix.memory_tables(),
        volume_experiments,
    ));
    total
}

/// The study's checks before anything runs: its preflight
/// ([`chart::preflight`] of `out` and the bodies) and its work bound (the
/// matrix's and the volume experiments') against [`MAX_CHART_TET_STEPS`],
/// the bound's time at the tet-step measured here printed on standard
/// error.
fn check_bound(matrix: &Matrix, out: &Path, volume_runs: &VolumeRuns) -> anyhow::Result<()> {
    let bodies = matrix.bodies()?;
    chart::preflight(&bodies, out)?;
    let bound = matrix.tet_step_bound(&bodies)? + volume_runs.tet_step_bound();
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
    Ok(())
}

/// The study's progress on standard error: a bar on a terminal; without
/// one (CI, a redirected run) the bar is hidden and each step is one line
/// with the time since the start.
struct Bar {
    bar: ProgressBar,
    lines: bool,
    start: Instant,
    total: usize,
}

impl Bar {
    /// A bar of `total` steps, its clock started.
    fn new(total: usize) -> Self {
        let bar = stderr::progress_bar(
            total as u64,
            "chart {bar:40} {pos}/{len} ({eta}) {msg}",
            true,
        );
        let lines = bar.is_hidden();
        Self {
            bar,
            lines,
            start: Instant::now(),
            total,
        }
    }
}

impl chart::Progress for Bar {
    fn tick(&mut self, message: &str) {
        self.bar.inc(1);
        if self.lines {
            stderr::line(&format!(
                "chart {}/{} {:7.1} s {message}",
                self.bar.position(),
                self.total,
                self.start.elapsed().as_secs_f64()
            ));
        } else {
            self.bar.set_message(message.to_string());
        }
    }
}

/// The haptic tick's instruction counts of the study's pre-computed models
/// ([`ticks::measure_ticks`]: child processes of this executable under
/// callgrind, in `dir/ticks`), or why they were not measured.
fn tick_counts(
    matrix: &Matrix,
    study: &chart::Study,
    dir: &Path,
    progress: &mut Bar,
) -> anyhow::Result<ticks::TickCounts> {
    if !matrix.tick_counts {
        return Ok(ticks::TickCounts::Skipped {
            reason: format!(
                "--quick ({} callgrind runs; `--tick-counts` measures them)",
                ticks::TICK_RUNS
            ),
        });
    }
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
    ticks::measure_ticks(&exe, child, &dir.join("ticks"), &quasi, progress)
}

/// Writes the charts, `report.md`, `index.html`, `study.json` (the
/// [`summary`], the study, the volume experiments and the charts' names)
/// and `memory.json` (the memory chart's tables, `study.memory`: an array
/// of `chart::memory::MemoryPoint`) into `dir`; returns the JSON and the
/// report.
fn write_outputs(
    matrix: &Matrix,
    study: &chart::Study,
    volume: &[SceneResult],
    dir: &Path,
) -> anyhow::Result<(serde_json::Value, String)> {
    let charts = plot::draw_all(study, volume, dir, &matrix.loads, &matrix.levels)?;
    let volume_table: String = volume
        .iter()
        .map(|r| volume_bend::table(core::slice::from_ref(r)))
        .collect::<Vec<_>>()
        .join("\n");
    let markdown = report::markdown(study, &matrix.loads, &matrix.levels, &charts, &volume_table);
    write_file(&dir.join("report.md"), markdown.as_bytes())?;
    write_file(
        &dir.join("index.html"),
        report::html(&markdown, &charts).as_bytes(),
    )?;
    let json = serde_json::json!({
        "summary": summary(matrix, study),
        "study": study,
        "volume": volume,
        "charts": charts,
    });
    write_file(&dir.join("study.json"), json.to_string().as_bytes())?;
    write_file(
        &dir.join("memory.json"),
        serde_json::to_string(&study.memory)?.as_bytes(),
    )?;
    Ok((json, markdown))
}

/// `study.json`'s summary: per load and level (`press-5`), the Pareto
/// front's members and the cheapest model within each of
/// [`report::BOUNDS`] (keyed by the bound in percent) against the
/// neo-Hookean truth (empty and `null` where it did not converge), the
/// truth's verdict (`truth`: `converged` or `no converged truth: …`), and
/// the same selections against the St Venant-Kirchhoff reference (`stvk`).
fn summary(matrix: &Matrix, study: &chart::Study) -> serde_json::Map<String, serde_json::Value> {
    let selections = |load, level, against| {
        let within: serde_json::Map<String, serde_json::Value> = report::BOUNDS
            .iter()
            .map(|&b| {
                (
                    format!("{:.0}", 100.0 * b),
                    report::cheapest(study, load, level, b, against).into(),
                )
            })
            .collect();
        serde_json::json!({
            "pareto": report::pareto_members(study, load, level, against),
            "cheapest_within_percent": within,
        })
    };
    let mut summary = serde_json::Map::new();
    for &load in &matrix.loads {
        for &level in &matrix.levels {
            let key = format!("{}-{:.0}", load.name(), 100.0 * level);
            let mut entry = selections(load, level, Against::Truth);
            let verdict = study
                .truths
                .iter()
                .find(|t| t.load == load && t.level == level)
                .map(chart::truth::Truth::verdict);
            entry["truth"] = verdict.into();
            entry["stvk"] = selections(load, level, Against::Stvk);
            summary.insert(key, entry);
        }
    }
    summary
}
