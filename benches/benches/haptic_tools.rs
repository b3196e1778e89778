//! The surgeon's tools in the haptic loop over the dynamic tensor-mass
//! model (`kernel/src/haptic/tool.rs`, `kernel/src/tensor_mass/tissue.rs`),
//! f32, on the liver-like organ (5868 tets, E = 5 kPa, ν = 0.4, base fixed;
//! linear law, symplectic Euler, dt 0.5 ms, damping 30/s, one physics
//! update per tick, cut capacity 8 tets per update). Three tool points on
//! a flat terrace of the right lobe's top: a grasper's two jaws pressed
//! 1 mm in 12 mm apart, closed to 4.5 mm, gripped and lifted 2 mm (their
//! contacts held), and 5 cm away a blade, its sphere 12.2 mm deep and the
//! blade 2 cm straight up out of the tissue, drawn 4.7 cm along a row of
//! vertices 1 mm off it (it cuts the tets of the row's two top layers of
//! vertices, about 20 per vertex, plus each tet its sphere presses):
//! - `tick_tools/grip2_cut1`: the tick between physics updates with the cut
//!   in progress and the grasp held (all three points in contact; two
//!   positions 0.05 mm apart alternate);
//! - `physics_update/cutting`: the update while the blade is drawn at
//!   0.1 mm per update (the mean over the path; each run of the path starts
//!   from the reset loop, set up again untimed, so the measurement never
//!   runs out of tissue); `cutting_8_tets`: only the updates that remove 8
//!   tets (the capacity; the path at 0.5 mm per update, replayed exactly,
//!   the other updates untimed); `blade_touching`: the same path with the
//!   blade a probe; `no_blade`: the blade 10 cm above the organ;
//! - `physics_update/after_slit`: the update once the slit is cut and the
//!   blade withdrawn (the grasp still held), against `uncut`, the same on
//!   the organ the blade never touched;
//! - `cut_scan`: the blade's scan of the tets alone
//!   (`TensorMassModel::cut_with_tool`, nothing in reach), which every
//!   update with an enabled blade runs.
//!
//! Targets (issue): a tick with a cut in progress and a grasp held ≤ 5 µs;
//! a physics update after a cut ≤ 1.2× one without (`after_slit` /
//! `uncut`). Printed after the group: the tets removed per update along the
//! path, a plain timing of every update of 3 runs per case (split by what
//! it removed; the cut-in-progress and after-slit ratios) and the RAM of
//! the surface buffers (`SurfaceBuffers::lengths`: a slot per mesh triangle
//! `F`, against the boundary triangles `B` alone before cuts could expose
//! faces).
//!
//! Run: `RUSTFLAGS="-C target-cpu=native" cargo bench -p palpate-benches --bench haptic_tools`.

use core::hint::black_box;
use core::time::Duration;
use std::time::Instant;

use criterion::measurement::WallTime;
use criterion::{BenchmarkGroup, BenchmarkId, Criterion, criterion_group, criterion_main};
use nalgebra::Vector3;
use palpate::mesh::generate::{ORGAN_CUBE_M, organ_mesh};
use palpate::table::load::TableFile;
use palpate::tensor_mass::{OwnedState, OwnedSurface};
use palpate_benches::{TOOL_RADIUS_M, haptic_config};
use palpate_kernel::haptic::{DynamicLoop, ForceOutput, OutputStatus, ToolAction, ToolInput};
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::tensor_mass::{
    DynamicParams, DynamicTissue, Integrator, PhysicsConfig, SurfaceBuffers, TensorMassModel,
};

fn physics() -> PhysicsConfig<f32> {
    PhysicsConfig::new(Integrator::SymplecticEuler, 5e-4, 1)
}

fn params() -> DynamicParams<f32> {
    DynamicParams::linear(30.0, 0.2)
}

/// The loop of the benches: two jaws (points 0, 1) and a blade (point 2).
type Loop<'a, 's> = DynamicLoop<'a, 's, f32, 3, 3>;

