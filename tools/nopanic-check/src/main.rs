//! Link-time proof that the kernel's step paths cannot panic.
//!
//! The panic handler calls `palpate_step_path_can_panic`, a symbol defined
//! nowhere. With `panic = "abort"`, LTO and optimisation, the linker keeps the
//! handler only if some panic is reachable from `main`; then the link fails
//! with "undefined symbol: palpate_step_path_can_panic". A successful link
//! proves that no panic is reachable in what `main` calls.
//!
//! The pre-computed model (RR-3510 §4), on the f32 table of the firmware
//! example's box (`$OUT_DIR/table.bin`, from `PALPATE_TABLE`) and on its two
//! compressed versions (`table-f16.bin`, `table-q16.bin`: 16-bit codes, blocks
//! dropped in both compliance parts), one of the three picked by a volatile
//! selector at each call:
//! - table validation, `PrecomputedTable::load` (not the step path, but it runs
//!   on bytes from flash or a file, so it is checked too);
//! - the haptic force path, `PrecomputedModel::contact_forces::<MAX_CONTACTS>`,
//!   linear or quasi-non-linear (`with_remap`, on volatile coefficients);
//! - the displacement updates, `PrecomputedModel::free_displacements` and
//!   `PrecomputedModel::displacements`.
//!
//! The dynamic tensor-mass model (RR-3510 §5), on the f32 tensor-mass table of
//! the same box (`$OUT_DIR/tensor_table.bin`, from `PALPATE_TENSOR_TABLE`):
//! - table validation, `TensorMassTable::load`;
//! - `TensorMassModel::new` (buffer-length and parameter checks) and `reset`, on
//!   `StateBuffers` sliced from fixed-capacity arrays, with each
//!   `ElasticLaw` (linear, St Venant-Kirchhoff, co-rotational, neo-Hookean) and the incompressibility
//!   penalty on or off;
//! - the inputs `set_external_force`, `set_velocity`, `impose`, `release`,
//!   `clear_external_forces`;
//! - `step` with each of the four `Integrator`s (explicit and symplectic
//!   Euler, RK4, central difference) and the divergence faults;
//! - topology changes: `remove_tet`, `cut_with_tool`, `tear`, and the live
//!   `surface_triangles`;
//! - the outputs `displacements_m`, `velocities_m_s`, `elastic_forces_n`,
//!   `fault`;
//!
//! and of the haptic loop over each model, driven by `tick_tools` (`tick` is
//! `tick_tools` with every action `Touch`, so it is covered too) with, for
//! each of two tool points, a volatile position, a volatile action selector
//! (`ToolAction::Touch`, `Grip` or `Cut`) and a volatile blade vector:
//! - over the pre-computed tables (the same volatile selector),
//!   `HapticLoop::new` (configuration and limits
//!   from volatile inputs) and `tick_tools` (contact detection in the
//!   collision grid from the motion segment or the penetration, sliding,
//!   grips closing, holding and opening, the contact solve with releases and
//!   refusals, a blade on a tissue that cannot cut, `cut_refused`, the safety
//!   supervisor), with `reset` on a volatile flag;
//! - over the tensor-mass table, `DynamicTissue::new` (every surface buffer
//!   length volatile, the face buffers `triangles`, `face_slot`, `slot_tet`
//!   and `planes` included, so the length refusals are reachable; the
//!   physics configuration volatile: integrator, extrapolation, step,
//!   sub-steps, the cut capacity, and tearing off or on with each threshold
//!   volatile and optional and a volatile capacity, so the capacity
//!   refusals are reachable) with its `DeformingSurface`, then
//!   `tick_tools`, `physics_update` (on a volatile flag: the blades of the
//!   last tick's cuts remove the tets they touch and the one pressed into,
//!   held grips impose their full displacement, the step, tearing, the
//!   exposed-face update of the surface, held forces, re-binning) and
//!   `reset`; the tets each update removed (`DynamicTissue::removed`) are
//!   published;
//!
//! and the hybrid model (RR-3510 §6.2, module `hybrid`), on the three f32
//! tables of the firmware's hybrid box (`$OUT_DIR/hybrid/`, from
//! `PALPATE_HYBRID_TABLES`: the top corner cell a tensor-mass region, the
//! rest pre-computed, 7 connection nodes):
//! - `InterfaceTable::load` (and the two region tables' loads), each on a
//!   volatile length of its bytes;
//! - `HybridModel::new` on a `TensorMassModel` of the region (state buffers
//!   and coupling buffers `passed_force_n`, `background_m` sliced to
//!   volatile lengths, so the length and table-mismatch refusals are
//!   reachable), then rounds on one model of `reset`, `impose` on the
//!   tensor-mass region, `update_background` with a volatile row count,
//!   `contact_forces::<MAX_CONTACTS>` with a volatile contact set,
//!   `pass_contact_forces` with the solution or none, `step` with each
//!   integrator, `displacements` into a volatile length;
//! - the haptic loop over the hybrid: `HybridTissue::new` (every buffer
//!   length volatile: the region's state and surface buffers, the coupling,
//!   the hybrid surface's eight buffers), `HybridLoop::new`, `tick_tools`
//!   with volatile positions, actions and blades, `physics_update` on a
//!   volatile flag, `reset`, and the tets each update removed.
//!
//! The hybrid proof is not vacuous either: `.unwrap()` on
//! `update_background` in the model round, or on `HybridLoop::new`, makes
//! the link fail and the script name the call (`core::result::unwrap_failed`).
//!
//! Why the proof holds for every input, not just one: every input (the table
//! lengths, the contact count, each contact's kind, vertices, barycentric
//! weights and imposed displacement, the output buffer lengths; for the
//! tensor-mass model every state-buffer length, the law and parameters, the
//! number of rounds on one model and whether each resets it, each vertex index
//! and value, the integrator, the time step, the tet index, the tool segment,
//! radius and capacity, which tearing criteria are on, their thresholds and
//! capacity; for the haptic loops each tool point's position, action and blade,
//! each surface buffer length, the cut capacity, whether tearing is on, its
//! thresholds and capacity) is read with `core::ptr::read_volatile` from a
//! `static mut` each time round the loop, so the optimiser must assume any
//! value (a debugger could write them). The tensor-mass calls run in a loop of
//! a volatile number of rounds on one model, so each also runs on any state the
//! others leave (tets removed, faulted, central-difference history valid);
//! likewise the loops tick a volatile number of times, so each tick and physics
//! update also runs on the contacts, grips and surface (faces exposed by cuts
//! and tears) the earlier ones leave. Every result is written with
//! `core::ptr::write_volatile`, so no computation can be dropped as dead.
//! `core::hint::black_box` is not used: its documentation says it must not be
//! relied on for correctness, and a too-weak barrier would make this check pass
//! vacuously. The table bytes themselves are link-time constants (only the
//! length passed to `load` is opaque), so strictly the proof is for these five
//! tables; the kernel does not rely on their values, as it reads every index
//! taken from a table through `get`.
//!
//! Never run; only linked. `tools/nopanic-check.sh` builds it.
#![no_std]
#![no_main]
// The only unsafe code: volatile access to the input/output statics and the
// call to the undefined symbol. The kernel itself stays `forbid(unsafe_code)`.
#![allow(unsafe_code)]

