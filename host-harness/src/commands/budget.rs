//! `palpate budget`: per-tick instruction counts (callgrind) of every
//! generated trajectory on a scene's mesh, against the static bound of
//! [`palpate::budget`]; `--probe` is the child process callgrind measures.

use core::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use palpate::budget::{
    BudgetRow, HOST_IR, M4F_IPS, budget_table, chosen_trajectories, measure, probe, record,
};
use palpate::output::atomic::work_folder;
use palpate::scene::{MAX_TOOL_POINTS, ToolKind, ToolSpec};
use palpate::scene::{MeshSource, Scene, Trajectory};
use palpate::session::model::{SceneModel, SceneTables};
use palpate::session::options::check_scene_table;
use palpate::session::stability::check_stable_step;
use palpate::table::compress::{BlockCode, Compression, ContactBlocks};

use super::stdout;

/// `palpate budget`'s arguments.
#[derive(clap::Args)]
pub struct BudgetArgs {
    /// Scene file (TOML), `built-in`, `built-in-dynamic`, `built-in-tools` or
    /// `built-in-hybrid`.
    scene: String,
    /// Working folder for tables, trajectories and callgrind dumps.
    #[arg(long, default_value = "budget-out")]
    work_dir: PathBuf,
    /// Print one JSON array instead of the table.
    #[arg(long)]
    json: bool,
    /// Measure only this generated trajectory (repeatable; default: every
    /// one the scene's tool can run).
    #[arg(long = "trajectory", value_name = "NAME")]
    only: Vec<String>,
    /// Run the scene with this many probes (1..=4), each on its own site
    /// of the built-in block's top, instead of its tool (a scene of probes
    /// only).
    #[arg(long, value_name = "N")]
    points: Option<usize>,
    /// Measure nothing: write the scene's tables, each generated
    /// trajectory's ticks (`--trajectory`: those only) and the host's output
    /// of each tick into the folder DIR, for the Cortex-M4F cycle count
    /// (`tools/cycles-check.sh`; the scene's own mesh only).
    #[arg(long, value_name = "DIR", conflicts_with_all = ["json", "probe"])]
    record: Option<PathBuf>,
    /// With --record: the pre-computed scene's table compressed with this
    /// code (`tables build --compress`, nothing dropped, the contact blocks
    /// coded), for the cycle count of the compressed decode.
    #[arg(long, value_name = "CODE", requires = "record")]
    compress: Option<BlockCode>,
    /// Internal: run the ticks of this trajectory on this table, built for
    /// the scene's mesh size SIZE (0 the coarse box, or the scene's own)
    /// (the process callgrind measures).
    #[arg(long, hide = true, num_args = 3, value_names = ["TABLE", "TRAJECTORY", "SIZE"])]
    probe: Option<Vec<PathBuf>>,
}

/// `palpate budget`: measure every generated trajectory on the scene's mesh
/// (and, for a generated box, at half its resolution) under callgrind.
///
/// Stages: `--record` ([`record_ticks`]) or `--probe` ([`run_probe`])
/// instead of a measure; else every size measured ([`measure_sizes`]), the
/// rows printed ([`print_rows`]), and a count above its bound an error.
pub fn run(args: &BudgetArgs) -> anyhow::Result<()> {
    let BudgetArgs {
        scene: scene_arg,
        work_dir,
        json,
        only,
        points,
        record: record_dir,
        compress,
        probe: probe_paths,
    } = args;
    let mut scene = Scene::named(scene_arg)?;
    if let Some(points) = *points {
        with_probes(&mut scene, points)?;
    }
    if let Some(dir) = record_dir {
        return record_ticks(&scene, dir, only, *compress);
    }
    let sizes = mesh_sizes(&scene);
    if let Some([table_path, trajectory_path, size]) = probe_paths.as_deref() {
        return run_probe(&mut scene, &sizes, table_path, trajectory_path, size);
    }
    let rows = measure_sizes(&mut scene, scene_arg, work_dir, only, sizes)?;
    if *json {
        stdout::println(&serde_json::to_string(&rows)?)?;
        return Ok(());
    }
    print_rows(&rows)?;
    if let Some(r) = rows.iter().find(|r| r.max_ir > r.bound_ir) {
        bail!(
            "{} on {}: {} instructions exceed the bound {}",
            r.trajectory,
            r.mesh,
            r.max_ir,
            r.bound_ir
        );
    }
    Ok(())
}