/// The organ's f32 tensor-mass table (E = 5 kPa, ν = 0.4, 1000 kg/m³), its
/// lowest vertices fixed, as `stvk_step` builds it.
fn organ_table() -> TableFile {
    palpate_benches::base_fixed_table(&organ_mesh(ORGAN_CUBE_M))
}

/// Height of the table's rest surface over `(x, y)`, m: the highest
/// boundary triangle whose projection holds the point.
fn top_z(table: &TensorMassTable<'_, f32>, x: f32, y: f32) -> f32 {
    let rest = table.rest_positions();
    let mut top = f32::NEG_INFINITY;
    for tri in table.surface_triangles() {
        let [a, b, c] = tri.map(|v| rest[v as usize]);
        let det = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
        if det.abs() < 1e-12 {
            continue;
        }
        let wb = ((x - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (y - a[1])) / det;
        let wc = ((b[0] - a[0]) * (y - a[1]) - (x - a[0]) * (b[1] - a[1])) / det;
        let wa = 1.0 - wb - wc;
        if [wa, wb, wc].iter().all(|&w| w >= -1e-6) {
            top = top.max(wa * a[2] + wb * b[2] + wc * c[2]);
        }
    }
    assert!(top.is_finite(), "({x}, {y}) is not over the organ");
    top
}

/// What the third tool point does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Blade {
    /// Cuts along the path (then is withdrawn).
    Cut,
    /// Drawn along the same path as a probe.
    Touch,
    /// Held 10 cm above the path: never in contact.
    Away,
}

/// Ticks of each stage of a run (one physics update after each tick).
const DESCEND: usize = 40;
const CLOSE: usize = 60;
const GRIP: usize = 20;
const LIFT: usize = 30;
/// Set-up ticks before the blade is drawn along the path.
const PREP: usize = DESCEND + CLOSE + GRIP + LIFT;
/// Updates along the 4.7 cm path: 0.1 mm per update, and 0.5 mm.
const SLOW_PATH: usize = 470;
const FAST_PATH: usize = 94;
const WITHDRAW: usize = 30;
const SETTLE: usize = 200;

/// The blade's sphere centre below the surface, m: half a millimetre
/// below the second layer of vertices, so the blade (2 cm up from it)
/// passes the row's vertices of both layers.
const BLADE_BELOW_TOP_M: f32 = ORGAN_CUBE_M as f32 + 0.0005;
/// From the blade's point to its other end, m.
const BLADE_M: [f32; 3] = [0.0, 0.0, 0.02];

/// Where the tools go on the organ's right lobe (a flat terrace of the
/// voxel surface: checked against the rest surface).
#[derive(Clone, Copy, Debug)]
struct Scene {
    /// Centre between the jaws (x, y), m, and the surface height there.
    grasp: [f32; 2],
    grasp_top_m: f32,
    /// The cut path along x at `y`, from `x[0]` to `x[1]`, m, and the
    /// surface height along it.
    path_y: f32,
    path_x: [f32; 2],
    path_top_m: f32,
    /// Updates along the path.
    path_updates: usize,
    blade: Blade,
}

impl Scene {
    fn new(table: &TensorMassTable<'_, f32>, blade: Blade, path_updates: usize) -> Self {
        let c = ORGAN_CUBE_M as f32;
        let grasp = [0.030, -0.028];
        // 1 mm off the row of vertices y = 2c: the blade passes within its
        // half-thickness (2 mm) of each and cuts their tets.
        let path_y = 2.0 * c + 0.001;
        let path_x = [0.006, 0.053];
        let grasp_top_m = top_z(table, grasp[0], grasp[1]);
        let path_top_m = top_z(table, path_x[0], path_y);
        let flat = |x: f32, y: f32, z: f32| (top_z(table, x, y) - z).abs() < 1e-6;
        for dx in [-0.008, 0.008] {
            assert!(
                flat(grasp[0] + dx, grasp[1], grasp_top_m),
                "grasp off the terrace"
            );
        }
        for s in 0..=10 {
            let x = path_x[0] + (path_x[1] - path_x[0]) * s as f32 / 10.0;
            for dy in [-0.003, 0.003] {
                assert!(flat(x, path_y + dy, path_top_m), "cut path off the terrace");
            }
        }
        Self {
            grasp,
            grasp_top_m,
            path_y,
            path_x,
            path_top_m,
            path_updates,
            blade,
        }
    }

