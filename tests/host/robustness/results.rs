//! See `super`: the results probes. Each input once gave a wrong or unusable
//! result with exit 0 (or an error that named nothing); each is now a clear
//! error naming the file, line, key or element, or a correct result. The
//! command-line side (exit status 2, one line) is in
//! `host-harness/tests/robustness_results.rs`.

use std::path::Path;

use nalgebra::Vector3;
use palpate::fem::material::Material;
use palpate::mesh::generate::box_mesh;
use palpate::mesh::{MeshFormat, MeshReport, TetMesh, read_mesh, read_mesh_bytes};
use palpate::session::Scene;
use palpate::table::build::{BuildOptions, build};
use palpate::table::compliance::Solver;
use palpate::table::file::Precision;
use palpate::table::load::{AnyModel, TableFile};
use palpate::tensor_mass::evaluate::{NonFiniteResult, forces_and_energy};
use palpate::tensor_mass::stability::critical_dt_of_mesh;
use palpate_kernel::tensor_mass::{ElasticLaw, Integrator, StvkForm};
use palpate_kernel::{Constraint, ContactError};
use palpate_tests::{reference_cube_table, reference_dir};

fn cube() -> (TetMesh, MeshReport) {
    read_mesh(&reference_dir().join("meshes/cube.msh")).expect("cube.msh")
}

fn base() -> Vec<palpate::fix::FixPredicate> {
    vec!["z<0.001".parse().expect("predicate")]
}

fn material(young_pa: f64) -> Material {
    Material::new(young_pa, 0.45).expect("material")
}

/// Item 1: E = 1e300 (or 1e-300) Pa in f32 gives compliances or stiffnesses
/// beyond f32; the build refuses the table its own loader would refuse,
/// naming the mesh, the loader's reason and what to change.
#[test]
fn a_table_its_own_loader_refuses_is_not_built() {
    let (mesh, report) = cube();
    for young in [1e300, 1e-300] {
        let options =
            BuildOptions::precomputed(material(young), base(), Solver::Cholesky, Precision::F32);
        let e = build(&mesh, &report, &options).expect_err("f32 table out of range");
        let msg = format!("{e:#}");
        for needle in [
            "cube.msh",
            "load check",
            "f32",
            "--precision f64",
            "SI units",
        ] {
            assert!(msg.contains(needle), "{needle}: {msg}");
        }
        assert!(!msg.contains('\n'), "{msg}");
        let options = BuildOptions::tensor_mass(material(young), 1000.0, base(), Precision::F32);
        let e = build(&mesh, &report, &options).expect_err("f32 tensor-mass table out of range");
        assert!(format!("{e:#}").contains("--precision f64"), "{e:#}");
    }
    // In range: the same build succeeds and loads.
    let options =
        BuildOptions::precomputed(material(5000.0), base(), Solver::Cholesky, Precision::F32);
    let built = build(&mesh, &report, &options).expect("build");
    assert!(TableFile::from_bytes(&built.bytes).model().is_ok());
}

/// Item 2: `tables info` reports a valid tensor-mass table as one (kind,
/// edges, density, its sections) and validates it with its own loader.
#[test]
fn info_reports_a_tensor_mass_table() {
    let (mesh, report) = cube();
    for precision in [Precision::F32, Precision::F64] {
        let options = BuildOptions::tensor_mass(material(5000.0), 1000.0, base(), precision);
        let built = build(&mesh, &report, &options).expect("build");
        let text = TableFile::from_bytes(&built.bytes)
            .info("cube-tm.tbl")
            .expect("a valid table");
        for needle in [
            "table kind: tensor-mass",
            "vertices: 216",
            &format!("edges: {}", built.edge_count),
            "density: 1000 kg/m3",
            "section edge-tensor:",
            "checksum: ok",
            "validation: ok",
        ] {
            assert!(text.contains(needle), "{needle}: {text}");
        }
    }
    // A corrupt one still fails, naming why.
    let options = BuildOptions::tensor_mass(material(5000.0), 1000.0, base(), Precision::F32);
    let mut bytes = build(&mesh, &report, &options).expect("build").bytes;
    let last = bytes.len() - 1;
    bytes[last] ^= 1;
    let text = TableFile::from_bytes(&bytes).info("bad.tbl").unwrap_err();
    assert!(text.contains("validation: FAILED: checksum"), "{text}");
}

/// Item 3: a barycentric contact whose vertices are not a surface triangle,
/// or repeat one, is refused by the kernel with the contact and vertices
/// named; a real surface triangle in any order is accepted.
#[test]
fn a_contact_off_the_surface_triangles_is_refused() {
    let file = reference_cube_table(Precision::F32);
    let AnyModel::F32(m) = file.model().expect("table") else {
        unreachable!()
    };
    let d = Vector3::new(0.0f32, 0.0, -0.002);
    let solve = |vertices: [u32; 3]| {
        palpate::precomputed::solve(&m, &[Constraint::on_triangle(vertices, [0.2, 0.3, 0.5], d)])
    };
    let Err(e) = solve([194, 194, 201]) else {
        panic!("a repeated vertex is refused")
    };
    assert_eq!(
        e.downcast_ref::<ContactError>(),
        Some(&ContactError::RepeatedVertex {
            contact: 0,
            vertex: 194
        })
    );
    assert!(e.to_string().contains("vertex 194 appears twice"), "{e}");
    // 194 and 200 are opposite corners of a top square (the other diagonal
    // is the surface edge), 194, 195 and 43 (interior) no triangle either.
    let Err(e) = solve([194, 195, 200]) else {
        panic!("not a surface triangle")
    };
    assert_eq!(
        e.to_string(),
        "contact 0: vertices 194,195,200 are not a triangle of the table's boundary surface"
    );
    let Err(e) = solve([194, 195, 43]) else {
        panic!("an interior vertex")
    };
    assert!(e.to_string().contains("vertex 43"), "{e}");
    // Far-apart surface vertices (the old check accepted any three).
    assert!(solve([194, 205, 215]).is_err());
    for rotation in [
        [194, 195, 201],
        [201, 194, 195],
        [195, 201, 194],
        [195, 194, 201],
    ] {
        let s = solve(rotation).expect("a surface triangle in any order");
        assert!(s.device_force[2] > 0.0);
    }
}