mod hybrid;
mod link;

use core::ptr::{addr_of, addr_of_mut, read_volatile, write_volatile};
use palpate_kernel::table::Plane;
use palpate_kernel::table::format::PLANE_LEN;

use cortex_m_rt::entry;
use nalgebra::Vector3;
use palpate_kernel::haptic::{
    DynamicLoop, ForceOutput, HapticLoop, LoopConfig, OutputStatus, PhysicsTissue, PrecomputedLoop,
    SafetyLimits, ToolAction, ToolInput,
};
use palpate_kernel::precomputed::{Constraint, PrecomputedTissue, QuasiNonLinear, Remap};
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::table::format::{
    EDGE_TERMS_LEN, TET_TERMS_LEN, TRIANGLE_TERMS_LEN, VERTEX_TERMS_LEN,
};
use palpate_kernel::tensor_mass::stvk_terms::TermArraysMut;
use palpate_kernel::tensor_mass::{
    DynamicParams, DynamicTissue, EdgeGroup, ElasticLaw, Extrapolation, Fault, Integrator,
    MAX_REMOVED_PER_UPDATE, PhysicsConfig, StateBuffers, StvkForm, SurfaceBuffers, TearThresholds,
    Tearing, TensorMassModel, VertexMode,
};
use palpate_kernel::{ContactSolution, MAX_CONTACTS, PrecomputedModel, PrecomputedTable};

/// The f32 table of the firmware example's box (64 vertices), 16-byte aligned
/// as `load` requires.
static TABLE: &[u8] = palpate_kernel::include_table!(concat!(env!("OUT_DIR"), "/table.bin"));

/// The same table compressed (`tools/box-table.sh --compress f16`): f16
/// codes, blocks dropped in both compliance parts.
static TABLE_F16: &[u8] =
    palpate_kernel::include_table!(concat!(env!("OUT_DIR"), "/table-f16.bin"));

/// The same table compressed (`tools/box-table.sh --compress q16`): q16
/// codes, blocks dropped in both compliance parts.
static TABLE_Q16: &[u8] =
    palpate_kernel::include_table!(concat!(env!("OUT_DIR"), "/table-q16.bin"));

/// One of the three pre-computed tables by a volatile selector (any value:
/// taken modulo 3; 0 the f32 table, 1 f16, 2 q16), so that the dense and
/// both coded compliance paths are all reachable from each call.
fn precomputed_table(selector: u8) -> &'static [u8] {
    match selector % 3 {
        0 => TABLE,
        1 => TABLE_F16,
        _ => TABLE_Q16,
    }
}

/// Capacity of the displacement buffers, vertices: the checked table has 64,
/// and the lengths actually passed are volatile inputs below that bound.
const VERTICES: usize = 64;

/// One more contact slot than the capacity, so that the "too many contacts"
/// refusal is reachable too.
const SLOTS: usize = MAX_CONTACTS + 1;

/// Everything the step path takes, opaque to the optimiser (see the crate
/// docs). Integers stand in for booleans so that any byte a debugger writes is
/// a valid value.
struct Inputs {
    /// Which table ([`precomputed_table`]).
    table: u8,
    /// Bytes of the table passed to `load` (clamped to the table length).
    table_len: usize,
    /// The contact set.
    contacts: ContactInputs,
    /// Entries passed to `displacements` (clamped to `VERTICES`).
    vertex_len: usize,
    /// Entries passed to `free_displacements` (clamped to `VERTICES`).
    free_len: usize,
    /// The quasi-non-linear remap's coefficients (radial `c_1..c_5`, its
    /// range, force `c_1..c_5`, its range); used when `Remap::new` accepts
    /// them, so the remapped force and field paths are in the proof.
    remap: [f32; 12],
}

/// A contact set, opaque to the optimiser.
#[derive(Clone, Copy)]
struct ContactInputs {
    /// Contacts in the set (clamped to `SLOTS`).
    count: usize,
    /// Non-zero: contact `p` is a triangle contact; zero: a vertex contact.
    on_triangle: [u8; SLOTS],
    /// Mesh vertex indices (a vertex contact uses the first).
    vertices: [[u32; 3]; SLOTS],
    /// Barycentric weights of a triangle contact, dimensionless.
    weights: [[f32; 3]; SLOTS],
    /// Imposed displacement of each contact point, m.
    displacement_m: [[f32; 3]; SLOTS],
}

/// No contact.
const NO_CONTACTS: ContactInputs = ContactInputs {
    count: 0,
    on_triangle: [0; SLOTS],
    vertices: [[0; 3]; SLOTS],
    weights: [[0.0; 3]; SLOTS],
    displacement_m: [[0.0; 3]; SLOTS],
};

impl ContactInputs {
    /// Every slot's constraint; the set is the first `count` of them
    /// ([`contact_set`]).
    fn constraints(&self) -> [Constraint<f32>; SLOTS] {
        core::array::from_fn(|p| {
            let (Some(&kind), Some(&vertices), Some(&weights), Some(&d)) = (
                self.on_triangle.get(p),
                self.vertices.get(p),
                self.weights.get(p),
                self.displacement_m.get(p),
            ) else {
                return Constraint::at_vertex(0, [0.0f32; 3].into());
            };
            if kind != 0 {
                Constraint::on_triangle(vertices, weights, d.into())
            } else {
                Constraint::at_vertex(vertices[0], d.into())
            }
        })
    }
}

/// The first `count` of `contacts` (all of them if `count` is larger).
fn contact_set(contacts: &[Constraint<f32>; SLOTS], count: usize) -> &[Constraint<f32>] {
    contacts.get(..count).unwrap_or(&contacts[..])
}

/// The inputs, read with `read_volatile` only.
static mut INPUTS: Inputs = Inputs {
    table: 0,
    table_len: usize::MAX,
    contacts: NO_CONTACTS,
    vertex_len: VERTICES,
    free_len: VERTICES,
    remap: [0.0; 12],
};