    /// The tick after the path.
    fn path_end(&self) -> usize {
        PREP + self.path_updates
    }

    /// The whole run: set-up, path, blade withdrawn, settled.
    fn run_end(&self) -> usize {
        self.path_end() + WITHDRAW + SETTLE
    }

    /// The jaws at tick `k` of a run: down to 1 mm deep 12 mm apart, closed
    /// to 4.5 mm, gripped, lifted 2 mm, held.
    fn jaws(&self, k: usize) -> [ToolInput<f32>; 2] {
        let s = |from: usize, ticks: usize| (k.saturating_sub(from) as f32 / ticks as f32).min(1.0);
        let depth = -0.004 + 0.005 * s(0, DESCEND);
        let opening = 0.012 - 0.0075 * s(DESCEND, CLOSE);
        let lift = 0.002 * s(DESCEND + CLOSE + GRIP, LIFT);
        let action = if k >= DESCEND + CLOSE {
            ToolAction::Grip
        } else {
            ToolAction::Touch
        };
        let z = self.grasp_top_m + TOOL_RADIUS_M - depth + lift;
        [-0.5, 0.5].map(|side| ToolInput {
            position_m: Vector3::new(self.grasp[0] + side * opening, self.grasp[1], z),
            action,
        })
    }

    /// The blade at tick `k` of a run: from 4 mm above the surface down to
    /// its depth at the path's start, drawn along the path, withdrawn 4 cm
    /// up (touching only).
    fn blade(&self, k: usize) -> ToolInput<f32> {
        let s = |from: usize, ticks: usize| (k.saturating_sub(from) as f32 / ticks as f32).min(1.0);
        let z = self.path_top_m + 0.004 + TOOL_RADIUS_M
            - (0.004 + TOOL_RADIUS_M + BLADE_BELOW_TOP_M) * s(0, DESCEND)
            + 0.04 * s(self.path_end(), WITHDRAW);
        let x = self.path_x[0] + (self.path_x[1] - self.path_x[0]) * s(PREP, self.path_updates);
        let mut position_m = Vector3::new(x, self.path_y, z);
        let action = match self.blade {
            Blade::Cut if k < self.path_end() => ToolAction::Cut {
                blade_m: Vector3::from(BLADE_M),
            },
            Blade::Away => {
                position_m.z += 0.1;
                ToolAction::Touch
            }
            _ => ToolAction::Touch,
        };
        ToolInput { position_m, action }
    }

    fn tools(&self, k: usize) -> [ToolInput<f32>; 3] {
        let [a, b] = self.jaws(k);
        [a, b, self.blade(k)]
    }
}

/// What a stretch of a run did, update by update.
#[derive(Clone, Debug, Default)]
struct Stretch {
    /// Tets removed by each update.
    removed: Vec<usize>,
    /// Each update's time, s.
    seconds: Vec<f64>,
    /// Ticks with the blade's point in contact.
    blade_contacts: usize,
}

impl Stretch {
    fn total(&self) -> usize {
        self.removed.iter().sum()
    }
}

/// Checks a tick's output: not faulted.
fn checked(k: usize, out: ForceOutput<f32>) -> ForceOutput<f32> {
    assert!(
        !matches!(out.status, OutputStatus::Faulted(_)),
        "tick {k}: {:?}",
        out.status
    );
    out
}

/// Ticks `ticks` of `scene`'s run, each followed by a physics update.
fn advance(
    haptic: &mut Loop<'_, '_>,
    scene: &Scene,
    ticks: core::ops::Range<usize>,
    stretch: &mut Stretch,
) {
    for k in ticks {
        checked(k, haptic.tick_tools(&scene.tools(k)));
        stretch.blade_contacts += usize::from(haptic.contacts()[2].is_some());
        let start = Instant::now();
        let report = haptic.physics_update();
        stretch.seconds.push(start.elapsed().as_secs_f64());
        report.expect("stable");
        stretch.removed.push(haptic.tissue().removed().len());
    }
}

