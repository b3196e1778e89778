//! Robustness, "wrong or unusable results with exit 0" and "messages", at the
//! process level: each probe that once printed a wrong or unusable result
//! with exit status 0, or an error naming nothing, now exits 2 with one line
//! `error: …` naming the file, line, key or element (or gives the correct
//! result). The in-process side is `tests/host/robustness/results.rs`.

use crate::common::{build_cube, build_cube_table, build_table, palpate, reference, temp, text};
use std::path::{Path, PathBuf};
use std::process::Output;

/// [`crate::common::assert_one_line_error`] (exit 2, stderr ending with its only
/// `error: …` line, containing every needle, no panic; `tables build`
/// prints its size estimate on stderr before it starts), and besides:
/// `error:` nowhere else on stderr, nothing on stdout.
fn assert_one_line_error(out: &Output, needles: &[&str]) {
    crate::common::assert_one_line_error(out, needles);
    let stderr = text(&out.stderr);
    assert_eq!(stderr.matches("error:").count(), 1, "{stderr}");
    assert!(out.stdout.is_empty(), "{}", text(&out.stdout));
}

/// `tables build` of the reference cube (base fixed) with Young's modulus
/// `young` and `extra` arguments into `temp(name)`: the run and that path.
fn build(name: &str, young: &str, extra: &[&str]) -> (Output, PathBuf) {
    let table = temp(name);
    (build_cube(&table, young, extra), table)
}

/// The reference cube's table built (E = 5000 Pa) with `extra` arguments:
/// its path.
fn built(name: &str, extra: &[&str]) -> String {
    let table = temp(name);
    build_cube_table(&table, extra);
    table.display().to_string()
}

#[test]
fn an_f32_table_out_of_range_is_refused_before_it_is_written() {
    for young in ["1e300", "1e-300"] {
        let (out, table) = build(&format!("cube-{young}.tbl"), young, &[]);
        assert_one_line_error(
            &out,
            &[
                "cube.msh",
                "load check",
                "overflow or underflow f32",
                "--precision f64",
            ],
        );
        assert!(!table.exists(), "no table written for E = {young}");
        let (out, _) = build(
            &format!("cube-tm-{young}.tbl"),
            young,
            &["--kind", "tensor-mass", "--density", "1000"],
        );
        assert_one_line_error(&out, &["cube.msh", "--precision f64"]);
    }
}

#[test]
fn info_reports_a_tensor_mass_table() {
    let table = built(
        "cube-tm.tbl",
        &["--kind", "tensor-mass", "--density", "1000"],
    );
    let out = palpate(&["tables", "info", &table]);
    let stdout = text(&out.stdout);
    assert!(out.status.success(), "{}{stdout}", text(&out.stderr));
    for needle in [
        "table kind: tensor-mass (dynamic)",
        "edges: ",
        "density: 1000 kg/m3",
        "checksum: ok",
        "validation: ok",
    ] {
        assert!(stdout.contains(needle), "{needle}: {stdout}");
    }
}

/// `tables info` on headers crafted so that the section sizes overflow (a
/// scalar size of 2²⁹ bytes, 2³²−1 touchable vertices): the report says
/// the table failed validation, exit 2, never a panic on the arithmetic.
#[test]
fn info_on_a_crafted_header_reports_instead_of_panicking() {
    let table = built("cube-crafted.tbl", &[]);
    let good = std::fs::read(&table).expect("table");
    // RawHeader offsets: scalar size at 16, touchable count at 40 (u32).
    for (offset, value) in [(16usize, 0x2000_0000u32), (40, u32::MAX)] {
        let mut bytes = good.clone();
        bytes[offset..offset + 4].copy_from_slice(&value.to_le_bytes());
        let crafted = temp(&format!("crafted-{offset}.tbl"));
        std::fs::write(&crafted, &bytes).expect("write");
        let out = palpate(&["tables", "info", crafted.to_str().expect("utf-8")]);
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "offset {offset}: {err}");
        assert!(!err.contains("panicked"), "offset {offset}: {err}");
        assert!(err.contains("failed validation"), "offset {offset}: {err}");
    }
}