/// Item 4: positions scaled by 1e200 overflow the force pass; the result is
/// an error (typed, so the command names the CSV), not `null` forces.
#[test]
fn non_finite_forces_are_an_error() {
    let mesh = box_mesh([2, 2, 2], [0.02; 3]);
    let material = material(3000.0);
    let law = ElasticLaw::StVenantKirchhoff(StvkForm::PerTet);
    let report = MeshReport::default();
    let scaled: Vec<[f64; 3]> = mesh
        .positions
        .iter()
        .map(|p| p.map(|x| x * 1e200))
        .collect();
    let e = forces_and_energy(&mesh, &report, material, law, None, &scaled).unwrap_err();
    assert!(e.downcast_ref::<NonFiniteResult>().is_some(), "{e:#}");
    assert!(format!("{e:#}").contains("non-finite"), "{e:#}");
    // At rest: finite (zero) forces.
    let (forces, energy) =
        forces_and_energy(&mesh, &report, material, law, None, &mesh.positions).expect("rest");
    assert!(forces.iter().flatten().all(|f| f.is_finite()) && energy == 0.0);
}

/// Item 5: `critical-dt` with nothing free, or with E = 1e300 Pa (ω_max
/// overflows f64), is an error instead of `critical_dt: 0.0`.
#[test]
fn critical_dt_without_a_critical_step_is_an_error() {
    let mesh = box_mesh([2, 2, 2], [0.02; 3]);
    let report = MeshReport::default();
    let all = vec!["z>-1".parse().expect("predicate")];
    let options = BuildOptions::tensor_mass(material(3000.0), 1000.0, all, Precision::F64);
    let e = critical_dt_of_mesh(&mesh, &report, &options, 2.0, Integrator::SymplecticEuler)
        .unwrap_err();
    assert!(format!("{e:#}").contains("every vertex is fixed"), "{e:#}");
    let options = BuildOptions::tensor_mass(material(1e300), 1000.0, base(), Precision::F64);
    let e = critical_dt_of_mesh(&mesh, &report, &options, 2.0, Integrator::SymplecticEuler)
        .unwrap_err();
    assert!(format!("{e:#}").contains("SI units"), "{e:#}");
}

/// Item 7: `replay` errors name the table or the sequence file.
#[test]
fn replay_errors_name_the_file() {
    let f32_table = reference_cube_table(Precision::F32);
    let e = palpate::replay::replay(&f32_table, "t.tbl", "194:0,0\n", "seq.txt").unwrap_err();
    let msg = format!("{e:#}");
    assert!(msg.starts_with("seq.txt: sequence line 1:"), "{msg}");
    let f64_table = reference_cube_table(Precision::F64);
    let e = palpate::replay::replay(&f64_table, "t64.tbl", "194:0,0,0\n", "seq.txt").unwrap_err();
    assert!(format!("{e:#}").starts_with("t64.tbl: "), "{e:#}");
    let junk = TableFile::from_bytes(b"not a table");
    let e = palpate::replay::replay(&junk, "junk.tbl", "-\n", "seq.txt").unwrap_err();
    assert!(
        format!("{e:#}").starts_with("junk.tbl: invalid table"),
        "{e:#}"
    );
}

/// Item 7: a safety limit (or radius, or tick) beyond f32, which the loop
/// runs in, names its key instead of failing later without one.
#[test]
fn scene_values_beyond_f32_name_their_key() {
    let scene = |extra: &str| {
        let text = format!(
            "fix = [\"z<0.001\"]\n[generated]\nbox_m = [0.1, 0.1, 0.05]\ncells = [2, 2, 1]\n\
             [material]\nyoung_pa = 3000.0\npoisson = 0.45\n{extra}"
        );
        Scene::from_toml_str_named(&text, "s.toml", Path::new("."))
    };
    assert!(scene("").is_ok());
    for (extra, key) in [
        (
            "[safety]\nmax_force_n = 1e300\n",
            "[safety] max_force_n = 1e300",
        ),
        (
            "[safety]\nmax_slew_n_per_s = 1e39\n",
            "[safety] max_slew_n_per_s",
        ),
        ("[safety]\nmax_force_n = 1e-50\n", "[safety] max_force_n"),
        ("[tool]\nradius_m = 1e-300\n", "[tool] radius_m"),
        ("[rates]\nhaptic_hz = 1e-300\n", "[rates] haptic_hz"),
    ] {
        let msg = scene(extra).expect_err(extra).to_string();
        assert!(msg.starts_with(&format!("s.toml: {key}")), "{msg}");
        assert!(msg.contains("f32"), "{msg}");
    }
}

/// Item 7: an MSH node id 0 (below the file's first id) is named as written,
/// not as vertex index -1.
#[test]
fn an_msh_node_id_of_zero_is_named_as_written() {
    let msh = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n\
               4 0 0 1\n$EndNodes\n$Elements\n1\n7 4 2 1 1 1 2 0 4\n$EndElements\n";
    let e = read_mesh_bytes(msh.as_bytes(), MeshFormat::Msh, "zero.msh").unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.starts_with("zero.msh: tet 0 (element id 7): node id 0 is not defined"),
        "{msg}"
    );
    assert!(!msg.contains("-1"), "{msg}");
}