/// `true` when both jaws' contacts are held.
fn gripped(haptic: &Loop<'_, '_>) -> bool {
    haptic.contacts()[..2]
        .iter()
        .all(|c| c.is_some_and(|c| c.grip_offset_m.is_some()))
}

/// Runs `body` on a fresh loop over `table`.
fn with_loop<R>(table: TensorMassTable<'_, f32>, body: impl FnOnce(&mut Loop<'_, '_>) -> R) -> R {
    let mut state = OwnedState::for_table(&table).without_split_terms();
    let model = TensorMassModel::new(table, state.buffers(), params()).expect("model");
    let mut owned = OwnedSurface::for_model(&model);
    let (buffers, forces) = owned.buffers();
    let tissue = DynamicTissue::<f32, 3>::new(model, buffers, forces, physics()).expect("tissue");
    let mut haptic = Loop::new(tissue, haptic_config()).expect("loop");
    body(&mut haptic)
}

/// `tools` with every point `dz` (m) lower.
fn lowered(tools: &[ToolInput<f32>; 3], dz: f32) -> [ToolInput<f32>; 3] {
    tools.map(|t| ToolInput {
        position_m: t.position_m - Vector3::new(0.0, 0.0, dz),
        ..t
    })
}

/// `tick_tools` with the cut in progress and the grasp held: the loop
/// half-way along the slow path, at the first tick from there with all
/// three points in contact (the blade's sphere on tissue it has not cut
/// yet), before that tick's update. The blade's contact is new at every
/// such tick: the update after it cuts the tet it presses.
fn tick_while_cutting(group: &mut BenchmarkGroup<'_, WallTime>, table: TensorMassTable<'_, f32>) {
    let scene = Scene::new(&table, Blade::Cut, SLOW_PATH);
    with_loop(table, |haptic| {
        let mut stretch = Stretch::default();
        let mut k = PREP + SLOW_PATH / 2;
        advance(haptic, &scene, 0..k, &mut stretch);
        loop {
            assert!(k < scene.path_end(), "the blade never touches again");
            checked(k, haptic.tick_tools(&scene.tools(k)));
            if haptic.contacts().iter().flatten().count() == 3 {
                break;
            }
            haptic.physics_update().expect("stable");
            stretch.removed.push(haptic.tissue().removed().len());
            k += 1;
        }
        assert!(gripped(haptic), "the grasp is held");
        assert!(stretch.total() > 0, "the blade has cut");
        let here = scene.tools(k);
        let mut n = 0u32;
        group.bench_function(BenchmarkId::new("tick_tools", "grip2_cut1"), |b| {
            b.iter(|| {
                // Two heights 0.05 mm apart alternate (never above where
                // the tick before the bench had them): the tools move.
                n = n.wrapping_add(1);
                let dz = if n.is_multiple_of(2) { 0.0 } else { 5e-5 };
                black_box(haptic.tick_tools(black_box(&lowered(&here, dz))))
            })
        });
        let out = checked(k, haptic.tick_tools(&here));
        assert_eq!(
            out.contacts,
            3,
            "all three still in contact: {:?}",
            haptic.contacts().map(|c| c.is_some())
        );
        assert!(gripped(haptic), "the grasp still held");
        println!(
            "tick bench: at tick {k} of the run ({} into the path), {} tets cut so far, \
             force on the hand {:?} N",
            k - PREP,
            stretch.total(),
            out.force_n.as_slice()
        );
    });
}

