//! The one table build (`palpate tables build`, and every table the harness
//! builds in memory): mesh + material + fixed predicates → table bytes, for
//! either kind of table.
//!
//! Stages: the shared preparation (fixed vertices, boundary surface) → the
//! kind's arrays (the compliance blocks over the free/touchable ordering, or
//! the tensor-mass arrays) → for a pre-computed table, the collision index of
//! the same surface (the kernel's grid builder) → the writer → a
//! [`BuiltTable`] summary.

use core::time::Duration;
use std::time::Instant;

use anyhow::{Context, anyhow, bail};
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::{LoadError, PrecomputedTable};

use super::collision::collision_index;
use super::compliance::{Solver, compute_compliance};
use super::compress::{BlockCode, Compression, encode, measured_record};
use super::estimate::{SizeLimits, TableEstimate};
use super::file::{Precision, TableContents, write_table};
use super::load::TableFile;
use super::tensor_mass::{TensorMassArrays, write_tensor_mass_table};
use crate::fem::assembly::FreeOrdering;
use crate::fem::material::TetMaterials;
use crate::fix::{FixPredicate, fixed_vertices};
use crate::mesh::{MeshReport, Surface, TetMesh, boundary_surface};

/// The options of a build, defined in [`super::options`] and named here too,
/// beside the build that takes them.
pub use super::options::{BuildOptions, DEFAULT_LIST_TOOL_RADIUS_M, TableKindOptions};

/// A built table and what went into it.
#[derive(Clone, Debug)]
pub struct BuiltTable {
    /// The table file bytes.
    pub bytes: Vec<u8>,
    /// Vertices fixed by a predicate.
    pub fixed_by_predicate: usize,
    /// Unreferenced vertices, kept in the numbering and fixed.
    pub fixed_unreferenced: usize,
    /// Free vertices (`F`).
    pub free_count: usize,
    /// Touchable vertices (`S`) of a pre-computed table; 0 for a
    /// tensor-mass table (its contacts are found on the deforming surface).
    pub touchable_count: usize,
    /// Edges (`E`, each once) of a tensor-mass table; 0 for a pre-computed
    /// table.
    pub edge_count: usize,
    /// Wall time of the kind's arrays: the compliance computation
    /// (assembly, factorization, solves) or the tensor-mass assembly.
    pub arrays_time: Duration,
}

/// Builds the table of `mesh` that `options` describe. Fixed vertices are
/// those matching a predicate plus the unreferenced ones (kept so numbering
/// is the file's, fixed because no tet gives them stiffness or mass). In a
/// pre-computed table the touchable vertices are the free vertices of the
/// boundary surface.
///
/// The table is loaded with the kernel's own loader before it is returned
/// ([`check_loads`]): a table every consumer would refuse (values beyond
/// the stored precision) is an error here, naming the cause.
///
/// Before any array is computed, the table's size and the build's memory
/// are estimated from the mesh's counts and checked against
/// [`SizeLimits::system`] (the largest table file, the memory available):
/// see [`build_with_limits`].
pub fn build(
    mesh: &TetMesh,
    report: &MeshReport,
    options: &BuildOptions,
) -> anyhow::Result<BuiltTable> {
    build_with_limits(mesh, report, options, &SizeLimits::system())
}

/// [`build`] with the size `limits` given: the estimate
/// ([`TableEstimate::of_build`], after the fixed vertices and the surface,
/// before the compliance or the tensor-mass arrays) is refused above them
/// with one line naming it and the alternatives, in a time linear in the
/// mesh and without allocating the table.
pub fn build_with_limits(
    mesh: &TetMesh,
    report: &MeshReport,
    options: &BuildOptions,
    limits: &SizeLimits,
) -> anyhow::Result<BuiltTable> {
    let built = build_unchecked(mesh, report, options, limits)?;
    check_loads(&built.bytes, options, &report.source)?;
    Ok(built)
}

