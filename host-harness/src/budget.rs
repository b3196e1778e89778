//! `palpate budget`: per-tick instruction counts of the haptic loop,
//! measured with callgrind (valgrind), against a static bound computed from
//! the table's sizes and the loop's capacities.
//!
//! Measurement: the session's ticks run in a child process under
//! `valgrind --tool=callgrind`, collecting only inside [`budget_tick`] and
//! dumping after each call, so every dump is one tick's instruction count
//! (`Ir`, deterministic: the same binary and input give the same count).
//!
//! Bound (instructions): `BASE + P · (TRIANGLE · D + WALK · MAX_WALK_STEPS +
//! TRACK) + (P + 1) · SOLVE · M³`, with `D` the worst-case triangle tests
//! of one detection (`SurfaceIndex::max_detection_tests`: with the table's
//! per-cell candidate lists, which serve the scene's tool radius, 9 times
//! the longest list, the tool's cell for the test and the penetration
//! test's second pass and up to 7 more cells along the sweep; without, `3
//! · max_query_triangles`, two point queries, the sweep's and the
//! penetration test's sharing the one at the tool, and the second pass;
//! plus one `max_query_triangles` for the deep check that may follow a
//! detection that made no contact; all table-declared maxima over all grid
//! cells, computed at load), `P` tool
//! points, `M` the contact capacity and `P + 1` the most solves a tick can
//! do. The unit costs are the largest per-unit costs callgrind measured on
//! this build (x86-64, `cargo build`, the workspace's opt-level 2 for our
//! crates) on the built-in scene's trajectories, rounded up: an idle tick
//! 469 Ir, a tracked contact with its solve 2420 Ir, each edge crossed
//! 602 Ir (564 on the dynamic model's surface), each triangle tested
//! ≤ 113 Ir, the new contact and its solve
//! included (`palpate budget built-in`).
//!
//! The dynamic model's tick (between physics updates, which run outside the
//! measured function) has the bound `BASE + P · (TRIANGLE · 9T + WALK ·
//! MAX_WALK_STEPS + DYNAMIC_TRACK) + (P + 1) · DYNAMIC_SOLVE · M`: a
//! detection on the re-binned grid tests at most every triangle reference
//! twice, and the deep check that may follow it once more (`3F` references
//! for the `F` faces a cut can expose), since compression can crowd a bucket, and
//! a solve is linear in the contacts (no factorization). The tick is the
//! same with grips and blades (a held contact skips the walk; a blade cuts
//! at the physics update, outside the tick). Measured on
//! `palpate budget built-in-dynamic`: a tracked contact with its solve
//! 1192 Ir over the idle 680, an edge crossed ≤ 564 Ir, a triangle tested
//! ≤ 113 Ir; the worst tick 12 939 Ir.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, bail};
use palpate_kernel::PrecomputedTable;
use palpate_kernel::contact::Tissue;
use palpate_kernel::haptic::{
    ForceOutput, HapticLoop, PhysicsTissue, PrecomputedLoop, TickCounters, ToolInput,
};
use palpate_kernel::math::Portable;
use palpate_kernel::precomputed::{PrecomputedTissue, QuasiNonLinear};
use palpate_kernel::table::TensorMassTable;

use palpate_script::ticks::{Header, Settings, tool_words, write_tick};

use crate::mesh::{MeshReport, TetMesh};
use crate::output::atomic::{AtomicFile, work_folder};
use crate::scene::{Scene, Trajectory};
use crate::session::hybrid::HybridSetup;
use crate::session::model::{SceneModel, SceneTables};
use crate::session::options::check_scene_table;
use crate::session::run::ticks;
use crate::session::setup::{DynamicSetup, loop_config};
use crate::session::stability::check_stable_step;
use crate::session::tool_points::{ForToolPoints, with_tool_points};
use crate::table::compress::Compression;

mod bound;
mod sites;
pub use bound::{
    HOST_IR, M4F_CYCLES, M4F_CYCLES_AT_WAIT_STATES, M4F_WAIT_STATES, UnitCosts, dynamic_tick_bound,
    hybrid_tick_bound, tick_bound,
};
pub use sites::{PROBE_SITE_SPACING_M, ProbeSites, trajectories};