/// `physics_update` along the path with `blade`: each measured iteration
/// is one tick (untimed) and its update (timed); at the path's end the
/// loop is reset and set up again, untimed. With `only_at_capacity`, only
/// the updates that remove 8 tets or more are timed (the same ones at
/// every run: the run is replayed exactly); the others run untimed.
fn update_along_path(
    group: &mut BenchmarkGroup<'_, WallTime>,
    table: TensorMassTable<'_, f32>,
    scene: Scene,
    name: &str,
    only_at_capacity: bool,
) {
    with_loop(table, |haptic| {
        // A reference run: which updates remove how many.
        let mut reference = Stretch::default();
        advance(haptic, &scene, 0..scene.path_end(), &mut reference);
        let path = &reference.removed[PREP..];
        let timed: Vec<usize> = (PREP..scene.path_end())
            .filter(|&k| !only_at_capacity || reference.removed[k] >= 8)
            .collect();
        assert!(!timed.is_empty(), "{name}: no update to time");
        let mut next = timed.len();
        let mut k = scene.path_end();
        let mut runs = 0usize;
        let mut removed_timed = 0usize;
        let mut updates_timed = 0usize;
        group.bench_function(BenchmarkId::new("physics_update", name), |b| {
            b.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                for _ in 0..iters {
                    if next == timed.len() {
                        haptic.reset();
                        advance(haptic, &scene, 0..PREP, &mut Stretch::default());
                        (k, next) = (PREP, 0);
                        runs += 1;
                    }
                    let at = timed[next];
                    advance(haptic, &scene, k..at, &mut Stretch::default());
                    checked(at, haptic.tick_tools(&scene.tools(at)));
                    let start = Instant::now();
                    let report = haptic.physics_update();
                    total += start.elapsed();
                    black_box(report).expect("stable");
                    let removed = haptic.tissue().removed().len();
                    assert_eq!(removed, reference.removed[at], "{name}: replayed");
                    removed_timed += removed;
                    updates_timed += 1;
                    (k, next) = (at + 1, next + 1);
                }
                total
            })
        });
        assert!(gripped(haptic), "{name}: the grasp held to the end");
        println!(
            "{name}: {runs} runs of the path; the path's {} updates remove {} tets, the \
             timed ones {:.2} per update",
            path.len(),
            path.iter().sum::<usize>(),
            removed_timed as f64 / updates_timed.max(1) as f64
        );
    });
}

/// `physics_update` at the end of a run, the blade withdrawn and the grasp
/// held: after the slit with `Blade::Cut`, on the uncut organ with
/// `Blade::Away`. Each iteration is a tick (untimed; the tools alternate
/// 0.05 mm) and its update (timed).
fn update_after(
    group: &mut BenchmarkGroup<'_, WallTime>,
    table: TensorMassTable<'_, f32>,
    blade: Blade,
    name: &str,
) {
    let scene = Scene::new(&table, blade, SLOW_PATH);
    with_loop(table, |haptic| {
        let mut stretch = Stretch::default();
        advance(haptic, &scene, 0..scene.run_end(), &mut stretch);
        let removed = stretch.total();
        assert_eq!(
            removed > 0,
            blade == Blade::Cut,
            "{name}: removed {removed}"
        );
        assert!(gripped(haptic), "{name}: the grasp is held");
        assert!(haptic.contacts()[2].is_none(), "{name}: the blade is out");
        let here = scene.tools(scene.run_end() - 1);
        let mut n = 0u32;
        group.bench_function(BenchmarkId::new("physics_update", name), |b| {
            b.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                for _ in 0..iters {
                    n = n.wrapping_add(1);
                    let dz = if n.is_multiple_of(2) { 0.0 } else { 5e-5 };
                    checked(n as usize, haptic.tick_tools(&lowered(&here, dz)));
                    let start = Instant::now();
                    let report = haptic.physics_update();
                    total += start.elapsed();
                    black_box(report).expect("stable");
                }
                total
            })
        });
        assert!(gripped(haptic), "{name}: the grasp held to the end");
        println!("{name}: {removed} tets removed before the measurement");
    });
}

/// The blade's scan alone: `TensorMassModel::cut_with_tool` with the
/// blade 1 m above the organ (one pass over the tets, nothing removed), as
/// every physics update with an enabled blade runs it.
fn cut_scan(group: &mut BenchmarkGroup<'_, WallTime>, table: TensorMassTable<'_, f32>) {
    let mut state = OwnedState::for_table(&table).without_split_terms();
    let mut model = TensorMassModel::new(table, state.buffers(), params()).expect("model");
    let from = Vector3::new(0.03, 0.0244, 1.0);
    let to = from + Vector3::from(BLADE_M);
    group.bench_function(BenchmarkId::new("cut_scan", "organ"), |b| {
        b.iter(|| black_box(model.cut_with_tool(black_box(from), to, TOOL_RADIUS_M, 8)))
    });
    assert!(model.tet_alive().iter().all(|&a| a), "nothing cut");
}

