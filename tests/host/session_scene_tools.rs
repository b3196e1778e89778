//! Scene files' tool kinds, `[cutting]` and `[tearing]`
//! (`palpate::scene`; the rest of the format is tested in
//! `host::session`).

use palpate::scene::{
    CuttingSpec, DEFAULT_CUT_FORCE_N, MAX_TOOL_POINTS, Scene, TearingSpec, ToolKind, ToolSpec,
};
use palpate_tests::{BASE_SCENE, assert_scene_errors, scene, scene_err};

/// `BASE_SCENE` on the dynamic model.
const DYNAMIC: &str = "mesh = \"a.msh\"\nfix = [\"z<0.001\"]\n[material]\nyoung_pa = 3000\n\
                       poisson = 0.45\n[model]\nkind = \"dynamic\"\ndamping_per_s = 2\n";

#[test]
fn tool_kinds_cutting_and_tearing_with_every_key() {
    let s = scene(&format!(
        "{DYNAMIC}\
         [tool]\n\
         points = 2\n\
         radius_m = 0.0015\n\
         kind = [\"grasper\", \"cutter\"]\n\
         jaw_axis = [0, 3, -4]          # normalized\n\
         grip_opening_m = 0.004\n\
         blade_m = [0.0, 0.005, -0.02]\n\
         [cutting]\n\
         capacity_tets = 16\n\
         force_n = 0.5\n\
         [tearing]\n\
         volume_change = 0.5\n\
         mean_elongation = 0.4\n\
         max_elongation = 0.6\n\
         capacity_tets = 4\n"
    ));
    assert_eq!(
        s.tool,
        ToolSpec {
            points: 2,
            radius_m: 0.0015,
            kinds: vec![ToolKind::Grasper, ToolKind::Cutter],
            jaw_axis: [0.0, 0.6, -0.8],
            grip_opening_m: 0.004,
            blade_m: [0.0, 0.005, -0.02],
        }
    );
    assert_eq!(s.tool.kernel_points(), 3);
    assert_eq!(
        s.cutting,
        CuttingSpec {
            capacity_tets: 16,
            force_n: 0.5
        }
    );
    assert_eq!(
        s.tearing,
        Some(TearingSpec {
            volume_change: Some(0.5),
            mean_elongation: Some(0.4),
            max_elongation: Some(0.6),
            capacity_tets: 4,
        })
    );
    s.validate().unwrap();
}

#[test]
fn tool_kinds_cutting_and_tearing_defaults() {
    // No key: one probe, the grasper and cutter settings at their defaults, cutting 8 tets
    // per update, no tearing.
    let s = scene(BASE_SCENE);
    assert_eq!(s.tool, ToolSpec::probes(1, 0.002));
    assert_eq!(s.tool.kinds, [ToolKind::Probe]);
    assert_eq!(s.tool.jaw_axis, [1.0, 0.0, 0.0]);
    assert_eq!(s.tool.grip_opening_m, 2.5 * 0.002);
    assert_eq!(s.tool.blade_m, [0.0, 0.0, -0.01]);
    assert_eq!(s.tool.kernel_points(), 1);
    assert_eq!(
        s.cutting,
        CuttingSpec {
            capacity_tets: 8,
            force_n: DEFAULT_CUT_FORCE_N
        }
    );
    assert_eq!(s.tearing, None);

    // One kind for every point; the grip opening follows the radius; one tearing criterion.
    let s = scene(&format!(
        "{DYNAMIC}[tool]\npoints = 3\nkind = \"cutter\"\nradius_m = 0.004\n\
         [tearing]\nmax_elongation = 0.3\n"
    ));
    assert_eq!(s.tool.kinds, [ToolKind::Cutter; 3]);
    assert_eq!(s.tool.kernel_points(), 3);
    assert_eq!(s.tool.grip_opening_m, 0.01);
    assert_eq!(
        s.tearing,
        Some(TearingSpec {
            volume_change: None,
            mean_elongation: None,
            max_elongation: Some(0.3),
            capacity_tets: 8,
        })
    );

    // Two graspers fill the kernel's 4 tool points; a blade of exactly 0.1 m is accepted;
    // tiny and huge jaw axes are normalized without underflow or overflow.
    let s = scene(&format!(
        "{BASE_SCENE}[tool]\npoints = 2\nkind = \"grasper\"\njaw_axis = [1e-300, 0, -1e-300]\n\
         blade_m = [0, 0.1, 0]\n"
    ));
    assert_eq!(s.tool.kernel_points(), 4);
    let h = core::f64::consts::FRAC_1_SQRT_2;
    assert!((s.tool.jaw_axis[0] - h).abs() < 1e-15 && (s.tool.jaw_axis[2] + h).abs() < 1e-15);
    let s = scene(&format!(
        "{BASE_SCENE}[tool]\njaw_axis = [1e308, 1e308, 0]\n"
    ));
    assert!((s.tool.jaw_axis[0] - h).abs() < 1e-15 && s.tool.jaw_axis[2] == 0.0);
    let length = s.tool.jaw_axis.iter().map(|x| x * x).sum::<f64>().sqrt();
    assert!((length - 1.0).abs() <= 1e-12);

    // `[cutting]` is accepted on the pre-computed model (which has nothing to cut).
    assert_eq!(
        scene(&format!("{BASE_SCENE}[cutting]\ncapacity_tets = 64\n")).cutting,
        CuttingSpec {
            capacity_tets: 64,
            force_n: DEFAULT_CUT_FORCE_N
        }
    );
}