#[test]
fn solve_refuses_contacts_off_the_surface_triangles() {
    let table = built("cube-bary.tbl", &[]);
    for (bary, needle) in [
        (
            "194,194,201@0.2,0.3,0.5:0,0,-0.002",
            "vertex 194 appears twice",
        ),
        (
            "194,195,200@0.2,0.3,0.5:0,0,-0.002",
            "vertices 194,195,200 are not a triangle",
        ),
    ] {
        let out = palpate(&[
            "precomputed",
            "solve",
            &table,
            "--contact-bary",
            bary,
            "--json",
        ]);
        assert_one_line_error(&out, &["contact 0", needle]);
    }
    let out = palpate(&[
        "precomputed",
        "solve",
        &table,
        "--contact-bary",
        "201,194,195@0.2,0.3,0.5:0,0,-0.002",
        "--json",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
}

/// One line `x,y,z` per vertex of the reference cube, scaled by `scale`.
fn deformed_csv(name: &str, scale: f64, drop_last: bool) -> String {
    let mesh = palpate::mesh::read_mesh(Path::new(&reference("meshes/cube.msh"))).unwrap();
    let mut lines: Vec<String> = mesh
        .0
        .positions
        .iter()
        .map(|p| format!("{:e},{:e},{:e}", p[0] * scale, p[1] * scale, p[2] * scale))
        .collect();
    if drop_last {
        lines.pop();
    }
    let path = temp(name);
    std::fs::write(&path, lines.join("\n") + "\n").unwrap();
    path.display().to_string()
}

#[test]
fn stvk_forces_refuses_non_finite_results_and_names_the_csv() {
    let mesh = reference("meshes/cube.msh");
    let stvk = |csv: &str| {
        palpate(&[
            "stvk",
            "forces",
            &mesh,
            "--young",
            "5000",
            "--poisson",
            "0.45",
            "--deformed",
            csv,
            "--json",
        ])
    };
    let huge = deformed_csv("huge.csv", 1e200, false);
    assert_one_line_error(&stvk(&huge), &["huge.csv", "non-finite"]);
    let short = deformed_csv("short.csv", 1.0, true);
    let out = stvk(&short);
    assert_one_line_error(&out, &["short.csv: 215 lines", "216 vertices"]);
    let rest = deformed_csv("rest.csv", 1.0, false);
    let out = stvk(&rest);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(!text(&out.stdout).contains("null"));
}

#[test]
fn critical_dt_without_a_critical_step_is_an_error() {
    let mesh = reference("meshes/cube.msh");
    let critical = |young: &str, fix: &str| {
        palpate(&[
            "dynamic",
            "critical-dt",
            &mesh,
            "--young",
            young,
            "--poisson",
            "0.45",
            "--density",
            "1000",
            "--damping",
            "2",
            "--fix",
            fix,
            "--integrator",
            "symplectic",
            "--json",
        ])
    };
    assert_one_line_error(
        &critical("5000", "z>-1"),
        &["cube.msh", "every vertex is fixed"],
    );
    assert_one_line_error(&critical("1e300", "z<0.001"), &["cube.msh", "SI units"]);
}

#[test]
fn replay_errors_name_the_file() {
    let table = built("cube-replay.tbl", &[]);
    let sequence = temp("bad-sequence.txt");
    std::fs::write(&sequence, "194:0,0,-0.001\n194:0,0\n").unwrap();
    let sequence = sequence.display().to_string();
    let out = palpate(&["precomputed", "replay", &table, &sequence]);
    assert_one_line_error(&out, &["bad-sequence.txt: sequence line 2"]);
    let table64 = built("cube-replay64.tbl", &["--precision", "f64"]);
    let good = temp("good-sequence.txt");
    std::fs::write(&good, "194:0,0,-0.001\n").unwrap();
    let out = palpate(&[
        "precomputed",
        "replay",
        &table64,
        &good.display().to_string(),
    ]);
    assert_one_line_error(&out, &["cube-replay64.tbl: ", "--precision f32"]);
}

#[test]
fn a_safety_limit_beyond_f32_names_its_key() {
    let scene = temp("huge-force.toml");
    std::fs::write(
        &scene,
        "fix = [\"z<0.001\"]\n[generated]\nbox_m = [0.1, 0.1, 0.05]\ncells = [2, 2, 1]\n\
         [material]\nyoung_pa = 3000.0\npoisson = 0.45\n[safety]\nmax_force_n = 1e300\n",
    )
    .unwrap();
    let out_csv = temp("huge-force-out.csv").display().to_string();
    let out = palpate(&[
        "session",
        "run",
        &scene.display().to_string(),
        "--trajectory",
        "/nonexistent-trajectory.csv",
        "--out",
        &out_csv,
    ]);
    assert_one_line_error(
        &out,
        &["huge-force.toml", "[safety] max_force_n = 1e300", "f32"],
    );
}

#[test]
fn negative_material_values_get_the_physics_message() {
    let (out, _) = build("cube-negative.tbl", "-3000", &[]);
    assert_one_line_error(
        &out,
        &["Young's modulus must be finite and > 0 Pa, got -3000"],
    );
    let table = temp("cube-negative-nu.tbl").display().to_string();
    let mesh = reference("meshes/cube.msh");
    let out = palpate(&[
        "tables",
        "build",
        &mesh,
        "--young",
        "5000",
        "--poisson",
        "-0.1",
        "--fix",
        "z<0.001",
        "--quiet",
        "-o",
        &table,
    ]);
    assert_one_line_error(
        &out,
        &["Poisson ratio must satisfy 0 <= nu <= 0.4999", "got -0.1"],
    );
}

#[test]
fn an_msh_node_id_of_zero_is_named_as_written() {
    let msh = temp("zero-node.msh");
    std::fs::write(
        &msh,
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n\
         4 0 0 1\n$EndNodes\n$Elements\n1\n7 4 2 1 1 1 2 0 4\n$EndElements\n",
    )
    .unwrap();
    let table = temp("zero-node.tbl").display().to_string();
    let out = build_table(&msh.display().to_string(), &table, "5000", &[]);
    assert_one_line_error(
        &out,
        &["zero-node.msh", "element id 7", "node id 0 is not defined"],
    );
}

/// A probe whose first sample is 5 mm inside the built-in block's top
/// (2.5 radii: deeper than the penetration test looks) and stays there
/// for 0.4 s once ran 401 ticks with 0 contacts, zero force and every
/// status `ok`: the tool was inside, silently. Now every tick says
/// `tool-inside` (zero force: the probe adds none) and the run's summary
/// counts them.
#[test]
fn a_probe_starting_inside_the_block_is_reported_not_silent() {
    let trajectory = temp("inside.csv");
    std::fs::write(
        &trajectory,
        "t,tool,x,y,z\n0,0,0.06,0.06,0.055\n0.4,0,0.06,0.06,0.055\n",
    )
    .unwrap();
    let forces = temp("inside-forces.csv");
    let out = palpate(&[
        "session",
        "run",
        "built-in",
        "--trajectory",
        trajectory.to_str().unwrap(),
        "--out",
        forces.to_str().unwrap(),
    ]);
    let stderr = text(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("401 ticks with a tool point inside the body"),
        "{stderr}"
    );
    let csv = std::fs::read_to_string(&forces).unwrap();
    let rows: Vec<Vec<&str>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), 401);
    for r in &rows {
        assert_eq!(r[1..6], ["0", "0", "0", "0", "tool-inside"], "{r:?}");
    }
}