/// The f32 tables of `scene` on `mesh` (pre-computed, tensor-mass or
/// hybrid, by its model: [`SceneModel`]) and the static bound of its tick
/// with the unit costs `costs`.
pub fn budget_table(
    scene: &Scene,
    mesh: &TetMesh,
    report: &MeshReport,
    costs: &UnitCosts,
    compression: Option<Compression>,
) -> anyhow::Result<(SceneTables, u64)> {
    let tables = SceneModel::of(scene, mesh, report)?.tables(scene, mesh, report, compression)?;
    let bound = tables_bound(scene, &tables, costs)?;
    Ok((tables, bound))
}

/// The static bound of the tick of `scene` over its f32 `tables` with the
/// unit costs `costs`.
pub fn tables_bound(scene: &Scene, tables: &SceneTables, costs: &UnitCosts) -> anyhow::Result<u64> {
    let points = scene.tool.kernel_points() as u64;
    let load = |e| anyhow::anyhow!("table: {e}");
    Ok(match tables {
        SceneTables::Precomputed(file) => {
            let table = PrecomputedTable::<f32>::load(file.bytes()).map_err(load)?;
            tick_bound(costs, &table, scene.tool.radius_m, points, points)
        }
        SceneTables::Dynamic(file, _) => {
            let table = TensorMassTable::<f32>::load(file.bytes()).map_err(load)?;
            dynamic_tick_bound(costs, &table, points, points)
        }
        SceneTables::Hybrid(files, _) => {
            let precomputed =
                PrecomputedTable::<f32>::load(files.precomputed.bytes()).map_err(load)?;
            let dynamic = TensorMassTable::<f32>::load(files.dynamic.bytes()).map_err(load)?;
            hybrid_tick_bound(costs, &precomputed, &dynamic, points, points)
        }
    })
}

/// One tick, kept out of line so callgrind can collect exactly its cost
/// (a dynamic model's physics updates run outside it).
#[inline(never)]
pub fn budget_tick<B: Tissue<f32, P>, const P: usize>(
    haptic: &mut HapticLoop<f32, B, P, P>,
    tools: &[ToolInput<f32>; P],
) -> ForceOutput<f32> {
    haptic.tick_tools(tools)
}

/// Runs every tick of `trajectory` through [`budget_tick`] on the loop of
/// `scene` over its `tables` and
/// returns each tick's work counters (the child side of [`measure`]) and
/// the wall time spent in the ticks. A dynamic scene's physics updates run
/// every `physics_every` ticks, after the tick and outside [`budget_tick`].
pub fn probe(
    tables: &SceneTables,
    scene: &Scene,
    trajectory: &Trajectory,
) -> anyhow::Result<Probe> {
    probe_remapped(tables, scene, trajectory, None)
}

/// [`probe`], the pre-computed tissue made quasi-non-linear by `remap`
/// when given (Cotin 1999 TVCG §3; `palpate chart`'s tick counts). A remap
/// on another model's tables is an error.
pub fn probe_remapped(
    tables: &SceneTables,
    scene: &Scene,
    trajectory: &Trajectory,
    remap: Option<QuasiNonLinear<f32>>,
) -> anyhow::Result<Probe> {
    with_tool_points(
        scene.tool.kernel_points(),
        ProbeRun {
            tables,
            scene,
            trajectory,
            remap,
        },
    )
}

/// What [`probe`] saw.
pub struct Probe {
    /// Each tick's work counters.
    pub counters: Vec<TickCounters>,
    /// Each tick's output.
    pub outputs: Vec<ForceOutput<f32>>,
    /// Each tick's tool inputs, as the words of a recording
    /// ([`palpate_script::ticks::tool_words`], tick-major).
    pub input_words: Vec<u32>,
    /// Wall time inside the ticks, s (physics updates excluded).
    pub ticks_s: f64,
}

/// [`probe`]'s arguments, run with the scene's tool points.
struct ProbeRun<'a> {
    tables: &'a SceneTables,
    scene: &'a Scene,
    trajectory: &'a Trajectory,
    remap: Option<QuasiNonLinear<f32>>,
}

impl ForToolPoints for ProbeRun<'_> {
    type Output = anyhow::Result<Probe>;

    fn call<const P: usize>(self) -> anyhow::Result<Probe> {
        probe_with::<P>(self.tables, self.scene, self.trajectory, self.remap)
    }
}

