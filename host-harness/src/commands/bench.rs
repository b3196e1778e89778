//! `palpate bench`: the timings of the models on the user's own mesh, in one
//! process (`palpate::bench`): the criterion benches are the reference
//! figures, this is for a mesh of one's own.

use std::path::PathBuf;

use palpate::bench::measure::Sampling;
use palpate::bench::run::{BenchModel, BenchOptions, Record, check, run};
use palpate::dispatch::HostDispatch;
use palpate::mesh::read_mesh;
use palpate::output::stderr;
use palpate::table::estimate::SizeLimits;
use palpate::table::file::Precision;

use super::args::{FixArgs, MaterialArgs};
use super::dynamic::IntegratorArg;
use super::stdout;

/// `palpate bench`: time the models on a mesh.
#[derive(clap::Args)]
pub struct BenchArgs {
    /// Input mesh (.msh, .node/.ele, .vtk), metres.
    mesh: PathBuf,
    #[command(flatten)]
    material: MaterialArgs,
    /// Mass density, kg/m3.
    #[arg(long)]
    density: f64,
    #[command(flatten)]
    fix: FixArgs,
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
    /// One JSON object per measurement and line, instead of the table.
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
    let (mesh, report) = read_mesh(&args.mesh)?;
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
        material: args.material.material()?,
        density_kg_m3: args.density,
        fix: args.fix.fix.clone(),
        models: args.models.clone(),
        integrators: args.integrators.iter().map(|&i| i.into()).collect(),
        precisions: match args.precision {
            PrecisionChoice::F32 => vec![Precision::F32],
            PrecisionChoice::F64 => vec![Precision::F64],
            PrecisionChoice::Both => vec![Precision::F32, Precision::F64],
        },
        dispatches,
        sampling: Sampling {
            warmup: args.warmup,
            samples: args.samples,
            sample_s: args.sample_ms / 1e3,
        },
    };
    let name = args.mesh.display().to_string();
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