/// Loads `bytes`, a table built with `options`, with the kernel's loader of
/// its kind and precision, as the firmware and every command will. A refusal
/// is an error naming `source` (the mesh), the loader's reason and, when a
/// value is out of the scalar's range (an overflow or underflow of the
/// compliance, stiffness or geometry), what to change.
pub fn check_loads(bytes: &[u8], options: &BuildOptions, source: &str) -> anyhow::Result<()> {
    let file = TableFile::from_bytes(bytes);
    let bytes = file.bytes();
    let precomputed = matches!(options.kind, TableKindOptions::Precomputed { .. });
    let loaded = match (precomputed, options.precision) {
        (true, Precision::F32) => PrecomputedTable::<f32>::load(bytes).map(drop),
        (true, Precision::F64) => PrecomputedTable::<f64>::load(bytes).map(drop),
        (false, Precision::F32) => TensorMassTable::<f32>::load(bytes).map(drop),
        (false, Precision::F64) => TensorMassTable::<f64>::load(bytes).map(drop),
    };
    let Err(error) = loaded else {
        return Ok(());
    };
    let young_pa = options.material.young_pa;
    let out_of_range = matches!(
        error,
        LoadError::NonFinite { .. }
            | LoadError::NotPositiveDefinite { .. }
            | LoadError::BadVertexData { .. }
            | LoadError::BadTet { .. }
            | LoadError::BadSurfacePlane { .. }
            | LoadError::BadSurfaceGrid { .. }
            | LoadError::BadMaterial
    );
    let hint = match (out_of_range, options.precision) {
        (true, Precision::F32) => format!(
            "its values overflow or underflow f32 with E = {young_pa:e} Pa on this mesh; \
             give E in Pa and the mesh in metres (SI units), or store f64 (--precision f64)"
        ),
        (true, Precision::F64) => format!(
            "its values overflow or underflow f64 with E = {young_pa:e} Pa on this mesh; \
             give E in Pa and the mesh in metres (SI units)"
        ),
        (false, _) => {
            "the table writer produced a table the kernel refuses (a bug: please report it)".into()
        }
    };
    let source = if source.is_empty() {
        String::new()
    } else {
        format!("{source}: ")
    };
    Err(anyhow!(
        "{source}the built table fails Palpate's own load check ({error}): {hint}"
    ))
}

/// [`build`] without the final load check.
fn build_unchecked(
    mesh: &TetMesh,
    report: &MeshReport,
    options: &BuildOptions,
    limits: &SizeLimits,
) -> anyhow::Result<BuiltTable> {
    if let TableKindOptions::TensorMass { density_kg_m3 } = options.kind
        && !(density_kg_m3.is_finite() && density_kg_m3 > 0.0)
    {
        bail!("density must be finite and > 0 kg/m3, got {density_kg_m3}");
    }
    let (fixed, fixed_by_predicate) =
        fixed_vertices(&mesh.positions, &options.fix, &report.unreferenced_vertices);
    if let TableKindOptions::Precomputed { compression, .. } = options.kind {
        if let Some(compression) = compression {
            compression.check()?;
            if options.precision != Precision::F32 {
                bail!(
                    "--compress applies to f32 tables (the firmware's); its errors are measured                      against the f32 table"
                );
            }
        }
        if fixed_by_predicate == 0 {
            bail!(
                "{}: no vertex matches the --fix predicates ({}); a free body has a singular stiffness",
                report.source,
                describe(&options.fix)
            );
        }
        if fixed.iter().all(|&f| f) {
            bail!(
                "{}: every vertex is fixed by the --fix predicates ({}); nothing can move",
                report.source,
                describe(&options.fix)
            );
        }
    }
    let materials = options
        .materials_for(mesh.tets.len())
        .with_context(|| format!("{}: the materials", report.source))?;
    let surface = boundary_surface(mesh);
    let estimate = TableEstimate::of_build(mesh, report, options, &fixed, &surface);
    limits.check(&estimate, &report.source)?;
    let summary = BuiltTable {
        bytes: Vec::new(),
        fixed_by_predicate,
        fixed_unreferenced: report.unreferenced_vertices.len(),
        free_count: fixed.iter().filter(|&&f| !f).count(),
        touchable_count: 0,
        edge_count: 0,
        arrays_time: Duration::ZERO,
    };
    match options.kind {
        TableKindOptions::Precomputed { solver, .. } => {
            let stages = Stages {
                fixed: &fixed,
                surface: &surface,
                materials: &materials,
            };
            precomputed(mesh, report, options, solver, &stages, summary)
        }
        TableKindOptions::TensorMass { density_kg_m3 } => {
            let start = Instant::now();
            let arrays = TensorMassArrays::new(mesh, &materials, density_kg_m3, fixed);
            let arrays_time = start.elapsed();
            if options.precision == Precision::F32 {
                // All zero once stored: the loader accepts it, the model
                // would have no stiffness (or mass). Overflows the loader
                // refuses ([`check_loads`]).
                for (what, largest) in [
                    ("stiffness", largest(arrays.vertex_tensors.iter().flatten())),
                    ("mass", largest(&arrays.masses_kg)),
                ] {
                    if largest > 0.0 && largest < f64::from(f32::MIN_POSITIVE) {
                        bail!(
                            "{}: the {what} values underflow f32 (largest {largest:e}) with E = {:e} Pa \
                             and {density_kg_m3} kg/m3 on this mesh; give them in SI units (Pa, \
                             kg/m3, mesh in metres), or store f64 (--precision f64)",
                            report.source,
                            options.material.young_pa
                        );
                    }
                }
            }
            Ok(BuiltTable {
                bytes: write_tensor_mass_table(
                    mesh,
                    &surface.triangles,
                    &arrays,
                    options.precision,
                ),
                edge_count: arrays.column.len(),
                arrays_time,
                ..summary
            })
        }
    }
}

/// What the shared preparation gives the pre-computed stages.
pub(crate) struct Stages<'a> {
    pub(crate) fixed: &'a [bool],
    pub(crate) surface: &'a Surface,
    pub(crate) materials: &'a TetMaterials,
}