fn probe_with<const P: usize>(
    tables: &SceneTables,
    scene: &Scene,
    trajectory: &Trajectory,
    remap: Option<QuasiNonLinear<f32>>,
) -> anyhow::Result<Probe> {
    let load = |e| anyhow::anyhow!("table: {e}");
    if remap.is_some() && !matches!(tables, SceneTables::Precomputed(_)) {
        bail!("the quasi-non-linear remap is an option of the pre-computed model only");
    }
    match tables {
        SceneTables::Precomputed(file) => {
            let table = PrecomputedTable::<f32>::load(file.bytes()).map_err(load)?;
            let tissue = PrecomputedTissue::new(&table);
            let tissue = match remap {
                Some(remap) => tissue.with_remap(remap),
                None => tissue,
            };
            let mut haptic = PrecomputedLoop::<f32, P, P>::new(tissue, loop_config(scene))
                .map_err(|e| anyhow::anyhow!("haptic loop: {e}"))?;
            probe_ticks(&mut haptic, scene, trajectory, |_| {})
        }
        SceneTables::Dynamic(file, spec) => {
            let table = TensorMassTable::<f32>::load(file.bytes()).map_err(load)?;
            DynamicSetup::of(scene, spec, table)?.with_loop::<P, _, _>(Portable, |haptic| {
                probe_ticks(haptic, scene, trajectory, physics_update)
            })
        }
        SceneTables::Hybrid(files, spec) => HybridSetup::of(scene, spec, files)?
            .with_loop::<P, _, _>(Portable, |haptic| {
                probe_ticks(haptic, scene, trajectory, physics_update)
            }),
    }
}

/// One physics update; a failed one faults the following ticks, which are
/// measured too.
fn physics_update<B: PhysicsTissue<f32, P>, const P: usize>(haptic: &mut HapticLoop<f32, B, P, P>) {
    let _ = haptic.physics_update();
}

fn probe_ticks<B: Tissue<f32, P>, const P: usize>(
    haptic: &mut HapticLoop<f32, B, P, P>,
    scene: &Scene,
    trajectory: &Trajectory,
    mut physics: impl FnMut(&mut HapticLoop<f32, B, P, P>),
) -> anyhow::Result<Probe> {
    let every = scene.rates.physics_every.max(1) as usize;
    let mut probe = Probe {
        counters: Vec::new(),
        outputs: Vec::new(),
        input_words: Vec::new(),
        ticks_s: 0.0,
    };
    // Under `measure`'s callgrind, instrument from here on (no-op otherwise).
    crate::callgrind::start_instrumentation();
    for (k, (_, tool)) in ticks::<P>(trajectory, scene.tick_s(), &scene.tool)?.enumerate() {
        let started = std::time::Instant::now();
        let output = core::hint::black_box(budget_tick(haptic, &tool));
        probe.ticks_s += started.elapsed().as_secs_f64();
        probe.counters.push(*haptic.counters());
        probe.outputs.push(output);
        probe.input_words.extend(tool.iter().flat_map(tool_words));
        if (k + 1) % every == 0 {
            physics(haptic);
        }
    }
    Ok(probe)
}

/// Where [`record`] writes the scene's tables, under its folder: `table`
/// (pre-computed or tensor-mass), or `table.precomputed`, `table.dynamic`
/// and `table.interface` for a hybrid ([`SceneTables::write`]).
pub const RECORD_TABLE: &str = "table";
/// The list of [`record`]'s runs, under its folder.
pub const RECORD_RUNS: &str = "runs.txt";
/// The tick's static bounds on the Cortex-M4F, under [`record`]'s folder:
/// one line `<cycles at zero wait states> <cycles at M4F_WAIT_STATES>`
/// ([`M4F_CYCLES`], [`M4F_CYCLES_AT_WAIT_STATES`]).
pub const RECORD_BOUNDS: &str = "bounds.txt";

