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
//! worst-case triangle tests of one detection (two point queries; the
//! table-declared maximum over all grid cells, computed at load), `P` tool
//! points, `M` the contact capacity and `P + 1` the most solves a tick can
//! do. The unit costs are the largest per-unit costs callgrind measured on
//! this build (x86-64, `cargo build`, the workspace's opt-level 2 for our
//! crates) on the built-in scene's trajectories, rounded up: an idle tick
//! 469 Ir, a tracked contact with its solve 2420 Ir, each edge crossed
//! 602 Ir, each triangle tested ≤ 113 Ir, the new contact and its solve
//! included (`palpate budget built-in`).

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, bail};
use nalgebra::Vector3;
use palpate_kernel::PrecomputedTable;
use palpate_kernel::haptic::contact::MAX_WALK_STEPS;
use palpate_kernel::haptic::haptic_loop::{ForceOutput, PrecomputedLoop, TickCounters};
use palpate_kernel::haptic::tissue::PrecomputedTissue;

use crate::session::run::{loop_config, ticks};
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

/// One tick, kept out of line so callgrind can collect exactly its cost.
#[inline(never)]
pub fn budget_tick<const P: usize>(
    haptic: &mut PrecomputedLoop<'_, f32, P, P>,
    tool_m: &[Vector3<f32>; P],
) -> ForceOutput<f32> {
    haptic.tick(tool_m)
}

/// Runs every tick of `trajectory` through [`budget_tick`] and returns each
/// tick's work counters (the child side of [`measure`]).
pub fn probe(
    table: &PrecomputedTable<'_, f32>,
    scene: &Scene,
    trajectory: &Trajectory,
) -> anyhow::Result<Vec<TickCounters>> {
    match scene.tool.points {
        1 => probe_with::<1>(table, scene, trajectory),
        2 => probe_with::<2>(table, scene, trajectory),
        3 => probe_with::<3>(table, scene, trajectory),
        _ => probe_with::<4>(table, scene, trajectory),
    }
}

fn probe_with<const P: usize>(
    table: &PrecomputedTable<'_, f32>,
    scene: &Scene,
    trajectory: &Trajectory,
) -> anyhow::Result<Vec<TickCounters>> {
    let mut haptic =
        PrecomputedLoop::<f32, P, P>::new(PrecomputedTissue::new(table), loop_config(scene))
            .map_err(|e| anyhow::anyhow!("haptic loop: {e}"))?;
    let mut counters = Vec::new();
    for (_, tool) in ticks::<P>(trajectory, scene.tick_s()) {
        core::hint::black_box(budget_tick(&mut haptic, &tool));
        counters.push(*haptic.counters());
    }
    Ok(counters)
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

/// The generated trajectories of the budget, by name (`pinch` needs two
/// tool points and is skipped below that).
pub fn trajectories(points: usize) -> anyhow::Result<Vec<(&'static str, Trajectory)>> {
    use crate::session::{Generator, Pinch, Poke, PressHold, Slide, Strike};
    let err = |e: crate::session::GenerateError| anyhow::anyhow!("{e}");
    let mut out = vec![
        ("poke", Poke::default().trajectory().map_err(err)?),
        (
            "press-hold",
            PressHold::default().trajectory().map_err(err)?,
        ),
        ("slide", Slide::default().trajectory().map_err(err)?),
        ("strike", Strike::default().trajectory().map_err(err)?),
    ];
    if points >= 2 {
        out.push(("pinch", Pinch::default().trajectory().map_err(err)?));
    }
    Ok(out)
}