/// The pre-computed stages: the free/touchable ordering, the compliance,
/// the collision index of the surface, the writer. With a compression
/// (`options.kind`), the `f32` table is written first, then the compressed
/// one, whose errors against it are measured over the probe set
/// ([`super::compress::measure`]) and stored in its record.
pub(crate) fn precomputed(
    mesh: &TetMesh,
    report: &MeshReport,
    options: &BuildOptions,
    solver: Solver,
    stages: &Stages<'_>,
    summary: BuiltTable,
) -> anyhow::Result<BuiltTable> {
    let Stages {
        fixed,
        surface,
        materials,
    } = *stages;
    if let TableKindOptions::Precomputed {
        compression: Some(c),
        ..
    } = options.kind
        && c.code.is_hierarchical()
    {
        return hierarchical(mesh, report, options, solver, stages, summary, c);
    }
    let ordering = FreeOrdering::new(mesh.positions.len(), fixed, &surface.vertices);
    let start = Instant::now();
    let compliance = compute_compliance(
        &mesh.positions,
        &mesh.tets,
        materials,
        &ordering,
        solver,
        options.progress,
    )
    .with_context(|| format!("{}: computing the compliance table", report.source))?;
    let arrays_time = start.elapsed();
    let collision = collision_index(
        &mesh.positions,
        &surface.triangles,
        options.list_tool_radius_m(),
        options.precision,
    );
    let (tet_lame, vertex_slot) = (materials.lame(), ordering.slot_entries());
    let contents = TableContents {
        tet_lame: &tet_lame,
        young_pa: options.material.young_pa,
        poisson: options.material.poisson,
        mesh_hash: mesh.content_hash(),
        vertex_slot: &vertex_slot,
        free_vertex: &ordering.free_vertex,
        touchable_count: ordering.touchable_count,
        positions: &mesh.positions,
        triangles: &surface.triangles,
        surface: &compliance.surface,
        interior: &compliance.interior,
        compressed: None,
        collision: &collision,
    };
    let mut bytes = write_table(&contents, options.precision);
    if let TableKindOptions::Precomputed {
        compression: Some(compression),
        ..
    } = options.kind
    {
        let context = || format!("{}: compressing the compliance table", report.source);
        let mut compressed =
            encode(&compliance, ordering.touchable_count, &compression).with_context(context)?;
        let draft = write_table(
            &TableContents {
                compressed: Some(&compressed),
                ..contents
            },
            options.precision,
        );
        let (record, _) =
            measured_record(&bytes, &draft, compressed.record).with_context(context)?;
        compressed.record = record;
        bytes = write_table(
            &TableContents {
                compressed: Some(&compressed),
                ..contents
            },
            options.precision,
        );
    }
    Ok(BuiltTable {
        bytes,
        touchable_count: ordering.touchable_count,
        arrays_time,
        ..summary
    })
}

/// The pre-computed stages of a hierarchical table (`--compress hmatrix`,
/// [`super::hmatrix::build`]): the collision index, then the clustered
/// ordering, the compliance by columns and its compression.
fn hierarchical(
    mesh: &TetMesh,
    report: &MeshReport,
    options: &BuildOptions,
    solver: Solver,
    stages: &Stages<'_>,
    summary: BuiltTable,
    compression: Compression,
) -> anyhow::Result<BuiltTable> {
    if solver != Solver::Cholesky {
        bail!("--compress hmatrix solves the compliance by sparse Cholesky: drop --solver cg");
    }
    let collision = collision_index(
        &mesh.positions,
        &stages.surface.triangles,
        options.list_tool_radius_m(),
        options.precision,
    );
    let tet_lame = stages.materials.lame();
    let contents = TableContents {
        tet_lame: &tet_lame,
        young_pa: options.material.young_pa,
        poisson: options.material.poisson,
        mesh_hash: mesh.content_hash(),
        vertex_slot: &[],
        free_vertex: &[],
        touchable_count: 0,
        positions: &mesh.positions,
        triangles: &stages.surface.triangles,
        surface: &[],
        interior: &[],
        compressed: None,
        collision: &collision,
    };
    let inputs = super::hmatrix::Inputs {
        fixed: stages.fixed,
        surface_vertices: &stages.surface.vertices,
        materials: stages.materials,
        tolerance: compression.tolerance,
        q16: compression.code == BlockCode::HmatrixQ16,
        progress: options.progress,
    };
    let built = super::hmatrix::build(mesh, &inputs, contents)
        .with_context(|| format!("{}: building the hierarchical compliance", report.source))?;
    Ok(BuiltTable {
        bytes: built.bytes,
        touchable_count: built.touchable_count,
        arrays_time: built.arrays_time,
        ..summary
    })
}

/// The largest magnitude of `values` (0 for none).
fn largest<'a>(values: impl IntoIterator<Item = &'a f64>) -> f64 {
    values.into_iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

fn describe(fix: &[FixPredicate]) -> String {
    let all: Vec<String> = fix.iter().map(ToString::to_string).collect();
    all.join(", ")
}
