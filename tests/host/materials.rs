//! Heterogeneous tissue: per-tet materials (`palpate::fem::material::TetMaterials`, the scene's
//! `[[region]]` in `palpate::scene::materials`, the table's `tet-material` section).
//!
//! Independent truth: a dense global linear FEM written here from MODELS.md §1 alone (own shape
//! gradients, own element blocks, nalgebra's dense Cholesky on the Dirichlet-reduced system),
//! sharing nothing with the host's sparse assembly, the compliance solve or the kernel; the
//! St Venant-Kirchhoff energy written here from its definition (MODELS.md §4); and the
//! tensor-mass arrays rebuilt from scratch on the mesh without the removed tets.
//!
//! The block: 10 × 6 × 4 cm, 1 cm Kuhn cells (385 vertices, 1440 tets), base fixed,
//! E = 3 kPa, ν = 0.45; a nodule of region 2, the 2 × 2 × 2 cells whose centre lies in
//! [2, 4] × [2, 4] × [1, 3] cm (48 tets, 1 cm under the top), E = 30 kPa (10×), ν = 0.45.
//! The presses: 2 mm down at the top vertex above the nodule's centre (3, 3, 4) cm, and at its
//! mirror image across the block's middle (7, 3, 4) cm, where the tissue is homogeneous.

use std::path::{Path, PathBuf};

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use palpate::fem::material::{Material, TetMaterials};
use palpate::mesh::generate::box_mesh;
use palpate::mesh::{MeshReport, TetMesh};
use palpate::scene::{Generator, Press, Scene, Slide};
use palpate::session::run::run_session;
use palpate::table::build::{BuildOptions, build};
use palpate::table::compliance::Solver;
use palpate::table::file::Precision;
use palpate::table::load::TableFile;
use palpate::table::tensor_mass::TensorMassArrays;
use palpate::tensor_mass::OwnedState;
use palpate::tensor_mass::run::host_params;
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::table::format::{HEADER_LEN, SECTION_ENTRY_LEN, SectionEntry, SectionKind};
use palpate_kernel::tensor_mass::{ElasticLaw, StvkForm, TensorMassModel};
use palpate_kernel::{Constraint, LoadError, PrecomputedModel, PrecomputedTable};

const SOFT_PA: f64 = 3000.0;
const NODULE_PA: f64 = 30000.0;
const POISSON: f64 = 0.45;
const NODULE: u32 = 2;
const ABOVE: [f64; 3] = [0.03, 0.03, 0.04];
const BESIDE: [f64; 3] = [0.07, 0.03, 0.04];

fn block() -> TetMesh {
    box_mesh([10, 6, 4], [0.10, 0.06, 0.04])
}

/// Region 2 for the tets whose centroid lies in the nodule's box, 1 elsewhere.
fn regions(mesh: &TetMesh) -> Vec<u32> {
    (0..mesh.tets.len())
        .map(|t| {
            let c = mesh.tet_centroid(t);
            let inside = (0.02..0.04).contains(&c[0])
                && (0.02..0.04).contains(&c[1])
                && (0.01..0.03).contains(&c[2]);
            if inside { NODULE } else { 1 }
        })
        .collect()
}

fn materials(mesh: &TetMesh) -> TetMaterials {
    let soft = Material::new(SOFT_PA, POISSON).unwrap();
    let stiff = Material::new(NODULE_PA, POISSON).unwrap();
    TetMaterials::from_regions(soft, &regions(mesh), &[(NODULE, stiff)])
}

fn vertex_at(mesh: &TetMesh, p: [f64; 3]) -> u32 {
    let d = |q: &[f64; 3]| (0..3).map(|i| (q[i] - p[i]).powi(2)).sum::<f64>();
    let (v, q) = mesh
        .positions
        .iter()
        .enumerate()
        .min_by(|a, b| d(a.1).total_cmp(&d(b.1)))
        .unwrap();
    assert!(d(q) < 1e-20, "no vertex at {p:?}");
    v as u32
}

fn base_fixed(mesh: &TetMesh) -> Vec<bool> {
    mesh.positions.iter().map(|p| p[2] < 0.001).collect()
}

