//! Host session input: scene files (every field, defaults, the built-in scene, every validation
//! error), trajectory files (round trip, interpolation values, every validation error, the lenient
//! reader) and the trajectory generators (poke, press-and-hold, slide, pinch, strike).

use std::path::PathBuf;

use palpate::fem::material::Material;
use palpate::scene::generate::MAX_GENERATED_SAMPLES;
use palpate::scene::{
    DynamicSpec, GenerateError, Generator, Keyframe, MaterialSpec, MeshSource, ModelSpec, Pinch,
    Poke, Press, PressHold, Rates, Sample, Scene, Slide, Strike, ToolSpec, Trajectory,
    TrajectoryError, sample_keyframes,
};
use palpate_kernel::haptic::SafetyLimits;
use palpate_kernel::tensor_mass::Extrapolation;
use palpate_kernel::tensor_mass::{ElasticLaw, Integrator, StvkForm};
use palpate_tests::{
    BASE_SCENE, assert_scene_errors, csv, keyframe, reference_dir, scene, scene_err, traj, traj_err,
};

/// A fresh folder for this test's files.
fn temp_dir(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("host_session")
        .join(name);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

// ---------------------------------------------------------------- scenes

const HAND_WRITTEN: &str = r#"
# A dynamic scene using every key.
mesh = "meshes/cube.msh"
fix = ["z<0.001", "x>=0.99"]

[material]
young_pa = 5000          # an integer is accepted
poisson = 0.4
density_kg_m3 = 1050.0

[model]
kind = "dynamic"
law = "stvk-incompressible"
form = "tensors"
integrator = "central"
dt_s = 0.0005
damping_per_s = 2.5
incompressibility_n = 0.75
extrapolation = "instantaneous"

[tool]
points = 2
radius_m = 0.0015

[rates]
haptic_hz = 1000.0
physics_every = 2

[safety]
max_force_n = 3.5
max_slew_n_per_s = 1500.0
"#;

#[test]
fn hand_written_scene_with_every_field() {
    let s = scene(HAND_WRITTEN);
    assert_eq!(s.source, "scene.toml");
    assert_eq!(
        s.mesh,
        MeshSource::File(PathBuf::from("/scenes/meshes/cube.msh"))
    );
    let fix: Vec<String> = s.fix.iter().map(ToString::to_string).collect();
    assert_eq!(fix, ["z<0.001", "x>=0.99"]);
    assert_eq!(
        s.material,
        MaterialSpec {
            elastic: Material {
                young_pa: 5000.0,
                poisson: 0.4
            },
            density_kg_m3: 1050.0
        }
    );
    assert_eq!(
        s.model,
        ModelSpec::Dynamic(DynamicSpec {
            law: ElasticLaw::StVenantKirchhoff(StvkForm::Tensors),
            incompressibility_n: Some(0.75),
            integrator: Integrator::CentralDifference,
            dt_s: 0.0005,
            damping_per_s: 2.5,
            extrapolation: Extrapolation::Instantaneous,
        })
    );
    assert_eq!(s.tool, ToolSpec::probes(2, 0.0015));
    assert_eq!(
        s.rates,
        Rates {
            haptic_hz: 1000.0,
            physics_every: 2
        }
    );
    assert_eq!(
        s.safety,
        SafetyLimits {
            max_force_n: 3.5,
            max_slew_n_per_s: 1500.0
        }
    );
    assert_eq!(s.tick_s(), 0.001);
    assert_eq!(s.physics_period_s(), 0.002);
    assert_eq!(s.dynamic_substeps(), Some(4));
    let material = s.material.elastic;
    assert_eq!((material.young_pa, material.poisson), (5000.0, 0.4));
}

#[test]
fn minimal_scene_takes_the_defaults() {
    let s = scene(
        r#"
fix = ["z<0.0001"]
[generated]
box_m = [0.1, 0.05, 0.02]
cells = [4, 2, 1]
[material]
young_pa = 3000
poisson = 0.45
"#,
    );
    assert_eq!(
        s.mesh,
        MeshSource::GeneratedBox {
            size_m: [0.1, 0.05, 0.02],
            cells: [4, 2, 1]
        }
    );
    assert_eq!(s.material.density_kg_m3, 1000.0);
    assert_eq!(s.model, ModelSpec::Precomputed);
    assert_eq!(s.tool, ToolSpec::probes(1, 0.002));
    assert_eq!(
        s.rates,
        Rates {
            haptic_hz: 1000.0,
            physics_every: 1
        }
    );
    assert_eq!(
        s.safety,
        SafetyLimits {
            max_force_n: 4.0,
            max_slew_n_per_s: 2000.0
        }
    );
    assert_eq!(s.dynamic_substeps(), None);
    let (mesh, report) = s.load_mesh().unwrap();
    assert_eq!(
        (mesh.positions.len(), mesh.tets.len()),
        (5 * 3 * 2, 4 * 2 * 6)
    );
    assert_eq!(mesh.positions[5 * 3 * 2 - 1], [0.1, 0.05, 0.02]);
    assert_eq!(
        report.source,
        "generated box 0.1 x 0.05 x 0.02 m, 4 x 2 x 1 cells"
    );

    // `box` is accepted for `box_m`.
    let s = scene(
        "fix = [\"z<0.0001\"]\n[generated]\nbox = [1, 2, 3]\ncells = [1, 1, 1]\n\
         [material]\nyoung_pa = 1\npoisson = 0\n",
    );
    assert_eq!(
        s.mesh,
        MeshSource::GeneratedBox {
            size_m: [1.0, 2.0, 3.0],
            cells: [1, 1, 1]
        }
    );
}

#[test]
fn dynamic_defaults_step_once_per_physics_period() {
    // 500 Hz, physics every 2 ticks: dt defaults to the 4 ms physics period. No fix: a free body
    // is fine for the dynamic model.
    let s = scene(
        "mesh = \"a.msh\"\n[material]\nyoung_pa = 3000\npoisson = 0.45\n\
         [model]\nkind = \"dynamic\"\ndamping_per_s = 2\n[rates]\nhaptic_hz = 500\nphysics_every = 2\n",
    );
    assert_eq!(
        s.model,
        ModelSpec::Dynamic(DynamicSpec {
            law: ElasticLaw::Linear,
            incompressibility_n: None,
            integrator: Integrator::SymplecticEuler,
            dt_s: 0.004,
            damping_per_s: 2.0,
            extrapolation: Extrapolation::Secant,
        })
    );
    assert!(s.fix.is_empty());
    assert_eq!(s.dynamic_substeps(), Some(1));
    // stvk defaults to the per-tet form; every integrator name.
    for (name, integrator) in [
        ("euler", Integrator::ExplicitEuler),
        ("symplectic", Integrator::SymplecticEuler),
        ("rk4", Integrator::Rk4),
        ("central", Integrator::CentralDifference),
    ] {
        let s = scene(&format!(
            "mesh = \"a.msh\"\n[material]\nyoung_pa = 3000\npoisson = 0.45\n\
             [model]\nkind = \"dynamic\"\nlaw = \"stvk\"\nintegrator = \"{name}\"\ndamping_per_s = 0\n"
        ));
        let ModelSpec::Dynamic(d) = s.model else {
            panic!("not dynamic")
        };
        assert_eq!(d.integrator, integrator);
        assert_eq!(d.law, ElasticLaw::StVenantKirchhoff(StvkForm::PerTet));
    }
    // The per-tet laws without a form.
    for (name, law) in [
        ("corotational", ElasticLaw::Corotational),
        ("neo-hookean", ElasticLaw::NeoHookean),
    ] {
        let s = scene(&format!(
            "mesh = \"a.msh\"\n[material]\nyoung_pa = 3000\npoisson = 0.45\n\
             [model]\nkind = \"dynamic\"\nlaw = \"{name}\"\ndamping_per_s = 0\n"
        ));
        let ModelSpec::Dynamic(d) = s.model else {
            panic!("not dynamic")
        };
        assert_eq!((d.law, d.incompressibility_n), (law, None));
    }
}

#[test]
fn built_in_scene_is_the_demo_block() {
    let s = Scene::built_in();
    s.validate().unwrap();
    assert_eq!(s.source, "built-in scene");
    assert_eq!(
        s.mesh,
        MeshSource::GeneratedBox {
            size_m: [0.12, 0.12, 0.06],
            cells: [12, 12, 6]
        }
    );
    assert_eq!(s.fix.len(), 1);
    assert!(s.fix[0].matches(&[0.05, 0.05, 0.0]) && !s.fix[0].matches(&[0.05, 0.05, 0.01]));
    assert_eq!(
        s.material,
        MaterialSpec {
            elastic: Material {
                young_pa: 3000.0,
                poisson: 0.45
            },
            density_kg_m3: 1000.0
        }
    );
    assert_eq!(s.model, ModelSpec::Precomputed);
    assert_eq!(s.tool.points, 1);
    assert_eq!(s.rates.haptic_hz, 1000.0);
    assert_eq!(s.rates.physics_every, 1);
    assert_eq!(s.tick_s(), 0.001);
    let (mesh, _) = s.load_mesh().unwrap();
    assert_eq!((mesh.positions.len(), mesh.tets.len()), (1183, 5184));
    let fixed = mesh
        .positions
        .iter()
        .filter(|p| s.fix[0].matches(p))
        .count();
    assert_eq!(fixed, 13 * 13);

    // Changing a field and validating again names the scene and the key.
    let mut bad = Scene::built_in();
    bad.tool.points = 5;
    assert_eq!(
        bad.validate().unwrap_err().to_string(),
        "built-in scene: [tool] points = 5: must be in 1..=4 (the kernel's contact capacity)"
    );
}

#[test]
fn scene_file_resolves_the_mesh_next_to_it() {
    let dir = temp_dir("scene_file");
    let path = dir.join("hand.toml");
    std::fs::write(&path, HAND_WRITTEN).unwrap();
    let s = Scene::read(&path).unwrap();
    assert_eq!(s.source, path.display().to_string());
    assert_eq!(s.mesh, MeshSource::File(dir.join("meshes/cube.msh")));

    // An absolute mesh path stays as it is, and loads.
    let cube = reference_dir().join("meshes").join("cube.msh");
    let text = format!(
        "mesh = '{}'\nfix = [\"z<0.001\"]\n[material]\nyoung_pa = 5000\npoisson = 0.45\n",
        cube.display()
    );
    std::fs::write(&path, text).unwrap();
    let s = Scene::read(&path).unwrap();
    assert_eq!(s.mesh, MeshSource::File(cube.clone()));
    let (mesh, report) = s.load_mesh().unwrap();
    assert_eq!((mesh.positions.len(), mesh.tets.len()), (216, 750));
    assert_eq!(report.source, cube.display().to_string());

    // A missing mesh file is the mesh reader's error, naming it.
    let s = scene(
        "mesh = \"nowhere.msh\"\nfix = [\"z<0.001\"]\n[material]\nyoung_pa = 1\npoisson = 0\n",
    );
    let msg = s.load_mesh().unwrap_err().to_string();
    assert!(
        msg.starts_with("/scenes/nowhere.msh: cannot read file: "),
        "{msg}"
    );

    let missing = dir.join("missing.toml");
    let msg = Scene::read(&missing).unwrap_err().to_string();
    assert!(
        msg.starts_with(&format!("{}: cannot read scene: ", missing.display())),
        "{msg}"
    );
}

/// `BASE_SCENE` with `young_pa`/`poisson` replaced.
fn with_material(young: &str, poisson: &str) -> String {
    format!(
        "mesh = \"a.msh\"\nfix = [\"z<0.001\"]\n[material]\nyoung_pa = {young}\npoisson = {poisson}\n"
    )
}

#[test]
fn every_scene_error_names_the_file_and_what_is_wrong() {
    let dynamic = |keys: &str| format!("{BASE_SCENE}[model]\nkind = \"dynamic\"\n{keys}");
    let cases: Vec<(String, &str)> = vec![
        // Syntax, unknown keys, types: the parser's message with the line.
        (
            format!("colour = 1\n{BASE_SCENE}"),
            "bad.toml: line 1: unknown field `colour`, expected one of `mesh`, `generated`, `fix`, `material`, `region`, `model`, `tool`, `cutting`, `tearing`, `rates`, `safety`, `zone`, `partition`, `tables`",
        ),
        (
            format!("{BASE_SCENE}[tool]\nradius = 0.002\n"),
            "bad.toml: line 7: unknown field `radius`, expected one of `points`, `radius_m`, `kind`, `jaw_axis`, `grip_opening_m`, `blade_m`",
        ),
        (
            format!("{BASE_SCENE}[tool]\npoints = \"one\"\n"),
            "bad.toml: line 7: invalid type: string \"one\", expected usize",
        ),
        (
            format!("{BASE_SCENE}[model]\nkind = \"hybrid\"\n"),
            "bad.toml: line 7: unknown variant `hybrid`, expected `precomputed` or `dynamic`",
        ),
        (
            dynamic("law = \"mooney-rivlin\"\ndamping_per_s = 1\n"),
            "bad.toml: line 8: unknown variant `mooney-rivlin`, expected one of `linear`, `stvk`, `stvk-incompressible`, `corotational`, `neo-hookean`",
        ),
        (
            format!("{BASE_SCENE}density = 1000\n"),
            "bad.toml: line 6: unknown field `density`, expected one of `young_pa`, `poisson`, `density_kg_m3`",
        ),
        (
            "mesh = \"a.msh\"\nfix = [\"z<0.001\"]\n".into(),
            "bad.toml: missing field `material`",
        ),
        (
            "fix = [\"z<0.001\"]\n[generated]\nbox_m = [1, 1]\ncells = [1, 1, 1]\n[material]\nyoung_pa = 1\npoisson = 0\n".into(),
            "bad.toml: line 3: box_m: invalid length 2, expected exactly 3 numbers, [x, y, z]",
        ),
        (
            "fix = [\"z<0.001\"]\n[generated]\nbox_m = [1, 1, 1]\ncells = [-1, 1, 1]\n[material]\nyoung_pa = 1\npoisson = 0\n".into(),
            "bad.toml: line 4: invalid value: integer `-1`, expected usize",
        ),
        ("mesh = \"a.msh\"\nmesh = \"b.msh\"\n".into(), "bad.toml: line 2: duplicate key"),
        // Mesh.
        (
            format!("{BASE_SCENE}[generated]\nbox_m = [1, 1, 1]\ncells = [1, 1, 1]\n"),
            "bad.toml: mesh: give either `mesh = \"<file>\"` or a [generated] table, not both",
        ),
        (
            "fix = [\"z<0.001\"]\n[material]\nyoung_pa = 3000\npoisson = 0.45\n".into(),
            "bad.toml: mesh: missing: give `mesh = \"<file>\"` or a [generated] table with box_m and cells",
        ),
        (
            "fix = [\"z<0.001\"]\n[generated]\nbox_m = [0.1, -0.1, 0.1]\ncells = [1, 1, 1]\n[material]\nyoung_pa = 1\npoisson = 0\n".into(),
            "bad.toml: [generated] box_m = [0.1, -0.1, 0.1]: every size must be finite and > 0 m",
        ),
        (
            "fix = [\"z<0.001\"]\n[generated]\nbox_m = [0.1, inf, 0.1]\ncells = [1, 1, 1]\n[material]\nyoung_pa = 1\npoisson = 0\n".into(),
            "bad.toml: [generated] box_m = [0.1, inf, 0.1]: every size must be finite and > 0 m",
        ),
        (
            "fix = [\"z<0.001\"]\n[generated]\nbox_m = [1, 1, 1]\ncells = [1, 0, 1]\n[material]\nyoung_pa = 1\npoisson = 0\n".into(),
            "bad.toml: [generated] cells = [1, 0, 1]: every cell count must be >= 1",
        ),
        (
            "fix = [\"z<0.001\"]\n[generated]\nbox_m = [1, 1, 1]\ncells = [1000, 1000, 1000]\n[material]\nyoung_pa = 1\npoisson = 0\n".into(),
            "bad.toml: [generated] cells = [1000, 1000, 1000]: too many vertices: at most 10000000",
        ),
        // Fixed vertices.
        (
            "mesh = \"a.msh\"\nfix = [\"z<0.001\", \"w<1\"]\n[material]\nyoung_pa = 1\npoisson = 0\n".into(),
            "bad.toml: fix[1] = \"w<1\": expected x|y|z, then <, <=, > or >=, then a finite number, e.g. \"z<0.001\"",
        ),
        (
            "mesh = \"a.msh\"\n[material]\nyoung_pa = 1\npoisson = 0\n".into(),
            "bad.toml: fix = []: the pre-computed model needs at least one fixed-vertex predicate (a free body has no compliance)",
        ),
        // Material.
        (with_material("0", "0.45"), "bad.toml: [material] young_pa = 0: must be finite and > 0 Pa"),
        (with_material("nan", "0.45"), "bad.toml: [material] young_pa = NaN: must be finite and > 0 Pa"),
        (with_material("3000", "0.5"), "bad.toml: [material] poisson = 0.5: must satisfy 0 <= nu <= 0.4999 (nearer 0.5 the material is too nearly incompressible for the f32 tables: λ/μ above 5000)"),
        (with_material("3000", "-0.1"), "bad.toml: [material] poisson = -0.1: must satisfy 0 <= nu <= 0.4999 (nearer 0.5 the material is too nearly incompressible for the f32 tables: λ/μ above 5000)"),
        (
            format!("{BASE_SCENE}density_kg_m3 = -1\n"),
            "bad.toml: [material] density_kg_m3 = -1: must be finite and > 0 kg/m3",
        ),
        // Tool.
        (
            format!("{BASE_SCENE}[tool]\npoints = 0\n"),
            "bad.toml: [tool] points = 0: must be in 1..=4 (the kernel's contact capacity)",
        ),
        (
            format!("{BASE_SCENE}[tool]\npoints = 5\n"),
            "bad.toml: [tool] points = 5: must be in 1..=4 (the kernel's contact capacity)",
        ),
        (format!("{BASE_SCENE}[tool]\nradius_m = 0\n"), "bad.toml: [tool] radius_m = 0: must be finite and > 0 m"),
        (format!("{BASE_SCENE}[tool]\nradius_m = inf\n"), "bad.toml: [tool] radius_m = inf: must be finite and > 0 m"),
        // Rates.
        (format!("{BASE_SCENE}[rates]\nhaptic_hz = 0\n"), "bad.toml: [rates] haptic_hz = 0: must be finite and > 0 Hz"),
        (
            format!("{BASE_SCENE}[rates]\nhaptic_hz = -1000.0\n"),
            "bad.toml: [rates] haptic_hz = -1000: must be finite and > 0 Hz",
        ),
        (
            format!("{BASE_SCENE}[rates]\nphysics_every = 0\n"),
            "bad.toml: [rates] physics_every = 0: must be >= 1 (a physics update every this many ticks)",
        ),
        // Safety.
        (
            format!("{BASE_SCENE}[safety]\nmax_force_n = 0\n"),
            "bad.toml: [safety] max_force_n = 0: must be finite and > 0 N",
        ),
        (
            format!("{BASE_SCENE}[safety]\nmax_slew_n_per_s = nan\n"),
            "bad.toml: [safety] max_slew_n_per_s = NaN: must be finite and > 0 N/s",
        ),
        // Model.
        (
            format!("{BASE_SCENE}[model]\nlaw = \"stvk\"\n"),
            "bad.toml: [model] law: applies to kind = \"dynamic\" only (this scene is \"precomputed\")",
        ),
        (
            format!("{BASE_SCENE}[model]\nkind = \"precomputed\"\ndt_s = 0.001\n"),
            "bad.toml: [model] dt_s: applies to kind = \"dynamic\" only (this scene is \"precomputed\")",
        ),
        (
            dynamic(""),
            "bad.toml: [model] damping_per_s: missing: kind = \"dynamic\" needs the mass-proportional damping (1/s)",
        ),
        (
            dynamic("law = \"stvk-incompressible\"\ndamping_per_s = 1\n"),
            "bad.toml: [model] incompressibility_n: missing: law = \"stvk-incompressible\" needs the penalty gamma (N)",
        ),
        (
            dynamic("law = \"stvk\"\nincompressibility_n = 1\ndamping_per_s = 1\n"),
            "bad.toml: [model] incompressibility_n: applies to law = \"stvk-incompressible\" only",
        ),
        (
            dynamic("form = \"tensors\"\ndamping_per_s = 1\n"),
            "bad.toml: [model] form: applies to law = \"stvk\" or \"stvk-incompressible\" only",
        ),
        (
            dynamic("law = \"neo-hookean\"\nform = \"per-tet\"\ndamping_per_s = 1\n"),
            "bad.toml: [model] form: applies to law = \"stvk\" or \"stvk-incompressible\" only",
        ),
        (
            dynamic("law = \"corotational\"\nincompressibility_n = 1\ndamping_per_s = 1\n"),
            "bad.toml: [model] incompressibility_n: applies to law = \"stvk-incompressible\" only",
        ),
        (
            dynamic("law = \"stvk-incompressible\"\nincompressibility_n = -1\ndamping_per_s = 1\n"),
            "bad.toml: [model] incompressibility_n = -1: must be finite and >= 0 N",
        ),
        (
            dynamic("damping_per_s = -1\n"),
            "bad.toml: [model] damping_per_s = -1: must be finite and >= 0 1/s",
        ),
        (
            dynamic("damping_per_s = 1\ndt_s = -0.001\n"),
            "bad.toml: [model] dt_s = -0.001: must be finite and > 0 s",
        ),
        (
            dynamic("damping_per_s = 1\ndt_s = 0.0003\n"),
            "bad.toml: [model] dt_s = 0.0003: the physics period (0.001 s = physics_every / haptic_hz) must be a whole number of steps, 1 to 10000",
        ),
        (
            dynamic("damping_per_s = 1\ndt_s = 0.002\n"),
            "bad.toml: [model] dt_s = 0.002: the physics period (0.001 s = physics_every / haptic_hz) must be a whole number of steps, 1 to 10000",
        ),
    ];
    assert_scene_errors(&cases);
}

// ---------------------------------------------------------------- trajectories

/// Two tool points; tool 0 jumps at t = 3 (two samples at the same time).
const TWO_POINTS: &str = "\
t,tool,x,y,z
0,0,0,0,0
0,1,1,1,1
1,0,0.5,0,-0.25
2,1,1,1,3
3,0,1.5,0,-1.25
3,0,1.5,0,-2.25
";

#[test]
fn positions_are_interpolated_linearly_per_tool_point() {
    let t = traj(TWO_POINTS, 2);
    assert_eq!(t.tool_count(), 2);
    assert_eq!(t.samples().len(), 6);
    assert_eq!(
        t.samples()[3],
        Sample {
            t_s: 2.0,
            tool: 1,
            position_m: [1.0, 1.0, 3.0],
            jaw_m: 0.0,
            cut: false,
        }
    );
    assert_eq!((t.start_s(), t.end_s()), (0.0, 3.0));
    let cases: [(f64, [[f64; 3]; 2]); 9] = [
        // Before the first sample: the first sample.
        (-1.0, [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]),
        (0.0, [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]),
        (0.5, [[0.25, 0.0, -0.125], [1.0, 1.0, 1.5]]),
        // At a sample: exactly the sample.
        (1.0, [[0.5, 0.0, -0.25], [1.0, 1.0, 2.0]]),
        (1.5, [[0.75, 0.0, -0.5], [1.0, 1.0, 2.5]]),
        // After tool 1's last sample: held.
        (2.5, [[1.25, 0.0, -1.0], [1.0, 1.0, 3.0]]),
        // The jump: from t = 3 on, the later sample.
        (3.0, [[1.5, 0.0, -2.25], [1.0, 1.0, 3.0]]),
        (10.0, [[1.5, 0.0, -2.25], [1.0, 1.0, 3.0]]),
        (f64::NAN, [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]),
    ];
    for (time, expected) in cases {
        assert_eq!(t.positions_at(time), expected, "t = {time}");
        let mut out = [[9.0; 3]; 2];
        t.positions_at_into(time, &mut out);
        assert_eq!(out, expected, "t = {time}");
    }
    // Just before the jump: on the way to the first of the two samples.
    let before = t.positions_at(2.999_999)[0];
    assert!((before[2] - -1.249_999_5).abs() < 1e-12, "{before:?}");
}

#[test]
fn blanks_comments_and_padding_keep_line_numbers() {
    let text = "# recorded by hand\n t , tool , x , y , z \n\n0, 0, 0.1, 0.2, 0.3\n# pause\n1, 0, 0.1, 0.2, nan\n";
    assert_eq!(traj_err(text, 1), "traj.csv: line 6: non-finite z = NaN");
    // Windows line ends.
    assert_eq!(
        traj_err("t,tool,x,y,z\r\n0,0,0,0,0\r\n\r\n1,0,1,0,nan\r\n", 1),
        "traj.csv: line 4: non-finite z = NaN"
    );
    let t = traj(&text.replace("nan", "0.4"), 1);
    assert_eq!(t.positions_at(0.5), [[0.1, 0.2, 0.35]]);
}

#[test]
fn trajectory_round_trips_through_write_csv() {
    // Awkward values: shortest round-trip formatting keeps every bit.
    let samples = vec![
        Sample {
            t_s: 0.0,
            tool: 0,
            position_m: [0.1, -0.0, 1e-7],
            jaw_m: 0.0,
            cut: false,
        },
        Sample {
            t_s: 0.0,
            tool: 1,
            position_m: [1.0 / 3.0, 2.0f64.sqrt(), -123.456],
            jaw_m: 0.0,
            cut: false,
        },
        Sample {
            t_s: 0.001,
            tool: 1,
            position_m: [f64::MIN_POSITIVE, 999.9999999999999, -5e-324],
            jaw_m: 0.0,
            cut: false,
        },
        Sample {
            t_s: 0.30000000000000004,
            tool: 0,
            position_m: [0.06, 0.06, 0.055],
            jaw_m: 0.0,
            cut: false,
        },
    ];
    let t = Trajectory::from_samples(samples.clone(), 2).unwrap();
    let text = csv(&t);
    assert!(
        text.starts_with("t,tool,x,y,z\n0,0,0.1,-0,0.0000001\n"),
        "{text}"
    );
    let back = traj(&text, 2);
    let bits = |t: &Trajectory| -> Vec<u64> {
        t.samples()
            .iter()
            .flat_map(|s| {
                [
                    s.t_s,
                    s.tool as f64,
                    s.position_m[0],
                    s.position_m[1],
                    s.position_m[2],
                ]
            })
            .map(f64::to_bits)
            .collect()
    };
    assert_eq!(bits(&back), bits(&t));
    assert_eq!(back.samples(), samples.as_slice());

    // Through a file, and a generated trajectory too.
    let dir = temp_dir("round_trip");
    let path = dir.join("poke.csv");
    let poke = Poke::default().trajectory().unwrap();
    poke.write_csv_file(&path).unwrap();
    let read = Trajectory::read(&path, 1).unwrap();
    assert_eq!(bits(&read), bits(&poke));
    assert_eq!(read.samples().len(), 1001);

    let msg = Trajectory::read(&dir.join("missing.csv"), 1)
        .unwrap_err()
        .to_string();
    assert!(
        msg.starts_with(&format!(
            "{}: cannot read trajectory: ",
            dir.join("missing.csv").display()
        )),
        "{msg}"
    );
    let msg = poke
        .write_csv_file(&dir.join("no-such-dir").join("x.csv"))
        .unwrap_err()
        .to_string();
    assert!(
        msg.contains("no-such-dir/x.csv: cannot write trajectory: "),
        "{msg}"
    );
}

#[test]
fn every_trajectory_error_names_the_file_and_line() {
    let h = "t,tool,x,y,z\n";
    let cases: Vec<(String, usize, &str)> = vec![
        (
            "".into(),
            1,
            "traj.csv: empty: expected the header line `t,tool,x,y,z` or `t,tool,x,y,z,jaw_m,cut`",
        ),
        (
            "\n\n# only comments\n".into(),
            1,
            "traj.csv: empty: expected the header line `t,tool,x,y,z` or `t,tool,x,y,z,jaw_m,cut`",
        ),
        (
            "0,0,0,0,0\n".into(),
            1,
            "traj.csv: line 1: expected the header `t,tool,x,y,z` or `t,tool,x,y,z,jaw_m,cut`, found `0,0,0,0,0`",
        ),
        (
            "time,tool,x,y,z\n".into(),
            1,
            "traj.csv: line 1: expected the header `t,tool,x,y,z` or `t,tool,x,y,z,jaw_m,cut`, found `time,tool,x,y,z`",
        ),
        (h.into(), 1, "traj.csv: no samples after the header"),
        (
            format!("{h}0,0,0,0,0\n1,0,0,0\n"),
            1,
            "traj.csv: line 3: expected 5 fields t,tool,x,y,z, found 4",
        ),
        (
            format!("{h}0,0,0,0,0,0\n"),
            1,
            "traj.csv: line 2: expected 5 fields t,tool,x,y,z, found 6",
        ),
        (
            format!("{h}0,0,0,abc,0\n"),
            1,
            "traj.csv: line 2: y = `abc` is not a number",
        ),
        (
            format!("{h}zero,0,0,0,0\n"),
            1,
            "traj.csv: line 2: t = `zero` is not a number",
        ),
        (
            format!("{h}0,,0,0,0\n"),
            1,
            "traj.csv: line 2: tool = `` is not a tool point index (an integer >= 0)",
        ),
        (
            format!("{h}0,1.0,0,0,0\n"),
            2,
            "traj.csv: line 2: tool = `1.0` is not a tool point index (an integer >= 0)",
        ),
        (
            format!("{h}0,-1,0,0,0\n"),
            2,
            "traj.csv: line 2: tool = `-1` is not a tool point index (an integer >= 0)",
        ),
        (
            format!("{h}0,0,0,0,0\nNaN,0,0,0,0\n"),
            1,
            "traj.csv: line 3: non-finite t = NaN",
        ),
        (
            format!("{h}0,0,inf,0,0\n"),
            1,
            "traj.csv: line 2: non-finite x = inf",
        ),
        (
            format!("{h}0,0,0,0,-infinity\n"),
            1,
            "traj.csv: line 2: non-finite z = -inf",
        ),
        (
            format!("{h}0,0,0,0,0\n0,2,0,0,0\n"),
            2,
            "traj.csv: line 3: tool point 2 does not exist: the scene has 2 (indices 0 to 1)",
        ),
        // Backwards for the same tool point, and across tool points.
        (
            format!("{h}0,0,0,0,0\n0.5,0,0,0,0\n0.25,0,0,0,0\n"),
            1,
            "traj.csv: line 4: time 0.25 s goes backwards: line 3 is at 0.5 s",
        ),
        (
            format!("{h}0,0,0,0,0\n0.5,1,0,0,0\n0.25,0,0,0,0\n"),
            2,
            "traj.csv: line 4: time 0.25 s goes backwards: line 3 is at 0.5 s",
        ),
        (
            format!("{h}0,1,0,0,0\n"),
            2,
            "traj.csv: tool point 0 has no sample",
        ),
        (
            format!("{h}0,0,0,0,0\n"),
            0,
            "traj.csv: tool point count 0 out of range 1..=4",
        ),
        (
            format!("{h}0,0,0,0,0\n"),
            5,
            "traj.csv: tool point count 5 out of range 1..=4",
        ),
    ];
    for (text, tools, expected) in cases {
        assert_eq!(traj_err(&text, tools), expected, "\n{text}");
    }
    // Invalid UTF-8 is a line error too.
    let msg = Trajectory::from_csv_str_unchecked("t,tool,x,y,z\n0,0,0,0,0\n", "x", 1)
        .map(|(t, f)| (t.samples().len(), f.len()))
        .unwrap();
    assert_eq!(msg, (1, 0));
    let dir = temp_dir("utf8");
    let path = dir.join("bad.csv");
    std::fs::write(&path, b"t,tool,x,y,z\n0,0,0,0,0\n1,0,\xff,0,0\n").unwrap();
    let msg = Trajectory::read(&path, 1).unwrap_err();
    assert!(
        matches!(msg, TrajectoryError::Line { line: 3, .. }),
        "{msg}"
    );
    // Samples given in code: line numbers as write_csv would write them.
    let s = |t_s, tool| Sample {
        t_s,
        tool,
        position_m: [0.0; 3],
        jaw_m: 0.0,
        cut: false,
    };
    let msg = Trajectory::from_samples(vec![s(0.0, 0), s(1.0, 0), s(0.5, 0)], 1)
        .unwrap_err()
        .to_string();
    assert_eq!(
        msg,
        "samples: line 4: time 0.5 s goes backwards: line 3 is at 1 s"
    );
}

#[test]
fn unchecked_reader_keeps_bad_values_and_reports_them() {
    let text = "t,tool,x,y,z\n0,0,0,0,0\n1,0,NaN,0,0\n2,0,1,1,1\n1.5,0,0,0,inf\n";
    let (t, findings) = Trajectory::from_csv_str_unchecked(text, "robust.csv", 1).unwrap();
    let findings: Vec<String> = findings.iter().map(ToString::to_string).collect();
    assert_eq!(
        findings,
        [
            "robust.csv: line 3: non-finite x = NaN",
            "robust.csv: line 5: non-finite z = inf",
            "robust.csv: line 5: time 1.5 s goes backwards: line 4 is at 2 s",
        ]
    );
    assert_eq!(t.samples().len(), 4);
    assert!(t.samples()[1].position_m[0].is_nan());
    assert_eq!(t.samples()[3].position_m[2], f64::INFINITY);
    // The bad values reach the positions (for the kernel to refuse), nothing panics.
    assert_eq!(t.positions_at(0.0), [[0.0; 3]]);
    assert!(t.positions_at(0.5)[0][0].is_nan());
    assert!(t.positions_at(1.0)[0][0].is_nan());
    assert_eq!(t.positions_at(3.0), [[0.0, 0.0, f64::INFINITY]]);
    assert_eq!((t.start_s(), t.end_s()), (0.0, 2.0));
    for k in 0..=40 {
        let _ = t.positions_at(f64::from(k) * 0.05);
    }
    // A non-finite time is kept too; end_s ignores it.
    let (t, findings) =
        Trajectory::from_csv_str_unchecked("t,tool,x,y,z\n0,0,0,0,0\ninf,0,1,0,0\n", "r", 1)
            .unwrap();
    assert_eq!(findings.len(), 1);
    assert_eq!(t.end_s(), 0.0);
    assert_eq!(t.positions_at(1e308), [[0.0; 3]]);
    // Structural errors are still refused.
    assert_eq!(
        Trajectory::from_csv_str_unchecked("t,tool,x,y,z\n0,3,0,0,0\n", "r", 1)
            .unwrap_err()
            .to_string(),
        "r: line 2: tool point 3 does not exist: the scene has 1 (indices 0 to 0)"
    );
    // Through a file.
    let dir = temp_dir("unchecked");
    let path = dir.join("nan.csv");
    std::fs::write(&path, text).unwrap();
    let (t, findings) = Trajectory::read_unchecked(&path, 1).unwrap();
    assert_eq!((t.samples().len(), findings.len()), (4, 3));
    // write_csv writes NaN and inf so that the lenient reader reads them back.
    assert_eq!(csv(&t), text);
}

// ---------------------------------------------------------------- generators

/// Powers of two, so that every keyframe time and position is exact.
fn exact_press() -> Press {
    Press {
        surface_m: [0.0625, 0.0625, 0.0625],
        normal: [0.0, 0.0, 2.0],
        standoff_m: 0.0078125,
        depth_m: 0.00390625,
        approach_speed_m_s: 0.0625,
        withdraw_speed_m_s: 0.03125,
    }
}

#[test]
fn poke_reaches_exactly_the_depth_at_the_requested_time() {
    let poke = Poke {
        tool: 0,
        press: exact_press(),
        rate_hz: 1000.0,
    };
    let keys = poke.keyframes().unwrap();
    let summary: Vec<(&str, f64, f64)> = keys
        .iter()
        .map(|k| (k.label, k.t_s, k.position_m[2]))
        .collect();
    // In: 7.8125 mm at 62.5 mm/s (0.125 s), then 3.90625 mm (0.0625 s); out at half the speed.
    assert_eq!(
        summary,
        [
            ("start", 0.0, 0.0703125),
            ("contact", 0.125, 0.0625),
            ("deepest", 0.1875, 0.05859375),
            ("release", 0.3125, 0.0625),
            ("end", 0.5625, 0.0703125),
        ]
    );
    let t = poke.trajectory().unwrap();
    assert_eq!(t.tool_count(), 1);
    assert_eq!(t.positions_at(0.1875), [[0.0625, 0.0625, 0.05859375]]);
    assert_eq!(t.end_s(), 0.5625);
    // The 1 kHz grid 0..=0.562 s (563 samples) plus the 3 keyframes off the grid.
    assert_eq!(t.samples().len(), 566);
    assert!(t.samples().iter().any(|s| s.t_s == 0.1875));
    assert!(t.samples().iter().any(|s| s.t_s == 0.1));
    // The deepest sample is exactly the requested depth below the surface, only there.
    let deepest = t
        .samples()
        .iter()
        .map(|s| s.position_m[2])
        .fold(f64::INFINITY, f64::min);
    assert_eq!(deepest, 0.0625 - 0.00390625);
    let at_depth: Vec<f64> = t
        .samples()
        .iter()
        .filter(|s| s.position_m[2] == deepest)
        .map(|s| s.t_s)
        .collect();
    assert_eq!(at_depth, [0.1875]);
    // Along the normal only, at the approach then the withdraw speed.
    for w in t.samples().windows(2) {
        let (a, b) = (w[0], w[1]);
        assert_eq!([a.position_m[0], a.position_m[1]], [0.0625, 0.0625]);
        let v = (b.position_m[2] - a.position_m[2]) / (b.t_s - a.t_s);
        let expected = if b.t_s <= 0.1875 { -0.0625 } else { 0.03125 };
        assert!((v - expected).abs() < 1e-9, "v = {v} at {}", a.t_s);
    }
    assert!((t.positions_at(0.1)[0][2] - 0.0640625).abs() < 1e-15);
}

#[test]
fn press_and_hold_stays_at_the_depth() {
    let hold = PressHold::default();
    let keys = hold.keyframes().unwrap();
    let deepest = keyframe(&keys, 0, "deepest");
    let held = keyframe(&keys, 0, "held");
    assert!((deepest.t_s - 0.5).abs() < 1e-12 && (held.t_s - 1.5).abs() < 1e-12);
    assert!((keyframe(&keys, 0, "end").t_s - 2.0).abs() < 1e-12);
    assert!((deepest.position_m[2] - 0.055).abs() < 1e-15);
    let t = hold.trajectory().unwrap();
    let during: Vec<&Sample> = t
        .samples()
        .iter()
        .filter(|s| s.t_s >= deepest.t_s && s.t_s <= held.t_s)
        .collect();
    assert!(during.len() >= 1000);
    for s in during {
        assert_eq!(s.position_m, deepest.position_m, "t = {}", s.t_s);
    }
    assert_eq!(t.positions_at(1.0), [deepest.position_m]);
}

#[test]
fn slide_moves_along_the_surface_at_the_depth() {
    let slide = Slide {
        tool: 0,
        press: exact_press(),
        // The part along the normal is removed: a slide along +x.
        direction: [1.0, 0.0, 1.0],
        distance_m: 0.015625,
        slide_speed_m_s: 0.0625,
        rate_hz: 1000.0,
    };
    let keys = slide.keyframes().unwrap();
    let slid = keyframe(&keys, 0, "slid");
    assert_eq!(slid.t_s, 0.4375);
    assert_eq!(slid.position_m, [0.078125, 0.0625, 0.05859375]);
    assert_eq!(
        keyframe(&keys, 0, "end").position_m,
        [0.078125, 0.0625, 0.0703125]
    );
    let t = slide.trajectory().unwrap();
    assert_eq!(t.positions_at(0.3125), [[0.0703125, 0.0625, 0.05859375]]);
    let mut last_x = f64::NEG_INFINITY;
    for s in t
        .samples()
        .iter()
        .filter(|s| s.t_s >= 0.1875 && s.t_s <= 0.4375)
    {
        assert_eq!(s.position_m[2], 0.05859375);
        assert!(s.position_m[0] > last_x);
        last_x = s.position_m[0];
    }
    assert_eq!(last_x, 0.078125);
}

#[test]
fn pinch_points_approach_each_other_while_pressed() {
    let pinch = Pinch {
        press: exact_press(),
        axis: [0.0, 3.0, 0.0],
        start_gap_m: 0.03125,
        end_gap_m: 0.0078125,
        close_speed_m_s: 0.01171875,
        hold_s: 0.0625,
        rate_hz: 1000.0,
    };
    let keys = pinch.keyframes().unwrap();
    assert_eq!(
        keyframe(&keys, 0, "start").position_m,
        [0.0625, 0.046875, 0.0703125]
    );
    assert_eq!(
        keyframe(&keys, 1, "start").position_m,
        [0.0625, 0.078125, 0.0703125]
    );
    // Closing 11.71875 mm each at 11.71875 mm/s: 1 s after reaching the depth at 0.1875 s.
    assert_eq!(keyframe(&keys, 0, "closed").t_s, 1.1875);
    assert_eq!(
        keyframe(&keys, 0, "closed").position_m,
        [0.0625, 0.05859375, 0.05859375]
    );
    assert_eq!(
        keyframe(&keys, 1, "closed").position_m,
        [0.0625, 0.06640625, 0.05859375]
    );
    assert_eq!(keyframe(&keys, 1, "held").t_s, 1.25);
    let t = pinch.trajectory().unwrap();
    assert_eq!(t.tool_count(), 2);
    let gap = |time: f64| {
        let p = t.positions_at(time);
        p[1][1] - p[0][1]
    };
    assert_eq!(gap(0.0), 0.03125);
    assert_eq!(gap(0.1875), 0.03125);
    assert_eq!(gap(1.1875), 0.0078125);
    assert_eq!(gap(1.25), 0.0078125);
    assert!((gap(0.6875) - 0.01953125).abs() < 1e-15);
    let mut last_gap = f64::INFINITY;
    for k in 0..=1300 {
        let time = f64::from(k) * 0.001;
        let p = t.positions_at(time);
        let g = gap(time);
        if (0.1875..=1.1875).contains(&time) {
            // Both pressed at the depth while they close, symmetric about the centre.
            assert_eq!([p[0][2], p[1][2]], [0.05859375; 2], "t = {time}");
            assert!((p[0][1] + p[1][1] - 0.125).abs() < 1e-15);
            if time > 0.1875 {
                assert!(g < last_gap, "t = {time}");
            }
        }
        assert!(g <= last_gap);
        last_gap = g;
    }
    // Samples come in pairs: tool 0 then tool 1 at each time.
    for pair in t.samples().chunks(2) {
        assert_eq!((pair[0].tool, pair[1].tool), (0, 1));
        assert_eq!(pair[0].t_s, pair[1].t_s);
    }
}

#[test]
fn strike_hits_at_its_speed() {
    let strike = Strike::default();
    let t = strike.trajectory().unwrap();
    let keys = strike.keyframes().unwrap();
    let deepest = keyframe(&keys, 0, "deepest");
    assert!((deepest.t_s - 0.03).abs() < 1e-15);
    assert!((keyframe(&keys, 0, "contact").t_s - 0.02).abs() < 1e-15);
    assert!((t.end_s() - 0.98).abs() < 1e-12);
    // 0.5 m/s: 0.5 mm per 1 kHz sample, through the surface without slowing down.
    let approach: Vec<&Sample> = t
        .samples()
        .iter()
        .filter(|s| s.t_s <= deepest.t_s)
        .collect();
    assert_eq!(approach.len(), 31);
    for w in approach.windows(2) {
        let dz = w[1].position_m[2] - w[0].position_m[2];
        let v = dz / (w[1].t_s - w[0].t_s);
        assert!((v + 0.5).abs() < 1e-9, "v = {v}");
        assert!((dz + 0.0005).abs() < 1e-12, "dz = {dz}");
    }
    assert!((approach[0].position_m[2] - 0.07).abs() < 1e-15);
    assert!((deepest.position_m[2] - 0.055).abs() < 1e-15);
}

#[test]
fn default_generators_give_valid_trajectories() {
    let end = |g: &dyn Generator| g.trajectory().unwrap().end_s();
    assert!((end(&Poke::default()) - 1.0).abs() < 1e-12);
    assert!((end(&PressHold::default()) - 2.0).abs() < 1e-12);
    assert!((end(&Slide::default()) - 2.5).abs() < 1e-12);
    assert!((end(&Pinch::default()) - 2.5).abs() < 1e-12);
    assert!((end(&Strike::default()) - 0.98).abs() < 1e-12);
}

#[test]
fn two_probes_by_concatenating_keyframes() {
    let first = PressHold::default();
    let second = PressHold {
        tool: 1,
        press: Press {
            surface_m: [0.03, 0.06, 0.06],
            ..Press::default()
        },
        ..PressHold::default()
    };
    let keys = [first.keyframes().unwrap(), second.keyframes().unwrap()].concat();
    let t = sample_keyframes(&keys, 1000.0).unwrap();
    assert_eq!(t.tool_count(), 2);
    assert_eq!(t.samples().len(), 2 * 2001);
    let p = t.positions_at(1.0);
    assert_eq!(p[0], keyframe(&keys, 0, "deepest").position_m);
    assert_eq!(p[1], keyframe(&keys, 1, "deepest").position_m);
    // Tool point 1 alone has no tool point 0.
    assert_eq!(
        second.trajectory().unwrap_err().to_string(),
        "keyframes: tool point 0 has no keyframe"
    );
    // A jump in keyframes is kept as two samples at the same time.
    let at = |t_s, z, label| Keyframe {
        tool: 0,
        t_s,
        position_m: [0.0, 0.0, z],
        jaw_m: 0.0,
        cut: false,
        label,
    };
    let t = sample_keyframes(
        &[at(0.0, 1.0, "start"), at(0.5, 1.0, "a"), at(0.5, 2.0, "b")],
        4.0,
    )
    .unwrap();
    let z: Vec<(f64, f64)> = t
        .samples()
        .iter()
        .map(|s| (s.t_s, s.position_m[2]))
        .collect();
    assert_eq!(z, [(0.0, 1.0), (0.25, 1.0), (0.5, 1.0), (0.5, 2.0)]);
}

#[test]
fn every_generator_error_names_the_parameter() {
    let press = |f: fn(&mut Press)| {
        let mut p = Press::default();
        f(&mut p);
        Poke {
            press: p,
            ..Poke::default()
        }
    };
    let msg = |g: &dyn Generator| -> String {
        let e: GenerateError = g.trajectory().unwrap_err();
        e.to_string()
    };
    assert_eq!(
        msg(&press(|p| p.normal = [0.0; 3])),
        "press.normal: must be a finite non-zero vector, got [0.0, 0.0, 0.0]"
    );
    assert_eq!(
        msg(&press(|p| p.surface_m[1] = f64::NAN)),
        "press.surface_m: must be finite, got [0.06, NaN, 0.06]"
    );
    assert_eq!(
        msg(&press(|p| p.depth_m = -0.001)),
        "press.depth_m: must be finite and >= 0 m, got -0.001"
    );
    assert_eq!(
        msg(&press(|p| p.standoff_m = f64::INFINITY)),
        "press.standoff_m: must be finite and >= 0 m, got inf"
    );
    assert_eq!(
        msg(&press(|p| p.approach_speed_m_s = 0.0)),
        "press.approach_speed_m_s: must be finite and > 0 m/s, got 0"
    );
    assert_eq!(
        msg(&press(|p| p.withdraw_speed_m_s = -1.0)),
        "press.withdraw_speed_m_s: must be finite and > 0 m/s, got -1"
    );
    assert_eq!(
        msg(&Poke {
            rate_hz: 0.0,
            ..Poke::default()
        }),
        "rate_hz: must be finite and > 0 Hz, got 0"
    );
    assert_eq!(
        msg(&Poke {
            tool: 4,
            ..Poke::default()
        }),
        "poke.tool: tool point 4 out of range 0..4"
    );
    assert_eq!(
        msg(&PressHold {
            hold_s: -1.0,
            ..PressHold::default()
        }),
        "press_hold.hold_s: must be finite and >= 0 s, got -1"
    );
    assert_eq!(
        msg(&Strike {
            hold_s: f64::NAN,
            ..Strike::default()
        }),
        "strike.hold_s: must be finite and >= 0 s, got NaN"
    );
    assert_eq!(
        msg(&Slide {
            direction: [0.0, 0.0, -1.0],
            ..Slide::default()
        }),
        "slide.direction: [0.0, 0.0, -1.0] is along the surface normal"
    );
    assert_eq!(
        msg(&Slide {
            slide_speed_m_s: 0.0,
            ..Slide::default()
        }),
        "slide.slide_speed_m_s: must be finite and > 0 m/s, got 0"
    );
    assert_eq!(
        msg(&Pinch {
            start_gap_m: 0.02,
            ..Pinch::default()
        }),
        "pinch.start_gap_m: must be finite and > end_gap_m = 0.02 m, got 0.02"
    );
    assert_eq!(
        msg(&Pinch {
            axis: [0.0, 0.0, 1.0],
            ..Pinch::default()
        }),
        "pinch.axis: [0.0, 0.0, 1.0] is along the surface normal"
    );
    let slow = msg(&press(|p| p.approach_speed_m_s = 1e-9));
    assert!(
        slow.starts_with("rate_hz: ")
            && slow.ends_with(&format!("at most {MAX_GENERATED_SAMPLES}")),
        "{slow}"
    );
    let at = |t_s| Keyframe {
        tool: 0,
        t_s,
        position_m: [0.0; 3],
        jaw_m: 0.0,
        cut: false,
        label: "x",
    };
    assert_eq!(
        sample_keyframes(&[at(1.0), at(0.5)], 10.0)
            .unwrap_err()
            .to_string(),
        "keyframes: x of tool point 0: time 0.5 s before 1 s"
    );
    assert_eq!(
        sample_keyframes(&[], 10.0).unwrap_err().to_string(),
        "keyframes: no keyframe"
    );
}

/// A haptic rate so small that the tick period overflows to infinity is
/// refused (found by fuzzing the scene parser).
#[test]
fn subnormal_haptic_rate_is_refused() {
    let err = scene_err(
        "generated = { box = [0.1, 0.1, 0.05], cells = [2, 2, 1] }\nfix = [\"z<0.001\"]\nmaterial = { young_pa = 3000, poisson = 0.45 }\nrates = { haptic_hz = 1e-310 }\n",
    );
    assert!(
        err.contains("haptic_hz") && err.contains("too small"),
        "{err}"
    );
}
