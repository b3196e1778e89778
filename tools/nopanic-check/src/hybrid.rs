//! The hybrid model (RR-3510 §6.2) in the no-panic proof (crate docs): on
//! the three f32 tables of the firmware's hybrid box (`tools/hybrid-tables.sh`:
//! the top corner cell a tensor-mass region, the rest pre-computed), the
//! scripted model's calls ([`model_step`]) and the haptic loop over the
//! hybrid tissue ([`haptic_step`]), every input read volatile from
//! [`HYBRID_INPUTS`] (and, for the tensor-mass region's parameters and the
//! loop's tool points and physics, from `TENSOR_INPUTS` and
//! `DYNAMIC_INPUTS`, as the dynamic loop reads them), every result written
//! volatile.

use core::ptr::{addr_of, addr_of_mut, read_volatile, write_volatile};
use palpate_kernel::table::Plane;
use palpate_kernel::table::format::PLANE_LEN;

use palpate_kernel::haptic::HybridLoop;
use palpate_kernel::hybrid::{HybridBuffers, HybridModel, HybridSurfaceBuffers, HybridTissue};
use palpate_kernel::table::{InterfaceTable, TensorMassTable};
use palpate_kernel::tensor_mass::TensorMassModel;
use palpate_kernel::{MAX_CONTACTS, PrecomputedTable, include_table};

use super::{
    BufferLengths, CELLS, ContactInputs, DynamicInputs, NO_CONTACTS, SurfaceState, TOOL_POINTS,
    TRIANGLES, TensorInputs, TensorState, VERTICES, contact_set, integrator, loop_config, params,
    physics_config, prefix, publish, publish_solution, refused, tick_with_physics,
};

/// The pre-computed region's table (connection nodes fixed), 16-byte aligned.
static PRECOMPUTED: &[u8] = include_table!(concat!(env!("OUT_DIR"), "/hybrid/precomputed.bin"));
/// The tensor-mass region's table.
static DYNAMIC: &[u8] = include_table!(concat!(env!("OUT_DIR"), "/hybrid/dynamic.bin"));
/// The interface table.
static INTERFACE: &[u8] = include_table!(concat!(env!("OUT_DIR"), "/hybrid/interface.bin"));

/// Everything the hybrid paths take beyond `TENSOR_INPUTS` and
/// `DYNAMIC_INPUTS`, opaque to the optimiser.
struct HybridInputs {
    /// Bytes of each table passed to `load`: pre-computed, tensor-mass,
    /// interface (each clamped to its table's length).
    table_lens: [usize; 3],
    /// The tensor-mass region's state-buffer lengths.
    lengths: BufferLengths,
    /// Entries of `passed_force_n` and `background_m` (`HybridBuffers`).
    coupling_lengths: [usize; 2],
    /// Entries of the tensor-mass region's surface buffers, as
    /// `DynamicInputs::surface_lengths`.
    surface_lengths: [usize; 10],
    /// Entries of the hybrid surface's `positions_m`, `triangles`, `planes`,
    /// `vertex_triangle_start`, `vertex_triangle`, `cell_start`,
    /// `grid_vertex`, `mesh_vertex`.
    hybrid_surface_lengths: [usize; 8],
    /// Rounds per tick on one scripted model.
    rounds: u32,
    /// Non-zero: `reset` at the start of the round.
    reset: u8,
    /// `impose` on the tensor-mass region: vertex and displacement, m.
    impose_vertex: u32,
    impose_m: [f32; 3],
    /// Rows of `update_background`.
    background_rows: usize,
    /// The contact set on the pre-computed region.
    contacts: ContactInputs,
    /// Non-zero: `pass_contact_forces` with the solution; zero: with none.
    pass: u8,
    /// `Integrator` by index (taken modulo 4) and time step, s.
    integrator: u8,
    dt_s: f32,
    /// Entries passed to `displacements` (clamped to `VERTICES`).
    vertex_len: usize,
}

/// The hybrid inputs, read with `read_volatile` only.
static mut HYBRID_INPUTS: HybridInputs = HybridInputs {
    table_lens: [usize::MAX; 3],
    lengths: BufferLengths {
        vertex_tensors: 8,
        edge_groups: 8,
        edge_group_starts: 9,
        masses_kg: 8,
        tet_alive: 6,
        live_tets: 8,
        modes: 8,
        displacement_m: 8,
        velocity_m_s: 8,
        previous_displacement_m: 8,
        external_force_n: 8,
        force_n: 8,
        rk4_scratch: 32,
        vertex_terms: 0,
        edge_terms: 0,
        triangle_terms: 0,
        tet_terms: 0,
    },
    coupling_lengths: [7, 40],
    surface_lengths: [8, 18, 18, 18, 18, 9, 54, CELLS + 1, 8, 8],
    hybrid_surface_lengths: [
        VERTICES,
        TRIANGLES,
        TRIANGLES,
        VERTICES + 1,
        3 * TRIANGLES,
        CELLS + 1,
        VERTICES,
        8,
    ],
    rounds: 1,
    reset: 0,
    impose_vertex: 7,
    impose_m: [0.0; 3],
    background_rows: usize::MAX,
    contacts: NO_CONTACTS,
    pass: 1,
    integrator: 1,
    dt_s: 5e-4,
    vertex_len: VERTICES,
};

