//! The hybrid model's replay (RR-3510 §6.2): the three f32 tables of
//! `hybrid-scene.toml` (the box with its top corner cell a tensor-mass
//! region, the rest pre-computed; `palpate scene tables`) are linked into
//! flash, the kernel validates and couples them once, then
//! [`palpate_script::hybrid::replay`] runs `hybrid-sequence.txt` (physics
//! steps with tool contacts on the pre-computed region and an imposed
//! displacement on the tensor-mass region) in the format of `palpate scene
//! replay-hybrid`.
//!
//! Memory: the tables and the sequence are read in place from flash; the
//! static RAM (`.bss`) is [`State`]: the tensor-mass region's state (no RK4
//! scratch, no split St Venant-Kirchhoff terms: the run is symplectic Euler
//! with the linear law, or with a per-tet law chosen at build time,
//! [`LAW`]), the coupling buffers and the displacement of every mesh
//! vertex. Each buffer is an array of a fixed capacity sliced to the
//! tables' count; a table that needs more than a capacity is refused by the
//! kernel on a `#` line naming the buffer.

use core::fmt::Write;

use cortex_m_semihosting::hio;
use palpate_kernel::hybrid::{HybridBuffers, HybridModel};
use palpate_kernel::table::{InterfaceTable, TensorMassTable};
use palpate_kernel::tensor_mass::stvk_terms::TermArraysMut;
use palpate_kernel::tensor_mass::{
    EDGE_LANES, EdgeGroup, StateBuffers, TensorMassModel, VertexMode,
};
use palpate_kernel::{PrecomputedTable, include_table};

/// The pre-computed region's table (connection nodes fixed), from
/// `PALPATE_HYBRID_TABLES/precomputed.bin` (`build.rs`), 16-byte aligned.
static PRECOMPUTED: &[u8] = include_table!(concat!(env!("OUT_DIR"), "/precomputed.bin"));
/// The tensor-mass region's table.
static DYNAMIC: &[u8] = include_table!(concat!(env!("OUT_DIR"), "/dynamic.bin"));
/// The interface table.
static INTERFACE: &[u8] = include_table!(concat!(env!("OUT_DIR"), "/interface.bin"));
/// The tensor-mass region's law, a name of `palpate_script::hybrid::LAWS`
/// (`PALPATE_HYBRID_LAW` at build time, default `linear`; `build.rs`).
const LAW: &str = env!("PALPATE_HYBRID_LAW");
/// The scripted sequence (syntax: `palpate_script::hybrid`), in flash.
static SEQUENCE: &str = include_str!("../hybrid-sequence.txt");

/// Mesh vertices of `mesh/box.node` (4 × 4 × 4).
const VERTICES: usize = 64;
/// Capacity for the tensor-mass region's vertices: the corner cell's 8.
const DYNAMIC_VERTICES: usize = 8;
/// Capacity for its edge groups (`StateBuffers::edge_group_count`): the
/// cell's 12 edges, 6 face diagonals and 1 body diagonal take 8 groups of 4.
const DYNAMIC_EDGE_GROUPS: usize = 8;
/// Capacity for its tets: the cell's 6 (Kuhn split).
const DYNAMIC_TETS: usize = 6;
/// Capacity for the connection nodes: the corner cell's vertices but the
/// box's corner.
const CONNECTIONS: usize = 7;
/// Capacity for the pre-computed region's free vertices.
const FREE: usize = 40;

/// The static state: fixed-capacity arrays (see the module docs).
struct State {
    vertex_tensors: [[f32; 9]; DYNAMIC_VERTICES],
    edge_groups: [EdgeGroup<f32>; DYNAMIC_EDGE_GROUPS],
    edge_group_starts: [u32; DYNAMIC_VERTICES + 1],
    masses_kg: [f32; DYNAMIC_VERTICES],
    tet_alive: [bool; DYNAMIC_TETS],
    live_tets: [u32; DYNAMIC_VERTICES],
    modes: [VertexMode; DYNAMIC_VERTICES],
    /// Displacement, velocity, previous displacement, external force, force
    /// scratch (m, m/s, m, N, N).
    vectors: [[[f32; 3]; DYNAMIC_VERTICES]; 5],
    /// Force passed to each connection node, N.
    passed_force_n: [[f32; 3]; CONNECTIONS],
    /// Background of each free pre-computed vertex, m.
    background_m: [[f32; 3]; FREE],
    /// Displacement of every mesh vertex, m.
    displacements_m: [[f32; 3]; VERTICES],
}