#[test]
fn tool_kind_names_and_kernel_points() {
    let named: Vec<(&str, usize)> = ToolKind::ALL
        .iter()
        .map(|k| (k.name(), k.kernel_points()))
        .collect();
    assert_eq!(named, [("probe", 1), ("grasper", 2), ("cutter", 1)]);
    // A scene file names each kind by its name, exactly.
    for kind in ToolKind::ALL {
        let s = scene(&format!("{BASE_SCENE}[tool]\nkind = \"{}\"\n", kind.name()));
        assert_eq!(s.tool.kinds, [kind]);
    }
    assert_eq!(
        scene_err(&format!("{BASE_SCENE}[tool]\nkind = \"Probe\"\n")),
        "bad.toml: [tool] kind = \"Probe\": expected \"probe\", \"grasper\" or \"cutter\""
    );
}

#[test]
fn built_in_scenes_have_one_probe_and_no_tearing() {
    for s in [Scene::built_in(), Scene::built_in_dynamic()] {
        s.validate().unwrap();
        assert_eq!(s.tool, ToolSpec::probes(1, 0.002));
        assert_eq!(
            s.cutting,
            CuttingSpec {
                capacity_tets: 8,
                force_n: DEFAULT_CUT_FORCE_N
            }
        );
        assert_eq!(s.tearing, None);
    }
}