/// Where the results go, written with `write_volatile` only: the device force
/// (N), each contact force (N), and the vertex displacements (m).
struct Outputs {
    /// `-Σ g_q`, N.
    device_force_n: [f32; 3],
    /// `g_q`, N.
    contact_forces_n: [[f32; 3]; MAX_CONTACTS],
    /// Displacements from the last update, m.
    displacements_m: [[f32; 3]; VERTICES],
    /// Which call refused, as a counter per outcome (keeps the `Err` arms live).
    refusals: u32,
}

/// The outputs.
static mut OUTPUTS: Outputs = Outputs {
    device_force_n: [0.0; 3],
    contact_forces_n: [[0.0; 3]; MAX_CONTACTS],
    displacements_m: [[0.0; 3]; VERTICES],
    refusals: 0,
};

#[entry]
fn main() -> ! {
    let mut displacements = [[0.0f32; 3]; VERTICES];
    let mut state = TensorState::new();
    let mut surface = SurfaceState::new();
    let mut hybrid = hybrid::HybridState::new();
    loop {
        // SAFETY: single-threaded, no interrupt touches INPUTS or
        // TENSOR_INPUTS; a volatile read of a plain-old-data static is always
        // valid.
        let inputs = unsafe { read_volatile(addr_of!(INPUTS)) };
        precomputed_step(&inputs, &mut displacements);
        // SAFETY: as above.
        let inputs = unsafe { read_volatile(addr_of!(TENSOR_INPUTS)) };
        tensor_mass_step(&inputs, &mut state);
        // SAFETY: as above.
        let inputs = unsafe { read_volatile(addr_of!(HAPTIC_INPUTS)) };
        haptic_step(&inputs);
        // SAFETY: as above.
        let (tensor, dynamic) = unsafe {
            (
                read_volatile(addr_of!(TENSOR_INPUTS)),
                read_volatile(addr_of!(DYNAMIC_INPUTS)),
            )
        };
        dynamic_haptic_step(&tensor, &dynamic, &mut state, &mut surface);
        hybrid::model_step(&tensor, &mut state, &mut hybrid);
        hybrid::haptic_step(&tensor, &dynamic, &mut state, &mut surface, &mut hybrid);
        link::controller_step();
    }
}

/// Tool points of the checked haptic loop (a grasper's two jaws).
const TOOL_POINTS: usize = 2;

/// Everything the haptic loop takes, opaque to the optimiser.
struct HapticInputs {
    /// Which table ([`precomputed_table`]).
    table: u8,
    /// Bytes of the table passed to `load` (clamped to the table length).
    table_len: usize,
    /// Tool sphere radius (m), haptic period (s), force clamp (N), slew (N/s).
    config: [f32; 4],
    /// Ticks per round on one loop.
    ticks: u32,
    /// The tool points each tick (read again every tick).
    tools: ToolInputs,
    /// Non-zero: `reset` before the tick.
    reset: u8,
}

/// Each tool point's position and action, opaque to the optimiser.
#[derive(Clone, Copy)]
struct ToolInputs {
    /// Sphere centres, m.
    position_m: [[f32; 3]; TOOL_POINTS],
    /// `ToolAction` by index (any value: taken modulo 3; 0 touch, 1 grip,
    /// 2 cut).
    action: [u8; TOOL_POINTS],
    /// The blade of a cut, from the tool point to its other end, m.
    blade_m: [[f32; 3]; TOOL_POINTS],
}

/// All tool points touching at the origin.
const TOOLS_AT_REST: ToolInputs = ToolInputs {
    position_m: [[0.0; 3]; TOOL_POINTS],
    action: [0; TOOL_POINTS],
    blade_m: [[0.0; 3]; TOOL_POINTS],
};

impl ToolInputs {
    /// The loop's input: each point's position and the action its selector
    /// names (a cut with its blade vector).
    fn inputs(&self) -> [ToolInput<f32>; TOOL_POINTS] {
        core::array::from_fn(|p| {
            let (Some(&position_m), Some(&action), Some(&blade_m)) = (
                self.position_m.get(p),
                self.action.get(p),
                self.blade_m.get(p),
            ) else {
                return ToolInput::touch(Vector3::zeros());
            };
            ToolInput {
                position_m: position_m.into(),
                action: match action % 3 {
                    0 => ToolAction::Touch,
                    1 => ToolAction::Grip,
                    _ => ToolAction::Cut {
                        blade_m: blade_m.into(),
                    },
                },
            }
        })
    }
}

/// The haptic inputs, read with `read_volatile` only.
static mut HAPTIC_INPUTS: HapticInputs = HapticInputs {
    table: 0,
    table_len: usize::MAX,
    config: [0.002, 1e-3, 4.0, 2000.0],
    ticks: 1,
    tools: TOOLS_AT_REST,
    reset: 0,
};

/// What the haptic loop produced, written with `write_volatile` only.
struct HapticOutputs {
    force_n: [f32; 3],
    status: u8,
    contacts: u8,
    refused: u8,
    cut_refused: bool,
    solves: u32,
    /// The dynamic loop: tets the last physics update removed, how many
    /// and which (in removal order).
    removed_count: u32,
    removed: [u32; MAX_REMOVED_PER_UPDATE],
}

/// The haptic outputs.
static mut HAPTIC_OUTPUTS: HapticOutputs = HapticOutputs {
    force_n: [0.0; 3],
    status: 0,
    contacts: 0,
    refused: 0,
    cut_refused: false,
    solves: 0,
    removed_count: 0,
    removed: [0; MAX_REMOVED_PER_UPDATE],
};

/// The loop configuration from `[radius m, tick s, max force N, slew N/s]`.
fn loop_config([radius_m, dt_s, max_force_n, max_slew_n_per_s]: [f32; 4]) -> LoopConfig<f32> {
    LoopConfig {
        radius_m,
        dt_s,
        limits: SafetyLimits {
            max_force_n,
            max_slew_n_per_s,
        },
    }
}

/// Load, build the loop, then tick on volatile tool positions and actions
/// (`reset` on a volatile flag), publishing every output.
fn haptic_step(inputs: &HapticInputs) {
    let table = precomputed_table(inputs.table);
    let bytes = table.get(..inputs.table_len).unwrap_or(table);
    let Ok(table) = PrecomputedTable::<f32>::load(bytes) else {
        refused();
        return;
    };
    let Ok(mut haptic) = PrecomputedLoop::<f32, TOOL_POINTS, TOOL_POINTS>::new(
        PrecomputedTissue::new(&table),
        loop_config(inputs.config),
    ) else {
        refused();
        return;
    };
    for _ in 0..inputs.ticks {
        // SAFETY: single-threaded; plain-old-data static.
        let tick = unsafe { read_volatile(addr_of!(HAPTIC_INPUTS)) };
        if tick.reset != 0 {
            haptic.reset();
        }
        let out = haptic.tick_tools(&tick.tools.inputs());
        publish_tick(&out, haptic.counters().solves);
    }
}

