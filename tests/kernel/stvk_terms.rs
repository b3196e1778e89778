//! Picinbono's split St Venant-Kirchhoff terms
//! (`palpate_kernel::tensor_mass::stvk_terms`, table sections `vertex-terms`
//! … `tet-terms`) against independent truth: the Green-strain energy
//! `Σ V (λ/2 (tr E)² + μ tr E²)` computed here from `F = Ds Dm⁻¹`, its central
//! finite differences, the JAX reference forces (`tests/reference/svk/`),
//! frame invariance under a rigid rotation, and the cut invariant (subtracting
//! a tet's terms equals rebuilding without it).

use core::f64::consts::PI;
use std::collections::HashMap;

use nalgebra::{Matrix3, Rotation3, Unit, Vector3};
use palpate::fem::material::{Material, TetMaterials};
use palpate::mesh::generate::box_mesh;
use palpate::mesh::{MeshReport, TetMesh, boundary_surface, read_mesh};
use palpate::table::build::{BuildOptions, build};
use palpate::table::file::Precision;
use palpate::table::load::TableFile;
use palpate::table::tensor_mass::{TensorMassArrays, write_tensor_mass_table};
use palpate_kernel::LoadError;
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::table::format::SectionKind;
use palpate_kernel::tensor_mass::stvk_terms::{NonLinearTerms, TermArraysMut, TetPlace, tet_terms};
use palpate_tests::{json_rows, read_reference_json, reference_dir};

const YOUNG_PA: f64 = 5000.0;
const POISSON: f64 = 0.45;

fn options() -> BuildOptions {
    BuildOptions::tensor_mass(
        Material::new(YOUNG_PA, POISSON).expect("material"),
        1000.0,
        Vec::new(),
        Precision::F64,
    )
}

fn cube() -> TetMesh {
    read_mesh(&reference_dir().join("meshes/cube.node"))
        .expect("cube.node")
        .0
}

/// A small generated box, 4×3×2 cells over 12×9×6 cm.
fn small_box() -> TetMesh {
    box_mesh([4, 3, 2], [0.12, 0.09, 0.06])
}

fn table_file(mesh: &TetMesh) -> TableFile {
    let bytes = build(mesh, &MeshReport::default(), &options())
        .expect("build")
        .bytes;
    TableFile::from_bytes(&bytes)
}

fn lame() -> (f64, f64) {
    palpate_kernel::math::element::lame(YOUNG_PA, POISSON)
}

/// xorshift64*, uniform in [-1, 1).
struct Rng(u64);

impl Rng {
    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let bits = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11;
        bits as f64 / (1u64 << 52) as f64 - 1.0
    }
}

/// `u_i = G X_i + δ r_i`: a homogeneous gradient `G` with entries in
/// `±gradient` plus nodal noise of amplitude `noise_m` (m).
fn deformation(mesh: &TetMesh, seed: u64, gradient: f64, noise_m: f64) -> Vec<[f64; 3]> {
    let mut rng = Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1);
    let g = Matrix3::from_fn(|_, _| gradient * rng.uniform());
    mesh.positions
        .iter()
        .map(|x| {
            let u = g * Vector3::from(*x);
            [0, 1, 2].map(|c| u[c] + noise_m * rng.uniform())
        })
        .collect()
}

/// Independent truth for one tet: `V (λ/2 (tr E)² + μ tr E²)` with
/// `F = Ds Dm⁻¹`, `E = ½(FᵀF − I)` (J), from rest and deformed positions.
fn tet_energy(rest: [[f64; 3]; 4], deformed: [[f64; 3]; 4]) -> f64 {
    let (lambda, mu) = lame();
    let columns = |p: [[f64; 3]; 4]| {
        let v = |j: usize| Vector3::from(p[j]) - Vector3::from(p[0]);
        Matrix3::from_columns(&[v(1), v(2), v(3)])
    };
    let dm = columns(rest);
    let f = columns(deformed) * dm.try_inverse().expect("non-degenerate");
    let e = (f.transpose() * f - Matrix3::identity()) * 0.5;
    let volume = dm.determinant() / 6.0;
    volume * (lambda / 2.0 * e.trace().powi(2) + mu * (e * e).trace())
}

fn corners(mesh: &TetMesh, tet: &[u32; 4], u: &[[f64; 3]]) -> ([[f64; 3]; 4], [[f64; 3]; 4]) {
    let rest = tet.map(|v| mesh.positions[v as usize]);
    let deformed = tet.map(|v| {
        let (x, d) = (mesh.positions[v as usize], u[v as usize]);
        [x[0] + d[0], x[1] + d[1], x[2] + d[2]]
    });
    (rest, deformed)
}