#[test]
fn every_tool_cutting_and_tearing_error_names_the_key() {
    let tool = |keys: &str| format!("{BASE_SCENE}[tool]\n{keys}");
    let cases: Vec<(String, &str)> = vec![
        // Parser errors, with the line.
        (
            tool("blade = 1\n"),
            "bad.toml: line 7: unknown field `blade`, expected one of `points`, `radius_m`, `kind`, `jaw_axis`, `grip_opening_m`, `blade_m`",
        ),
        (
            tool("kind = 3\n"),
            "bad.toml: line 7: invalid type: integer `3`, expected a tool kind (\"probe\", \"grasper\" or \"cutter\") or an array of them",
        ),
        (
            tool("points = 2\nkind = [\"probe\", 1]\n"),
            "bad.toml: line 8: invalid type: integer `1`, expected a string",
        ),
        (
            tool("jaw_axis = [1, 0]\n"),
            "bad.toml: line 7: jaw_axis: invalid length 2, expected exactly 3 numbers, [x, y, z]",
        ),
        (
            format!("{BASE_SCENE}[cutting]\ncapacity = 8\n"),
            "bad.toml: line 7: unknown field `capacity`, expected `capacity_tets` or `force_n`",
        ),
        (
            format!("{BASE_SCENE}[cutting]\ncapacity_tets = -1\n"),
            "bad.toml: line 7: invalid value: integer `-1`, expected u32",
        ),
        (
            format!("{DYNAMIC}[tearing]\nstrain = 0.5\n"),
            "bad.toml: line 10: unknown field `strain`, expected one of `volume_change`, `mean_elongation`, `max_elongation`, `capacity_tets`",
        ),
        // Kinds.
        (
            tool("kind = \"knife\"\n"),
            "bad.toml: [tool] kind = \"knife\": expected \"probe\", \"grasper\" or \"cutter\"",
        ),
        (
            tool("points = 2\nkind = [\"probe\", \"Scalpel\"]\n"),
            "bad.toml: [tool] kind[1] = \"Scalpel\": expected \"probe\", \"grasper\" or \"cutter\"",
        ),
        (
            tool("points = 3\nkind = [\"grasper\", \"cutter\"]\n"),
            "bad.toml: [tool] kind = [\"grasper\", \"cutter\"]: 2 given for points = 3: give one kind per trajectory tool point, or a single kind for all",
        ),
        (
            tool("kind = []\n"),
            "bad.toml: [tool] kind = []: 0 given for points = 1: give one kind per trajectory tool point, or a single kind for all",
        ),
        (
            tool("points = 3\nkind = [\"grasper\", \"probe\", \"grasper\"]\n"),
            "bad.toml: [tool] kind = [\"grasper\", \"probe\", \"grasper\"]: needs 5 kernel tool points (a grasper is 2 jaws, a probe or cutter 1): at most 4 (MAX_TOOL_POINTS, the kernel's contact capacity)",
        ),
        (
            tool("points = 3\nkind = \"grasper\"\n"),
            "bad.toml: [tool] kind = [\"grasper\", \"grasper\", \"grasper\"]: needs 6 kernel tool points (a grasper is 2 jaws, a probe or cutter 1): at most 4 (MAX_TOOL_POINTS, the kernel's contact capacity)",
        ),
        (
            tool("points = 5\nkind = \"grasper\"\n"),
            "bad.toml: [tool] points = 5: must be in 1..=4 (the kernel's contact capacity)",
        ),
        // Grasper.
        (
            tool("jaw_axis = [0, 0, 0]\n"),
            "bad.toml: [tool] jaw_axis = [0.0, 0.0, 0.0]: must be finite and non-zero (the direction from jaw 0 to jaw 1)",
        ),
        (
            tool("jaw_axis = [nan, 0, 1]\n"),
            "bad.toml: [tool] jaw_axis = [NaN, 0.0, 1.0]: must be finite and non-zero (the direction from jaw 0 to jaw 1)",
        ),
        (
            tool("jaw_axis = [inf, 0, 0]\n"),
            "bad.toml: [tool] jaw_axis = [inf, 0.0, 0.0]: must be finite and non-zero (the direction from jaw 0 to jaw 1)",
        ),
        (
            tool("grip_opening_m = 0\n"),
            "bad.toml: [tool] grip_opening_m = 0: must be finite and > 0 m",
        ),
        (
            tool("grip_opening_m = -0.001\n"),
            "bad.toml: [tool] grip_opening_m = -0.001: must be finite and > 0 m",
        ),
        (
            tool("grip_opening_m = nan\n"),
            "bad.toml: [tool] grip_opening_m = NaN: must be finite and > 0 m",
        ),
        (
            tool("grip_opening_m = 1e-300\n"),
            "bad.toml: [tool] grip_opening_m = 1e-300: out of range of the loop's f32: must lie between 1.1754944e-38 and 3.4028235e38 m",
        ),
        // Cutter.
        (
            tool("blade_m = [0, 0, -0.2]\n"),
            "bad.toml: [tool] blade_m = [0.0, 0.0, -0.2]: must be finite, with a length > 0 and at most 0.1 m (MAX_BLADE_M), from the tool point to the blade's tip",
        ),
        (
            tool("blade_m = [0.08, 0, -0.08]\n"),
            "bad.toml: [tool] blade_m = [0.08, 0.0, -0.08]: must be finite, with a length > 0 and at most 0.1 m (MAX_BLADE_M), from the tool point to the blade's tip",
        ),
        (
            tool("blade_m = [0, 0, 0]\n"),
            "bad.toml: [tool] blade_m = [0.0, 0.0, 0.0]: must be finite, with a length > 0 and at most 0.1 m (MAX_BLADE_M), from the tool point to the blade's tip",
        ),
        (
            tool("blade_m = [0, 0, -inf]\n"),
            "bad.toml: [tool] blade_m = [0.0, 0.0, -inf]: must be finite, with a length > 0 and at most 0.1 m (MAX_BLADE_M), from the tool point to the blade's tip",
        ),
        (
            tool("blade_m = [0, 0, -1e-300]\n"),
            "bad.toml: [tool] blade_m = [0.0, 0.0, -1e-300]: out of range of the loop's f32: its length must lie between 1.1754944e-38 and 3.4028235e38 m",
        ),
        // Capacities.
        (
            format!("{DYNAMIC}[cutting]\ncapacity_tets = 0\n"),
            "bad.toml: [cutting] capacity_tets = 0: must be in 1..=64 (MAX_CAPACITY_TETS: tets one physics update removes at most)",
        ),
        (
            format!("{DYNAMIC}[cutting]\ncapacity_tets = 65\n"),
            "bad.toml: [cutting] capacity_tets = 65: must be in 1..=64 (MAX_CAPACITY_TETS: tets one physics update removes at most)",
        ),
        (
            format!("{DYNAMIC}[tearing]\nvolume_change = 0.5\ncapacity_tets = 0\n"),
            "bad.toml: [tearing] capacity_tets = 0: must be in 1..=64 (MAX_CAPACITY_TETS: tets one physics update removes at most)",
        ),
        (
            format!("{DYNAMIC}[tearing]\nvolume_change = 0.5\ncapacity_tets = 65\n"),
            "bad.toml: [tearing] capacity_tets = 65: must be in 1..=64 (MAX_CAPACITY_TETS: tets one physics update removes at most)",
        ),
        // Tearing.
        (
            format!("{BASE_SCENE}[tearing]\nvolume_change = 0.5\n"),
            "bad.toml: [tearing]: applies to kind = \"dynamic\" only (this scene is \"precomputed\", which cannot tear)",
        ),
        (
            format!("{DYNAMIC}[tearing]\ncapacity_tets = 4\n"),
            "bad.toml: [tearing]: no criterion: give at least one of volume_change, mean_elongation and max_elongation (or remove the table: no tearing)",
        ),
        (
            format!("{DYNAMIC}[tearing]\n"),
            "bad.toml: [tearing]: no criterion: give at least one of volume_change, mean_elongation and max_elongation (or remove the table: no tearing)",
        ),
        (
            format!("{DYNAMIC}[tearing]\nvolume_change = 0\n"),
            "bad.toml: [tearing] volume_change = 0: must be finite and > 0",
        ),
        (
            format!("{DYNAMIC}[tearing]\nvolume_change = 0.5\nmean_elongation = -0.1\n"),
            "bad.toml: [tearing] mean_elongation = -0.1: must be finite and > 0",
        ),
        (
            format!("{DYNAMIC}[tearing]\nmax_elongation = inf\n"),
            "bad.toml: [tearing] max_elongation = inf: must be finite and > 0",
        ),
        (
            format!("{DYNAMIC}[cutting]\nforce_n = 0\n"),
            "bad.toml: [cutting] force_n = 0: must be finite, > 0 N and fit f32",
        ),
    ];
    assert_scene_errors(&cases);
}

