//! Hierarchical compliance tables (`tables build --compress hmatrix
//! [--tolerance REL]`; format in `palpate_kernel::table::format::hierarchy`):
//! the touchable–touchable compliance as an H-matrix (Hackbusch,
//! *Hierarchical Matrices*, 2015; Bebendorf 2008): the compliance between
//! two distant surface points decays like `1/r`, so the blocks between
//! well-separated clusters of touchable vertices are numerically low-rank
//! (James & Pai 2003). Stages:
//! - [`cluster`]: the cluster tree of the touchable vertices, which
//!   renumbers them in its leaves' order;
//! - [`partition`]: the admissible (far) and near blocks;
//! - [`columns`] and [`assemble`]: the compliance columns solved in batches
//!   of consecutive leaves and cut into the blocks, far ones truncated
//!   ([`lowrank`]);
//! - [`measure`]: the table's force and displacement errors against the
//!   exact columns.
//!
//! The interior part is not stored (a coded part with every block dropped):
//! a hierarchical table moves its touchable vertices only, its interior
//! displacements are zero.

pub mod assemble;
pub mod cluster;
pub mod columns;
pub mod lowrank;
pub mod measure;
pub mod partition;

use std::time::Instant;

use anyhow::Context;
use bytemuck::Zeroable;
use palpate_kernel::table::format::{BlockEncoding, CompressionRecord};
use palpate_kernel::{PrecomputedModel, PrecomputedTable};

use self::assemble::{Assembler, batches};
use self::cluster::{ClusterTree, LEAF_SIZE};
use self::columns::ColumnSolver;
use self::partition::{ETA, Partition};
use super::compress::{CodedPart, CompressedCompliance, Hierarchy};
use super::file::{Precision, TableContents, write_table};
use super::load::TableFile;
use crate::fem::assembly::FreeOrdering;
use crate::fem::material::TetMaterials;
use crate::mesh::TetMesh;
use crate::output::stderr;

/// The default relative tolerance of a far block, `‖C_b − L Rᵀ‖_F ≤ tol ·
/// ‖C_b‖_F`: `1e-5`, which keeps the measured contact-force and touchable
/// displacement errors below `1e-3` with a margin of 2.9 or more on every
/// organ measured (docs/tables.md, "Hierarchical tables"); at `1e-4` the
/// touchable displacement error reached `2.75e-3` on a 55k-tet organ, at
/// `3e-5` `6.6e-4` on a 19k-tet one.
pub const DEFAULT_TOLERANCE: f64 = 1e-5;

/// The far-block rank a size estimate assumes: above the mean far rank
/// measured at the default tolerance (about 16 on the 55k-tet organ of
/// docs/tables.md, "Hierarchical tables"), so the estimate is an upper
/// figure for it.
pub const ESTIMATE_RANK: usize = 20;

/// The scalars of a hierarchical table's data and the bytes of its other
/// hierarchy sections, estimated before a build from the touchable
/// vertices' rest positions `points` (m): the cluster tree and partition
/// are those of the build, every far block at [`ESTIMATE_RANK`];
/// `scale_bytes` per block for its scales (q16 data; 0 otherwise).
pub fn estimate(points: &[[f64; 3]], scale_bytes: u64) -> (u64, u64) {
    estimate_with_leaves(points, LEAF_SIZE, scale_bytes)
}

/// [`estimate`] with leaves of at most `leaf_size` points (`≥ 1`).
pub fn estimate_with_leaves(points: &[[f64; 3]], leaf_size: usize, scale_bytes: u64) -> (u64, u64) {
    let tree = ClusterTree::new(points, leaf_size);
    let partition = Partition::new(&tree, ETA);
    let blocks = partition.blocks.len() as u64;
    let entries: u64 = partition.columns.iter().map(|c| c.len() as u64).sum();
    let other = 40 + 8 * (tree.leaves.len() as u64 + 1) + (32 + scale_bytes) * blocks + 4 * entries;
    (partition.data_len_at_rank(&tree, ESTIMATE_RANK), other)
}

/// A hierarchical table built: its bytes, the free ordering it uses and
/// the time of the compliance stage.
pub struct HierarchicalTable {
    /// The table file.
    pub bytes: Vec<u8>,
    /// Touchable vertices.
    pub touchable_count: usize,
    /// Wall time of assembly, factorization, solves and compression.
    pub arrays_time: core::time::Duration,
}

/// The cluster tree of the touchable vertices of `ordering` (rest
/// `positions`, m) and the ordering renumbered in its leaves' order.
pub fn clustered(positions: &[[f64; 3]], ordering: FreeOrdering) -> (ClusterTree, FreeOrdering) {
    let s = ordering.touchable_count;
    let points: Vec<[f64; 3]> = ordering.free_vertex[..s]
        .iter()
        .map(|&v| positions[v as usize])
        .collect();
    let tree = ClusterTree::new(&points, LEAF_SIZE);
    let ordering = ordering.with_touchable_order(&tree.order);
    (tree, ordering)
}