/// Writes a tick's output to `HAPTIC_OUTPUTS` (volatile).
fn publish_tick(out: &ForceOutput<f32>, solves: u32) {
    let status = match out.status {
        OutputStatus::Ok => 0,
        OutputStatus::Clamped => 1,
        OutputStatus::Faulted(_) => 2,
        OutputStatus::ToolInside => 3,
    };
    let o = addr_of_mut!(HAPTIC_OUTPUTS);
    // SAFETY: single-threaded; plain-old-data fields of a live static.
    unsafe {
        write_volatile(addr_of_mut!((*o).force_n), out.force_n.into());
        write_volatile(addr_of_mut!((*o).status), status);
        write_volatile(addr_of_mut!((*o).contacts), out.contacts);
        write_volatile(addr_of_mut!((*o).refused), out.refused);
        write_volatile(addr_of_mut!((*o).cut_refused), out.cut_refused);
        write_volatile(addr_of_mut!((*o).solves), solves);
    }
}

/// Grid cells of the checked deforming surface's buffer.
const CELLS: usize = 128;

/// The dynamic haptic loop's inputs beyond the tensor-mass ones.
struct DynamicInputs {
    /// Entries given to `positions_m`, `triangles`, `face_slot`,
    /// `slot_tet`, `planes`, `vertex_triangle_start`, `vertex_triangle`,
    /// `cell_start`, `grid_vertex` and the force scratch (each clamped to
    /// its capacity).
    surface_lengths: [usize; 10],
    /// Integrator (as `TensorInputs::integrator`), extrapolation (0:
    /// secant, else instantaneous).
    integrator: u8,
    extrapolation: u8,
    /// Physics step, s, and steps per update.
    dt_s: f32,
    substeps: u32,
    /// Most tets the blades remove per update.
    cut_capacity_tets: u32,
    /// The blade sphere's push at which the tissue ahead gives way, N.
    cut_force_n: f32,
    /// Non-zero: tearing on, with each criterion (volume change, mean
    /// elongation, max elongation) on where `tear_on` is non-zero, with its
    /// threshold, and the capacity.
    tearing: u8,
    tear_on: [u8; 3],
    tear_thresholds: [f32; 3],
    tear_capacity_tets: u32,
    /// Loop configuration, as `HapticInputs::config`.
    config: [f32; 4],
    /// Ticks per round.
    ticks: u32,
    /// The tool points each tick (positions, actions, blades).
    tools: ToolInputs,
    /// Non-zero: `reset` before the tick; a physics update after it.
    reset: u8,
    update: u8,
}

/// The dynamic haptic inputs, read with `read_volatile` only.
static mut DYNAMIC_INPUTS: DynamicInputs = DynamicInputs {
    surface_lengths: [
        VERTICES,
        TRIANGLES - 1,
        TRIANGLES - 1,
        TRIANGLES - 1,
        TRIANGLES - 1,
        VERTICES + 1,
        3 * (TRIANGLES - 1),
        CELLS + 1,
        VERTICES,
        VERTICES,
    ],
    integrator: 1,
    extrapolation: 0,
    dt_s: 1e-3,
    substeps: 1,
    cut_capacity_tets: 8,
    cut_force_n: 0.2,
    tearing: 0,
    tear_on: [0; 3],
    tear_thresholds: [0.0; 3],
    tear_capacity_tets: 8,
    config: [0.002, 1e-3, 4.0, 2000.0],
    ticks: 1,
    tools: TOOLS_AT_REST,
    reset: 0,
    update: 1,
};

/// The deforming surface's storage (fixed capacity, sliced to the volatile
/// lengths). The per-face buffers hold one more entry than the table's 378
/// mesh triangles (as `TRIANGLES`), so a too-long buffer is reachable as well
/// as a too-short one.
struct SurfaceState {
    positions_m: [[f32; 3]; VERTICES],
    triangles: [[u32; 3]; TRIANGLES],
    face_slot: [u32; TRIANGLES],
    slot_tet: [u32; TRIANGLES],
    planes: [Plane<f32>; TRIANGLES],
    vertex_triangle_start: [u32; VERTICES + 1],
    vertex_triangle: [u32; 3 * TRIANGLES],
    cell_start: [u32; CELLS + 1],
    grid_vertex: [u32; VERTICES],
    forces_n: [[f32; 3]; VERTICES],
}

impl SurfaceState {
    fn new() -> Self {
        Self {
            positions_m: [[0.0; 3]; VERTICES],
            triangles: [[0; 3]; TRIANGLES],
            face_slot: [0; TRIANGLES],
            slot_tet: [0; TRIANGLES],
            planes: [[0.0; PLANE_LEN]; TRIANGLES],
            vertex_triangle_start: [0; VERTICES + 1],
            vertex_triangle: [0; 3 * TRIANGLES],
            cell_start: [0; CELLS + 1],
            grid_vertex: [0; VERTICES],
            forces_n: [[0.0; 3]; VERTICES],
        }
    }

    /// The surface buffers and the force scratch, each the first
    /// `lengths` entries of its array (`DynamicInputs::surface_lengths`).
    fn buffers(
        &mut self,
        [p, tr, fs, st, pl, vs, vt, c, g, f]: [usize; 10],
    ) -> (SurfaceBuffers<'_, f32>, &mut [[f32; 3]]) {
        let buffers = SurfaceBuffers {
            positions_m: prefix(&mut self.positions_m, p),
            triangles: prefix(&mut self.triangles, tr),
            face_slot: prefix(&mut self.face_slot, fs),
            slot_tet: prefix(&mut self.slot_tet, st),
            planes: prefix(&mut self.planes, pl),
            vertex_triangle_start: prefix(&mut self.vertex_triangle_start, vs),
            vertex_triangle: prefix(&mut self.vertex_triangle, vt),
            cell_start: prefix(&mut self.cell_start, c),
            grid_vertex: prefix(&mut self.grid_vertex, g),
        };
        (buffers, prefix(&mut self.forces_n, f))
    }
}