fn median(seconds: &[f64]) -> f64 {
    let mut s = seconds.to_vec();
    s.sort_by(f64::total_cmp);
    s.get(s.len() / 2).copied().unwrap_or(f64::NAN)
}

fn mean(seconds: &[f64]) -> f64 {
    seconds.iter().sum::<f64>() / seconds.len().max(1) as f64
}

/// A plain timing of whole runs, for the summary: 3 runs per blade along
/// the slow path (and the cutting blade along the fast one), then 2000
/// updates once settled, each update timed alone.
fn summary(table: TensorMassTable<'_, f32>) {
    println!("\nplain timing, 3 runs each (one update per tick, the update alone timed):");
    let mut along = Vec::new();
    let mut after = Vec::new();
    let cases = [
        (Blade::Cut, SLOW_PATH),
        (Blade::Touch, SLOW_PATH),
        (Blade::Away, SLOW_PATH),
        (Blade::Cut, FAST_PATH),
    ];
    for (blade, path_updates) in cases {
        let scene = Scene::new(&table, blade, path_updates);
        let (path, settled) = with_loop(table, |haptic| {
            let mut path = Stretch::default();
            let mut settled = Stretch::default();
            for _ in 0..3 {
                haptic.reset();
                advance(haptic, &scene, 0..PREP, &mut Stretch::default());
                advance(haptic, &scene, PREP..scene.path_end(), &mut path);
                let end = scene.run_end();
                advance(
                    haptic,
                    &scene,
                    scene.path_end()..end,
                    &mut Stretch::default(),
                );
                let here = scene.tools(end - 1);
                for j in 0..2000 {
                    let dz = if j % 2 == 0 { 0.0 } else { 5e-5 };
                    checked(end + j, haptic.tick_tools(&lowered(&here, dz)));
                    let start = Instant::now();
                    haptic.physics_update().expect("stable");
                    settled.seconds.push(start.elapsed().as_secs_f64());
                }
                assert!(gripped(haptic), "{blade:?}: the grasp held");
            }
            (path, settled)
        });
        let updates = path.removed.len();
        let cutting = path.removed.iter().filter(|&&r| r > 0).count();
        let most = path.removed.iter().copied().max().unwrap_or(0);
        let at_capacity = path.removed.iter().filter(|&&r| r >= 8).count();
        let split = |keep: &dyn Fn(usize) -> bool| -> Vec<f64> {
            path.seconds
                .iter()
                .zip(&path.removed)
                .filter(|(_, r)| keep(**r))
                .map(|(s, _)| *s)
                .collect()
        };
        println!(
            "{blade:?}, {:.1} mm per update: {updates} updates, blade in contact at {} \
             ticks; removed {} tets ({:.3} per update; {cutting} updates removing, \
             {at_capacity} of them ≥ 8, most {most}); update median {:.1} µs, mean {:.1} µs \
             (removing none: median {:.1} µs; removing 1-7: median {:.1} µs; ≥ 8: median \
             {:.1} µs)",
            47.0 / path_updates as f64,
            path.blade_contacts,
            path.total(),
            path.total() as f64 / updates as f64,
            median(&path.seconds) * 1e6,
            mean(&path.seconds) * 1e6,
            median(&split(&|r| r == 0)) * 1e6,
            median(&split(&|r| (1..8).contains(&r))) * 1e6,
            median(&split(&|r| r >= 8)) * 1e6,
        );
        along.push((mean(&path.seconds), median(&path.seconds)));
        after.push(median(&settled.seconds));
    }
    let [
        (cut, cut_median),
        (touch, touch_median),
        (away, away_median),
        _,
    ] = along[..]
    else {
        unreachable!()
    };
    println!(
        "update with the cut in progress / without (slow path): {:.2}× the touching blade, \
         {:.2}× no blade (means); medians {:.2}×, {:.2}×",
        cut / touch,
        cut / away,
        cut_median / touch_median,
        cut_median / away_median
    );
    let [slit, touched, uncut, _] = after[..] else {
        unreachable!()
    };
    println!(
        "settled, blade withdrawn, grasp held (medians): after the slit {:.1} µs, uncut \
         {:.1} µs (after the touching blade {:.1} µs): after a slit / uncut {:.3}×",
        slit * 1e6,
        uncut * 1e6,
        touched * 1e6,
        slit / uncut
    );
}

