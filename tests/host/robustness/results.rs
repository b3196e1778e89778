//! See `super`: the results probes. Each input once gave a wrong or unusable
//! result with exit 0 (or an error that named nothing); each is now a clear
//! error naming the file, line, key or element, or a correct result. The
//! command-line side (exit status 2, one line) is in
//! `host-harness/tests/cli/robustness/results.rs`.

use std::path::Path;

use nalgebra::Vector3;
use palpate::fem::material::{Material, TetMaterials};
use palpate::limits::MAX_TOOL_COORDINATE_M;
use palpate::mesh::generate::box_mesh;
use palpate::mesh::{MeshFormat, MeshReport, TetMesh, read_mesh, read_mesh_bytes};
use palpate::partition::cost::{CostOptions, costs};
use palpate::partition::geometry::TetGrid;
use palpate::partition::{Partition, PlanInput, PlanReport, plan};
use palpate::scene::Scene;
use palpate::scene::{Trajectory, Zone, ZoneKind, ZoneShape};
use palpate::session::model::hybrid_tables;
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

/// `scene plan` printed a pre-computed table 1.46× the size of the one the
/// session builds on the built-in hybrid (its grid's bound, another vertex
/// numbering), and tables a session refuses with exit 0. Plan's figures are
/// now the hybrid build's own estimate, with the collision grid built:
/// equal to the built tables' sizes (to the byte: the layout is the
/// writer's, from the same counts), and nothing refused here.
#[test]
fn plan_table_bytes_are_the_built_tables_sizes() {
    let scene = Scene::built_in_hybrid();
    let (mesh, report) = scene.load_mesh().expect("mesh");
    let partition = Partition::of_scene(&scene, &mesh, &report).expect("partition");
    let plan = PlanReport::new(&scene, &mesh, &report, &partition).expect("plan");
    let built = hybrid_tables(&scene, &mesh, &report, &partition, Precision::F32).expect("tables");
    assert_eq!(plan.regions[0].model, "precomputed");
    assert_eq!(
        plan.regions[0].table_bytes,
        built.precomputed.bytes().len() as u64
    );
    assert_eq!(
        plan.interface.table_bytes,
        built.interface.bytes().len() as u64
    );
    assert!(plan.regions.iter().all(|r| r.refused.is_none()));
    assert!(plan.interface.refused.is_none());
}

/// `scene plan` costed every region with the scene's `[material]` alone: a
/// region 10⁴ times stiffer still showed its soft critical step. The costs
/// take the materials per tet: the dynamic region's step scales as
/// `1/sqrt(E)` (ω² = k/m, the mass unchanged), a factor of 100 to the
/// Lanczos tolerance (1e-10 on ω², so 1e-6 here).
#[test]
fn plan_costs_take_the_materials_per_tet() {
    let mesh = box_mesh([4, 4, 4], [0.04; 3]);
    let fixed: Vec<bool> = mesh.positions.iter().map(|p| p[2] < 1e-9).collect();
    let zones = [Zone {
        kind: ZoneKind::Cut,
        shape: ZoneShape::Box {
            min_m: [0.0, 0.0, 0.02],
            max_m: [0.02, 0.02, 0.04],
        },
    }];
    let partition = plan(&PlanInput {
        mesh: &mesh,
        fixed: &fixed,
        zones: &zones,
        margin_rings: 0,
        poisson: 0.3,
        scene: "scene.toml",
        mesh_name: "block",
    })
    .expect("partition");
    let soft = Material::new(3000.0, 0.3).expect("material");
    let stiff = Material::new(3e7, 0.3).expect("material");
    let options = |materials| CostOptions {
        materials,
        tool_radius_m: 0.002,
        density_kg_m3: 1000.0,
        integrator: Integrator::SymplecticEuler,
        damping_per_s: 0.0,
        incompressibility_n: None,
        interface_compression: None,
    };
    let dt = |materials| {
        let (regions, _, _) = costs(&mesh, &fixed, &partition, &options(materials)).expect("costs");
        regions[1].critical_dt_s.expect("a dynamic region")
    };
    let uniform = dt(TetMaterials::uniform(soft, mesh.tets.len()));
    let regions: Vec<u32> = partition.dynamic.iter().map(|&d| u32::from(d)).collect();
    let stiffer = dt(TetMaterials::from_regions(soft, &regions, &[(1, stiff)]));
    assert!(
        ((uniform / stiffer) / 100.0 - 1.0).abs() < 1e-6,
        "{uniform} {stiffer}"
    );
}

