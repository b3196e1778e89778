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
//! TRACK) + (P + 1) · SOLVE · M³`, with `D = 2 · max_query_triangles` the
//! worst-case triangle tests of one detection (two point queries, the
//! sweep's and the penetration test's sharing the one at the tool; the
//! table-declared maximum over all grid cells, computed at load), `P` tool
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
//! measured function) has the bound `BASE + P · (TRIANGLE · 6T + WALK ·
//! MAX_WALK_STEPS + DYNAMIC_TRACK) + (P + 1) · DYNAMIC_SOLVE · M`: a
//! detection on the re-binned grid tests at most every triangle reference
//! twice (`3F` references for the `F` faces a cut can expose), since compression can crowd a bucket, and
//! a solve is linear in the contacts (no factorization). The tick is the
//! same with grips and blades (a held contact skips the walk; a blade cuts
//! at the physics update, outside the tick). Measured on
//! `palpate budget built-in-dynamic`: a tracked contact with its solve
//! 1192 Ir over the idle 680, an edge crossed ≤ 564 Ir, a triangle tested
//! ≤ 113 Ir; the worst tick 12 939 Ir.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, bail};
use palpate_kernel::PrecomputedTable;
use palpate_kernel::contact::{MAX_WALK_STEPS, Tissue};
use palpate_kernel::haptic::{
    ForceOutput, HapticLoop, PhysicsTissue, PrecomputedLoop, TickCounters, ToolInput,
};
use palpate_kernel::math::Portable;
use palpate_kernel::precomputed::PrecomputedTissue;
use palpate_kernel::table::TensorMassTable;

use crate::mesh::{MeshReport, TetMesh};
use crate::session::generate::{hepatectomy, surgery};
use crate::session::hybrid::HybridSetup;
use crate::session::model::{SceneModel, SceneTables};
use crate::session::run::{DynamicSetup, loop_config, ticks};
use crate::session::scene::{MeshSource, ToolKind};
use crate::session::tool_points::{ForToolPoints, with_tool_points};
use crate::session::{Scene, Trajectory};

/// Instructions of a tick outside detection, tracking and solves.
pub const BASE_IR: u64 = 600;
/// Instructions per candidate triangle tested in a detection.
pub const TRIANGLE_IR: u64 = 125;
/// Instructions per triangle edge crossed while sliding.
pub const WALK_IR: u64 = 700;
/// Instructions to track one contact (projection, gap).
pub const TRACK_IR: u64 = 1000;
/// Instructions per contact solve, per cubed contact capacity (the block
/// Cholesky is `O(M³)`).
pub const SOLVE_IR_PER_M3: u64 = 2500;

/// The static per-tick bound (instructions) for `points` tool points and
/// capacity `capacity` over `table`.
pub fn tick_bound(table: &PrecomputedTable<'_, f32>, points: u64, capacity: u64) -> u64 {
    let detection = 2 * u64::from(table.surface_index().max_query_triangles());
    BASE_IR
        + points * (TRIANGLE_IR * detection + WALK_IR * u64::from(MAX_WALK_STEPS) + TRACK_IR)
        + (points + 1) * SOLVE_IR_PER_M3 * capacity * capacity * capacity
}

/// Instructions to track one contact on the dynamic model's deforming
/// surface (projection, gap).
pub const DYNAMIC_TRACK_IR: u64 = 1000;
/// Instructions per contact per solve on the dynamic model (the rest-frame
/// normal, the stiffness `k` from 9 tensors and 6 edge look-ups, the
/// extrapolated force).
pub const DYNAMIC_SOLVE_IR: u64 = 1500;

/// The static per-tick bound (instructions) of the dynamic model's tick,
/// between physics updates, for `points` tool points and capacity
/// `capacity` over `table`. A detection tests at most every triangle
/// reference of the surface twice (`2 × 3F`, `F` the mesh's faces,
/// every one of which a cut may expose): the re-binned grid's buckets
/// depend on the deformation, so no tighter bound holds for any state.
pub fn dynamic_tick_bound(table: &TensorMassTable<'_, f32>, points: u64, capacity: u64) -> u64 {
    let detection = 2 * 3 * table.mesh_triangles().len() as u64;
    BASE_IR
        + points
            * (TRIANGLE_IR * detection + WALK_IR * u64::from(MAX_WALK_STEPS) + DYNAMIC_TRACK_IR)
        + (points + 1) * DYNAMIC_SOLVE_IR * capacity
}

/// The static per-tick bound (instructions) of the hybrid model's tick
/// (RR-3510 §6.2), between physics updates, for `points` tool points and
/// capacity `capacity`: a detection tests at most every triangle reference
/// of the whole surface twice (`2 × 3 (B + F)`, the pre-computed region's
/// `B` boundary triangles and the tensor-mass region's `F` faces), and each
/// solve is the pre-computed one (`O(M³)`) and the tensor-mass one
/// (linear) together.
pub fn hybrid_tick_bound(
    precomputed: &PrecomputedTable<'_, f32>,
    dynamic: &TensorMassTable<'_, f32>,
    points: u64,
    capacity: u64,
) -> u64 {
    let slots = precomputed.surface_triangles().len() + dynamic.mesh_triangles().len();
    let detection = 2 * 3 * slots as u64;
    BASE_IR
        + points
            * (TRIANGLE_IR * detection
                + WALK_IR * u64::from(MAX_WALK_STEPS)
                + TRACK_IR.max(DYNAMIC_TRACK_IR))
        + (points + 1)
            * (SOLVE_IR_PER_M3 * capacity * capacity * capacity + DYNAMIC_SOLVE_IR * capacity)
}