/// The dense global stiffness (N/m, DOF `3v + c`) from MODELS.md §1, per tet with its own
/// `(λ, μ)`: `K_jk = V (λ a_j a_kᵀ + μ a_k a_jᵀ + μ (a_j·a_k) I)`, `a_1..a_3` the rows of
/// `[p1−p0, p2−p0, p3−p0]⁻¹`.
fn dense_stiffness(mesh: &TetMesh, lame: &[[f64; 2]]) -> DMatrix<f64> {
    let n = 3 * mesh.positions.len();
    let mut k = DMatrix::zeros(n, n);
    for (tet, &[lambda, mu]) in mesh.tets.iter().zip(lame) {
        let p = tet.map(|v| Vector3::from(mesh.positions[v as usize]));
        let d = Matrix3::from_columns(&[p[1] - p[0], p[2] - p[0], p[3] - p[0]]);
        let volume = d.determinant().abs() / 6.0;
        let inv = d.try_inverse().unwrap();
        let [a1, a2, a3] = [0, 1, 2].map(|r| inv.row(r).transpose());
        let a = [-(a1 + a2 + a3), a1, a2, a3];
        for j in 0..4 {
            for l in 0..4 {
                let block = volume
                    * (lambda * a[j] * a[l].transpose()
                        + mu * a[l] * a[j].transpose()
                        + mu * a[j].dot(&a[l]) * Matrix3::identity());
                let (r, c) = (3 * tet[j] as usize, 3 * tet[l] as usize);
                let mut view = k.view_mut((r, c), (3, 3));
                view += block;
            }
        }
    }
    k
}

/// The reaction (N) at vertex `v` displaced by `d` (m), base fixed, every other vertex
/// force-free: `K_UU u_U = −K_UP u_P` by dense Cholesky, then `(K u)_v`.
fn dense_press(mesh: &TetMesh, k: &DMatrix<f64>, v: u32, d: [f64; 3]) -> Vector3<f64> {
    let fixed = base_fixed(mesh);
    let unknown: Vec<usize> = (0..mesh.positions.len())
        .filter(|&w| !fixed[w] && w != v as usize)
        .flat_map(|w| [3 * w, 3 * w + 1, 3 * w + 2])
        .collect();
    let mut u = DVector::zeros(k.nrows());
    for c in 0..3 {
        u[3 * v as usize + c] = d[c];
    }
    let rhs = -(k * &u);
    let k_uu = k.select_rows(&unknown).select_columns(&unknown);
    let rhs_u = DVector::from_iterator(unknown.len(), unknown.iter().map(|&i| rhs[i]));
    let x = k_uu.cholesky().expect("SPD").solve(&rhs_u);
    for (&i, xi) in unknown.iter().zip(x.iter()) {
        u[i] = *xi;
    }
    let f = k * &u;
    Vector3::new(
        f[3 * v as usize],
        f[3 * v as usize + 1],
        f[3 * v as usize + 2],
    )
}

fn f64_table(mesh: &TetMesh, options: BuildOptions) -> TableFile {
    let options = options.with_tet_materials(materials(mesh));
    TableFile::from_bytes(&build(mesh, &MeshReport::default(), &options).unwrap().bytes)
}

fn precomputed_table(mesh: &TetMesh) -> TableFile {
    let soft = Material::new(SOFT_PA, POISSON).unwrap();
    let fix = vec!["z<0.001".parse().unwrap()];
    f64_table(
        mesh,
        BuildOptions::precomputed(soft, fix, Solver::Cholesky, Precision::F64),
    )
}

fn tensor_mass_table(mesh: &TetMesh) -> TableFile {
    let soft = Material::new(SOFT_PA, POISSON).unwrap();
    f64_table(
        mesh,
        BuildOptions::tensor_mass(soft, 1000.0, Vec::new(), Precision::F64),
    )
}