/// Where the hybrid results go that `OUTPUTS` and `TENSOR_OUTPUTS` do not
/// hold, written with `write_volatile` only.
struct HybridOutputs {
    /// Kinetic energy after the step, J, and its force evaluations.
    kinetic_energy_j: f32,
    force_evaluations: u32,
}

/// The hybrid outputs.
static mut HYBRID_OUTPUTS: HybridOutputs = HybridOutputs {
    kinetic_energy_j: 0.0,
    force_evaluations: 0,
};

/// The coupling's and the hybrid surface's storage (fixed capacity, sliced
/// to the volatile lengths).
pub(super) struct HybridState {
    passed_force_n: [[f32; 3]; VERTICES],
    background_m: [[f32; 3]; VERTICES],
    positions_m: [[f32; 3]; VERTICES],
    triangles: [[u32; 3]; TRIANGLES],
    planes: [Plane<f32>; TRIANGLES],
    vertex_triangle_start: [u32; VERTICES + 1],
    vertex_triangle: [u32; 3 * TRIANGLES],
    cell_start: [u32; CELLS + 1],
    grid_vertex: [u32; VERTICES],
    mesh_vertex: [u32; VERTICES],
}

impl HybridState {
    pub(super) fn new() -> Self {
        Self {
            passed_force_n: [[0.0; 3]; VERTICES],
            background_m: [[0.0; 3]; VERTICES],
            positions_m: [[0.0; 3]; VERTICES],
            triangles: [[0; 3]; TRIANGLES],
            planes: [[0.0; PLANE_LEN]; TRIANGLES],
            vertex_triangle_start: [0; VERTICES + 1],
            vertex_triangle: [0; 3 * TRIANGLES],
            cell_start: [0; CELLS + 1],
            grid_vertex: [0; VERTICES],
            mesh_vertex: [0; VERTICES],
        }
    }

    /// The coupling buffers, each the first `lengths` entries of its array.
    fn coupling(&mut self, lengths: [usize; 2]) -> HybridBuffers<'_, f32> {
        coupling(&mut self.passed_force_n, &mut self.background_m, lengths)
    }

    /// The coupling and the hybrid surface's buffers, each the first
    /// `lengths` entries of its array.
    fn buffers(
        &mut self,
        coupling: [usize; 2],
        [p, tr, pl, vs, vt, c, g, m]: [usize; 8],
    ) -> (HybridBuffers<'_, f32>, HybridSurfaceBuffers<'_, f32>) {
        let surface = HybridSurfaceBuffers {
            positions_m: prefix(&mut self.positions_m, p),
            triangles: prefix(&mut self.triangles, tr),
            planes: prefix(&mut self.planes, pl),
            vertex_triangle_start: prefix(&mut self.vertex_triangle_start, vs),
            vertex_triangle: prefix(&mut self.vertex_triangle, vt),
            cell_start: prefix(&mut self.cell_start, c),
            grid_vertex: prefix(&mut self.grid_vertex, g),
            mesh_vertex: prefix(&mut self.mesh_vertex, m),
        };
        let coupling = self::coupling(&mut self.passed_force_n, &mut self.background_m, coupling);
        (coupling, surface)
    }
}

/// `passed_force_n` and `background_m`, each the first `lengths` entries.
fn coupling<'s>(
    passed_force_n: &'s mut [[f32; 3]],
    background_m: &'s mut [[f32; 3]],
    [p, b]: [usize; 2],
) -> HybridBuffers<'s, f32> {
    HybridBuffers {
        passed_force_n: prefix(passed_force_n, p),
        background_m: prefix(background_m, b),
    }
}

/// The three tables, each loaded from a volatile length of its bytes.
fn load(
    [p, d, i]: [usize; 3],
) -> Option<(
    PrecomputedTable<'static, f32>,
    TensorMassTable<'static, f32>,
    InterfaceTable<'static, f32>,
)> {
    let bytes = |table: &'static [u8], n: usize| table.get(..n).unwrap_or(table);
    let tables = (
        PrecomputedTable::<f32>::load(bytes(PRECOMPUTED, p)),
        TensorMassTable::<f32>::load(bytes(DYNAMIC, d)),
        InterfaceTable::<f32>::load(bytes(INTERFACE, i)),
    );
    match tables {
        (Ok(p), Ok(d), Ok(i)) => Some((p, d, i)),
        _ => {
            refused();
            None
        }
    }
}