/// `--record DIR`: writes the scene's tables (compressed with `compress`,
/// nothing dropped, the contact blocks coded), the ticks of the `only`
/// trajectories (all without) and the host's output of each tick into
/// `dir`, and prints what it recorded.
fn record_ticks(
    scene: &Scene,
    dir: &Path,
    only: &[String],
    compress: Option<BlockCode>,
) -> anyhow::Result<()> {
    let compression = compress.map(|code| Compression {
        code,
        drop_below: 0.0,
        contact: ContactBlocks::Coded,
        tolerance: palpate::table::hmatrix::DEFAULT_TOLERANCE,
    });
    let runs = record(scene, dir, only, compression)?;
    let mut text = format!("recorded in {}:\n", dir.display());
    for run in runs {
        let _ = writeln!(text, "  {run}");
    }
    stdout::print(&text)?;
    Ok(())
}

/// `--probe TABLE TRAJECTORY SIZE`, the process callgrind measures: the
/// ticks of the trajectory on the table built for mesh `sizes[SIZE]`, each
/// tick's work (triangles tested, walk steps, solves) written beside the
/// trajectory (`.work`).
fn run_probe(
    scene: &mut Scene,
    sizes: &[MeshSource],
    table_path: &Path,
    trajectory_path: &Path,
    size: &Path,
) -> anyhow::Result<()> {
    // The model of the mesh the parent built these tables for.
    let size: usize = size.to_string_lossy().parse().context("--probe SIZE")?;
    scene.mesh = sizes
        .get(size)
        .context("--probe SIZE out of range")?
        .clone();
    let (mesh, report) = scene.load_mesh()?;
    let model = SceneModel::of(scene, &mesh, &report)?;
    let tables = SceneTables::read(model, table_path)?;
    let trajectory = Trajectory::read(trajectory_path, scene.tool.points)?;
    let counters = probe(&tables, scene, &trajectory)
        .with_context(|| table_path.display().to_string())?
        .counters;
    let lines: Vec<String> = counters
        .iter()
        .map(|c| {
            format!(
                "{},{},{}",
                c.contact.triangles_tested, c.contact.walk_steps, c.solves
            )
        })
        .collect();
    std::fs::write(trajectory_path.with_extension("work"), lines.join("\n"))?;
    Ok(())
}