/// A press above the nodule needs more force than one beside it, and both forces of the
/// pre-computed model (compliance by sparse Cholesky, contact solve in the kernel) equal the
/// dense global solve's reaction. Tolerance 1e-6 relative: both are direct solves of the same
/// SPD system in f64 (the reduced stiffness' condition number here is about 1e5, so rounding
/// leaves at most some 1e-11); measured 2.4e-15 above and 1.4e-15 beside (printed). Forces:
/// 0.1543 N above, 0.0936 N beside, ratio 1.649; the homogeneous block's two presses differ by
/// 1.5 % (the Kuhn split is not mirror-symmetric), so the nodule's ratio is its own.
#[test]
fn stiff_nodule_raises_the_press_force_and_matches_a_global_solve() {
    let mesh = block();
    let lame = materials(&mesh).lame();
    assert_eq!(regions(&mesh).iter().filter(|&&r| r == NODULE).count(), 48);
    let k = dense_stiffness(&mesh, &lame);
    let file = precomputed_table(&mesh);
    let table = PrecomputedTable::<f64>::load(file.bytes()).unwrap();
    assert_eq!(table.tet_materials().len(), mesh.tets.len());
    assert_eq!(table.header().tet_count as usize, mesh.tets.len());
    let model = PrecomputedModel::new(table);
    let d = [0.0, 0.0, -0.002];
    let mut forces = Vec::new();
    for p in [ABOVE, BESIDE] {
        let v = vertex_at(&mesh, p);
        let kernel = model
            .contact_forces::<1>(&[Constraint::at_vertex(v, Vector3::from(d))])
            .unwrap()
            .contact_forces_n()[0];
        let truth = dense_press(&mesh, &k, v, d);
        let error = (kernel - truth).norm() / truth.norm();
        println!(
            "press at {p:?}: pre-computed {:.9} N, global solve {:.9} N, relative error {error:.1e}",
            kernel.norm(),
            truth.norm()
        );
        assert!(error <= 1e-6, "{error:e}");
        forces.push(truth.norm());
    }
    let ratio = forces[0] / forces[1];
    let uniform = dense_stiffness(&mesh, &vec![lame[0]; mesh.tets.len()]);
    let homogeneous = dense_press(&mesh, &uniform, vertex_at(&mesh, ABOVE), d).norm()
        / dense_press(&mesh, &uniform, vertex_at(&mesh, BESIDE), d).norm();
    println!("above / beside: nodule {ratio:.4}, homogeneous block {homogeneous:.4}");
    assert!((homogeneous - 1.0).abs() < 0.02, "{homogeneous}");
    assert!(ratio > 1.2 * homogeneous, "{ratio}");
}

/// The tensor-mass model's linear force with per-tet materials is `−K u` of the dense global
/// stiffness: the same sums in another order, so equal to 1e-12 relative (measured 7.7e-16);
/// its St Venant-Kirchhoff energy equals the definition with each tet's `(λ, μ)` (1e-12), and
/// its per-tet forces equal a central difference of that energy (step 1e-7 m: truncation
/// ~h² W''' and rounding ~ε W / h both below 1e-8 of the largest force; tolerance 1e-6,
/// measured 1.5e-9).
#[test]
fn tensor_mass_forces_and_energy_use_each_tets_material() {
    let mesh = block();
    let lame = materials(&mesh).lame();
    let k = dense_stiffness(&mesh, &lame);
    let file = tensor_mass_table(&mesh);
    let table = TensorMassTable::<f64>::load(file.bytes()).unwrap();
    let n = mesh.positions.len();
    // A smooth field, 1 mm at most, largest over the nodule.
    let u: Vec<[f64; 3]> = mesh
        .positions
        .iter()
        .map(|p| {
            let s = (p[0] * 40.0).sin() * (p[1] * 50.0).cos();
            [
                3e-4 * s,
                -2e-4 * s * p[2] * 25.0,
                -1e-3 * (p[2] / 0.04) * s.abs(),
            ]
        })
        .collect();
    let ku = &k * DVector::from_iterator(3 * n, u.iter().flatten().copied());

    let mut state = OwnedState::for_table(&table);
    let linear =
        TensorMassModel::new(table, state.buffers(), host_params(&mesh.positions, 0.0)).unwrap();
    let mut f = vec![[0.0; 3]; n];
    linear.elastic_forces_of(&u, &mut f);
    let scale = ku.amax();
    let error = f
        .iter()
        .flatten()
        .zip(ku.iter())
        .map(|(a, b)| (a + b).abs())
        .fold(0.0f64, f64::max)
        / scale;
    println!("linear tensor-mass force vs -K u: {error:.1e} of the largest");
    assert!(error <= 1e-12, "{error:e}");

    let table = TensorMassTable::<f64>::load(file.bytes()).unwrap();
    let mut state = OwnedState::for_table(&table);
    let params =
        host_params(&mesh.positions, 0.0).with_law(ElasticLaw::StVenantKirchhoff(StvkForm::PerTet));
    let stvk = TensorMassModel::new(table, state.buffers(), params).unwrap();
    let mut scratch = vec![[0.0; 3]; n];
    let energy = |u: &[[f64; 3]], scratch: &mut Vec<[f64; 3]>| stvk.elastic_energy_of(u, scratch);
    let truth = stvk_energy(&mesh, &lame, &u);
    let e = energy(&u, &mut scratch);
    println!("St Venant-Kirchhoff energy {e:.6e} J, definition {truth:.6e} J");
    assert!((e - truth).abs() <= 1e-12 * truth, "{e} vs {truth}");
    let mut f = vec![[0.0; 3]; n];
    stvk.elastic_forces_of(&u, &mut f);
    let largest = f.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    let h = 1e-7;
    let mut worst = 0.0f64;
    for v in [
        vertex_at(&mesh, ABOVE),
        vertex_at(&mesh, [0.03, 0.03, 0.02]),
    ] {
        for c in 0..3 {
            let mut plus = u.clone();
            plus[v as usize][c] += h;
            let mut minus = u.clone();
            minus[v as usize][c] -= h;
            let slope = (energy(&plus, &mut scratch) - energy(&minus, &mut scratch)) / (2.0 * h);
            worst = worst.max((f[v as usize][c] + slope).abs() / largest);
        }
    }
    println!("per-tet StVK force vs -dW/du: {worst:.1e} of the largest");
    assert!(worst <= 1e-6, "{worst:e}");
}

