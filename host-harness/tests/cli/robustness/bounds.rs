//! Robustness, bounded runs and inputs: the probes that need the `palpate`
//! binary (the in-process ones are `tests/host/robustness/bounds.rs`). Each
//! once grew without bound or aborted; each now exits 2 with one line, fast.

use crate::common::{
    assert_one_line_error, build_cube, build_cube_table, build_table, fresh_dir, palpate,
    palpate_with_stdin, reference, stderr, temp,
};
use core::time::Duration;
use std::process::Command;
use std::time::Instant;

/// How soon a refusal "before any work" must come, as in the in-process
/// probes (`tests/host/robustness/bounds.rs`): the refusals below take well
/// under a second alone, and the work they refuse takes minutes or grows
/// without bound, so a generous bound tells the two apart on a shared,
/// loaded machine (one of these runs took 6.6 s beside the other process
/// tests of this binary and four other builds).
const REFUSED_WITHIN: Duration = Duration::from_secs(10);

/// `precomputed solve /dev/zero` grew to 18.5 GB; `tables info /dev/zero`
/// likewise. The header is read first: refused at once.
#[test]
fn dev_zero_is_not_a_table() {
    let started = Instant::now();
    let out = palpate(&[
        "precomputed",
        "solve",
        "/dev/zero",
        "--contact",
        "194:0,0,-0.01",
        "--json",
    ]);
    assert_one_line_error(&out, &["/dev/zero: not a Palpate table"]);
    let out = palpate(&["tables", "info", "/dev/zero"]);
    assert_one_line_error(&out, &["/dev/zero: not a Palpate table"]);
    assert!(started.elapsed() < REFUSED_WITHIN);
}

/// A table through a pipe (not a regular file: no size to check) is read up
/// to the length its header declares: the exact table solves, one with
/// bytes beyond that length is refused.
#[test]
fn piped_table_is_read_to_its_declared_length() {
    let table = temp("piped.tbl");
    build_cube_table(&table, &[]);
    let table = std::fs::read(table).expect("table");
    let args = [
        "precomputed",
        "solve",
        "/dev/stdin",
        "--contact",
        "194:0,0,-0.01",
        "--json",
    ];
    let out = palpate_with_stdin(&args, &table);
    assert!(out.status.success(), "{}", stderr(&out));
    let mut longer = table.clone();
    longer.extend_from_slice(&[0; 64]);
    let out = palpate_with_stdin(&args, &longer);
    assert_one_line_error(&out, &["longer than the"]);
    let out = palpate_with_stdin(&args, &table[..table.len() / 2]);
    assert_one_line_error(&out, &["truncated"]);
}

/// A trajectory with a row at `t = 1e9` ran 10¹² ticks (670 MB of output in
/// a minute); `t = 1e300` printed "0 ticks" with exit 0; `haptic_hz = 1e7`
/// was accepted. Each is refused before the run, naming the line or key.
#[test]
fn session_run_refuses_unbounded_trajectories_and_rates() {
    let far = temp("far.csv");
    std::fs::write(
        &far,
        "t,tool,x,y,z\n0,0,0.06,0.06,0.07\n1e9,0,0.06,0.06,0.07\n",
    )
    .expect("csv");
    let huge = temp("huge.csv");
    std::fs::write(
        &huge,
        "t,tool,x,y,z\n0,0,0.06,0.06,0.07\n1e300,0,0.06,0.06,0.07\n",
    )
    .expect("csv");
    let out_csv = temp("far-out.csv");
    let out_csv = out_csv.display().to_string();
    for (trajectory, needle) in [
        (
            &far,
            "line 3: time 1000000000 s is 1000000000 s from line 2 at 0 s",
        ),
        (&huge, "line 3: time 1e300 s is out of range"),
    ] {
        let started = Instant::now();
        let out = palpate(&[
            "session",
            "run",
            "built-in",
            "--trajectory",
            &trajectory.display().to_string(),
            "--out",
            &out_csv,
        ]);
        assert_one_line_error(&out, &[needle]);
        assert!(started.elapsed() < REFUSED_WITHIN);
    }
    let scene = temp("fast.toml");
    std::fs::write(
        &scene,
        "generated = { box = [0.1, 0.1, 0.05], cells = [2, 2, 1] }\nfix = [\"z<0.001\"]\n\
         material = { young_pa = 3000, poisson = 0.45 }\nrates = { haptic_hz = 1e7 }\n",
    )
    .expect("scene");
    let poke = temp("poke.csv");
    std::fs::write(&poke, "t,tool,x,y,z\n0,0,0.05,0.05,0.06\n").expect("csv");
    let out = palpate(&[
        "session",
        "run",
        &scene.display().to_string(),
        "--trajectory",
        &poke.display().to_string(),
        "--out",
        &out_csv,
    ]);
    assert_one_line_error(
        &out,
        &["[rates] haptic_hz = 10000000: above 10000 Hz (MAX_HAPTIC_HZ)"],
    );
}

