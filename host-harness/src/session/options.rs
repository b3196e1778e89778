//! The table build options of a scene, by its model (its materials per tet, supports, f32,
//! the tool radius of the collision lists), and the size check of its table before a build.

use crate::fix::fixed_vertices;
use crate::mesh::{MeshReport, TetMesh, boundary_surface};
use crate::scene::{ModelSpec, Scene};
use crate::table::build::BuildOptions;
use crate::table::compliance::Solver;
use crate::table::estimate::{SizeLimits, TableEstimate};
use crate::table::file::Precision;

/// The build options of `scene`'s table on `mesh` (read with `report`), by
/// its model: its materials per tet ([`Scene::tet_materials`]) and
/// supports, f32 (the firmware precision), quiet; a pre-computed table
/// solved by sparse Cholesky, a tensor-mass table of the scene's density.
pub fn table_options(
    scene: &Scene,
    mesh: &TetMesh,
    report: &MeshReport,
) -> anyhow::Result<BuildOptions> {
    match scene.model {
        ModelSpec::Precomputed => precomputed_options(scene, mesh, report),
        ModelSpec::Dynamic(_) => tensor_mass_options(scene, mesh, report),
    }
}

/// The pre-computed table options of `scene` on `mesh` (see [`table_options`]).
pub fn precomputed_options(
    scene: &Scene,
    mesh: &TetMesh,
    report: &MeshReport,
) -> anyhow::Result<BuildOptions> {
    let materials = scene.tet_materials(mesh, report)?;
    let options = BuildOptions::precomputed(
        materials.default_material(),
        scene.fix.clone(),
        Solver::Cholesky,
        Precision::F32,
    )
    .with_tool_radius(scene.tool.radius_m);
    Ok(options.with_tet_materials(materials))
}

/// The tensor-mass table options of `scene` on `mesh` (see [`table_options`]).
pub fn tensor_mass_options(
    scene: &Scene,
    mesh: &TetMesh,
    report: &MeshReport,
) -> anyhow::Result<BuildOptions> {
    let materials = scene.tet_materials(mesh, report)?;
    let options = BuildOptions::tensor_mass(
        materials.default_material(),
        scene.material.density_kg_m3,
        scene.fix.clone(),
        Precision::F32,
    );
    Ok(options.with_tet_materials(materials))
}

/// Checks that `scene`'s table on `mesh` fits the limits every build
/// applies ([`SizeLimits::system`]: the largest table file, the memory
/// available), from the estimate of its size, without building it (linear
/// in the mesh): for a command that builds several tables, before the
/// first. Returns the estimate.
pub fn check_scene_table(
    scene: &Scene,
    mesh: &TetMesh,
    report: &MeshReport,
) -> anyhow::Result<TableEstimate> {
    let options = table_options(scene, mesh, report)?;
    let (fixed, _) = fixed_vertices(&mesh.positions, &options.fix, &report.unreferenced_vertices);
    let surface = boundary_surface(mesh);
    let estimate = TableEstimate::of_build(mesh, report, &options, &fixed, &surface);
    SizeLimits::system().check(&estimate, &report.source)?;
    Ok(estimate)
}