/// `Σ V (λ/2 (tr E)² + μ tr E²)`, `E = ½(FᵀF − I)`, `F = I + Σ_j u_j a_jᵀ`.
fn stvk_energy(mesh: &TetMesh, lame: &[[f64; 2]], u: &[[f64; 3]]) -> f64 {
    let mut w = 0.0;
    for (tet, &[lambda, mu]) in mesh.tets.iter().zip(lame) {
        let p = tet.map(|v| Vector3::from(mesh.positions[v as usize]));
        let x = tet.map(|v| p_of(u, v));
        let d = Matrix3::from_columns(&[p[1] - p[0], p[2] - p[0], p[3] - p[0]]);
        let dx = Matrix3::from_columns(&[x[1] - x[0], x[2] - x[0], x[3] - x[0]]);
        let f = Matrix3::identity() + dx * d.try_inverse().unwrap();
        let e = (f.transpose() * f - Matrix3::identity()) / 2.0;
        let volume = d.determinant().abs() / 6.0;
        w += volume * (lambda / 2.0 * e.trace().powi(2) + mu * (e * e).trace());
    }
    w
}

fn p_of(u: &[[f64; 3]], v: u32) -> Vector3<f64> {
    Vector3::from(u[v as usize])
}

/// Removing tets with their own material (a nodule tet, a soft tet touching the nodule) leaves
/// the stiffness of the mesh built without them: the same blocks subtracted that were added, so
/// equal to rounding (1e-12 of the largest tensor; measured ~1e-16).
#[test]
fn removing_a_nodule_tet_leaves_the_stiffness_of_the_mesh_without_it() {
    let mesh = block();
    let regions = regions(&mesh);
    let file = tensor_mass_table(&mesh);
    let table = TensorMassTable::<f64>::load(file.bytes()).unwrap();
    let mut state = OwnedState::for_table(&table);
    let mut model =
        TensorMassModel::new(table, state.buffers(), host_params(&mesh.positions, 0.0)).unwrap();
    let nodule = regions.iter().position(|&r| r == NODULE).unwrap();
    let touches = |t: usize| mesh.tets[t].iter().any(|v| mesh.tets[nodule].contains(v));
    let soft = (0..mesh.tets.len())
        .find(|&t| regions[t] != NODULE && touches(t))
        .unwrap();
    for t in [nodule, soft] {
        model.remove_tet(t as u32).unwrap();
    }
    let alive = model.tet_alive().to_vec();
    let live = palpate_tests::live_mesh(&mesh, &alive);
    let all = materials(&mesh);
    let live_materials = TetMaterials::from_regions(
        all.default_material(),
        &regions
            .iter()
            .zip(&alive)
            .filter(|(_, a)| **a)
            .map(|(r, _)| *r)
            .collect::<Vec<_>>(),
        &[(NODULE, Material::new(NODULE_PA, POISSON).unwrap())],
    );
    let rebuilt = TensorMassArrays::new(
        &live,
        &live_materials,
        1000.0,
        vec![false; mesh.positions.len()],
    );
    let (worst, scale) = palpate_tests::tensor_difference(&model, &file, &rebuilt);
    println!(
        "removal vs rebuild: {:.1e} of the largest tensor",
        worst / scale
    );
    assert!(worst <= 1e-12 * scale, "{}", worst / scale);
}