/// A trajectory position of 1e39 m (beyond f32) passed the checks and
/// faulted 7 101 of 7 201 ticks with exit 0. Coordinates and jaw openings
/// are within ±1 km (`MAX_TOOL_COORDINATE_M`), checked at parse, naming the
/// line.
#[test]
fn trajectory_values_beyond_the_coordinate_bound_name_the_line() {
    let err = Trajectory::from_csv_str("t,tool,x,y,z\n0,0,0,0,0\n1,0,1e39,0,0\n", "t.csv", 1)
        .expect_err("refused")
        .to_string();
    assert!(
        err.starts_with("t.csv: line 3: x = 1e39 m is out of range"),
        "{err}"
    );
    assert!(err.contains("MAX_TOOL_COORDINATE_M"), "{err}");
    let err = Trajectory::from_csv_str("t,tool,x,y,z,jaw_m,cut\n0,0,0,0,0,1e39,0\n", "t.csv", 1)
        .expect_err("refused")
        .to_string();
    assert!(err.starts_with("t.csv: line 2: jaw_m = 1e39 m"), "{err}");
    Trajectory::from_csv_str(
        &format!("t,tool,x,y,z\n0,0,{MAX_TOOL_COORDINATE_M},0,-1000\n"),
        "t.csv",
        1,
    )
    .expect("1 km is in range");
}

/// `min_m = [0, 0, 0, 0]` was read as its first three numbers. An array of
/// the wrong length is refused, the parser's message showing its key.
#[test]
fn scene_arrays_of_the_wrong_length_are_refused() {
    let base = "fix = [\"z<0.001\"]\n[generated]\nbox_m = [0.1, 0.1, 0.05]\ncells = [2, 2, 1]\n\
                [material]\nyoung_pa = 3000.0\npoisson = 0.45\n";
    for (extra, key) in [
        (
            "[model]\nkind = \"dynamic\"\n[[zone]]\nkind = \"cut\"\nshape = \"box\"\n\
             min_m = [0, 0, 0, 0]\nmax_m = [0.01, 0.01, 0.01]\n",
            "min_m",
        ),
        ("[tool]\nblade_m = [0, 0, -0.01, 5]\n", "blade_m"),
        ("[tool]\njaw_axis = [1, 0]\n", "jaw_axis"),
    ] {
        let err = Scene::from_toml_str_named(&format!("{base}{extra}"), "s.toml", Path::new("."))
            .expect_err(extra)
            .to_string();
        assert!(err.contains(key) && err.contains("exactly 3"), "{err}");
    }
    let err = Scene::from_toml_str_named(
        &base.replace("[2, 2, 1]", "[2, 2, 1, 9]"),
        "s.toml",
        Path::new("."),
    )
    .expect_err("cells")
    .to_string();
    assert!(err.contains("cells") && err.contains("exactly 3"), "{err}");
}

/// `[tool] radius_m = 1.0` on a 12-cm block was accepted and faulted every
/// tick. A radius above half the mesh's largest extent is refused, naming
/// the key.
#[test]
fn a_tool_wider_than_the_body_is_refused() {
    let text = |radius: f64| {
        format!(
            "fix = [\"z<0.001\"]\n[generated]\nbox_m = [0.04, 0.12, 0.06]\ncells = [2, 4, 2]\n\
             [material]\nyoung_pa = 3000.0\npoisson = 0.45\n[tool]\nradius_m = {radius}\n"
        )
    };
    let scene = Scene::from_toml_str_named(&text(1.0), "s.toml", Path::new(".")).expect("scene");
    let (mesh, _) = scene.load_mesh().expect("mesh");
    let err = scene.check_on_mesh(&mesh).expect_err("refused").to_string();
    assert!(
        err.starts_with("s.toml: [tool] radius_m = 1: above 0.5 of the mesh's largest extent"),
        "{err}"
    );
    assert!(err.contains("MAX_TOOL_RADIUS_FRACTION"), "{err}");
    let scene = Scene::from_toml_str_named(&text(0.06), "s.toml", Path::new(".")).expect("scene");
    scene.check_on_mesh(&mesh).expect("half the block's length");
}

/// A capsule zone from −10¹² to 10¹² m took other tets than the same line
/// from −10 to 10 m (the search along a 2·10¹² m segment resolved metres).
/// The segment is clipped to the mesh's box first: the same tets, on an
/// axis and on a diagonal whose endpoints are exact in f64.
#[test]
fn a_capsule_with_far_endpoints_takes_the_same_tets() {
    let mesh = box_mesh([4, 4, 4], [0.04; 3]);
    let grid = TetGrid::new(&mesh);
    let taken = |a: [f64; 3], b: [f64; 3]| {
        let mut flags = vec![false; mesh.tets.len()];
        let n = grid.select(
            &ZoneShape::Capsule {
                a_m: a,
                b_m: b,
                radius_m: 0.006,
            },
            &mut flags,
        );
        assert!(n > 0);
        flags
    };
    let c = [0.015625, 0.0234375, 0.03125];
    for d in [[1.0, 0.0, 0.0], [1.0, 1.0, 0.0]] {
        let at = |s: f64| [0, 1, 2].map(|i| c[i] + s * d[i]);
        assert_eq!(
            taken(at(-1e12), at(1e12)),
            taken(at(-10.0), at(10.0)),
            "{d:?}"
        );
    }
}