/// Every chosen trajectory (`only`, all without) on each of `sizes` under
/// callgrind, in `work_dir`: every size's table checked against the build
/// limits first, then per size its table built, and per trajectory a
/// `--probe` child of `scene_arg` measured and its ticks' work read back.
fn measure_sizes(
    scene: &mut Scene,
    scene_arg: &str,
    work_dir: &Path,
    only: &[String],
    sizes: Vec<MeshSource>,
) -> anyhow::Result<Vec<BudgetRow>> {
    work_folder("--work-dir", work_dir)?;
    let exe = std::env::current_exe()?;
    let chosen = chosen_trajectories(scene, only)?;
    // Every size's table is checked against the build limits before the
    // first is built (the coarse one can take a while).
    for source in &sizes {
        let mut sized = scene.clone();
        sized.mesh = source.clone();
        let (mesh, report) = sized.load_mesh()?;
        check_scene_table(&sized, &mesh, &report)?;
        check_stable_step(&sized, &mesh, &report)?;
    }
    let mut rows: Vec<BudgetRow> = Vec::new();
    for (s, source) in sizes.into_iter().enumerate() {
        scene.mesh = source;
        let (mesh, report) = scene.load_mesh()?;
        let (tables, bound) = budget_table(scene, &mesh, &report, &HOST_IR, None)?;
        let table_path = work_dir.join(format!("table-{s}.bin"));
        tables.write(&table_path)?;
        for (name, trajectory) in &chosen {
            let csv = work_dir.join(format!("{name}-{s}.csv"));
            trajectory.write_csv_file(&csv)?;
            let probe_args: Vec<String> = vec![
                "budget".into(),
                scene_arg.into(),
                "--probe".into(),
                table_path.display().to_string(),
                csv.display().to_string(),
                s.to_string(),
            ];
            let irs = measure(&exe, &probe_args, &work_dir.join(format!("cg-{name}-{s}")))?;
            let work = std::fs::read_to_string(csv.with_extension("work"))?;
            // The probe writes one work line per tick it ran.
            anyhow::ensure!(
                irs.len() == work.lines().count(),
                "{name}: callgrind counted {} ticks, the probe ran {}",
                irs.len(),
                work.lines().count()
            );
            let mut max_work = [0u32; 3];
            for line in work.lines() {
                for (m, v) in max_work.iter_mut().zip(line.split(',')) {
                    *m = (*m).max(v.parse().unwrap_or(0));
                }
            }
            let max_ir = irs.iter().copied().max().unwrap_or(0);
            let total_ir = irs.iter().sum::<u64>();
            let mean_ir = total_ir as f64 / irs.len().max(1) as f64;
            // The host's time per instruction in the ticks, run natively.
            let native = probe(&tables, scene, trajectory)?;
            let host_ns_per_ir = native.ticks_s * 1e9 / total_ir.max(1) as f64;
            rows.push(BudgetRow {
                mesh: format!(
                    "{} vertices, {} tets",
                    mesh.positions.len(),
                    mesh.tets.len()
                ),
                trajectory: name,
                ticks: irs.len(),
                max_ir,
                mean_ir,
                bound_ir: bound,
                bound_host_us: bound as f64 * host_ns_per_ir / 1e3,
                max_work,
            });
        }
    }
    Ok(rows)
}

/// Prints the measured rows as a table, one line a trajectory and size.
fn print_rows(rows: &[BudgetRow]) -> anyhow::Result<()> {
    let mut text = format!(
        "{:<26} {:<11} {:>6} {:>9} {:>9} {:>9} {:>6} {:>11} {:>11} {:>12}",
        "mesh",
        "trajectory",
        "ticks",
        "mean Ir",
        "max Ir",
        "bound Ir",
        "max/b",
        "bound@168M",
        "bound@host",
        "tests/walk/solves"
    );
    text.push('\n');
    for r in rows {
        let _ = writeln!(
            text,
            "{:<26} {:<11} {:>6} {:>9.0} {:>9} {:>9} {:>6.3} {:>8.1} µs {:>8.2} µs {:>5}/{}/{}",
            r.mesh,
            r.trajectory,
            r.ticks,
            r.mean_ir,
            r.max_ir,
            r.bound_ir,
            r.max_ir as f64 / r.bound_ir as f64,
            r.bound_ir as f64 / M4F_IPS * 1e6,
            r.bound_host_us,
            r.max_work[0],
            r.max_work[1],
            r.max_work[2]
        );
    }
    stdout::print(&text)?;
    Ok(())
}

/// Gives `scene` `points` probes of its radius (`--points`): a scene of
/// probes only, `points` in `1..=MAX_TOOL_POINTS`.
fn with_probes(scene: &mut Scene, points: usize) -> anyhow::Result<()> {
    if !(1..=MAX_TOOL_POINTS).contains(&points) {
        bail!("--points {points}: expected 1..={MAX_TOOL_POINTS}");
    }
    if let Some(kind) = scene.tool.kinds.iter().find(|k| **k != ToolKind::Probe) {
        bail!(
            "--points: {} has a {}; only a scene of probes takes --points",
            scene.source,
            kind.name()
        );
    }
    scene.tool = ToolSpec::probes(points, scene.tool.radius_m);
    Ok(())
}

/// The meshes a budget measures: a generated box at half its resolution
/// first, then the scene's own mesh.
fn mesh_sizes(scene: &Scene) -> Vec<MeshSource> {
    let mut sizes = vec![scene.mesh.clone()];
    if let MeshSource::GeneratedBox { size_m, cells } = &scene.mesh {
        let coarse = cells.map(|c| (c / 2).max(1));
        sizes.insert(
            0,
            MeshSource::GeneratedBox {
                size_m: *size_m,
                cells: coarse,
            },
        );
    }
    sizes
}