/// Load, model, dynamic tissue and loop on volatile inputs (surface buffer
/// lengths, physics configuration with cut capacity and tearing), then
/// ticks on volatile tool positions and actions (touch, grip, cut) with
/// physics updates (cuts, tearing, exposed faces) and resets on volatile
/// flags, publishing every output and the tets each update removed.
fn dynamic_haptic_step(
    tensor: &TensorInputs,
    inputs: &DynamicInputs,
    state: &mut TensorState,
    surface: &mut SurfaceState,
) {
    let bytes = TENSOR_TABLE.get(..tensor.table_len).unwrap_or(TENSOR_TABLE);
    let Ok(table) = TensorMassTable::<f32>::load(bytes) else {
        refused();
        return;
    };
    let Ok(model) = TensorMassModel::new(table, state.buffers(&tensor.lengths), params(tensor))
    else {
        refused();
        return;
    };
    let (buffers, forces) = surface.buffers(inputs.surface_lengths);
    let Ok(tissue) =
        DynamicTissue::<f32, TOOL_POINTS>::new(model, buffers, forces, physics_config(inputs))
    else {
        refused();
        return;
    };
    let Ok(haptic) =
        DynamicLoop::<f32, TOOL_POINTS, TOOL_POINTS>::new(tissue, loop_config(inputs.config))
    else {
        refused();
        return;
    };
    tick_with_physics(haptic, |tissue| tissue.removed());
}

/// The physics configuration of `inputs`: integrator, extrapolation, step,
/// sub-steps, cut capacity and force, tearing.
fn physics_config(inputs: &DynamicInputs) -> PhysicsConfig<f32> {
    PhysicsConfig {
        extrapolation: if inputs.extrapolation == 0 {
            Extrapolation::Secant
        } else {
            Extrapolation::Instantaneous
        },
        integrator: integrator(inputs.integrator),
        dt_s: inputs.dt_s,
        substeps: inputs.substeps,
        cut_capacity_tets: inputs.cut_capacity_tets,
        cut_force_n: inputs.cut_force_n,
        tearing: (inputs.tearing != 0).then_some(Tearing {
            thresholds: tear_thresholds(inputs.tear_on, inputs.tear_thresholds),
            capacity_tets: inputs.tear_capacity_tets,
        }),
    }
}

/// Ticks `haptic` `DYNAMIC_INPUTS.ticks` times on freshly read tool points,
/// with `reset` and `physics_update` on volatile flags, publishing every
/// output and the tets each update removed (`removed` of the tissue).
fn tick_with_physics<B: PhysicsTissue<f32, TOOL_POINTS>>(
    mut haptic: HapticLoop<f32, B, TOOL_POINTS, TOOL_POINTS>,
    removed: impl Fn(&B) -> &[u32],
) {
    // SAFETY: single-threaded; plain-old-data static.
    let ticks = unsafe { read_volatile(addr_of!(DYNAMIC_INPUTS)) }.ticks;
    for _ in 0..ticks {
        // SAFETY: as above.
        let tick = unsafe { read_volatile(addr_of!(DYNAMIC_INPUTS)) };
        if tick.reset != 0 {
            haptic.reset();
        }
        let out = haptic.tick_tools(&tick.tools.inputs());
        publish_tick(&out, haptic.counters().solves);
        if tick.update != 0 && haptic.physics_update().is_err() {
            refused();
        }
        publish_removed(removed(haptic.tissue()));
    }
}

/// Writes the tets the last physics update removed to `HAPTIC_OUTPUTS`
/// (volatile): their count and the list.
fn publish_removed(removed: &[u32]) {
    let o = addr_of_mut!(HAPTIC_OUTPUTS);
    // SAFETY: single-threaded; plain-old-data fields of a live static.
    unsafe {
        write_volatile(addr_of_mut!((*o).removed_count), removed.len() as u32);
        let list = &mut *addr_of_mut!((*o).removed);
        for (t, slot) in removed.iter().zip(list.iter_mut()) {
            write_volatile(slot, *t);
        }
    }
}

/// One tick of the pre-computed model: load, contact forces, both
/// displacement updates, on `inputs`.
fn precomputed_step(inputs: &Inputs, displacements: &mut [[f32; 3]; VERTICES]) {
    let table = precomputed_table(inputs.table);
    let bytes = table.get(..inputs.table_len).unwrap_or(table);
    let Ok(table) = PrecomputedTable::<f32>::load(bytes) else {
        refused();
        return;
    };
    let model = PrecomputedModel::new(table);
    let [r @ .., r_max, f1, f2, f3, f4, f5, f_max] = inputs.remap;
    let model = match (
        Remap::new(r, r_max),
        Remap::new([f1, f2, f3, f4, f5], f_max),
    ) {
        (Ok(radial), Ok(force)) => model.with_remap(QuasiNonLinear { radial, force }),
        _ => model,
    };

    let contacts = inputs.contacts.constraints();
    let set = contact_set(&contacts, inputs.contacts.count);
    let Ok(solution) = model.contact_forces::<MAX_CONTACTS>(set) else {
        refused();
        return;
    };
    publish_solution(&solution);

    let vertex_len = inputs.vertex_len.min(VERTICES);
    if model
        .displacements(&solution, &mut displacements[..vertex_len])
        .is_err()
    {
        refused();
    }
    publish(displacements);
    let free_len = inputs.free_len.min(VERTICES);
    if model
        .free_displacements(&solution, &mut displacements[..free_len])
        .is_err()
    {
        refused();
    }
    publish(displacements);
}

/// Writes the device force and each contact force of `solution` to
/// `OUTPUTS` (volatile).
fn publish_solution(solution: &ContactSolution<f32, MAX_CONTACTS>) {
    let out = addr_of_mut!(OUTPUTS);
    // SAFETY: single-threaded, `out` points to a live static, every field is
    // plain old data.
    unsafe {
        write_volatile(
            addr_of_mut!((*out).device_force_n),
            solution.device_force_n().into(),
        );
        for (g, o) in solution
            .contact_forces_n()
            .iter()
            .zip((*out).contact_forces_n.iter_mut())
        {
            write_volatile(o, (*g).into());
        }
    }
}

/// Counts a refusal (volatile, so the error arms are not dead code).
fn refused() {
    let out = addr_of_mut!(OUTPUTS);
    // SAFETY: single-threaded; plain-old-data field of a live static.
    unsafe {
        let n = read_volatile(addr_of!((*out).refusals));
        write_volatile(addr_of_mut!((*out).refusals), n.wrapping_add(1));
    }
}

/// Writes the displacement buffer to `OUTPUTS` (volatile, so the updates are
/// not dead code).
fn publish(displacements: &[[f32; 3]; VERTICES]) {
    let out = addr_of_mut!(OUTPUTS);
    // SAFETY: single-threaded; plain-old-data field of a live static.
    unsafe {
        for (u, o) in displacements.iter().zip((*out).displacements_m.iter_mut()) {
            write_volatile(o, *u);
        }
    }
}