/// Records what `tools/cycles-check.sh` runs on the Cortex-M4F, for
/// `scene` on its own mesh, into the folder `dir` (created): the scene's f32
/// tables ([`RECORD_TABLE`]); for each generated trajectory
/// ([`trajectories`]) its ticks as the loop receives them
/// (`<trajectory>.ticks`, the format of [`palpate_script::ticks`]) and the
/// host's line for each tick (`<trajectory>.expected`,
/// [`palpate_script::ticks::write_tick`]), which the target must print
/// byte for byte; and [`RECORD_RUNS`], one line per trajectory,
/// `<trajectory> <ticks> <bound>`, with the tick's static bound in
/// Cortex-M4F cycles ([`M4F_CYCLES`]); and [`RECORD_BOUNDS`]. Only the trajectories named in
/// `only`, if any (each must be one of the scene's). Returns the runs' lines.
pub fn record(
    scene: &Scene,
    dir: &Path,
    only: &[String],
    compression: Option<Compression>,
) -> anyhow::Result<Vec<String>> {
    let chosen = chosen_trajectories(scene, only)?;
    let (mesh, report) = scene.load_mesh()?;
    check_scene_table(scene, &mesh, &report)?;
    check_stable_step(scene, &mesh, &report)?;
    work_folder("--record", dir)?;
    let (tables, bound) = budget_table(scene, &mesh, &report, &M4F_CYCLES, compression)?;
    let bound_at_wait_states = tables_bound(scene, &tables, &M4F_CYCLES_AT_WAIT_STATES)?;
    tables.write(&dir.join(RECORD_TABLE))?;
    let bounds = format!("{bound} {bound_at_wait_states}\n");
    write_whole(&dir.join(RECORD_BOUNDS), bounds.as_bytes())?;
    let load = |e| anyhow::anyhow!("table: {e}");
    let dynamic = match &tables {
        SceneTables::Precomputed(_) => None,
        SceneTables::Dynamic(file, spec) => {
            let table = TensorMassTable::<f32>::load(file.bytes()).map_err(load)?;
            let setup = DynamicSetup::of(scene, spec, table)?;
            Some((setup.params(), setup.physics()))
        }
        SceneTables::Hybrid(files, spec) => {
            let setup = HybridSetup::of(scene, spec, files)?;
            Some((setup.dynamic().params(), setup.dynamic().physics()))
        }
    };
    // The probe runs physics updates on the dynamic and hybrid tissues only.
    let physics_every = match dynamic {
        Some(_) => scene.rates.physics_every.max(1),
        None => 0,
    };
    let settings = Settings {
        loop_config: loop_config(scene),
        dynamic,
    };
    let mut runs = Vec::new();
    for (name, trajectory) in chosen {
        let probe = probe(&tables, scene, &trajectory)?;
        let header = Header {
            points: scene.tool.kernel_points(),
            ticks: probe.outputs.len(),
            physics_every,
            settings,
        };
        let bytes: Vec<u8> = header
            .words()
            .into_iter()
            .chain(probe.input_words.iter().copied())
            .flat_map(u32::to_le_bytes)
            .collect();
        write_whole(&dir.join(format!("{name}.ticks")), &bytes)?;
        let mut expected = String::new();
        for (k, (output, counters)) in probe.outputs.iter().zip(&probe.counters).enumerate() {
            write_tick(&mut expected, k, output, counters)?;
        }
        write_whole(&dir.join(format!("{name}.expected")), expected.as_bytes())?;
        runs.push(format!("{name} {} {bound}", header.ticks));
    }
    let mut list = runs.join("\n");
    list.push('\n');
    write_whole(&dir.join(RECORD_RUNS), list.as_bytes())?;
    Ok(runs)
}

/// Writes `bytes` to `path` whole ([`AtomicFile`]).
fn write_whole(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    let mut out = AtomicFile::create(path)?;
    out.write_all(bytes)?;
    out.commit()?;
    Ok(())
}

/// Where callgrind starts instrumenting a probe ([`measure_from`]). The
/// per-tick counts are the same either way: only the ticks are collected.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InstrumentFrom {
    /// The process's start (`--instr-atstart=yes`): every per-tick dump then
    /// walks the start-up's and the table load's code too.
    Start,
    /// The probe's first tick (`--instr-atstart=no` and the probe's client
    /// request, [`crate::callgrind`]; x86-64 Linux only): the dumps walk
    /// only the ticks' code (and a dynamic tissue's physics updates), about
    /// twice as fast on the pre-computed scenes.
    FirstTick,
}

/// Per-tick instruction counts of `args` (a `palpate budget --probe …`
/// command line) under callgrind, in tick order, instrumented from the
/// first tick where this platform can ([`crate::callgrind::STARTS_INSTRUMENTATION`]).
pub fn measure(exe: &Path, args: &[String], work_dir: &Path) -> anyhow::Result<Vec<u64>> {
    let from = if crate::callgrind::STARTS_INSTRUMENTATION {
        InstrumentFrom::FirstTick
    } else {
        InstrumentFrom::Start
    };
    measure_from(exe, args, work_dir, from)
}