/// The f32 tables of `scene` on `mesh` (pre-computed, tensor-mass or
/// hybrid, by its model: [`SceneModel`]) and the static bound of its tick.
pub fn budget_table(
    scene: &Scene,
    mesh: &TetMesh,
    report: &MeshReport,
) -> anyhow::Result<(SceneTables, u64)> {
    let points = scene.tool.kernel_points() as u64;
    let tables = SceneModel::of(scene, mesh, report)?.tables(scene, mesh, report)?;
    let load = |e| anyhow::anyhow!("table: {e}");
    let bound = match &tables {
        SceneTables::Precomputed(file) => {
            let table = PrecomputedTable::<f32>::load(file.bytes()).map_err(load)?;
            tick_bound(&table, points, points)
        }
        SceneTables::Dynamic(file, _) => {
            let table = TensorMassTable::<f32>::load(file.bytes()).map_err(load)?;
            dynamic_tick_bound(&table, points, points)
        }
        SceneTables::Hybrid(files, _) => {
            let precomputed =
                PrecomputedTable::<f32>::load(files.precomputed.bytes()).map_err(load)?;
            let dynamic = TensorMassTable::<f32>::load(files.dynamic.bytes()).map_err(load)?;
            hybrid_tick_bound(&precomputed, &dynamic, points, points)
        }
    };
    Ok((tables, bound))
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
    with_tool_points(
        scene.tool.kernel_points(),
        ProbeRun {
            tables,
            scene,
            trajectory,
        },
    )
}

/// What [`probe`] saw.
pub struct Probe {
    /// Each tick's work counters.
    pub counters: Vec<TickCounters>,
    /// Wall time inside the ticks, s (physics updates excluded).
    pub ticks_s: f64,
}

/// [`probe`]'s arguments, run with the scene's tool points.
struct ProbeRun<'a> {
    tables: &'a SceneTables,
    scene: &'a Scene,
    trajectory: &'a Trajectory,
}

impl ForToolPoints for ProbeRun<'_> {
    type Output = anyhow::Result<Probe>;

    fn call<const P: usize>(self) -> anyhow::Result<Probe> {
        probe_with::<P>(self.tables, self.scene, self.trajectory)
    }
}

fn probe_with<const P: usize>(
    tables: &SceneTables,
    scene: &Scene,
    trajectory: &Trajectory,
) -> anyhow::Result<Probe> {
    let load = |e| anyhow::anyhow!("table: {e}");
    match tables {
        SceneTables::Precomputed(file) => {
            let table = PrecomputedTable::<f32>::load(file.bytes()).map_err(load)?;
            let mut haptic = PrecomputedLoop::<f32, P, P>::new(
                PrecomputedTissue::new(&table),
                loop_config(scene),
            )
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
            .with_loop::<P, _>(|haptic| probe_ticks(haptic, scene, trajectory, physics_update)),
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
    let mut counters = Vec::new();
    let mut ticks_s = 0.0;
    for (k, (_, tool)) in ticks::<P>(trajectory, scene.tick_s(), &scene.tool)?.enumerate() {
        let started = std::time::Instant::now();
        core::hint::black_box(budget_tick(haptic, &tool));
        ticks_s += started.elapsed().as_secs_f64();
        counters.push(*haptic.counters());
        if (k + 1) % every == 0 {
            physics(haptic);
        }
    }
    Ok(Probe { counters, ticks_s })
}

/// Per-tick instruction counts of `args` (a `palpate budget --probe …`
/// command line) under callgrind, in tick order.
pub fn measure(exe: &Path, args: &[String], work_dir: &Path) -> anyhow::Result<Vec<u64>> {
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
    let status = Command::new("valgrind")
        .arg("--tool=callgrind")
        .arg(format!("--callgrind-out-file={}", out_file.display()))
        .args([
            "--collect-atstart=no",
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

/// The generated trajectories a budget runs for `scene`'s tool: for probes
/// the poke, press-hold, slide and strike (and the pinch with two points);
/// for a scene with a grasper or a cutter, [`surgery`] (on the built-in
/// block's top), or [`hepatectomy`] on the generated organ.
pub fn trajectories(scene: &Scene) -> anyhow::Result<Vec<(&'static str, Trajectory)>> {
    use crate::session::{Generator, Pinch, Poke, PressHold, Slide, Strike};
    let err = |e: crate::session::GenerateError| anyhow::anyhow!("{e}");
    let tool = &scene.tool;
    if tool.kinds.iter().any(|k| *k != ToolKind::Probe) {
        return Ok(match scene.mesh {
            MeshSource::GeneratedOrgan => {
                vec![("hepatectomy", hepatectomy(tool).map_err(err)?)]
            }
            _ => vec![("surgery", surgery(tool).map_err(err)?)],
        });
    }
    let mut out = vec![
        ("poke", Poke::default().trajectory().map_err(err)?),
        (
            "press-hold",
            PressHold::default().trajectory().map_err(err)?,
        ),
        ("slide", Slide::default().trajectory().map_err(err)?),
        ("strike", Strike::default().trajectory().map_err(err)?),
    ];
    if tool.points >= 2 {
        out.push(("pinch", Pinch::default().trajectory().map_err(err)?));
    }
    Ok(out)
}