/// The f32 tensor-mass table of the same box (64 vertices, 279 edges, 162
/// tets), 16-byte aligned as `load` requires.
static TENSOR_TABLE: &[u8] =
    palpate_kernel::include_table!(concat!(env!("OUT_DIR"), "/tensor_table.bin"));

/// Capacity of the edge-term buffer: the checked table has 279 edges; one
/// more than that, so that a too-long `edge_terms` is reachable as well as
/// a too-short one.
const EDGES: usize = 280;

/// Capacity of the edge-group buffer: the checked table needs 78 groups of
/// 4 edges (`StateBuffers::edge_group_count`); one more, as for `EDGES`.
const EDGE_GROUPS: usize = 79;

/// Capacity of the per-tet buffer: the checked table has 162 tets.
const TETS: usize = 162;

/// Capacity of the RK4 scratch: `4N`.
const RK4: usize = 4 * VERTICES;

/// Capacity of the mesh-triangle term buffer: the checked table has 378
/// triangles (every face of every tet once); one more, as for `EDGES`.
const TRIANGLES: usize = 379;

/// Capacity of the surface output: a live surface has at most `4 × tets`
/// triangles.
const SURFACE: usize = 4 * TETS;

/// Entries given to each `StateBuffers` field, each clamped to its capacity
/// (any other length than the table's is refused by `TensorMassModel::new`).
#[derive(Clone, Copy)]
struct BufferLengths {
    vertex_tensors: usize,
    edge_groups: usize,
    edge_group_starts: usize,
    masses_kg: usize,
    tet_alive: usize,
    live_tets: usize,
    modes: usize,
    displacement_m: usize,
    velocity_m_s: usize,
    previous_displacement_m: usize,
    external_force_n: usize,
    force_n: usize,
    /// Zero means no RK4 scratch (RK4 refused by `step`); `4N` is accepted.
    rk4_scratch: usize,
    /// St Venant-Kirchhoff split-term buffers: all zero means none (the
    /// tensors form is refused by `new`); the table's counts are accepted.
    vertex_terms: usize,
    edge_terms: usize,
    triangle_terms: usize,
    tet_terms: usize,
}

/// Everything the tensor-mass path takes, opaque to the optimiser (see the
/// crate docs). Integers stand in for booleans and enums so that any byte a
/// debugger writes is a valid value.
struct TensorInputs {
    /// Bytes of `TENSOR_TABLE` passed to `load` (clamped to the table length).
    table_len: usize,
    /// State-buffer lengths.
    lengths: BufferLengths,
    /// Rounds per tick on one model (`tensor_mass_step`).
    rounds: u32,
    /// Non-zero: `reset` at the start of the round.
    reset: u8,
    /// `ElasticLaw` by index (any value: taken modulo 5; the tensor form of
    /// St Venant-Kirchhoff is refused by `new` without the term buffers).
    law: u8,
    /// Non-zero: the incompressibility penalty is on, with this `γ`, N.
    incompressibility_on: u8,
    incompressibility_n: f32,
    /// Mass-proportional damping, 1/s.
    damping_per_s: f32,
    /// Gravity, m/s².
    gravity_m_s2: [f32; 3],
    /// Divergence bound on a displacement norm, m.
    max_displacement_m: f32,
    /// Divergence bound on the kinetic energy, J.
    max_kinetic_energy_j: f32,
    /// `set_external_force`: vertex and force, N.
    force_vertex: u32,
    force_n: [f32; 3],
    /// `set_velocity`: vertex and velocity, m/s.
    velocity_vertex: u32,
    velocity_m_s: [f32; 3],
    /// `impose`: vertex and displacement, m.
    impose_vertex: u32,
    impose_m: [f32; 3],
    /// `release`: vertex.
    release_vertex: u32,
    /// Non-zero: `clear_external_forces` before the step.
    clear_forces: u8,
    /// `Integrator` by index (any value: taken modulo 4).
    integrator: u8,
    /// Time step, s.
    dt_s: f32,
    /// `remove_tet`: tet index.
    remove_tet: u32,
    /// `cut_with_tool`: segment ends, m, radius, m, and capacity.
    tool_a_m: [f32; 3],
    tool_b_m: [f32; 3],
    tool_radius_m: f32,
    cut_capacity: u32,
    /// `tear`: non-zero switches each criterion on (volume change, mean
    /// elongation, max elongation), with its threshold; and the capacity.
    tear_on: [u8; 3],
    tear_thresholds: [f32; 3],
    tear_capacity: u32,
    /// Entries passed to `elastic_forces_n` (clamped to `VERTICES`).
    forces_len: usize,
}

/// The tensor-mass inputs, read with `read_volatile` only.
static mut TENSOR_INPUTS: TensorInputs = TensorInputs {
    table_len: usize::MAX,
    lengths: BufferLengths {
        vertex_tensors: VERTICES,
        edge_groups: EDGE_GROUPS - 1,
        edge_group_starts: VERTICES + 1,
        masses_kg: VERTICES,
        tet_alive: TETS,
        live_tets: VERTICES,
        modes: VERTICES,
        displacement_m: VERTICES,
        velocity_m_s: VERTICES,
        previous_displacement_m: VERTICES,
        external_force_n: VERTICES,
        force_n: VERTICES,
        rk4_scratch: RK4,
        vertex_terms: VERTICES,
        edge_terms: EDGES - 1,
        triangle_terms: TRIANGLES - 1,
        tet_terms: TETS,
    },
    rounds: 1,
    reset: 0,
    law: 0,
    incompressibility_on: 0,
    incompressibility_n: 0.0,
    damping_per_s: 0.0,
    gravity_m_s2: [0.0; 3],
    max_displacement_m: f32::INFINITY,
    max_kinetic_energy_j: f32::INFINITY,
    force_vertex: 0,
    force_n: [0.0; 3],
    velocity_vertex: 0,
    velocity_m_s: [0.0; 3],
    impose_vertex: 0,
    impose_m: [0.0; 3],
    release_vertex: 0,
    clear_forces: 0,
    integrator: 0,
    dt_s: 0.001,
    remove_tet: 0,
    tool_a_m: [0.0; 3],
    tool_b_m: [0.0; 3],
    tool_radius_m: 0.0,
    cut_capacity: 0,
    tear_on: [0; 3],
    tear_thresholds: [0.0; 3],
    tear_capacity: 0,
    forces_len: VERTICES,
};

