//! The static tick bounds of `palpate budget` (module docs of
//! [`super`]): the unit costs, in x86-64 instructions ([`HOST_IR`]) or
//! Cortex-M4F cycles ([`M4F_CYCLES`], and [`M4F_CYCLES_AT_WAIT_STATES`] at
//! [`M4F_WAIT_STATES`] flash wait states), and the bound of each model's
//! tick from its tables' declared sizes and the capacities.

use palpate_kernel::PrecomputedTable;
use palpate_kernel::contact::MAX_WALK_STEPS;
use palpate_kernel::table::TensorMassTable;

/// The unit costs of the static tick bound, in one unit: x86-64
/// instructions for the host ([`HOST_IR`], measured with callgrind) or
/// Cortex-M4F cycles for the target ([`M4F_CYCLES`], counted by
/// `tools/cycles`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UnitCosts {
    /// A tick outside detection, tracking and solves.
    pub base: u64,
    /// Per candidate triangle tested in a detection.
    pub triangle: u64,
    /// Per triangle edge crossed while sliding.
    pub walk: u64,
    /// To track one contact (projection, gap).
    pub track: u64,
    /// Per contact solve, per cubed contact capacity (the block LDLᵀ
    /// is `O(M³)`).
    pub solve_per_m3: u64,
    /// To track one contact on the dynamic model's deforming surface.
    pub dynamic_track: u64,
    /// Per contact per solve on the dynamic model (the rest-frame normal,
    /// the stiffness `k` from 9 tensors and 6 edge look-ups, the
    /// extrapolated force).
    pub dynamic_solve: u64,
}

/// The host's unit costs, x86-64 instructions (see the module docs).
pub const HOST_IR: UnitCosts = UnitCosts {
    base: 600,
    triangle: 125,
    walk: 700,
    track: 1000,
    solve_per_m3: 2500,
    dynamic_track: 1000,
    dynamic_solve: 1500,
};

/// The Cortex-M4F's unit costs, cycles at zero wait states: the largest
/// per-unit costs `palpate-cycles --unit-costs` (`tools/cycles`) derived
/// from every tick of `tools/cycles-check.sh --all` (the release build of
/// `tools/cycles-m4f`: the kernel as firmware links it, every generated
/// trajectory with 1 to 4 probes on the three scenes it records), the
/// largest over the three models, rounded up (2026-11-25, after the
/// detection's visited set): an idle tick 4987 (the hybrid's; 2362
/// pre-computed), a triangle tested 492 (dynamic), an edge crossed 3838
/// (the dynamic model's, its base not separable: every idle tick there
/// tests triangles), a tracked contact with its solve 2193 (pre-computed)
/// and 3333 (dynamic), a solve 915 per `M³` (hybrid; 540 pre-computed) and
/// 821 per `M` (dynamic).
pub const M4F_CYCLES: UnitCosts = UnitCosts {
    base: 5000,
    triangle: 600,
    walk: 4000,
    track: 2200,
    solve_per_m3: 950,
    dynamic_track: 3500,
    dynamic_solve: 900,
};

/// The Cortex-M4F's unit costs at [`M4F_WAIT_STATES`] flash wait states
/// (every instruction word fetched and every word loaded from flash `W`
/// cycles more, no accelerator): each of [`M4F_CYCLES`] times the largest
/// ratio, over the three models, of the unit costs `palpate-cycles
/// --unit-costs` derived at those wait states to those at zero
/// (`tools/cycles-check.sh`, 2026-11-28: base 3.45, triangle 3.72, edge
/// crossed 4.22, tracked contact 4.75, solve per `M³` 3.54, per `M` 3.99),
/// rounded up.
pub const M4F_CYCLES_AT_WAIT_STATES: UnitCosts = UnitCosts {
    base: 17_500,
    triangle: 2_300,
    walk: 17_000,
    track: 10_500,
    solve_per_m3: 3_400,
    dynamic_track: 16_700,
    dynamic_solve: 3_600,
};

/// The flash wait states of [`M4F_CYCLES_AT_WAIT_STATES`] (a 168 MHz
/// STM32F4 at 3.3 V: 5).
pub const M4F_WAIT_STATES: u32 = 5;

/// The static per-tick bound (in the unit of `costs`) for `points` tool
/// points of radius `radius_m` (m) and capacity `capacity` over `table`.
pub fn tick_bound(
    costs: &UnitCosts,
    table: &PrecomputedTable<'_, f32>,
    radius_m: f64,
    points: u64,
    capacity: u64,
) -> u64 {
    let radius_m = radius_m as f32;
    let detection = u64::from(table.surface_index().max_detection_tests(radius_m));
    costs.base
        + points
            * (costs.triangle * detection + costs.walk * u64::from(MAX_WALK_STEPS) + costs.track)
        + (points + 1) * costs.solve_per_m3 * capacity * capacity * capacity
}

/// The static per-tick bound (in the unit of `costs`) of the dynamic
/// model's tick, between physics updates, for `points` tool points and
/// capacity `capacity` over `table`. A detection tests at most every
/// triangle reference of the surface twice, and the deep check that may
/// follow it once more (`3 × 3F`, `F` the mesh's
/// faces, every one of which a cut may expose): the re-binned grid's
/// buckets depend on the deformation, so no tighter bound holds for any
/// state.
pub fn dynamic_tick_bound(
    costs: &UnitCosts,
    table: &TensorMassTable<'_, f32>,
    points: u64,
    capacity: u64,
) -> u64 {
    let detection = 3 * 3 * table.mesh_triangles().len() as u64;
    costs.base
        + points
            * (costs.triangle * detection
                + costs.walk * u64::from(MAX_WALK_STEPS)
                + costs.dynamic_track)
        + (points + 1) * costs.dynamic_solve * capacity
}

/// The static per-tick bound (in the unit of `costs`) of the hybrid
/// model's tick (RR-3510 §6.2), between physics updates, for `points` tool
/// points and capacity `capacity`: a detection and its deep check test at
/// most every triangle reference of the whole surface three times
/// (`3 × 3 (B + F)`, the pre-computed
/// region's `B` boundary triangles and the tensor-mass region's `F` faces),
/// and each solve is the pre-computed one (`O(M³)`) and the tensor-mass one
/// (linear) together.
pub fn hybrid_tick_bound(
    costs: &UnitCosts,
    precomputed: &PrecomputedTable<'_, f32>,
    dynamic: &TensorMassTable<'_, f32>,
    points: u64,
    capacity: u64,
) -> u64 {
    let slots = precomputed.surface_triangles().len() + dynamic.mesh_triangles().len();
    let detection = 3 * 3 * slots as u64;
    costs.base
        + points
            * (costs.triangle * detection
                + costs.walk * u64::from(MAX_WALK_STEPS)
                + costs.track.max(costs.dynamic_track))
        + (points + 1)
            * (costs.solve_per_m3 * capacity * capacity * capacity + costs.dynamic_solve * capacity)
}