/// The scripted hybrid model: load, `TensorMassModel::new`, `HybridModel::new`
/// on volatile buffer lengths, then `inputs.rounds` rounds on the same model,
/// each on freshly read inputs ([`model_round`]).
pub(super) fn model_step(tensor: &TensorInputs, state: &mut TensorState, hybrid: &mut HybridState) {
    // SAFETY: single-threaded; a volatile read of a plain-old-data static.
    let inputs = unsafe { read_volatile(addr_of!(HYBRID_INPUTS)) };
    let Some((precomputed, dynamic, interface)) = load(inputs.table_lens) else {
        return;
    };
    let Ok(model) = TensorMassModel::new(dynamic, state.buffers(&inputs.lengths), params(tensor))
    else {
        refused();
        return;
    };
    let Ok(mut model) = HybridModel::new(
        model,
        precomputed,
        interface,
        hybrid.coupling(inputs.coupling_lengths),
    ) else {
        refused();
        return;
    };
    let mut displacements = [[0.0f32; 3]; VERTICES];
    for _ in 0..inputs.rounds {
        // SAFETY: as above.
        let inputs = unsafe { read_volatile(addr_of!(HYBRID_INPUTS)) };
        model_round(&mut model, &inputs, &mut displacements);
    }
}

/// One round: optional reset, an imposed displacement on the tensor-mass
/// region, the background, the contact solve on the pre-computed region,
/// the passed forces, one step, the displacement of every vertex.
fn model_round(
    model: &mut HybridModel<'_, '_, f32>,
    inputs: &HybridInputs,
    displacements: &mut [[f32; 3]; VERTICES],
) {
    if inputs.reset != 0 {
        model.reset();
    }
    if model
        .dynamic_mut()
        .impose(inputs.impose_vertex, inputs.impose_m.into())
        .is_err()
    {
        refused();
    }
    if model.update_background(inputs.background_rows).is_err() {
        refused();
    }
    let contacts = inputs.contacts.constraints();
    let set = contact_set(&contacts, inputs.contacts.count);
    let solution = model.contact_forces::<MAX_CONTACTS>(set);
    match &solution {
        Ok(solution) => publish_solution(solution),
        Err(_) => refused(),
    }
    let solution = solution.ok().filter(|_| inputs.pass != 0);
    model.pass_contact_forces(solution.as_ref());
    match model.step(integrator(inputs.integrator), inputs.dt_s) {
        Ok(report) => {
            let out = addr_of_mut!(HYBRID_OUTPUTS);
            // SAFETY: single-threaded, `out` points to a live static, every
            // field is plain old data.
            unsafe {
                write_volatile(
                    addr_of_mut!((*out).kinetic_energy_j),
                    report.kinetic_energy_j,
                );
                write_volatile(
                    addr_of_mut!((*out).force_evaluations),
                    report.force_evaluations,
                );
            }
        }
        Err(_) => refused(),
    }
    let n = inputs.vertex_len.min(VERTICES);
    if model
        .displacements(solution.as_ref(), &mut displacements[..n])
        .is_err()
    {
        refused();
    }
    publish(displacements);
}

/// The haptic loop over the hybrid: load, `TensorMassModel::new`,
/// `HybridTissue::new` (every buffer length volatile; the physics
/// configuration of `DYNAMIC_INPUTS`), `HybridLoop::new`, then ticks with
/// physics updates and resets ([`tick_with_physics`]).
pub(super) fn haptic_step(
    tensor: &TensorInputs,
    dynamic: &DynamicInputs,
    state: &mut TensorState,
    surface: &mut SurfaceState,
    hybrid: &mut HybridState,
) {
    // SAFETY: single-threaded; a volatile read of a plain-old-data static.
    let inputs = unsafe { read_volatile(addr_of!(HYBRID_INPUTS)) };
    let Some((precomputed, table, interface)) = load(inputs.table_lens) else {
        return;
    };
    let Ok(model) = TensorMassModel::new(table, state.buffers(&inputs.lengths), params(tensor))
    else {
        refused();
        return;
    };
    let (buffers, forces) = surface.buffers(inputs.surface_lengths);
    let (coupling, hybrid_surface) =
        hybrid.buffers(inputs.coupling_lengths, inputs.hybrid_surface_lengths);
    let Ok(tissue) = HybridTissue::<f32, TOOL_POINTS, TOOL_POINTS>::new(
        model,
        buffers,
        forces,
        physics_config(dynamic),
        precomputed,
        interface,
        coupling,
        hybrid_surface,
    ) else {
        refused();
        return;
    };
    let Ok(haptic) =
        HybridLoop::<f32, TOOL_POINTS, TOOL_POINTS>::new(tissue, loop_config(dynamic.config))
    else {
        refused();
        return;
    };
    tick_with_physics(haptic, |tissue| tissue.dynamic().removed());
}
