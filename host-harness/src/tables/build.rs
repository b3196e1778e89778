//! `palpate tables build`: mesh + material + fixed predicates → table bytes.

use core::time::Duration;
use std::time::Instant;

use anyhow::{Context, bail};

use super::compliance::{Solver, compute_compliance};
use super::file::{Precision, TableContents, write_table};
use crate::fem::assembly::FreeOrdering;
use crate::fem::material::Material;
use crate::fix::{FixPredicate, fixed_vertices};
use crate::mesh::{MeshReport, TetMesh, boundary_surface};

/// Everything `tables build` needs besides the mesh.
#[derive(Clone, Debug)]
pub struct BuildOptions {
    /// Young's modulus and Poisson ratio.
    pub material: Material,
    /// A vertex matching any predicate is fixed.
    pub fix: Vec<FixPredicate>,
    /// Sparse Cholesky (default) or the paper's CG baseline.
    pub solver: Solver,
    /// Stored float width.
    pub precision: Precision,
    /// Show a progress bar.
    pub progress: bool,
}

/// A built table and what went into it.
pub struct BuiltTable {
    /// The table file bytes.
    pub bytes: Vec<u8>,
    /// Vertices fixed by a predicate.
    pub fixed_by_predicate: usize,
    /// Unreferenced vertices, kept in the numbering and fixed.
    pub fixed_unreferenced: usize,
    /// Free vertices (`F`).
    pub free_count: usize,
    /// Touchable vertices (`S`).
    pub touchable_count: usize,
    /// Wall time of the compliance computation (assembly, factorization, solves).
    pub solve_time: Duration,
}

/// Builds the pre-computed table of `mesh` (RR-3510 §4): fixed vertices are
/// those matching a predicate plus the unreferenced ones (kept so numbering is
/// the file's, fixed so the stiffness stays non-singular); touchable vertices
/// are the free vertices of the boundary surface.
pub fn build_table(
    mesh: &TetMesh,
    report: &MeshReport,
    options: &BuildOptions,
) -> anyhow::Result<BuiltTable> {
    let n = mesh.positions.len();
    let (fixed, fixed_by_predicate) =
        fixed_vertices(&mesh.positions, &options.fix, &report.unreferenced_vertices);
    if fixed_by_predicate == 0 {
        bail!(
            "{}: no vertex matches the --fix predicates ({}); a free body has a singular stiffness",
            report.source,
            describe(&options.fix)
        );
    }
    let fixed_unreferenced = report.unreferenced_vertices.len();
    if fixed.iter().all(|&f| f) {
        bail!(
            "{}: every vertex is fixed by the --fix predicates ({}); nothing can move",
            report.source,
            describe(&options.fix)
        );
    }
    let surface = boundary_surface(mesh);
    let ordering = FreeOrdering::new(n, &fixed, &surface.vertices);
    let start = Instant::now();
    let compliance = compute_compliance(
        &mesh.positions,
        &mesh.tets,
        &options.material,
        &ordering,
        options.solver,
        options.progress,
    )
    .with_context(|| format!("{}: computing the compliance table", report.source))?;
    let solve_time = start.elapsed();
    let bytes = write_table(
        &TableContents {
            tet_count: mesh.tets.len(),
            young_pa: options.material.young_pa,
            poisson: options.material.poisson,
            mesh_hash: mesh.content_hash(),
            vertex_slot: &ordering.vertex_slot,
            free_vertex: &ordering.free_vertex,
            touchable_count: ordering.touchable_count,
            positions: &mesh.positions,
            triangles: &surface.triangles,
            surface: &compliance.surface,
            interior: &compliance.interior,
        },
        options.precision,
    );
    Ok(BuiltTable {
        bytes,
        fixed_by_predicate,
        fixed_unreferenced,
        free_count: ordering.free_count(),
        touchable_count: ordering.touchable_count,
        solve_time,
    })
}

fn describe(fix: &[FixPredicate]) -> String {
    let all: Vec<String> = fix.iter().map(ToString::to_string).collect();
    all.join(", ")
}