/// `tables build` prints its estimate before building and refuses a table
/// above `--max-table-bytes`, leaving no output.
#[test]
fn tables_build_prints_the_estimate_and_honours_max_table_bytes() {
    let table = temp("limited.tbl");
    let _ = std::fs::remove_file(&table);
    let out = build_cube(&table, "5000", &[]);
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(
        err.contains("estimate: the pre-computed table (14210 compliance blocks: 180 free x 116 touchable vertices, f32) would be"),
        "{err}"
    );
    let built = std::fs::metadata(&table).expect("table").len();
    std::fs::remove_file(&table).expect("remove");
    let out = build_cube(&table, "5000", &["--max-table-bytes", "100000"]);
    assert_one_line_error(&out, &["the table is above --max-table-bytes 100000 bytes"]);
    assert!(!table.exists(), "no table written");
    // At the real size plus the estimate's slack (`palpate::table::estimate`) it builds (152
    // surface vertices, 300 surface triangles).
    let limit = (built + 2080 * 152 + 1372 * 300 + 32).to_string();
    let out = build_cube(&table, "5000", &["--max-table-bytes", &limit]);
    assert!(out.status.success(), "{}", stderr(&out));
}

/// A 40³-cell generated box (68 921 vertices, under the scene cap) aborted
/// `session run` with "memory allocation of 33 830 337 528 bytes failed"
/// (exit 134). Now refused from the estimate, fast and under a 4 GiB
/// address-space limit (`ulimit -v`): the table is never allocated. So is
/// `budget` on that scene.
#[test]
fn generated_scene_too_large_for_a_table_is_refused_without_allocating() {
    let scene = temp("box40.toml");
    std::fs::write(
        &scene,
        "generated = { box = [0.4, 0.4, 0.4], cells = [40, 40, 40] }\nfix = [\"z<0.001\"]\n\
         material = { young_pa = 3000, poisson = 0.45 }\n",
    )
    .expect("scene");
    let poke = temp("poke40.csv");
    std::fs::write(&poke, "t,tool,x,y,z\n0,0,0.2,0.2,0.5\n0.01,0,0.2,0.2,0.5\n").expect("csv");
    let out_csv = temp("box40-out.csv");
    let command = format!(
        "ulimit -v 4194304 && exec '{}' session run '{}' --trajectory '{}' --out '{}'",
        env!("CARGO_BIN_EXE_palpate"),
        scene.display(),
        poke.display(),
        out_csv.display()
    );
    let started = Instant::now();
    let out = Command::new("sh")
        .args(["-c", &command])
        .output()
        .expect("run sh");
    let elapsed = started.elapsed();
    assert_one_line_error(
        &out,
        &[
            "the pre-computed table (501240880 compliance blocks: 67240 free x 7921 touchable vertices, f32) would be 18.1 GB",
        ],
    );
    assert!(stderr(&out).contains("tensor-mass"), "{}", stderr(&out));
    assert!(elapsed < REFUSED_WITHIN, "{elapsed:?}");
    // `budget` checks every size it measures (here 20³ and 40³ cells) before
    // building the first.
    let started = Instant::now();
    let out = palpate(&[
        "budget",
        &scene.display().to_string(),
        "--work-dir",
        &temp("budget40").display().to_string(),
    ]);
    assert_one_line_error(&out, &["would be 18.1 GB"]);
    assert!(started.elapsed() < REFUSED_WITHIN);
}