/// The directory entry of section `kind` in `bytes`.
fn section_entry(bytes: &[u8], kind: SectionKind) -> SectionEntry {
    bytes[HEADER_LEN..]
        .chunks_exact(SECTION_ENTRY_LEN)
        .map(entry_of)
        .find(|e| e.kind == kind as u32)
        .unwrap()
}

fn entry_of(raw: &[u8]) -> SectionEntry {
    let word = |i: usize| u64::from_le_bytes(raw[i..i + 8].try_into().unwrap());
    SectionEntry {
        kind: u32::from_le_bytes(raw[0..4].try_into().unwrap()),
        elem_bytes: u32::from_le_bytes(raw[4..8].try_into().unwrap()),
        offset: word(8),
        count: word(16),
    }
}

/// `bytes` with a fresh CRC-32 trailer.
fn with_crc(mut bytes: Vec<u8>) -> Vec<u8> {
    let body = bytes.len() - 4;
    let sum = crc::Crc::<u32>::new(&palpate_kernel::table::format::CRC32).checksum(&bytes[..body]);
    bytes[body..].copy_from_slice(&sum.to_le_bytes());
    bytes
}

/// A version-2 table is refused by the kernel and by the host's reader, whose message says to
/// rebuild it; a tet's Lamé coefficients out of range are refused naming the tet.
#[test]
fn version_2_tables_and_bad_tet_materials_are_refused() {
    let mesh = box_mesh([2, 2, 2], [0.02, 0.02, 0.02]);
    let file = tensor_mass_table(&mesh);
    let mut old = file.bytes().to_vec();
    old[8..12].copy_from_slice(&2u32.to_le_bytes());
    let old = TableFile::from_bytes(&with_crc(old));
    assert_eq!(
        TensorMassTable::<f64>::load(old.bytes()).unwrap_err(),
        LoadError::UnsupportedVersion { found: 2 }
    );
    let dir = temp_dir("version2");
    let path = dir.join("old.tbl");
    std::fs::write(&path, old.bytes()).unwrap();
    let message = TableFile::read(&path).err().unwrap().to_string();
    println!("{message}");
    assert!(
        message.contains(
            "table format version 2 is not read by this kernel (version 6): rebuild the table with `palpate tables build`"
        ),
        "{message}"
    );
    assert!(!message.contains('\n'));

    let entry = section_entry(file.bytes(), SectionKind::TetMaterial);
    let mut bad = file.bytes().to_vec();
    // Tet 1's μ (the second f64 of its pair) negative.
    let at = entry.offset as usize + 16 + 8;
    bad[at..at + 8].copy_from_slice(&(-1.0f64).to_le_bytes());
    let bad = TableFile::from_bytes(&with_crc(bad));
    assert_eq!(
        TensorMassTable::<f64>::load(bad.bytes()).unwrap_err(),
        LoadError::BadTetMaterial { tet: 1 }
    );
}