fn green_energy(mesh: &TetMesh, u: &[[f64; 3]]) -> f64 {
    mesh.tets
        .iter()
        .map(|t| {
            let (rest, deformed) = corners(mesh, t, u);
            tet_energy(rest, deformed)
        })
        .sum()
}

/// Largest Frobenius norm of the Green strain over the tets (how strained
/// a configuration is).
fn max_green_strain(mesh: &TetMesh, u: &[[f64; 3]]) -> f64 {
    mesh.tets
        .iter()
        .map(|t| {
            let (rest, deformed) = corners(mesh, t, u);
            let columns = |p: [[f64; 3]; 4]| {
                let v = |j: usize| Vector3::from(p[j]) - Vector3::from(p[0]);
                Matrix3::from_columns(&[v(1), v(2), v(3)])
            };
            let f = columns(deformed) * columns(rest).try_inverse().unwrap();
            ((f.transpose() * f - Matrix3::identity()) * 0.5).norm()
        })
        .fold(0.0, f64::max)
}

/// The linear force `−K u` (N) from the table's vertex and edge tensors
/// (`K_ji = K_ijᵀ`, MODELS.md §1).
fn linear_forces(table: &TensorMassTable<f64>, u: &[[f64; 3]]) -> Vec<[f64; 3]> {
    let mat = |k: &[f64; 9]| Matrix3::from_row_slice(k);
    let mut f: Vec<Vector3<f64>> = u
        .iter()
        .zip(table.vertex_tensors())
        .map(|(ui, k)| -(mat(k) * Vector3::from(*ui)))
        .collect();
    let rows = table.edge_row_starts();
    for i in 0..table.vertex_count() {
        for e in rows[i] as usize..rows[i + 1] as usize {
            let j = table.edge_columns()[e] as usize;
            let k = mat(&table.edge_tensors()[e]);
            f[i] -= k * Vector3::from(u[j]);
            f[j] -= k.transpose() * Vector3::from(u[i]);
        }
    }
    f.into_iter().map(Into::into).collect()
}

/// `½ uᵀ K u` (J) = `−½ Σ u·(−K u)`.
fn quadratic_energy(table: &TensorMassTable<f64>, u: &[[f64; 3]]) -> f64 {
    let f = linear_forces(table, u);
    -0.5 * u
        .iter()
        .zip(&f)
        .map(|(a, b)| Vector3::from(*a).dot(&Vector3::from(*b)))
        .sum::<f64>()
}

/// Linear plus cubic and quartic: the whole St Venant-Kirchhoff force (N) and
/// energy (J) of the split form.
fn split_form(table: &TensorMassTable<f64>, u: &[[f64; 3]]) -> (Vec<[f64; 3]>, f64) {
    let alive = vec![true; table.tet_count()];
    let terms = NonLinearTerms::of_table(table, &alive);
    let mut f = linear_forces(table, u);
    terms.add_forces(u, &mut f);
    (f, quadratic_energy(table, u) + terms.energy_j(u))
}

fn max_abs(v: &[[f64; 3]]) -> f64 {
    v.iter().flatten().fold(0.0, |m, x| m.max(x.abs()))
}

fn max_diff(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    a.iter()
        .flatten()
        .zip(b.iter().flatten())
        .fold(0.0, |m, (x, y)| m.max((x - y).abs()))
}