/// The same 40³-cell box as a TetGen mesh file: `tables build` aborted with
/// the 33.8 GB allocation; now it prints nothing but one line with the
/// estimate and exits 2 (under a 4 GiB address-space limit).
#[test]
fn tables_build_of_a_40_cubed_box_is_refused_without_allocating() {
    use core::fmt::Write as _;
    let mesh = palpate::mesh::generate::box_mesh([40, 40, 40], [0.4, 0.4, 0.4]);
    let mut node = format!("{} 3 0 0\n", mesh.positions.len());
    for (i, [x, y, z]) in mesh.positions.iter().enumerate() {
        let _ = writeln!(node, "{i} {x} {y} {z}");
    }
    let mut ele = format!("{} 4 0\n", mesh.tets.len());
    for (i, [a, b, c, d]) in mesh.tets.iter().enumerate() {
        let _ = writeln!(ele, "{i} {a} {b} {c} {d}");
    }
    let base = temp("box40");
    std::fs::write(base.with_extension("node"), node).expect("node");
    std::fs::write(base.with_extension("ele"), ele).expect("ele");
    let table = temp("box40.tbl");
    let command = format!(
        "ulimit -v 4194304 && exec '{}' tables build '{}' --young 3000 --poisson 0.45 --fix 'z<0.001' -o '{}'",
        env!("CARGO_BIN_EXE_palpate"),
        base.with_extension("node").display(),
        table.display()
    );
    let started = Instant::now();
    let out = Command::new("sh")
        .args(["-c", &command])
        .output()
        .expect("run sh");
    assert_one_line_error(
        &out,
        &[
            "box40.node: the pre-computed table (501240880 compliance blocks: 67240 free x 7921 touchable vertices, f32) would be 18.1 GB",
        ],
    );
    assert!(started.elapsed() < REFUSED_WITHIN);
    assert!(!table.exists());
}

/// A mesh file above the limit is refused from its size, before reading (a
/// sparse file: no disk used).
#[test]
fn oversized_mesh_file_is_refused_before_reading() {
    let mesh = temp("big.msh");
    let file = std::fs::File::create(&mesh).expect("create");
    file.set_len((2 << 30) + 1).expect("sparse file");
    drop(file);
    let out = build_table(
        &mesh.display().to_string(),
        &temp("big.tbl").display().to_string(),
        "5000",
        &[],
    );
    assert_one_line_error(&out, &["the limit for a mesh file (MAX_MESH_FILE_BYTES)"]);
    std::fs::remove_file(&mesh).expect("remove");
}

/// The other inputs read whole are bounded the same way (sparse files just
/// over each limit): a trajectory (1 GiB), a scene (1 MiB), a contact
/// sequence (256 MiB).
#[test]
fn oversized_trajectory_scene_and_sequence_files_are_refused() {
    let sparse = |name: &str, len: u64| {
        let path = temp(name);
        let file = std::fs::File::create(&path).expect("create");
        file.set_len(len).expect("sparse file");
        path.display().to_string()
    };
    let trajectory = sparse("big.csv", (1 << 30) + 1);
    let scene = sparse("big.toml", (1 << 20) + 1);
    let sequence = sparse("big.seq", (256 << 20) + 1);
    let out_csv = temp("big-out.csv").display().to_string();
    let out = palpate(&[
        "session",
        "run",
        "built-in",
        "--trajectory",
        &trajectory,
        "--out",
        &out_csv,
    ]);
    assert_one_line_error(
        &out,
        &["the limit for a trajectory file (MAX_TRAJECTORY_FILE_BYTES)"],
    );
    let out = palpate(&[
        "session",
        "run",
        &scene,
        "--trajectory",
        &trajectory,
        "--out",
        &out_csv,
    ]);
    assert_one_line_error(&out, &["the limit for a scene file (MAX_SCENE_FILE_BYTES)"]);
    let table = temp("seq.tbl");
    build_cube_table(&table, &[]);
    let table = table.display().to_string();
    let out = palpate(&["precomputed", "replay", &table, &sequence]);
    assert_one_line_error(
        &out,
        &["the limit for a sequence file (MAX_SEQUENCE_FILE_BYTES)"],
    );
    for path in [trajectory, scene, sequence] {
        std::fs::remove_file(path).expect("remove");
    }
}

/// `session run --vtk` on a trajectory whose series would exceed
/// `MAX_VTK_SERIES_BYTES` (a minute of the built-in block with a frame
/// every 1 ms tick: about 60 000 frames of up to 0.43 MB, 26 GB) is refused
/// before the table build, naming `--vtk` and the remedy; nothing is written.
#[test]
fn a_vtk_series_too_large_is_refused_before_the_run() {
    let dir = temp("vtk-too-large");
    std::fs::create_dir_all(&dir).expect("dir");
    let trajectory = dir.join("minute.csv");
    std::fs::write(
        &trajectory,
        "t,tool,x,y,z\n0,0,0.06,0.06,0.1\n60,0,0.06,0.06,0.1\n",
    )
    .expect("trajectory");
    let (out_csv, series) = (dir.join("forces.csv"), dir.join("series"));
    let start = Instant::now();
    let out = palpate(&[
        "session",
        "run",
        "built-in",
        "--trajectory",
        trajectory.to_str().expect("utf-8"),
        "--out",
        out_csv.to_str().expect("utf-8"),
        "--vtk",
        series.to_str().expect("utf-8"),
    ]);
    assert_one_line_error(&out, &["--vtk", "physics_every", "GiB limit"]);
    assert!(
        start.elapsed() < Duration::from_secs(20),
        "{:?}",
        start.elapsed()
    );
    assert!(!out_csv.exists() && !series.exists());
    std::fs::remove_dir_all(&dir).ok();
}

