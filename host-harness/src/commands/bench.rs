//! `palpate bench`: the timings of the models on the user's own mesh, in one
//! process (`palpate::bench`): the criterion benches are the reference
//! figures, this is for a mesh of one's own.

use std::path::PathBuf;

use palpate::bench::measure::Sampling;
use palpate::bench::run::{BenchModel, BenchOptions, Record, check, run};
use palpate::bench::scene::{SceneBenchOptions, bench_scene, check_scene_bench};
use palpate::dispatch::HostDispatch;
use palpate::mesh::read_mesh;
use palpate::output::stderr;
use palpate::scene::Scene;
use palpate::table::estimate::SizeLimits;
use palpate::table::file::Precision;

use super::args::{FixArgs, MassMaterialArgs, ThreadsArgs};
use super::dynamic::IntegratorArg;
use super::stdout;

/// `palpate bench`: time the models on a mesh, or a scene's own model
/// (`--scene`).
#[derive(clap::Args)]
#[command(mut_arg("fix", |a| a.required(false).required_unless_present("scene")))]
pub struct BenchArgs {
    /// Input mesh (.msh, .node/.ele, .vtk), metres.
    #[arg(required_unless_present = "scene")]
    mesh: Option<PathBuf>,
    /// A scene (file, or a built-in name) in place of the mesh and its
    /// options: its own model timed stage by stage (physics update,
    /// interface update of a hybrid, haptic tick with 1-4 tool points)
    /// against each stage's real-time period. Takes --samples, --warmup,
    /// --sample-ms, --threads and --json only.
    #[arg(long, conflicts_with_all = [
        "mesh", "young", "poisson", "density", "fix", "models", "integrators", "precision",
        "dispatch",
    ])]
    scene: Option<String>,
    #[command(flatten)]
    material: MassMaterialArgs,
    #[command(flatten)]
    fix: FixArgs,
    #[command(flatten)]
    threads: ThreadsArgs,
    /// Models to time (comma-separated; default all).
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = BenchModel::ALL)]
    models: Vec<BenchModel>,
    /// Integrators of the tensor-mass steps (comma-separated; default all).
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = IntegratorArg::ALL)]
    integrators: Vec<IntegratorArg>,
    /// Precision of the tables and the arithmetic.
    #[arg(long, value_enum, default_value = "both")]
    precision: PrecisionChoice,
    /// Where the dispatched passes (steps, displacement update) run: the
    /// best this CPU has (`auto`), the build's baseline (`portable`), both
    /// in turn (`both`), or every level this CPU has (`all`: portable,
    /// AVX2 + FMA, AVX-512).
    #[arg(long, value_enum, default_value = "auto")]
    dispatch: DispatchChoice,
    /// Samples kept per measurement.
    #[arg(long, default_value_t = Sampling::default().samples)]
    samples: usize,
    /// Samples run and discarded first.
    #[arg(long, default_value_t = Sampling::default().warmup)]
    warmup: usize,
    /// Target duration of one sample (a batch of calls), ms.
    #[arg(long, default_value_t = Sampling::default().sample_s * 1e3)]
    sample_ms: f64,
    /// One JSON object per measurement and line, instead of the table
    /// (with --scene: one JSON object for the run).
    #[arg(long)]
    json: bool,
}

/// `--precision` of `bench`.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum PrecisionChoice {
    F32,
    F64,
    Both,
}

/// `--dispatch` of `bench`.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum DispatchChoice {
    Auto,
    Portable,
    Both,
    All,
}