/// A named mesh and its displacement fields (m).
type Case = (&'static str, TetMesh, Vec<Vec<[f64; 3]>>);

/// The meshes and deformations of the energy and finite-difference checks:
/// homogeneous gradients with entries up to ±0.04, ±0.07 and ±0.10 plus
/// nodal noise of 5 % of the cell size; measured max ‖E‖_F between 0.1 and
/// 0.3 (printed).
fn cases() -> Vec<Case> {
    let mut out = Vec::new();
    for (name, mesh, cell) in [("cube", cube(), 0.2), ("box", small_box(), 0.03)] {
        let configs = (0..3)
            .map(|seed| deformation(&mesh, seed + 1, 0.04 + 0.03 * seed as f64, 0.05 * cell))
            .collect();
        out.push((name, mesh, configs));
    }
    out
}

/// Quadratic (linear tensors) plus `energy_j` equals the Green-strain energy
/// computed from `F`. Bound 1e-12 relative; measured ≤ 3.5e-15 (printed).
#[test]
fn energy_equals_green_strain_energy() {
    for (name, mesh, configs) in cases() {
        let file = table_file(&mesh);
        let table = TensorMassTable::<f64>::load(file.bytes()).expect("valid table");
        for (k, u) in configs.iter().enumerate() {
            let (_, ours) = split_form(&table, u);
            let truth = green_energy(&mesh, u);
            let rel = (ours - truth).abs() / truth.abs();
            println!(
                "{name} config {k}: max |E|_F {:.3}, W = {truth:.6e} J, relative error {rel:.2e}",
                max_green_strain(&mesh, u)
            );
            assert!(rel <= 1e-12, "{name} config {k}: {rel:e}");
        }
    }
}

/// The split-form force (`−K u` plus `add_forces`) equals the central finite
/// difference of the Green-strain energy (summed over the tets around the
/// perturbed vertex), every DOF, step `h = 1e-6 ×` the mesh's size (m).
/// FD error `O(h²)` plus rounding `ε W / h`: bound 1e-8 relative to the
/// largest force; measured ≤ 1.4e-10 (printed).
#[test]
fn forces_equal_finite_differences_of_the_energy() {
    for (name, mesh, configs) in cases() {
        let file = table_file(&mesh);
        let table = TensorMassTable::<f64>::load(file.bytes()).expect("valid table");
        let mut around: Vec<Vec<usize>> = vec![Vec::new(); mesh.positions.len()];
        for (t, tet) in mesh.tets.iter().enumerate() {
            for &v in tet {
                around[v as usize].push(t);
            }
        }
        let size = mesh
            .positions
            .iter()
            .flatten()
            .fold(0.0f64, |m, x| m.max(x.abs()));
        let h = 1e-6 * size;
        for (k, u) in configs.iter().enumerate() {
            let (f, _) = split_form(&table, u);
            let mut fd = vec![[0.0; 3]; u.len()];
            let mut v = u.clone();
            for (i, tets) in around.iter().enumerate() {
                let local = |v: &[[f64; 3]]| -> f64 {
                    tets.iter()
                        .map(|&t| {
                            let (rest, deformed) = corners(&mesh, &mesh.tets[t], v);
                            tet_energy(rest, deformed)
                        })
                        .sum()
                };
                for c in 0..3 {
                    v[i][c] = u[i][c] + h;
                    let plus = local(&v);
                    v[i][c] = u[i][c] - h;
                    let minus = local(&v);
                    v[i][c] = u[i][c];
                    fd[i][c] = -(plus - minus) / (2.0 * h);
                }
            }
            let rel = max_diff(&f, &fd) / max_abs(&fd);
            println!(
                "{name} config {k}: max |f| {:.3e} N, FD (h = {h:e} m) relative error {rel:.2e}",
                max_abs(&fd)
            );
            assert!(rel <= 1e-8, "{name} config {k}: {rel:e}");
        }
    }
}

/// Every configuration of `svk/svk_cube.json` (JAX f64, exact to rounding)
/// and `svk/svk_single_tet.json`. Where the body barely deforms (rigid
/// motions: W ~ 1e-27 J) the result is far below the terms the split form
/// sums, which round like `k |u|`: errors are relative to
/// `max(|W_ref|, Σ_i k_i |u_i|²)` (energy) and `max(max |f_ref|, max_i k_i |u_i|)`
/// (forces), `k_i` the largest entry of `K_ii` (N/m). Bound 1e-12 (f64
/// rounding of sums over ~24 tets), plus an absolute allowance for the
/// reference's own rounding, which works from positions `x`: `64 ε max_i k_i |x_i|`
/// (N) and `64 ε Σ_i k_i |x_i|²` (J) (only the identity configuration, whose
/// reference forces are 8.5e-16 N of noise, needs it). Measured: ≤ 3.4e-14
/// relative (printed).
#[test]
fn matches_jax_reference() {
    for (file_name, mesh) in [
        ("svk/svk_cube.json", cube()),
        ("svk/svk_single_tet.json", {
            let reference = read_reference_json("svk/svk_single_tet.json");
            let tet = reference["tet"].as_array().unwrap();
            TetMesh {
                positions: json_rows(&reference["X"]),
                tets: vec![[0, 1, 2, 3].map(|j| tet[j].as_u64().unwrap() as u32)],
            }
        }),
    ] {
        let reference = read_reference_json(file_name);
        assert_eq!(reference["E"].as_f64(), Some(YOUNG_PA));
        assert_eq!(reference["nu"].as_f64(), Some(POISSON));
        let file = table_file(&mesh);
        let table = TensorMassTable::<f64>::load(file.bytes()).expect("valid table");
        for config in reference["configs"].as_array().unwrap() {
            let name = config["name"].as_str().unwrap();
            let u: Vec<[f64; 3]> = json_rows(&config["x"])
                .iter()
                .zip(&mesh.positions)
                .map(|(x, p)| [x[0] - p[0], x[1] - p[1], x[2] - p[2]])
                .collect();
            let forces = json_rows(&config["forces"]);
            let energy = config["energy"].as_f64().unwrap();
            let (f, w) = split_form(&table, &u);
            let k: Vec<f64> = table
                .vertex_tensors()
                .iter()
                .map(|k| k.iter().fold(0.0f64, |m, x| m.max(x.abs())))
                .collect();
            let norm = |x: &[f64; 3]| Vector3::from(*x).norm();
            let x = json_rows(&config["x"]);
            let sum = |s: &[[f64; 3]], p: i32| -> f64 {
                k.iter().zip(s).map(|(k, s)| k * norm(s).powi(p)).sum()
            };
            let largest = |s: &[[f64; 3]]| -> f64 {
                k.iter()
                    .zip(s)
                    .map(|(k, s)| k * norm(s))
                    .fold(0.0, f64::max)
            };
            let energy_scale = sum(&u, 2).max(energy.abs());
            let force_scale = largest(&u).max(max_abs(&forces));
            let energy_floor = 64.0 * f64::EPSILON * sum(&x, 2);
            let force_floor = 64.0 * f64::EPSILON * largest(&x);
            let (we, fe) = ((w - energy).abs(), max_diff(&f, &forces));
            println!(
                "{file_name} {name}: W {w:.6e} vs {energy:.6e} J, energy error {we:.2e} J \
                 ({:.2e} relative), force error {fe:.2e} N ({:.2e} relative to {force_scale:.3e} N)",
                we / energy_scale,
                fe / force_scale
            );
            assert!(
                we <= 1e-12 * energy_scale + energy_floor,
                "{name}: {we:e} J"
            );
            assert!(fe <= 1e-12 * force_scale + force_floor, "{name}: {fe:e} N");
        }
    }
}

/// A rigid 90° rotation of the free cube about its centre: the linear model
/// alone gives large forces (it swells, MODELS.md §3); with the cubic and
/// quartic terms the total is zero to rounding. Bound 1e-9 relative to the
/// linear force; measured ≤ 1.3e-13 (printed).
#[test]
fn rigid_rotation_gives_zero_force() {
    let mesh = cube();
    let file = table_file(&mesh);
    let table = TensorMassTable::<f64>::load(file.bytes()).expect("valid table");
    let centre = Vector3::new(0.5, 0.5, 0.5);
    for axis in [Vector3::z(), Vector3::new(1.0, 2.0, 3.0)] {
        let rotation = Rotation3::from_axis_angle(&Unit::new_normalize(axis), 0.5 * PI);
        let u: Vec<[f64; 3]> = mesh
            .positions
            .iter()
            .map(|x| {
                let x = Vector3::from(*x) - centre;
                (rotation * x - x).into()
            })
            .collect();
        let linear = max_abs(&linear_forces(&table, &u));
        let (f, w) = split_form(&table, &u);
        let rel = max_abs(&f) / linear;
        let energy_rel = w.abs() / quadratic_energy(&table, &u);
        println!(
            "axis {axis:?}: linear force {linear:.3e} N, total {:.3e} N (relative {rel:.2e}), energy relative {energy_rel:.2e}",
            max_abs(&f)
        );
        assert!(rel <= 1e-9, "{rel:e}");
        assert!(energy_rel <= 1e-9, "{energy_rel:e}");
    }
}

/// Removing tets by subtracting their `tet_terms` (computed, as the kernel
/// will, from the table's rest shapes and Lamé coefficients) leaves the term
/// arrays of the mesh built without them: every vertex, edge (by vertex
/// pair), triangle (by vertex triple) and live tet, primitives that lost all
/// their tets compared with zero. Bound 1e-12 relative to the largest entry
/// of each kind; measured ≤ 2.8e-16 (printed).
#[test]
fn subtracting_tet_terms_equals_rebuild_without_the_tets() {
    let mesh = cube();
    let file = table_file(&mesh);
    let table = TensorMassTable::<f64>::load(file.bytes()).expect("valid table");
    // A corner tet, a few interior tets, and all 6 tets of one cell (so some
    // interior edges and triangles lose every tet).
    let removed: Vec<usize> = [0, 17, 100, 101, 374, 749]
        .into_iter()
        .chain(6 * 61..6 * 62)
        .collect();
    assert!((1..removed.len()).all(|k| !removed[k..].contains(&removed[k - 1])));
    let mut vertex = table.vertex_terms().to_vec();
    let mut edge = table.edge_terms().to_vec();
    let mut triangle = table.triangle_terms().to_vec();
    let mut tet = table.tet_terms().to_vec();
    let mut arrays = TermArraysMut {
        vertex: &mut vertex,
        edge: &mut edge,
        triangle: &mut triangle,
        tet: &mut tet,
    };
    for &t in &removed {
        let (a, volume) = table.tet_shape(t).unwrap();
        let [lambda, mu] = table.tet_materials()[t];
        let place = TetPlace {
            tet: t as u32,
            vertices: table.tets()[t],
            edges: table.tet_edges()[t],
            triangles: table.tet_triangles()[t],
        };
        tet_terms(place.vertices, &a, volume, lambda, mu).subtract_from(&place, &mut arrays);
    }

    let live = TetMesh {
        positions: mesh.positions.clone(),
        tets: mesh
            .tets
            .iter()
            .enumerate()
            .filter(|(t, _)| !removed.contains(t))
            .map(|(_, tet)| *tet)
            .collect(),
    };
    let rebuilt = TensorMassArrays::new(
        &live,
        &TetMaterials::uniform(options().material, live.tets.len()),
        1000.0,
        vec![false; mesh.positions.len()],
    );
    fn largest<const L: usize>(x: &[[f64; L]]) -> f64 {
        x.iter().flatten().fold(0.0, |m, v| m.max(v.abs()))
    }
    fn diff<const L: usize>(a: &[f64; L], b: Option<&[f64; L]>) -> f64 {
        let zero = [0.0; L];
        let b = b.unwrap_or(&zero);
        a.iter().zip(b).fold(0.0, |m, (x, y)| m.max((x - y).abs()))
    }

    let vertex_err = vertex
        .iter()
        .zip(&rebuilt.vertex_terms)
        .map(|(a, b)| diff(a, Some(b)))
        .fold(0.0, f64::max)
        / largest(table.vertex_terms());

    let pairs = |row_start: &[u32], column: &[u32]| -> HashMap<[u32; 2], usize> {
        let mut out = HashMap::new();
        for (i, row) in row_start.windows(2).enumerate() {
            for (e, &j) in column
                .iter()
                .enumerate()
                .take(row[1] as usize)
                .skip(row[0] as usize)
            {
                out.insert([i as u32, j], e);
            }
        }
        out
    };
    let rebuilt_edges = pairs(&rebuilt.row_start, &rebuilt.column);
    let mut emptied_edges = 0;
    let edge_err = pairs(table.edge_row_starts(), table.edge_columns())
        .iter()
        .map(|(pair, &e)| {
            let theirs = rebuilt_edges.get(pair).map(|&k| &rebuilt.edge_terms[k]);
            emptied_edges += usize::from(theirs.is_none());
            diff(&edge[e], theirs)
        })
        .fold(0.0, f64::max)
        / largest(table.edge_terms());

    let rebuilt_triangles: HashMap<[u32; 3], usize> = rebuilt
        .mesh_triangles
        .iter()
        .enumerate()
        .map(|(k, t)| (*t, k))
        .collect();
    let mut emptied_triangles = 0;
    let triangle_err = table
        .mesh_triangles()
        .iter()
        .zip(&triangle)
        .map(|(tri, ours)| {
            let theirs = rebuilt_triangles
                .get(tri)
                .map(|&k| &rebuilt.triangle_terms[k]);
            emptied_triangles += usize::from(theirs.is_none());
            diff(ours, theirs)
        })
        .fold(0.0, f64::max)
        / largest(table.triangle_terms());

    let live_tets: Vec<&[f64; 3]> = tet
        .iter()
        .enumerate()
        .filter(|(t, _)| !removed.contains(t))
        .map(|(_, x)| x)
        .collect();
    assert_eq!(live_tets.len(), rebuilt.tet_terms.len());
    let removed_tet_err = removed
        .iter()
        .map(|&t| diff(&tet[t], None))
        .fold(0.0, f64::max);
    let tet_err = live_tets
        .iter()
        .zip(&rebuilt.tet_terms)
        .map(|(a, b)| diff(a, Some(b)))
        .fold(removed_tet_err, f64::max)
        / largest(table.tet_terms());

    println!(
        "removed {} tets ({emptied_edges} edges, {emptied_triangles} triangles emptied): \
         relative error vertex {vertex_err:.2e}, edge {edge_err:.2e}, triangle {triangle_err:.2e}, tet {tet_err:.2e}",
        removed.len()
    );
    assert!(emptied_edges > 0 && emptied_triangles > 0);
    for err in [vertex_err, edge_err, triangle_err, tet_err] {
        assert!(err <= 1e-12, "{err:e}");
    }
}

/// The f32 table of the same mesh loads, and its terms are the f64 ones
/// rounded.
#[test]
fn f32_table_loads() {
    let mesh = small_box();
    let bytes = build(
        &mesh,
        &MeshReport::default(),
        &BuildOptions {
            precision: Precision::F32,
            ..options()
        },
    )
    .unwrap()
    .bytes;
    let file = TableFile::from_bytes(&bytes);
    let t32 = TensorMassTable::<f32>::load(file.bytes()).expect("valid f32 table");
    let f64_file = table_file(&mesh);
    let t64 = TensorMassTable::<f64>::load(f64_file.bytes()).unwrap();
    assert_eq!(t32.mesh_triangles(), t64.mesh_triangles());
    assert_eq!(t32.tet_triangles(), t64.tet_triangles());
    for (a, b) in t32.triangle_terms().iter().zip(t64.triangle_terms()) {
        for (x, y) in a.iter().zip(b) {
            assert_eq!(*x, *y as f32);
        }
    }
    // Every face of a conformal mesh: (4 T + boundary) / 2.
    let boundary = t64.surface_triangles().len();
    assert_eq!(
        t64.mesh_triangles().len(),
        (4 * t64.tet_count() + boundary) / 2
    );
}

/// Structural corruption of the new sections behind a valid checksum is
/// refused at load with the precise error.
#[test]
fn broken_triangle_sections_are_refused() {
    let mesh = small_box();
    let opts = options();
    let arrays = TensorMassArrays::new(
        &mesh,
        &TetMaterials::uniform(opts.material, mesh.tets.len()),
        1000.0,
        vec![false; mesh.positions.len()],
    );
    let triangles = boundary_surface(&mesh).triangles;
    let load = |arrays: &TensorMassArrays| {
        let bytes = write_tensor_mass_table(&mesh, &triangles, arrays, opts.precision);
        let file = TableFile::from_bytes(&bytes);
        TensorMassTable::<f64>::load(file.bytes()).map(|_| ())
    };
    assert_eq!(load(&arrays), Ok(()));

    let mut bad = arrays.clone();
    bad.mesh_triangles.swap(3, 4);
    assert_eq!(load(&bad), Err(LoadError::BadMeshTriangle { triangle: 4 }));
    let mut bad = arrays.clone();
    bad.mesh_triangles[2] = [bad.mesh_triangles[2][1], bad.mesh_triangles[2][0], 99];
    assert_eq!(load(&bad), Err(LoadError::BadMeshTriangle { triangle: 2 }));
    let mut bad = arrays.clone();
    bad.tet_triangles[5][2] = bad.tet_triangles[5][3];
    assert_eq!(load(&bad), Err(LoadError::BadTetTriangle { tet: 5 }));
    let mut bad = arrays.clone();
    bad.tet_triangles[7][0] = bad.mesh_triangles.len() as u32;
    assert_eq!(load(&bad), Err(LoadError::BadTetTriangle { tet: 7 }));
    // A triangle that is no tet's face (after the last one, so still sorted).
    let mut bad = arrays.clone();
    let n = mesh.positions.len() as u32;
    assert!(bad.mesh_triangles.last() < Some(&[n - 3, n - 2, n - 1]));
    bad.mesh_triangles.push([n - 3, n - 2, n - 1]);
    bad.triangle_terms.push([0.0; 15]);
    assert_eq!(load(&bad), Err(LoadError::InconsistentHeader));
    let mut bad = arrays.clone();
    bad.triangle_terms[11][4] = f64::NAN;
    assert_eq!(
        load(&bad),
        Err(LoadError::NonFinite {
            kind: SectionKind::TriangleTerms,
            index: 11
        })
    );
}
