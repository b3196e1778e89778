//! Shared fixtures for the criterion benches: procedural box meshes with the
//! base fixed, built into tables through the same pipeline as
//! `palpate tables build`.

use palpate::fem::material::Material;
use palpate::mesh::generate::box_mesh;
use palpate::mesh::{MeshReport, TetMesh};
use palpate::tables::build::{BuildOptions, BuiltTable, build_table};
use palpate::tables::compliance::Solver;
use palpate::tables::file::Precision;

/// A cube of `cells³` Kuhn cells, 0.1 m wide, soft tissue (E = 3000 Pa,
/// ν = 0.45), its base `z = 0` fixed.
pub fn tissue_cube(cells: usize) -> (TetMesh, MeshReport, BuildOptions) {
    let mesh = box_mesh([cells; 3], [0.1; 3]);
    let options = BuildOptions {
        material: Material::new(3000.0, 0.45).expect("material"),
        fix: vec!["z<1e-6".parse().expect("predicate")],
        solver: Solver::Cholesky,
        precision: Precision::F32,
        progress: false,
    };
    (mesh, MeshReport::default(), options)
}

/// The f32 table of [`tissue_cube`]`(cells)`.
pub fn cube_table(cells: usize) -> BuiltTable {
    let (mesh, report, options) = tissue_cube(cells);
    build_table(&mesh, &report, &options).expect("table")
}

/// Touchable top-surface vertices of the `cells³` cube spread over the top
/// face: the vertices at `(i, j)` = (¼, ¼), (¾, ¾), (¼, ¾), (¾, ¼) of the grid.
pub fn top_vertices(cells: usize) -> [u32; 4] {
    let n = cells + 1;
    let at = |i: usize, j: usize| (i + n * (j + n * cells)) as u32;
    let (a, b) = (cells / 4, 3 * cells / 4);
    [at(a, a), at(b, b), at(a, b), at(b, a)]
}