/// The surface buffers' RAM for the organ, f32: every mesh triangle (`F`)
/// has a slot, against the `B` boundary triangles only (before cut faces).
fn memory(table: TensorMassTable<'_, f32>) {
    with_loop(table, |haptic| {
        let model = haptic.tissue().model();
        let t = model.table();
        let surface_vertices = {
            let mut seen = vec![false; t.vertex_count()];
            for &v in t.surface_triangles().iter().flatten() {
                seen[v as usize] = true;
            }
            seen.iter().filter(|&&s| s).count()
        };
        // `OwnedSurface::for_model`'s grid: one cell per surface vertex.
        let l = SurfaceBuffers::<f32>::lengths(model, surface_vertices);
        let (n, f, b) = (l.vertices, l.triangles, t.surface_triangles().len());
        // Either way: positions (12 B), grid_vertex (4 B),
        // vertex_triangle_start and cell_start (4 B each).
        let shared = n * 12 + n * 4 + l.vertex_triangle_start * 4 + l.cell_start * 4;
        let (fp, ft, fm, fv) = (f * 16, f * 12, f * 8, l.vertex_triangle * 4);
        let (bp, bt, bv) = (b * 16, b * 12, 3 * b * 4);
        let now = shared + fp + ft + fm + fv;
        let before = shared + bp + bt + bv;
        println!(
            "\nsurface buffers, organ ({} tets, {n} vertices, {surface_vertices} surface \
             vertices, F = {f} mesh triangles, B = {b} boundary triangles), f32:",
            t.tet_count()
        );
        println!(
            "  planes F×16 = {fp} B (B×16 = {bp} B); triangles F×12 = {ft} B ({bt} B); \
             face_slot + slot_tet F×8 = {fm} B (new); vertex_triangle 3F×4 = {fv} B ({bv} B)"
        );
        println!(
            "  unchanged (positions, grid_vertex, vertex_triangle_start, cell_start of {} \
             cells): {shared} B; force scratch N×12 = {} B besides",
            l.cell_start - 1,
            n * 12
        );
        println!(
            "  total {now} B ({:.1} KiB) against {before} B ({:.1} KiB): +{} B, {:.2}×",
            now as f64 / 1024.0,
            before as f64 / 1024.0,
            now - before,
            now as f64 / before as f64
        );
        println!(
            "  loop object: {} B (P = M = 3, f32)",
            core::mem::size_of::<Loop<'_, '_>>()
        );
    });
}

fn tools(c: &mut Criterion) {
    let file = organ_table();
    let table = TensorMassTable::<f32>::load(file.bytes()).expect("table");
    let mut group = c.benchmark_group("haptic_tools");
    group
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3))
        .sample_size(30);
    tick_while_cutting(&mut group, table);
    let scene = |blade, path_updates| Scene::new(&table, blade, path_updates);
    update_along_path(
        &mut group,
        table,
        scene(Blade::Cut, SLOW_PATH),
        "cutting",
        false,
    );
    update_along_path(
        &mut group,
        table,
        scene(Blade::Cut, FAST_PATH),
        "cutting_8_tets",
        true,
    );
    update_along_path(
        &mut group,
        table,
        scene(Blade::Touch, SLOW_PATH),
        "blade_touching",
        false,
    );
    update_along_path(
        &mut group,
        table,
        scene(Blade::Away, SLOW_PATH),
        "no_blade",
        false,
    );
    update_after(&mut group, table, Blade::Cut, "after_slit");
    update_after(&mut group, table, Blade::Away, "uncut");
    cut_scan(&mut group, table);
    group.finish();
    summary(table);
    memory(table);
}

criterion_group!(benches, tools);
criterion_main!(benches);