/// The `tet-lanes` section (the St Venant-Kirchhoff pass's rest data by
/// blocks of 8 tets) must repeat `tet-shape` and `tet-material`: a lane
/// that differs is refused naming its tet, and so is a non-zero lane past
/// the last tet (6 tets: lanes 6 and 7 of the one block are padding).
#[test]
fn tet_lanes_that_differ_from_their_tets_are_refused() {
    let mesh = box_mesh([1, 1, 1], [0.02, 0.02, 0.02]);
    assert_eq!(mesh.tets.len(), 6);
    let file = tensor_mass_table(&mesh);
    let table = TensorMassTable::<f64>::load(file.bytes()).unwrap();
    let lanes = table.tet_lanes();
    assert_eq!(lanes.len(), 1);
    let (a, volume) = table.tet_shape(4).unwrap();
    assert_eq!(lanes[0][3 * 2 + 1][4], a[3][1], "a_3.y of tet 4");
    assert_eq!(lanes[0][9][4], volume);
    assert_eq!(lanes[0][11][4], table.tet_materials()[4][1], "mu of tet 4");
    assert_eq!(lanes[0][0][6], 0.0);

    let entry = section_entry(file.bytes(), SectionKind::TetLanes);
    // Row r, lane l of block 0 (f64): byte (8 r + l) · 8.
    let corrupt = |row: usize, lane: usize, value: f64| {
        let mut bytes = file.bytes().to_vec();
        let at = entry.offset as usize + (8 * row + lane) * 8;
        bytes[at..at + 8].copy_from_slice(&value.to_le_bytes());
        TableFile::from_bytes(&with_crc(bytes))
    };
    let mu_of_tet_1 = corrupt(11, 1, 2.0 * table.tet_materials()[1][1]);
    assert_eq!(
        TensorMassTable::<f64>::load(mu_of_tet_1.bytes()).unwrap_err(),
        LoadError::BadTetLanes { tet: 1 }
    );
    let padding = corrupt(0, 7, 1.0);
    assert_eq!(
        TensorMassTable::<f64>::load(padding.bytes()).unwrap_err(),
        LoadError::BadTetLanes { tet: 7 }
    );
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("palpate-materials-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `mesh` as MSH 2.2 ASCII, each tet's physical tag its region.
fn write_msh(path: &Path, mesh: &TetMesh, regions: &[u32]) {
    let mut text = String::from("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n");
    text += &format!("{}\n", mesh.positions.len());
    for (i, p) in mesh.positions.iter().enumerate() {
        text += &format!("{} {:?} {:?} {:?}\n", i + 1, p[0], p[1], p[2]);
    }
    text += &format!("$EndNodes\n$Elements\n{}\n", mesh.tets.len());
    for (t, (tet, r)) in mesh.tets.iter().zip(regions).enumerate() {
        let [a, b, c, d] = tet.map(|v| v + 1);
        text += &format!("{} 4 2 {r} {r} {a} {b} {c} {d}\n", t + 1);
    }
    text += "$EndElements\n";
    std::fs::write(path, text).unwrap();
}

const NODULE_SCENE: &str = "mesh = \"nodule.msh\"\nfix = [\"z<0.001\"]\n\
    [material]\nyoung_pa = 3000.0\npoisson = 0.45\n\
    [[region]]\nid = 2\nyoung_pa = 30000.0\npoisson = 0.45\n";

/// The scene's `[[region]]` gives the nodule's tets its material, the rest `[material]`; a
/// region id absent from the mesh, or a mesh without region ids, is one line naming the key
/// and the mesh.
#[test]
fn scene_regions_map_to_tets_and_a_missing_region_is_named() {
    let dir = temp_dir("scene");
    let mesh = block();
    write_msh(&dir.join("nodule.msh"), &mesh, &regions(&mesh));
    let scene = Scene::from_toml_str_named(NODULE_SCENE, "nodule.toml", &dir).unwrap();
    let (read, report) = scene.load_mesh().unwrap();
    let per_tet = scene.tet_materials(&read, &report).unwrap();
    for (m, r) in per_tet.per_tet().iter().zip(regions(&mesh)) {
        let want = if r == NODULE { NODULE_PA } else { SOFT_PA };
        assert_eq!((m.young_pa, m.poisson), (want, POISSON));
    }
    assert_eq!(per_tet.default_material().young_pa, SOFT_PA);

    let absent = NODULE_SCENE.replace("id = 2", "id = 5");
    let scene = Scene::from_toml_str_named(&absent, "nodule.toml", &dir).unwrap();
    let (read, report) = scene.load_mesh().unwrap();
    let message = scene.tet_materials(&read, &report).unwrap_err().to_string();
    println!("{message}");
    assert!(
        message.starts_with("nodule.toml: [[region]] id = 5: "),
        "{message}"
    );
    assert!(message.contains("nodule.msh") && message.contains("regions: 1, 2"));
    assert!(!message.contains('\n'));

    let generated = NODULE_SCENE.replace(
        "mesh = \"nodule.msh\"",
        "[generated]\nbox_m = [0.1, 0.06, 0.04]\ncells = [10, 6, 4]\n",
    );
    // `[generated]` is a table: the top-level keys go first.
    let generated = generated.replace(
        "[generated]\nbox_m = [0.1, 0.06, 0.04]\ncells = [10, 6, 4]\n\nfix = [\"z<0.001\"]\n",
        "fix = [\"z<0.001\"]\n[generated]\nbox_m = [0.1, 0.06, 0.04]\ncells = [10, 6, 4]\n",
    );
    let scene = Scene::from_toml_str_named(&generated, "box.toml", &dir).unwrap();
    let (read, report) = scene.load_mesh().unwrap();
    let message = scene.tet_materials(&read, &report).unwrap_err().to_string();
    assert!(
        message.starts_with("box.toml: [[region]] id = 2: the mesh generated box"),
        "{message}"
    );

    for (text, key) in [
        (
            NODULE_SCENE.replace("young_pa = 30000.0", "young_pa = -1.0"),
            "[[region]] id = 2: young_pa = -1",
        ),
        (
            NODULE_SCENE.replace(
                "id = 2\nyoung_pa = 30000.0\npoisson = 0.45",
                "id = 2\nyoung_pa = 30000.0\npoisson = 0.5",
            ),
            "[[region]] id = 2: poisson = 0.5",
        ),
        (
            format!("{NODULE_SCENE}[[region]]\nid = 2\nyoung_pa = 1.0\npoisson = 0.1\n"),
            "[[region]] id = 2: given twice",
        ),
        (
            format!("{NODULE_SCENE}density_kg_m3 = 1200.0\n"),
            "[[region]] id = 2: density_kg_m3 = 1200",
        ),
    ] {
        let message = Scene::from_toml_str_named(&text, "nodule.toml", &dir)
            .unwrap_err()
            .to_string();
        assert!(
            message.starts_with(&format!("nodule.toml: {key}")),
            "{message}"
        );
    }
}

/// `palpate session run` (the function the command calls) on the nodule scene, a probe sliding
/// 3 mm deep across the top from x = 1 cm to 9 cm over the nodule (at x = 3 cm) and its mirror
/// point (7 cm): the force at the same depth is larger over the nodule by the factor printed
/// (measured 0.415 N over 0.251 N, 1.65; asserted > 1.2).
#[test]
fn palpation_sweep_feels_the_nodule() {
    let dir = temp_dir("sweep");
    let mesh = block();
    write_msh(&dir.join("nodule.msh"), &mesh, &regions(&mesh));
    let scene = Scene::from_toml_str_named(NODULE_SCENE, "nodule.toml", &dir).unwrap();
    let slide = Slide {
        press: Press {
            surface_m: [0.01, 0.03, 0.04],
            depth_m: 0.003,
            ..Press::default()
        },
        direction: [1.0, 0.0, 0.0],
        distance_m: 0.08,
        ..Slide::default()
    };
    let trajectory = slide.trajectory().unwrap();
    let mut out = Vec::new();
    run_session(&scene, &trajectory, &mut out, None).unwrap();
    let text = String::from_utf8(out).unwrap();
    let near = |x0: f64| {
        let forces: Vec<f64> = text
            .lines()
            .skip(1)
            .filter_map(|line| {
                let cols: Vec<f64> = line
                    .split(',')
                    .take(4)
                    .map(|c| c.parse().unwrap())
                    .collect();
                let p = trajectory.positions_at(cols[0])[0];
                let deep = (p[2] - (0.04 - 0.003)).abs() < 1e-9;
                (deep && (p[0] - x0).abs() <= 0.001)
                    .then(|| (cols[1].powi(2) + cols[2].powi(2) + cols[3].powi(2)).sqrt())
            })
            .collect();
        assert!(forces.len() > 50, "{} samples near x = {x0}", forces.len());
        forces.iter().sum::<f64>() / forces.len() as f64
    };
    let (over, away) = (near(ABOVE[0]), near(BESIDE[0]));
    println!(
        "sweep: |F| over the nodule {over:.4} N, at the mirror point {away:.4} N, ratio {:.3}",
        over / away
    );
    assert!(over / away > 1.2, "{over} vs {away}");
}