/// Runs `palpate bench`.
pub fn run_bench(args: &BenchArgs) -> anyhow::Result<()> {
    let sampling = Sampling {
        warmup: args.warmup,
        samples: args.samples,
        sample_s: args.sample_ms / 1e3,
    };
    let (Some(path), Some(material)) = (&args.mesh, args.material.given()) else {
        let scene = Scene::named(args.scene.as_deref().unwrap_or_default())?;
        return run_scene_bench(&scene, sampling, args.threads.count(), args.json);
    };
    let (material, density) = material?;
    let (mesh, report) = read_mesh(path)?;
    for w in &report.warnings {
        stderr::line(&format!("warning: {w}"));
    }
    let detected = HostDispatch::detect();
    let dispatches = match args.dispatch {
        DispatchChoice::Auto => vec![detected],
        DispatchChoice::Portable => vec![HostDispatch::Portable],
        DispatchChoice::Both if detected == HostDispatch::Portable => vec![detected],
        DispatchChoice::Both => vec![HostDispatch::Portable, detected],
        DispatchChoice::All => HostDispatch::available(),
    };
    let options = BenchOptions {
        material,
        density_kg_m3: density,
        fix: args.fix.fix.clone(),
        models: args.models.clone(),
        integrators: args.integrators.iter().map(|&i| i.into()).collect(),
        precisions: match args.precision {
            PrecisionChoice::F32 => vec![Precision::F32],
            PrecisionChoice::F64 => vec![Precision::F64],
            PrecisionChoice::Both => vec![Precision::F32, Precision::F64],
        },
        dispatches,
        sampling,
    };
    let name = path.display().to_string();
    let estimate = check(&mesh, &options)?;
    stderr::line(&format!(
        "bench {name}: {} vertices, {} tets; {} measurements, estimated {:.0} s \
         (at most {} s); this CPU runs the dispatched passes as {}",
        mesh.positions.len(),
        mesh.tets.len(),
        estimate.measurements,
        estimate.seconds.ceil(),
        palpate::limits::MAX_BENCH_ESTIMATE_S,
        detected.name(),
    ));
    let bar = stderr::progress_bar(
        estimate.measurements as u64,
        "bench {bar:30} {pos}/{len} {wide_msg}",
        true,
    );
    let limits = SizeLimits {
        print_estimate: true,
        ..SizeLimits::system()
    };
    if !args.json {
        stdout::println(&format!(
            "{:<44} {:<4} {:<9} {:>10}  {:<21} {:>9} {:>10} {:>6}",
            "measurement", "prec", "dispatch", "median", "q1-q3", "bytes", "copy", "×copy"
        ))?;
    }
    let result = run(
        &mesh,
        &report,
        &name,
        &options,
        &limits,
        |label| bar.set_message(label.to_string()),
        |record| {
            bar.inc(1);
            let line = if args.json {
                serde_json::to_string(record)?
            } else {
                row(record)
            };
            bar.suspend(|| stdout::println(&line))?;
            Ok(())
        },
    );
    bar.finish_and_clear();
    result
}

/// One line of the text table.
fn row(r: &Record) -> String {
    let t = &r.timing;
    let spread = format!("{}-{}", seconds(t.q1_s), seconds(t.q3_s));
    let bytes = r.bytes_read.map_or(String::new(), |b| b.to_string());
    let copy = r.copy_median_s.map_or(String::new(), seconds);
    let ratio = r.ratio_to_copy.map_or(String::new(), |x| format!("{x:.2}"));
    let w = &r.what;
    format!(
        "{:<44} {:<4} {:<9} {:>10}  {:<21} {:>9} {:>10} {:>6}",
        w.label(),
        w.precision,
        w.dispatch,
        seconds(t.median_s),
        spread,
        bytes,
        copy,
        ratio
    )
}

/// A time for people: `123 ns`, `45.6 µs`, `7.89 ms`.
fn seconds(s: f64) -> String {
    if s < 1e-6 {
        format!("{:.0} ns", s * 1e9)
    } else if s < 1e-3 {
        format!("{:.1} µs", s * 1e6)
    } else {
        format!("{:.2} ms", s * 1e3)
    }
}

/// `palpate bench --scene`: the scene's stages (`palpate::bench::scene`),
/// as a table or one JSON object.
fn run_scene_bench(
    scene: &Scene,
    sampling: Sampling,
    threads: usize,
    json: bool,
) -> anyhow::Result<()> {
    let options = SceneBenchOptions { sampling, threads };
    let estimate_s = check_scene_bench(&options)?;
    stderr::line(&format!(
        "bench --scene {}: building its tables, then up to {} measurements, estimated {:.0} s \
         (at most {} s); tensor-mass steps on {threads} threads",
        scene.source,
        palpate::bench::scene::MAX_SCENE_STAGES,
        estimate_s.ceil(),
        palpate::limits::MAX_BENCH_ESTIMATE_S,
    ));
    let bench = bench_scene(scene, &options)?;
    if json {
        stdout::println(&serde_json::to_string(&bench)?)?;
        return Ok(());
    }
    stdout::println(&format!(
        "{} ({} model, {} vertices, {} tets, {} in the tensor-mass region, {} threads)",
        bench.scene, bench.model, bench.vertices, bench.tets, bench.dynamic_tets, bench.threads
    ))?;
    stdout::println(&format!(
        "{:<17} {:>6} {:>8} {:>10}  {:<21} {:>10} {:>10}",
        "stage", "points", "contacts", "median", "q1-q3", "period", "real-time"
    ))?;
    for s in &bench.stages {
        stdout::println(&format!(
            "{:<17} {:>6} {:>8} {:>10}  {:<21} {:>10} {:>9.2}x",
            s.stage,
            s.tool_points,
            s.contacts,
            seconds(s.median_s),
            format!("{}-{}", seconds(s.q1_s), seconds(s.q3_s)),
            seconds(s.period_s),
            s.real_time_factor
        ))?;
    }
    Ok(())
}