impl State {
    const ZERO: Self = Self {
        vertex_tensors: [[0.0; 9]; DYNAMIC_VERTICES],
        edge_groups: [EdgeGroup {
            tensors: [[0.0; EDGE_LANES]; 9],
            columns: [0; EDGE_LANES],
        }; DYNAMIC_EDGE_GROUPS],
        edge_group_starts: [0; DYNAMIC_VERTICES + 1],
        masses_kg: [0.0; DYNAMIC_VERTICES],
        tet_alive: [false; DYNAMIC_TETS],
        live_tets: [0; DYNAMIC_VERTICES],
        modes: [VertexMode::Free; DYNAMIC_VERTICES],
        vectors: [[[0.0; 3]; DYNAMIC_VERTICES]; 5],
        passed_force_n: [[0.0; 3]; CONNECTIONS],
        background_m: [[0.0; 3]; FREE],
        displacements_m: [[0.0; 3]; VERTICES],
    };
}

/// Loads and couples the tables, reports their figures on a `#` line, and
/// replays the sequence to semihosting stdout. Any failure is printed on a
/// `#` line.
pub fn run() -> Result<(), ()> {
    let mut out = hio::hstdout()?;
    let mut refused = |what: &str, e: &dyn core::fmt::Display| {
        let _ = writeln!(out, "# {what} refused: {e}");
    };
    let (precomputed, dynamic, interface) = match (
        PrecomputedTable::<f32>::load(PRECOMPUTED),
        TensorMassTable::<f32>::load(DYNAMIC),
        InterfaceTable::<f32>::load(INTERFACE),
    ) {
        (Ok(p), Ok(d), Ok(i)) => (p, d, i),
        (p, d, i) => {
            for (what, e) in [
                ("pre-computed table", p.err()),
                ("tensor-mass table", d.err()),
                ("interface table", i.err()),
            ] {
                if let Some(e) = e {
                    refused(what, &e);
                }
            }
            return Err(());
        }
    };
    let Some(state) = cortex_m::singleton!(: State = State::ZERO) else {
        refused("state", &"already taken");
        return Err(());
    };
    let (n, t) = (dynamic.vertex_count(), dynamic.tet_count());
    let [u, v, previous, external, force] = &mut state.vectors;
    let buffers = StateBuffers {
        vertex_tensors: prefix(&mut state.vertex_tensors, n),
        edge_groups: prefix(
            &mut state.edge_groups,
            StateBuffers::edge_group_count(&dynamic),
        ),
        edge_group_starts: prefix(&mut state.edge_group_starts, n + 1),
        masses_kg: prefix(&mut state.masses_kg, n),
        tet_alive: prefix(&mut state.tet_alive, t),
        live_tets: prefix(&mut state.live_tets, n),
        modes: prefix(&mut state.modes, n),
        displacement_m: prefix(u, n),
        velocity_m_s: prefix(v, n),
        previous_displacement_m: prefix(previous, n),
        external_force_n: prefix(external, n),
        force_n: prefix(force, n),
        rk4_scratch: &mut [],
        stvk_terms: TermArraysMut {
            vertex: &mut [],
            edge: &mut [],
            triangle: &mut [],
            tet: &mut [],
        },
    };
    let Some(law) = palpate_script::hybrid::law_named(LAW) else {
        refused("PALPATE_HYBRID_LAW", &LAW);
        return Err(());
    };
    let model = match TensorMassModel::new(dynamic, buffers, palpate_script::hybrid::params(law)) {
        Ok(model) => model,
        Err(e) => {
            refused("tensor-mass region", &e);
            return Err(());
        }
    };
    let coupling = HybridBuffers {
        passed_force_n: prefix(&mut state.passed_force_n, interface.connection_count()),
        background_m: prefix(&mut state.background_m, interface.free_count()),
    };
    let mut hybrid = match HybridModel::new(model, precomputed, interface, coupling) {
        Ok(hybrid) => hybrid,
        Err(e) => {
            refused("coupling", &e);
            return Err(());
        }
    };
    let _ = writeln!(
        out,
        "# hybrid tables: {} + {} + {} bytes in flash (pre-computed, tensor-mass, interface); \
         {} vertices, {n} tensor-mass, {} connection nodes; static state {} bytes",
        PRECOMPUTED.len(),
        DYNAMIC.len(),
        INTERFACE.len(),
        hybrid.interface().vertex_count(),
        hybrid.interface().connection_count(),
        core::mem::size_of::<State>()
    );
    let displacements = prefix(
        &mut state.displacements_m,
        hybrid.interface().vertex_count(),
    );
    palpate_script::hybrid::replay(&mut hybrid, SEQUENCE, displacements, &mut out).map_err(|e| {
        let _ = writeln!(out, "# replay failed: {e}");
    })
}

/// The first `n` entries of `s` (all of them if `n` is larger: the kernel
/// then refuses the length, naming the buffer).
fn prefix<E>(s: &mut [E], n: usize) -> &mut [E] {
    let n = n.min(s.len());
    &mut s[..n]
}