/// Where the tensor-mass results go, written with `write_volatile` only.
struct TensorOutputs {
    /// Displacements after the step, m.
    displacements_m: [[f32; 3]; VERTICES],
    /// Velocities after the step, m/s.
    velocities_m_s: [[f32; 3]; VERTICES],
    /// Elastic forces after the cuts, N.
    elastic_forces_n: [[f32; 3]; VERTICES],
    /// The fault: 0 none, 1 non-finite, 2 displacement bound, 3 kinetic
    /// energy bound; then the vertex (0 for 3).
    fault: [u32; 2],
    /// Kinetic energy after the step, J, and its force evaluations.
    kinetic_energy_j: f32,
    force_evaluations: u32,
    /// Tets removed by `remove_tet`, `cut_with_tool` and `tear`, and the
    /// two `pending` flags.
    removed: [u32; 3],
    pending: [bool; 2],
    /// The live surface: triangle count and the triangles.
    surface_count: u32,
    surface_triangles: [[u32; 3]; SURFACE],
}

/// The tensor-mass outputs.
static mut TENSOR_OUTPUTS: TensorOutputs = TensorOutputs {
    displacements_m: [[0.0; 3]; VERTICES],
    velocities_m_s: [[0.0; 3]; VERTICES],
    elastic_forces_n: [[0.0; 3]; VERTICES],
    fault: [0; 2],
    kinetic_energy_j: 0.0,
    force_evaluations: 0,
    removed: [0; 3],
    pending: [false; 2],
    surface_count: 0,
    surface_triangles: [[0; 3]; SURFACE],
};

/// The storage behind `StateBuffers`: fixed-capacity arrays (on `main`'s
/// stack), sliced to the volatile lengths each tick.
struct TensorState {
    vertex_tensors: [[f32; 9]; VERTICES],
    edge_groups: [EdgeGroup<f32>; EDGE_GROUPS],
    edge_group_starts: [u32; VERTICES + 2],
    masses_kg: [f32; VERTICES],
    tet_alive: [bool; TETS],
    live_tets: [u32; VERTICES],
    modes: [VertexMode; VERTICES],
    displacement_m: [[f32; 3]; VERTICES],
    velocity_m_s: [[f32; 3]; VERTICES],
    previous_displacement_m: [[f32; 3]; VERTICES],
    external_force_n: [[f32; 3]; VERTICES],
    force_n: [[f32; 3]; VERTICES],
    rk4_scratch: [[f32; 3]; RK4],
    vertex_terms: [[f32; VERTEX_TERMS_LEN]; VERTICES],
    edge_terms: [[f32; EDGE_TERMS_LEN]; EDGES],
    triangle_terms: [[f32; TRIANGLE_TERMS_LEN]; TRIANGLES],
    tet_terms: [[f32; TET_TERMS_LEN]; TETS],
}

impl TensorState {
    fn new() -> Self {
        Self {
            vertex_tensors: [[0.0; 9]; VERTICES],
            edge_groups: [EdgeGroup::default(); EDGE_GROUPS],
            edge_group_starts: [0; VERTICES + 2],
            masses_kg: [0.0; VERTICES],
            tet_alive: [false; TETS],
            live_tets: [0; VERTICES],
            modes: [VertexMode::Free; VERTICES],
            displacement_m: [[0.0; 3]; VERTICES],
            velocity_m_s: [[0.0; 3]; VERTICES],
            previous_displacement_m: [[0.0; 3]; VERTICES],
            external_force_n: [[0.0; 3]; VERTICES],
            force_n: [[0.0; 3]; VERTICES],
            rk4_scratch: [[0.0; 3]; RK4],
            vertex_terms: [[0.0; VERTEX_TERMS_LEN]; VERTICES],
            edge_terms: [[0.0; EDGE_TERMS_LEN]; EDGES],
            triangle_terms: [[0.0; TRIANGLE_TERMS_LEN]; TRIANGLES],
            tet_terms: [[0.0; TET_TERMS_LEN]; TETS],
        }
    }

    /// The buffers, each the first `lengths` entries of its array.
    fn buffers(&mut self, n: &BufferLengths) -> StateBuffers<'_, f32> {
        StateBuffers {
            vertex_tensors: prefix(&mut self.vertex_tensors, n.vertex_tensors),
            edge_groups: prefix(&mut self.edge_groups, n.edge_groups),
            edge_group_starts: prefix(&mut self.edge_group_starts, n.edge_group_starts),
            masses_kg: prefix(&mut self.masses_kg, n.masses_kg),
            tet_alive: prefix(&mut self.tet_alive, n.tet_alive),
            live_tets: prefix(&mut self.live_tets, n.live_tets),
            modes: prefix(&mut self.modes, n.modes),
            displacement_m: prefix(&mut self.displacement_m, n.displacement_m),
            velocity_m_s: prefix(&mut self.velocity_m_s, n.velocity_m_s),
            previous_displacement_m: prefix(
                &mut self.previous_displacement_m,
                n.previous_displacement_m,
            ),
            external_force_n: prefix(&mut self.external_force_n, n.external_force_n),
            force_n: prefix(&mut self.force_n, n.force_n),
            rk4_scratch: prefix(&mut self.rk4_scratch, n.rk4_scratch),
            stvk_terms: TermArraysMut {
                vertex: prefix(&mut self.vertex_terms, n.vertex_terms),
                edge: prefix(&mut self.edge_terms, n.edge_terms),
                triangle: prefix(&mut self.triangle_terms, n.triangle_terms),
                tet: prefix(&mut self.tet_terms, n.tet_terms),
            },
        }
    }
}

/// The first `n` entries of `s` (all of them if `n` is larger).
fn prefix<E>(s: &mut [E], n: usize) -> &mut [E] {
    let n = n.min(s.len());
    &mut s[..n]
}

/// `None` unless `on` is non-zero.
fn option(on: u8, value: f32) -> Option<f32> {
    (on != 0).then_some(value)
}

/// Tearing thresholds: each criterion (volume change, mean elongation, max
/// elongation) on where its flag is non-zero, with its value.
fn tear_thresholds(
    [volume_on, mean_on, max_on]: [u8; 3],
    [volume, mean, max]: [f32; 3],
) -> TearThresholds<f32> {
    TearThresholds {
        volume_change: option(volume_on, volume),
        mean_elongation: option(mean_on, mean),
        max_elongation: option(max_on, max),
    }
}

/// The integrator a byte names.
fn integrator(code: u8) -> Integrator {
    match code % 4 {
        0 => Integrator::ExplicitEuler,
        1 => Integrator::SymplecticEuler,
        2 => Integrator::Rk4,
        _ => Integrator::CentralDifference,
    }
}