/// A 40³-cell box (68 921 vertices) with a 1-cm dynamic zone.
const BIG_HYBRID: &str = "fix = [\"z<0.001\"]\n[generated]\nbox_m = [0.4, 0.4, 0.4]\n\
    cells = [40, 40, 40]\n[material]\nyoung_pa = 3000.0\npoisson = 0.45\n[model]\n\
    kind = \"dynamic\"\ndamping_per_s = 0\n[[zone]]\nkind = \"cut\"\nshape = \"box\"\nmin_m = [0.0, 0.0, 0.39]\n\
    max_m = [0.01, 0.01, 0.4]\n[partition]\nmargin_rings = 0\n";

/// That scene aborted `scene tables`, `dynamic run --scene` and `dynamic
/// critical-dt --scene` on a 32 GB allocation (exit 134), and `scene plan`
/// printed its 18 GB table with exit 0 without saying a session refuses it.
/// Now each command refuses it before building, with the estimate; the plan
/// marks the table refused, in text and in JSON.
#[test]
fn a_hybrid_too_large_is_refused_before_building_and_marked_by_plan() {
    let dir = fresh_dir("big-hybrid");
    let scene = dir.join("big.toml");
    std::fs::write(&scene, BIG_HYBRID).expect("scene");
    let scene = scene.to_str().expect("path");
    let out_dir = dir.join("tables");
    let out = palpate(&[
        "scene",
        "tables",
        scene,
        "--out-dir",
        out_dir.to_str().expect("path"),
    ]);
    assert_one_line_error(
        &out,
        &[
            "pre-computed region",
            "MAX_TABLE_FILE_BYTES",
            "refused before building",
        ],
    );
    assert!(!out_dir.exists());
    let out = palpate(&[
        "dynamic",
        "run",
        "--scene",
        scene,
        "--damping",
        "0",
        "--integrator",
        "symplectic",
        "--dt",
        "1e-4",
        "--steps",
        "1",
        "--json",
    ]);
    assert_one_line_error(&out, &["MAX_TABLE_FILE_BYTES", "refused before building"]);
    let out = palpate(&[
        "dynamic",
        "critical-dt",
        "--scene",
        scene,
        "--damping",
        "0",
        "--integrator",
        "symplectic",
        "--json",
    ]);
    assert_one_line_error(&out, &["MAX_RUN_TET_STEPS", "refused before starting"]);

    let out = palpate(&["scene", "plan", scene, "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let plan: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    let refused = plan["regions"][0]["refused"].as_str().expect("refused");
    assert!(refused.contains("MAX_TABLE_FILE_BYTES"), "{refused}");
    assert!(plan["regions"][0]["table_bytes"].as_u64().expect("bytes") > 4 << 30);
    assert!(plan["regions"][1]["refused"].is_null());
    let out = palpate(&["scene", "plan", scene]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(String::from_utf8_lossy(&out.stdout).contains("REFUSED"));
    std::fs::remove_dir_all(&dir).ok();
}

/// `dynamic run --steps 18446744073709551615` was accepted; `stvk forces
/// --deformed /dev/zero` grew to 23 GB. Both are refused at once.
#[test]
fn unbounded_steps_and_positions_are_refused() {
    let cube = reference("meshes/cube.msh");
    let out = palpate(&[
        "dynamic",
        "run",
        &cube,
        "--young",
        "5000",
        "--poisson",
        "0.45",
        "--density",
        "1000",
        "--fix",
        "z<0.001",
        "--damping",
        "0",
        "--integrator",
        "symplectic",
        "--dt",
        "1e-4",
        "--steps",
        "18446744073709551615",
        "--json",
    ]);
    assert_one_line_error(&out, &["dynamic run", "MAX_RUN_TET_STEPS"]);
    let out = palpate(&[
        "stvk",
        "forces",
        &cube,
        "--young",
        "5000",
        "--poisson",
        "0.45",
        "--deformed",
        "/dev/zero",
        "--json",
    ]);
    assert_one_line_error(&out, &["/dev/zero", "MAX_POSITION_LINE_BYTES"]);
}