/// The cube's mesh with its second half of tets in region 2 (MSH 2.2
/// physical tag), written to `dir/regions.msh`.
fn cube_with_two_regions(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(reference("meshes/cube.msh")).expect("cube");
    let mut elements = false;
    let lines: Vec<String> = text
        .lines()
        .map(|line| {
            match line {
                "$Elements" => elements = true,
                "$EndElements" => elements = false,
                _ => {}
            }
            let mut words: Vec<&str> = line.split_whitespace().collect();
            let second_half = words.first().and_then(|w| w.parse::<usize>().ok()) > Some(375);
            if elements && words.len() > 5 && second_half {
                words[3] = "2";
            }
            words.join(" ")
        })
        .collect();
    let mesh = dir.join("regions.msh");
    std::fs::write(&mesh, lines.join("\n") + "\n").expect("mesh");
    mesh
}

/// Messages name what to change, in one bounded line: a `[[region]]`'s
/// out-of-range E names the region and its key (it once named
/// `[material]`'s E), in at most a few hundred bytes (a value printed
/// without exponent was 300 digits); ν too near 0.5 is refused at parse
/// with the range (it once ran into "contact system singular"); a
/// non-finite `--gravity` says "finite"; a negative `--dt`, `--damping` or
/// `--drop-below` is one line (it was clap's seven); `--work-dir` a file
/// says so (not "File exists (os error 17)"); the VTK estimate names the
/// user's folder (not the hidden temporary one); a pre-computed scene with
/// a floating piece says which, as `scene plan` does (not the Cholesky
/// pivot); `remap fit` past the sample's collapse says what to lower.
#[test]
fn messages_name_what_to_change_in_one_bounded_line() {
    let dir = temp("messages");
    std::fs::create_dir_all(&dir).expect("folder");
    let d = |name: &str| dir.join(name).display().to_string();
    let poke = d("poke.csv");
    let out = palpate(&["session", "generate", "poke", "-o", &poke]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let session = |scene: &str, extra: &[&str]| {
        let mut args = vec!["session", "run", scene, "--trajectory", &poke];
        args.extend_from_slice(extra);
        palpate(&args)
    };

    cube_with_two_regions(&dir);
    for (young, shown) in [("1e300", "1e300"), ("1e-300", "1e-300")] {
        let scene = d("regions.toml");
        std::fs::write(
            &scene,
            format!(
                "mesh = \"regions.msh\"\nfix = [\"z<0.001\"]\n[material]\nyoung_pa = 3000.0\n\
                 poisson = 0.45\n[[region]]\nid = 2\nyoung_pa = {young}\npoisson = 0.45\n"
            ),
        )
        .expect("scene");
        let out = session(&scene, &["--out", &d("forces.csv")]);
        assert_one_line_error(
            &out,
            &[
                &format!("[[region]] id = 2: young_pa = {shown}: "),
                "at most 1e8 times",
            ],
        );
        assert!(out.stderr.len() < 400, "{}", text(&out.stderr));
    }

    let mesh = reference("meshes/cube.msh");
    let out = palpate(&[
        "tables",
        "build",
        &mesh,
        "--young",
        "5000",
        "--poisson",
        "0.49999999",
        "--fix",
        "z<0.001",
        "-o",
        &d("nu.tbl"),
    ]);
    assert_one_line_error(&out, &["0 <= nu <= 0.4999", "got 0.49999999"]);

    let dynamic = |extra: &[&str]| {
        let mut args = vec![
            "dynamic",
            "run",
            &mesh,
            "--young",
            "5000",
            "--poisson",
            "0.45",
            "--density",
            "1000",
            "--fix",
            "z<0.001",
            "--integrator",
            "symplectic",
            "--steps",
            "2",
            "--json",
        ];
        args.extend_from_slice(extra);
        palpate(&args)
    };
    let out = dynamic(&["--damping", "1", "--dt", "1e-4", "--gravity", "nan,0,0"]);
    crate::common::assert_one_line_error(&out, &["--gravity", "finite number"]);
    for (extra, needle) in [
        (
            ["--damping", "1", "--dt", "-1"],
            "'-1' for '--dt <DT>': must be finite and > 0",
        ),
        (
            ["--damping", "-1", "--dt", "1e-4"],
            "'-1' for '--damping <DAMPING>': must be finite and >= 0",
        ),
    ] {
        let out = dynamic(&extra);
        crate::common::assert_one_line_error(&out, &[needle]);
        assert!(
            text(&out.stderr).lines().count() <= 3,
            "{}",
            text(&out.stderr)
        );
    }
    let out = build_table(
        &mesh,
        &d("c.tbl"),
        "5000",
        &["--compress", "f16", "--drop-below", "-0.5"],
    );
    crate::common::assert_one_line_error(
        &out,
        &["'--drop-below <REL>': must be a fraction in [0, 1)"],
    );
    assert!(
        text(&out.stderr).lines().count() <= 3,
        "{}",
        text(&out.stderr)
    );

    let file = d("a-file");
    std::fs::write(&file, "keep\n").expect("file");
    let out = palpate(&["budget", "built-in", "--work-dir", &file]);
    assert_one_line_error(&out, &["--work-dir", "is a file, not a folder"]);
    assert!(
        !text(&out.stderr).contains("os error"),
        "{}",
        text(&out.stderr)
    );

    let long = d("long.csv");
    std::fs::write(
        &long,
        "t,tool,x,y,z\n0,0,0.06,0.06,0.1\n3000,0,0.06,0.06,0.1\n",
    )
    .expect("csv");
    let vtk = d("my-series");
    let out = palpate(&[
        "session",
        "run",
        "built-in-dynamic",
        "--trajectory",
        &long,
        "--out",
        &d("f.csv"),
        "--vtk",
        &vtk,
    ]);
    assert_one_line_error(&out, &[&format!("--vtk {vtk}: "), "8 GiB limit"]);
    assert!(
        !text(&out.stderr).contains("palpate-tmp"),
        "{}",
        text(&out.stderr)
    );

    // Two tets, one on the support, one apart from it: the second floats.
    std::fs::write(
        dir.join("two.node"),
        "8 3 0 0\n0 0 0 0\n1 0.01 0 0\n2 0 0.01 0\n3 0 0 0.01\n\
         4 0.05 0.05 0.05\n5 0.06 0.05 0.05\n6 0.05 0.06 0.05\n7 0.05 0.05 0.06\n",
    )
    .expect("node");
    std::fs::write(dir.join("two.ele"), "2 4 0\n0 0 1 2 3\n1 4 5 6 7\n").expect("ele");
    let floating = d("floating.toml");
    std::fs::write(
        &floating,
        "mesh = \"two.node\"\nfix = [\"z<0.001\"]\n[material]\nyoung_pa = 3000.0\npoisson = 0.45\n",
    )
    .expect("scene");
    let plan = palpate(&["scene", "plan", &floating]);
    let out = session(&floating, &["--out", &d("f.csv")]);
    assert_one_line_error(
        &out,
        &["piece 2 of 2 of the pre-computed region", "it floats"],
    );
    assert_eq!(
        text(&out.stderr),
        text(&plan.stderr),
        "the same words as scene plan"
    );

    let out = palpate(&[
        "remap",
        "fit",
        "--young",
        "3000",
        "--poisson",
        "0.45",
        "--max-strain",
        "0.4",
        "--out",
        &d("fit.json"),
    ]);
    assert_one_line_error(&out, &["lower --max-strain to 0.250", "--curves"]);
    let out = palpate(&[
        "remap",
        "fit",
        "--young",
        "3000",
        "--poisson",
        "0.45",
        "--out",
        &d("fit.json"),
    ]);
    assert!(
        out.status.success(),
        "the defaults converge: {}",
        text(&out.stderr)
    );
    std::fs::remove_dir_all(&dir).ok();
}