/// What a hierarchical build takes besides the mesh and the table's other
/// contents.
pub struct Inputs<'a> {
    /// Per mesh vertex, fixed.
    pub fixed: &'a [bool],
    /// The boundary surface's vertices (the touchable ones are those not
    /// fixed).
    pub surface_vertices: &'a [u32],
    /// Per-tet materials.
    pub materials: &'a TetMaterials,
    /// The far blocks' relative tolerance, in `(0, 1)`.
    pub tolerance: f64,
    /// Store the numbers as q16 codes (`--compress hmatrix-q16`).
    pub q16: bool,
    /// Show a progress bar over the columns.
    pub progress: bool,
}

/// Builds the hierarchical table of `mesh` (module docs), `f32` only;
/// `contents` gives everything but the compliance (and its ordering,
/// replaced by the clustered one).
pub fn build(
    mesh: &TetMesh,
    inputs: &Inputs<'_>,
    contents: TableContents<'_>,
) -> anyhow::Result<HierarchicalTable> {
    let (tolerance, progress) = (inputs.tolerance, inputs.progress);
    let start = Instant::now();
    let ordering = FreeOrdering::new(mesh.positions.len(), inputs.fixed, inputs.surface_vertices);
    let (tree, ordering) = clustered(&mesh.positions, ordering);
    let s = ordering.touchable_count;
    let partition = Partition::new(&tree, ETA);
    let solver = ColumnSolver::new(&mesh.positions, &mesh.tets, inputs.materials, &ordering)?;
    log::debug!(
        "hmatrix: {s} touchable vertices, {} leaves, {} blocks, {} scalars in L",
        tree.leaves.len(),
        partition.blocks.len(),
        solver.factor_len()
    );
    let batches = batches(&tree);
    let mut assembler = Assembler::new(&tree, &partition, &batches, tolerance);
    let bar = stderr::progress_bar(
        s as u64,
        "compliance {bar:40} {pos}/{len} touchable vertices ({eta})",
        progress,
    );
    for batch in &batches {
        let vertices: Vec<usize> = batch.clone().collect();
        let x = solver.columns(&vertices);
        assembler.add_batch(batch, x.as_ref())?;
        bar.inc(batch.len() as u64);
    }
    bar.finish_and_clear();
    let hierarchy = Hierarchy {
        q16: inputs.q16,
        ..assembler.finish(s, ETA, LEAF_SIZE)?
    };
    let slot_entries = ordering.slot_entries();
    let contents = TableContents {
        vertex_slot: &slot_entries,
        free_vertex: &ordering.free_vertex,
        touchable_count: s,
        surface: &[],
        interior: &[],
        ..contents
    };
    let (probe_set, at) = measure::probe_indices(s);
    let mut compressed = compressed(hierarchy, s, probe_set);
    let draft = write_table(
        &TableContents {
            compressed: Some(&compressed),
            ..contents
        },
        Precision::F32,
    );
    let file = TableFile::from_bytes(&draft);
    let table = PrecomputedTable::<f32>::load(file.bytes()).context(
        "the hierarchical table fails Palpate's own load check (a bug: please report it)",
    )?;
    let measured = measure::measure(
        &PrecomputedModel::new(table),
        &solver,
        &ordering.vertex_slot,
        &at,
    );
    compressed.record = CompressionRecord {
        max_force_error: measured.max_force_error,
        max_displacement_error: measured.max_displacement_error,
        max_surface_displacement_error: measured.max_surface_displacement_error,
        probe_count: measured.probes,
        ..compressed.record
    };
    let bytes = write_table(
        &TableContents {
            compressed: Some(&compressed),
            ..contents
        },
        Precision::F32,
    );
    Ok(HierarchicalTable {
        bytes,
        touchable_count: s,
        arrays_time: start.elapsed(),
    })
}

/// The compressed compliance of a hierarchical table of `s` touchable
/// vertices: the surface part the hierarchy (in the table scalar or q16),
/// the interior part coded with
/// every block dropped (a scale of 1 per column, no codes), the errors
/// zero until measured.
fn compressed(hierarchy: Hierarchy, s: usize, probe_set: u32) -> CompressedCompliance {
    CompressedCompliance {
        record: CompressionRecord {
            surface_encoding: if hierarchy.q16 {
                BlockEncoding::HierarchicalQ16
            } else {
                BlockEncoding::Hierarchical
            } as u32,
            interior_encoding: BlockEncoding::F16 as u32,
            probe_set,
            ..CompressionRecord::zeroed()
        },
        surface: None,
        interior: CodedPart {
            scales: vec![1.0; s],
            codes: Vec::new(),
            kept: None,
        },
        hierarchy: Some(hierarchy),
    }
}