/// The dynamic parameters of `inputs` (law, penalty, damping, gravity,
/// divergence limits).
fn params(inputs: &TensorInputs) -> DynamicParams<f32> {
    let law = match inputs.law % 5 {
        0 => ElasticLaw::Linear,
        1 => ElasticLaw::StVenantKirchhoff(StvkForm::PerTet),
        2 => ElasticLaw::StVenantKirchhoff(StvkForm::Tensors),
        3 => ElasticLaw::Corotational,
        _ => ElasticLaw::NeoHookean,
    };
    DynamicParams::linear(inputs.damping_per_s, inputs.max_displacement_m)
        .with_law(law)
        .with_incompressibility(option(
            inputs.incompressibility_on,
            inputs.incompressibility_n,
        ))
        .with_gravity(inputs.gravity_m_s2.into())
        .with_max_kinetic_energy(inputs.max_kinetic_energy_j)
}

/// One tick of the tensor-mass model: load and model on `inputs`, then
/// `inputs.rounds` rounds on the same model, each on freshly read inputs
/// (see [`tensor_mass_round`]), so that every call also runs on a state any
/// earlier round may have left: tets removed, the central-difference history
/// valid, the model faulted.
fn tensor_mass_step(inputs: &TensorInputs, state: &mut TensorState) {
    let bytes = TENSOR_TABLE.get(..inputs.table_len).unwrap_or(TENSOR_TABLE);
    let Ok(table) = TensorMassTable::<f32>::load(bytes) else {
        refused();
        return;
    };
    let Ok(mut model) = TensorMassModel::new(table, state.buffers(&inputs.lengths), params(inputs))
    else {
        refused();
        return;
    };
    for _ in 0..inputs.rounds {
        // SAFETY: as in `main`.
        let inputs = unsafe { read_volatile(addr_of!(TENSOR_INPUTS)) };
        tensor_mass_round(&mut model, &inputs);
    }
}

/// One round: optional reset, per-vertex inputs, one step, tet removal, cut,
/// tear, surface, outputs.
fn tensor_mass_round(model: &mut TensorMassModel<'_, '_, f32>, inputs: &TensorInputs) {
    if inputs.reset != 0 {
        model.reset();
    }
    let results = [
        model.set_external_force(inputs.force_vertex, inputs.force_n.into()),
        model.set_velocity(inputs.velocity_vertex, inputs.velocity_m_s.into()),
        model.impose(inputs.impose_vertex, inputs.impose_m.into()),
        model.release(inputs.release_vertex),
    ];
    for result in results {
        if result.is_err() {
            refused();
        }
    }
    if inputs.clear_forces != 0 {
        model.clear_external_forces();
    }

    let out = addr_of_mut!(TENSOR_OUTPUTS);
    match model.step(integrator(inputs.integrator), inputs.dt_s) {
        // SAFETY (all volatile writes in this function): single-threaded,
        // `out` points to a live static, every field is plain old data.
        Ok(report) => unsafe {
            write_volatile(
                addr_of_mut!((*out).kinetic_energy_j),
                report.kinetic_energy_j,
            );
            write_volatile(
                addr_of_mut!((*out).force_evaluations),
                report.force_evaluations,
            );
        },
        Err(_) => refused(),
    }
    let fault = match model.fault() {
        None => [0, 0],
        Some(Fault::NonFinite { vertex }) => [1, vertex],
        Some(Fault::DisplacementBound { vertex }) => [2, vertex],
        Some(Fault::KineticEnergyBound) => [3, 0],
    };
    // SAFETY: see above.
    unsafe { write_volatile(addr_of_mut!((*out).fault), fault) };
    match model.displacements_m() {
        // SAFETY: see above.
        Ok(u) => unsafe { publish_vectors(u, addr_of_mut!((*out).displacements_m)) },
        Err(_) => refused(),
    }
    match model.velocities_m_s() {
        // SAFETY: see above.
        Ok(v) => unsafe { publish_vectors(v, addr_of_mut!((*out).velocities_m_s)) },
        Err(_) => refused(),
    }

    let removed = model.remove_tet(inputs.remove_tet).unwrap_or_else(|_| {
        refused();
        0
    });
    let cut = model.cut_with_tool(
        inputs.tool_a_m.into(),
        inputs.tool_b_m.into(),
        inputs.tool_radius_m,
        inputs.cut_capacity,
    );
    let thresholds = tear_thresholds(inputs.tear_on, inputs.tear_thresholds);
    let tear = model.tear(&thresholds, inputs.tear_capacity);
    // SAFETY: see above.
    unsafe {
        write_volatile(
            addr_of_mut!((*out).removed),
            [removed, cut.removed, tear.removed],
        );
        write_volatile(addr_of_mut!((*out).pending), [cut.pending, tear.pending]);
    }

    let mut count = 0u32;
    // SAFETY: see above.
    unsafe {
        let triangles = &mut *addr_of_mut!((*out).surface_triangles);
        for (triangle, o) in model.surface_triangles().zip(triangles.iter_mut()) {
            write_volatile(o, triangle);
            count += 1;
        }
        write_volatile(addr_of_mut!((*out).surface_count), count);
    }

    let mut forces = [[0.0f32; 3]; VERTICES];
    let forces_len = inputs.forces_len.min(VERTICES);
    model.elastic_forces_n(&mut forces[..forces_len]);
    // SAFETY: see above.
    unsafe { publish_vectors(&forces, addr_of_mut!((*out).elastic_forces_n)) };
}

/// Writes `values` to the output array at `out`, volatile, entry by entry
/// (as many as both hold).
///
/// # Safety
/// `out` points to a live output array no one else accesses meanwhile.
unsafe fn publish_vectors(values: &[[f32; 3]], out: *mut [[f32; 3]; VERTICES]) {
    // SAFETY: the caller's contract.
    let out = unsafe { &mut *out };
    for (u, o) in values.iter().zip(out.iter_mut()) {
        // SAFETY: `o` is a valid, aligned element of `out`.
        unsafe { write_volatile(o, *u) };
    }
}

#[cfg(not(feature = "locate"))]
unsafe extern "C" {
    /// Defined nowhere: referencing it fails the link.
    fn palpate_step_path_can_panic() -> !;
}

/// Reachable only if some panic is: then the link fails on the undefined
/// symbol, which is the point of this crate.
#[cfg(not(feature = "locate"))]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo<'_>) -> ! {
    // SAFETY: never executed; the link fails if this handler is reachable.
    unsafe { palpate_step_path_can_panic() }
}

/// With `--features locate` (used by `tools/nopanic-check.sh` after a failed
/// link) the handler is an ordinary loop, so the program links and its
/// disassembly shows which code calls into `core::panicking`.
#[cfg(feature = "locate")]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo<'_>) -> ! {
    loop {
        core::hint::spin_loop();
    }
}
