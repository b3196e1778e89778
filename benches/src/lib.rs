//! Shared fixtures for the criterion benches: procedural box meshes with the
//! base fixed, built into tables through the same pipeline as
//! `palpate tables build`.

use nalgebra::Vector3;
use palpate::fem::material::Material;
use palpate::mesh::generate::box_mesh;
use palpate::mesh::{MeshReport, TetMesh};
use palpate::scene::Scene;
use palpate::session::options::precomputed_options;
use palpate::table::build::{
    BuildOptions, BuiltTable, DEFAULT_LIST_TOOL_RADIUS_M, TableKindOptions, build,
};
use palpate::table::compliance::Solver;
use palpate::table::compress::Compression;
use palpate::table::file::Precision;
use palpate_kernel::haptic::LoopConfig;
use palpate_kernel::haptic::SafetyLimits;

/// A cube of `cells³` Kuhn cells, 0.1 m wide, soft tissue (E = 3000 Pa,
/// ν = 0.45), its base `z = 0` fixed, with the options of its f32
/// pre-computed table (sparse Cholesky).
pub fn tissue_cube(cells: usize) -> (TetMesh, MeshReport, BuildOptions) {
    let mesh = box_mesh([cells; 3], [0.1; 3]);
    let options = BuildOptions::precomputed(
        Material::new(3000.0, 0.45).expect("material"),
        vec!["z<1e-6".parse().expect("predicate")],
        Solver::Cholesky,
        Precision::F32,
    );
    (mesh, MeshReport::default(), options)
}

/// The f32 table of [`tissue_cube`]`(cells)`.
pub fn cube_table(cells: usize) -> BuiltTable {
    let (mesh, report, options) = tissue_cube(cells);
    build(&mesh, &report, &options).expect("table")
}

/// The f32 pre-computed table of `scene`'s mesh (its materials and
/// supports, whatever its model), compressed as `compression` says: the
/// built-in block ([`Scene::built_in`]) and the organ of the built-in hybrid
/// scene, all pre-computed ([`Scene::built_in_hybrid`]).
pub fn scene_table(scene: &Scene, compression: Option<Compression>) -> BuiltTable {
    let (mesh, report) = scene.load_mesh().expect("scene mesh");
    let options = precomputed_options(scene, &mesh, &report).expect("options");
    let options = BuildOptions {
        kind: TableKindOptions::Precomputed {
            solver: Solver::Cholesky,
            compression,
            tool_radius_m: DEFAULT_LIST_TOOL_RADIUS_M,
        },
        ..options
    };
    build(&mesh, &report, &options).expect("table")
}

/// Touchable top-surface vertices of the `cells³` cube spread over the top
/// face: the vertices at `(i, j)` = (¼, ¼), (¾, ¾), (¼, ¾), (¾, ¼) of the grid.
pub fn top_vertices(cells: usize) -> [u32; 4] {
    let n = cells + 1;
    let at = |i: usize, j: usize| (i + n * (j + n * cells)) as u32;
    let (a, b) = (cells / 4, 3 * cells / 4);
    [at(a, a), at(b, b), at(a, b), at(b, a)]
}

/// The f32 tensor-mass table of [`tissue_cube`]`(cells)`, density 1000 kg/m³.
pub fn tensor_cube_table(cells: usize) -> Vec<u8> {
    let (mesh, report, options) = tissue_cube(cells);
    let options = BuildOptions {
        kind: TableKindOptions::TensorMass {
            density_kg_m3: 1000.0,
        },
        ..options
    };
    build(&mesh, &report, &options)
        .expect("tensor-mass table")
        .bytes
}

/// Tool sphere radius of the haptic benches, m.
pub const TOOL_RADIUS_M: f32 = 0.002;

/// The haptic benches' loop: 1 kHz, limits high enough never to clamp.
pub fn haptic_config() -> LoopConfig<f32> {
    LoopConfig {
        radius_m: TOOL_RADIUS_M,
        dt_s: 1e-3,
        limits: SafetyLimits {
            max_force_n: 50.0,
            max_slew_n_per_s: 1e6,
        },
    }
}

/// Tool point `p` (0..4) over the cube's top face (z = 0.1 m) at a quarter
/// point, `depth_m` below first touch.
pub fn haptic_tool(p: usize, depth_m: f32) -> Vector3<f32> {
    let [x, y] = [
        [0.031, 0.029],
        [0.071, 0.069],
        [0.029, 0.072],
        [0.068, 0.031],
    ][p % 4];
    Vector3::new(x, y, 0.1 + TOOL_RADIUS_M - depth_m)
}

/// The f32 tensor-mass table of `mesh` with its lowest vertices fixed
/// (E = 5 kPa, ν = 0.4, 1000 kg/m³): the St Venant-Kirchhoff and tools
/// benches' meshes resting on their base.
pub fn base_fixed_table(mesh: &TetMesh) -> palpate::table::load::TableFile {
    let z_min = mesh
        .positions
        .iter()
        .map(|p| p[2])
        .fold(f64::INFINITY, f64::min);
    let options = BuildOptions::tensor_mass(
        Material::new(5000.0, 0.4).expect("material"),
        1000.0,
        vec![format!("z<{}", z_min + 1e-6).parse().expect("predicate")],
        Precision::F32,
    );
    let built = build(mesh, &MeshReport::default(), &options).expect("table");
    palpate::table::load::TableFile::from_bytes(&built.bytes)
}