/// [`measure`], instrumented `from` there.
pub fn measure_from(
    exe: &Path,
    args: &[String],
    work_dir: &Path,
    from: InstrumentFrom,
) -> anyhow::Result<Vec<u64>> {
    std::fs::create_dir_all(work_dir).with_context(|| work_dir.display().to_string())?;
    for entry in std::fs::read_dir(work_dir)? {
        let path = entry?.path();
        if path
            .file_name()
            .is_some_and(|n| n.to_string_lossy().starts_with("cg.out"))
        {
            std::fs::remove_file(&path)?;
        }
    }
    let out_file = work_dir.join("cg.out");
    let instr_atstart = match from {
        InstrumentFrom::Start => "--instr-atstart=yes",
        InstrumentFrom::FirstTick => "--instr-atstart=no",
    };
    let status = Command::new("valgrind")
        .arg("--tool=callgrind")
        .arg(format!("--callgrind-out-file={}", out_file.display()))
        .args([
            "--collect-atstart=no",
            instr_atstart,
            "--toggle-collect=palpate::budget::budget_tick",
            "--dump-after=palpate::budget::budget_tick",
            "--dump-instr=no",
            "--compress-strings=no",
            "-q",
        ])
        .arg(exe)
        .args(args)
        .status()
        .context("running valgrind (install it: tools/setup.sh)")?;
    if !status.success() {
        bail!("valgrind run failed: {status}");
    }
    let mut dumps: Vec<(u64, u64)> = Vec::new();
    for entry in std::fs::read_dir(work_dir)? {
        let path: PathBuf = entry?.path();
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        // Dumps are `cg.out.<n>`; the final `cg.out` holds the remainder.
        let Some(n) = name
            .strip_prefix("cg.out.")
            .and_then(|n| n.parse::<u64>().ok())
        else {
            continue;
        };
        let text = std::fs::read_to_string(&path)?;
        let ir = text
            .lines()
            .find_map(|l| {
                l.strip_prefix("summary:")
                    .or_else(|| l.strip_prefix("totals:"))
            })
            .and_then(|v| v.split_whitespace().next())
            .and_then(|v| v.parse::<u64>().ok())
            .with_context(|| format!("{}: no summary line", path.display()))?;
        dumps.push((n, ir));
    }
    // A child that never reached its first tick (instrumentation not
    // started) dumps nothing: an error, never a row of zero ticks.
    anyhow::ensure!(
        !dumps.is_empty(),
        "callgrind counted no tick in {}",
        work_dir.display()
    );
    dumps.sort_unstable();
    Ok(dumps.into_iter().map(|(_, ir)| ir).collect())
}

/// One line of the budget table.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct BudgetRow {
    /// Mesh description.
    pub mesh: String,
    /// Trajectory name.
    pub trajectory: &'static str,
    /// Ticks measured.
    pub ticks: usize,
    /// Largest per-tick instruction count.
    pub max_ir: u64,
    /// Mean per-tick instruction count.
    pub mean_ir: f64,
    /// The static bound.
    pub bound_ir: u64,
    /// The bound's time on this host, µs: `bound_ir` times the host's
    /// wall time per instruction on this trajectory run natively (an
    /// estimate, printed, never asserted: these machines are shared).
    pub bound_host_us: f64,
    /// Largest per-tick triangle tests, edge crossings and solves seen.
    pub max_work: [u32; 3],
}

/// Instructions per second assumed for the equivalent times: a
/// Cortex-M4F-class controller at 168 MHz, one instruction per cycle.
pub const M4F_IPS: f64 = 168e6;

/// The generated trajectories of `scene` ([`trajectories`]) named in
/// `only`, or all of them; an error names an unknown one and the known.
pub fn chosen_trajectories(
    scene: &Scene,
    only: &[String],
) -> anyhow::Result<Vec<(&'static str, Trajectory)>> {
    let mut chosen = trajectories(scene)?;
    if let Some(unknown) = only
        .iter()
        .find(|name| !chosen.iter().any(|(known, _)| known == name))
    {
        let known: Vec<&str> = chosen.iter().map(|(name, _)| *name).collect();
        bail!(
            "--trajectory {unknown}: not a generated trajectory of this scene (one of: {})",
            known.join(", ")
        );
    }
    if !only.is_empty() {
        chosen.retain(|(name, _)| only.iter().any(|o| o == name));
    }
    Ok(chosen)
}