#[test]
fn changed_tools_are_checked_again() {
    let mut s = Scene::built_in();
    s.tool.points = 2;
    assert_eq!(
        s.validate().unwrap_err().to_string(),
        "built-in scene: [tool] kind = [\"probe\"]: 1 given for points = 2: give one kind per trajectory tool point, or a single kind for all"
    );
    s.tool.kinds = vec![ToolKind::Grasper, ToolKind::Probe];
    s.validate().unwrap();
    s.tool.jaw_axis = [0.0, 2.0, 0.0];
    assert_eq!(
        s.validate().unwrap_err().to_string(),
        "built-in scene: [tool] jaw_axis = [0.0, 2.0, 0.0]: must have unit length (a scene file's jaw_axis is normalized when read)"
    );
    s.tool.jaw_axis = [0.0, 1.0, 0.0];
    s.tearing = Some(TearingSpec {
        volume_change: Some(0.5),
        mean_elongation: None,
        max_elongation: None,
        capacity_tets: 8,
    });
    assert_eq!(
        s.validate().unwrap_err().to_string(),
        "built-in scene: [tearing]: applies to kind = \"dynamic\" only (this scene is \"precomputed\", which cannot tear)"
    );
    s.model = Scene::built_in_dynamic().model;
    s.rates = Scene::built_in_dynamic().rates;
    s.validate().unwrap();
    // `probes` caps the kinds at MAX_TOOL_POINTS, so a bad count is refused, not allocated.
    let tool = ToolSpec::probes(usize::MAX, 0.002);
    assert_eq!(tool.kinds.len(), MAX_TOOL_POINTS);
}
