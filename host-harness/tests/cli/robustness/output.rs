//! Robustness, output safety, through the binary: a run killed while writing
//! leaves the previous output byte-identical; a failed run leaves it too;
//! an output that is an input is refused; a closed standard output is a
//! normal end (exit 0, nothing on stderr) and a full one a one-line error
//! (exit 2), never a panic. The in-process probes are in
//! `tests/host/robustness/output.rs`.

use crate::common::{
    assert_one_line_error, build_cube_table, build_table, fresh_dir, palpate, palpate_command,
    reference, stderr,
};
use core::time::Duration;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Stdio};
use std::time::Instant;

/// `path` as a `&str` argument (a `String` or a `Path`).
fn s<P: AsRef<Path> + ?Sized>(path: &P) -> &str {
    path.as_ref().to_str().expect("utf-8 path")
}

/// The temporary files palpate leaves in `dir` (only a killed run may).
fn temporaries(dir: &Path) -> Vec<PathBuf> {
    std::fs::read_dir(dir)
        .expect("read test folder")
        .map(|e| e.expect("entry").path())
        .filter(|p| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy().contains(".palpate-tmp."))
        })
        .collect()
}

/// Kills `child` (if still running) and reaps it.
fn kill(mut child: Child) {
    let _ = child.kill();
    let _ = child.wait();
}

/// `session run --out` over previous results, killed once the run has
/// written into its output (its temporary file holds bytes): the previous
/// CSV is byte-identical. The old `File::create` truncated it at the start.
/// The run is 100 s of trajectory on the dynamic block (about ten seconds
/// or more of physics); the first 64 KiB reach the temporary file within
/// the first few seconds of trajectory, so the kill comes long before the
/// end. The poll waits up to two minutes.
#[test]
fn a_killed_session_run_leaves_the_previous_csv() {
    let dir = fresh_dir("killed-session");
    let trajectory = dir.join("still.csv");
    // The probe held above the block: no contact, every tick a CSV line.
    std::fs::write(
        &trajectory,
        "t,tool,x,y,z\n0,0,0.06,0.06,0.1\n100,0,0.06,0.06,0.1\n",
    )
    .expect("trajectory");
    let csv = dir.join("forces.csv");
    let old = b"t,fx,fy,fz,contacts,status\n0,0.1,0.2,0.3,1,ok\n".to_vec();
    std::fs::write(&csv, &old).expect("previous results");

    let mut child = palpate_command(&[
        "session",
        "run",
        "built-in-dynamic",
        "--trajectory",
        s(&trajectory),
        "--out",
        s(&csv),
    ])
    .stdout(Stdio::null())
    .stderr(Stdio::null())
    .spawn()
    .expect("spawn palpate");
    let started = Instant::now();
    let writing = loop {
        let written = temporaries(&dir)
            .iter()
            .any(|t| std::fs::metadata(t).is_ok_and(|m| m.len() > 0));
        if written {
            break true;
        }
        if started.elapsed() > Duration::from_secs(120) || child.try_wait().ok().flatten().is_some()
        {
            break false;
        }
        std::thread::sleep(Duration::from_millis(2));
    };
    let status = child.try_wait().ok().flatten();
    kill(child);
    assert!(
        writing,
        "no temporary output with bytes seen (exited: {status:?})"
    );
    assert_eq!(std::fs::read(&csv).expect("csv"), old, "byte-identical");
    std::fs::remove_dir_all(&dir).ok();
}

/// A failed run keeps the previous output, through the binary:
/// `session run` whose scene's mesh is missing (the first robustness probe),
/// and `tables build` over a good table whose `--fix` matches no vertex
/// (the output was opened before the mesh was read). Nothing is left
/// beside them.
#[test]
fn a_failed_run_keeps_the_previous_output() {
    let dir = fresh_dir("failed-run");
    let scene = dir.join("scene.toml");
    std::fs::write(
        &scene,
        "mesh = \"missing.msh\"\nfix = [\"z<0.0001\"]\n[material]\nyoung_pa = 3000.0\npoisson = 0.45\n",
    )
    .expect("scene");
    let trajectory = dir.join("poke.csv");
    let out = palpate(&["session", "generate", "poke", "-o", s(&trajectory)]);
    assert!(out.status.success(), "{out:?}");
    let csv = dir.join("forces.csv");
    let old = b"previous results\n".to_vec();
    std::fs::write(&csv, &old).expect("previous results");
    let out = palpate(&[
        "session",
        "run",
        s(&scene),
        "--trajectory",
        s(&trajectory),
        "--out",
        s(&csv),
    ]);
    assert_one_line_error(&out, &["missing.msh"]);
    assert_eq!(std::fs::read(&csv).expect("csv"), old);

    let table = dir.join("cube.tbl");
    build_cube_table(&table, &[]);
    let good = std::fs::read(&table).expect("table");
    let mesh = reference("meshes/cube.msh");
    let out = palpate(&[
        "tables",
        "build",
        s(&mesh),
        "--young",
        "5000",
        "--poisson",
        "0.45",
        "--fix",
        "z<-1",
        "--quiet",
        "-o",
        s(&table),
    ]);
    assert_one_line_error(&out, &["no vertex matches"]);
    assert_eq!(std::fs::read(&table).expect("table"), good);
    assert_eq!(temporaries(&dir), Vec::<PathBuf>::new());
    std::fs::remove_dir_all(&dir).ok();
}

/// An output that is an input is refused with one line naming both, and
/// the input keeps every byte: `tables build -o` the mesh (and the other
/// file of a TetGen pair), `session run --out` the trajectory or the
/// scene file.
#[test]
fn an_output_that_is_an_input_is_refused() {
    let dir = fresh_dir("output-is-input");
    let mesh = dir.join("cube.msh");
    std::fs::copy(reference("meshes/cube.msh"), &mesh).expect("mesh");
    let node = dir.join("cube.node");
    let ele = dir.join("cube.ele");
    std::fs::copy(reference("meshes/cube.node"), &node).expect("node");
    std::fs::copy(reference("meshes/cube.ele"), &ele).expect("ele");
    let before: Vec<Vec<u8>> = [&mesh, &node, &ele]
        .iter()
        .map(|p| std::fs::read(p).expect("input"))
        .collect();
    for (input, output) in [(&mesh, &mesh), (&node, &ele)] {
        let out = build_table(s(input), s(output), "5000", &[]);
        assert_one_line_error(
            &out,
            &[&format!(
                "-o {} is the same file as the mesh {}",
                s(output),
                s(output)
            )],
        );
    }
    let after: Vec<Vec<u8>> = [&mesh, &node, &ele]
        .iter()
        .map(|p| std::fs::read(p).expect("input"))
        .collect();
    assert!(before == after, "inputs changed");

    let trajectory = dir.join("poke.csv");
    let out = palpate(&["session", "generate", "poke", "-o", s(&trajectory)]);
    assert!(out.status.success(), "{out:?}");
    let poke = std::fs::read(&trajectory).expect("trajectory");
    let scene = dir.join("scene.toml");
    let scene_text =
        "mesh = \"cube.msh\"\nfix = [\"z<0.001\"]\n[material]\nyoung_pa = 3000.0\npoisson = 0.45\n";
    std::fs::write(&scene, scene_text).expect("scene");
    for (scene_arg, output, needle) in [
        ("built-in", &trajectory, "is the same file as --trajectory"),
        (s(&scene), &scene, "is the same file as the scene"),
        (s(&scene), &mesh, "is the same file as the scene's mesh"),
    ] {
        let out = palpate(&[
            "session",
            "run",
            scene_arg,
            "--trajectory",
            s(&trajectory),
            "--out",
            s(output),
        ]);
        assert_one_line_error(&out, &[needle]);
    }
    assert_eq!(std::fs::read(&trajectory).expect("trajectory"), poke);
    assert_eq!(std::fs::read_to_string(&scene).expect("scene"), scene_text);
    assert_eq!(std::fs::read(&mesh).expect("mesh"), before[0]);
    std::fs::remove_dir_all(&dir).ok();
}

/// `--vtk` onto an existing file, or a folder palpate did not write: a
/// clear one-line error before the run (not "File exists (os error 17)"),
/// and the file or folder untouched.
#[test]
fn a_vtk_path_that_is_a_file_or_a_foreign_folder_is_refused() {
    let dir = fresh_dir("vtk");
    let trajectory = dir.join("poke.csv");
    let out = palpate(&["session", "generate", "poke", "-o", s(&trajectory)]);
    assert!(out.status.success(), "{out:?}");
    let file = dir.join("notes.txt");
    std::fs::write(&file, "keep\n").expect("file");
    let foreign = dir.join("results");
    std::fs::create_dir(&foreign).expect("folder");
    std::fs::write(foreign.join("paper.tex"), "keep\n").expect("file");
    for (vtk, needle) in [
        (&file, "is not a folder"),
        (&foreign, "palpate did not write"),
    ] {
        let out = palpate(&[
            "session",
            "run",
            "built-in",
            "--trajectory",
            s(&trajectory),
            "--out",
            s(&dir.join("forces.csv")),
            "--vtk",
            s(vtk),
        ]);
        assert_one_line_error(&out, &[needle]);
        assert!(!String::from_utf8_lossy(&out.stderr).contains("os error 17"));
    }
    assert_eq!(std::fs::read_to_string(&file).expect("file"), "keep\n");
    assert_eq!(
        std::fs::read_to_string(foreign.join("paper.tex")).expect("file"),
        "keep\n"
    );
    assert!(!dir.join("forces.csv").exists());
    let out = palpate(&["demo", "--out", s(&file)]);
    assert_one_line_error(&out, &["is not a folder"]);
    std::fs::remove_dir_all(&dir).ok();
}

/// The inputs of the standard-output probes: the f32 cube table, a replay
/// sequence of `steps` steps, the deformed positions of the JSON reference.
fn stdout_inputs(dir: &Path, steps: usize) -> (PathBuf, PathBuf, PathBuf) {
    let table = dir.join("cube.tbl");
    build_cube_table(&table, &[]);
    let sequence = dir.join("steps.seq");
    std::fs::write(&sequence, "194:0,0,-0.001\n".repeat(steps)).expect("sequence");
    let text = std::fs::read_to_string(reference("svk/svk_cube.json")).expect("svk");
    let json: serde_json::Value = serde_json::from_str(&text).expect("json");
    let deformed = dir.join("deformed.csv");
    let lines: String = json["configs"][0]["x"]
        .as_array()
        .expect("positions")
        .iter()
        .map(|p| format!("{},{},{}\n", p[0], p[1], p[2]))
        .collect();
    std::fs::write(&deformed, lines).expect("deformed");
    (table, sequence, deformed)
}

/// The commands that print, each with its arguments.
fn printing_commands<'a>(
    table: &'a str,
    sequence: &'a str,
    deformed: &'a str,
    mesh: &'a str,
    demo_out: &'a str,
) -> Vec<Vec<&'a str>> {
    vec![
        vec!["precomputed", "replay", table, sequence],
        vec![
            "precomputed",
            "solve",
            table,
            "--contact",
            "194:0,0,-0.001",
            "--json",
        ],
        vec![
            "stvk",
            "forces",
            mesh,
            "--young",
            "5000",
            "--poisson",
            "0.45",
            "--deformed",
            deformed,
            "--json",
        ],
        vec!["tables", "info", table],
        vec!["demo", "--out", demo_out],
    ]
}

/// `… | head -1`, `… | head -c10`: standard output closed by its reader
/// is a normal end: exit 0, nothing on stderr but a table estimate
/// (println! panicked, exit 134 in release). Closed before the first write, and (`replay`, 3000 lines,
/// more than a pipe holds) after reading one line.
#[test]
fn a_closed_standard_output_is_a_normal_end() {
    let dir = fresh_dir("closed-stdout");
    let (table, sequence, deformed) = stdout_inputs(&dir, 3000);
    let mesh = reference("meshes/cube.msh");
    let demo_out = dir.join("demo-out");
    for args in printing_commands(
        s(&table),
        s(&sequence),
        s(&deformed),
        s(&mesh),
        s(&demo_out),
    ) {
        let mut child = palpate_command(&args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("spawn palpate");
        drop(child.stdout.take());
        let out = child.wait_with_output().expect("wait");
        assert_eq!(
            out.status.code(),
            Some(0),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        // Nothing on stderr but, for the demo, the estimate line its
        // hybrid organ's table build prints, as `session run` does.
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.lines().all(|l| l.contains(": estimate: ")),
            "{args:?}: {err}"
        );
    }
    // The demo puts its series in place before it prints: a closed output
    // does not cost the files, and nothing is left beside them.
    assert!(demo_out.join("demo.pvd").is_file());
    assert!(demo_out.join("organ.pvd").is_file());
    assert_eq!(temporaries(&dir), Vec::<PathBuf>::new());

    let mut child = palpate_command(&["precomputed", "replay", s(&table), s(&sequence)])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn palpate");
    let mut first = String::new();
    BufReader::new(child.stdout.take().expect("stdout"))
        .read_line(&mut first)
        .expect("first line");
    assert!(first.starts_with("step 0 "), "{first}");
    let out = child.wait_with_output().expect("wait");
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    assert!(out.stderr.is_empty(), "{out:?}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `… > /dev/full`: a full standard output is one line `error: standard
/// output: …` and exit 2, and a full `--out` names the file.
#[test]
fn a_full_standard_output_or_file_is_a_one_line_error() {
    let full = Path::new("/dev/full");
    if !full.exists() {
        return; // not on this system
    }
    let dir = fresh_dir("full");
    let (table, sequence, deformed) = stdout_inputs(&dir, 10);
    let mesh = reference("meshes/cube.msh");
    let demo_out = dir.join("demo-out");
    for args in printing_commands(
        s(&table),
        s(&sequence),
        s(&deformed),
        s(&mesh),
        s(&demo_out),
    ) {
        let device = std::fs::OpenOptions::new()
            .write(true)
            .open(full)
            .expect("/dev/full");
        let out = palpate_command(&args)
            .stdout(device)
            .output()
            .expect("run palpate");
        assert_one_line_error(&out, &["error: standard output: "]);
    }
    // The demo's series was complete before its report failed to print.
    assert!(demo_out.join("demo.pvd").is_file());

    let trajectory = dir.join("poke.csv");
    let out = palpate(&["session", "generate", "poke", "-o", s(&trajectory)]);
    assert!(out.status.success(), "{out:?}");
    let out = palpate(&[
        "session",
        "run",
        "built-in",
        "--trajectory",
        s(&trajectory),
        "--out",
        "/dev/full",
    ]);
    assert_one_line_error(&out, &["/dev/full: cannot write: "]);
    let out = palpate(&["session", "generate", "slide", "-o", "/dev/full"]);
    assert_one_line_error(&out, &["/dev/full: cannot write: "]);
    std::fs::remove_dir_all(&dir).ok();
}

/// A session whose CSV cannot be written leaves the previous VTK series in
/// place: the CSV is complete and synced before the series is swapped in,
/// so a full disk (`--out /dev/full`) fails before the swap.
#[test]
fn a_csv_that_cannot_be_written_keeps_the_previous_series() {
    let dir = fresh_dir("csv-before-series");
    let trajectory = dir.join("poke.csv");
    let out = palpate(&["session", "generate", "poke", "-o", s(&trajectory)]);
    assert!(out.status.success(), "{}", stderr(&out));
    let series = dir.join("series");
    let forces = dir.join("forces.csv");
    let run = |out_path: &str| {
        palpate(&[
            "session",
            "run",
            "built-in",
            "--trajectory",
            s(&trajectory),
            "--out",
            out_path,
            "--vtk",
            s(&series),
        ])
    };
    let first = run(s(&forces));
    assert!(first.status.success(), "{}", stderr(&first));
    let pvd = std::fs::read(series.join("session.pvd")).expect("first series");
    let failed = run("/dev/full");
    assert_one_line_error(&failed, &["/dev/full"]);
    assert_eq!(
        std::fs::read(series.join("session.pvd")).expect("series kept"),
        pvd
    );
    assert_eq!(temporaries(&dir), Vec::<PathBuf>::new());
    std::fs::remove_dir_all(&dir).ok();
}

/// How a probe's standard error is broken.
#[derive(Clone, Copy, Debug)]
enum BrokenStderr {
    /// `2>/dev/full`: every write fails with "No space left on device".
    Full,
    /// A pipe whose reader has gone: every write fails with a broken pipe.
    Closed,
}

/// Starts `palpate args` with its standard error broken as `how`, standard
/// output captured; `None` where `/dev/full` is missing.
fn spawn_with_broken_stderr(args: &[&str], how: BrokenStderr) -> Option<Child> {
    let mut command = palpate_command(args);
    command.stdout(Stdio::piped());
    match how {
        BrokenStderr::Full => {
            let full = std::fs::OpenOptions::new()
                .write(true)
                .open("/dev/full")
                .ok()?;
            command.stderr(full);
        }
        BrokenStderr::Closed => {
            command.stderr(Stdio::piped());
        }
    }
    let mut child = command.spawn().expect("spawn palpate");
    drop(child.stderr.take());
    Some(child)
}

/// A full or closed standard error never stops a run (the release build
/// aborted, exit 134, at the first progress line, leaving a 0-byte
/// temporary file): `tables build` (with its progress bar), `session run
/// --vtk`, `bench`, `chart --quick` and an error path each end with their
/// own status, write their outputs complete (the table loads, the CSV has
/// a line per tick, the series and the chart are in place) and leave no
/// temporary file.
#[test]
fn a_full_or_closed_standard_error_never_stops_a_run() {
    if !Path::new("/dev/full").exists() {
        return; // not on this system
    }
    let dir = fresh_dir("broken-stderr");
    let mesh = reference("meshes/cube.msh");
    let trajectory = dir.join("poke.csv");
    let out = palpate(&["session", "generate", "poke", "-o", s(&trajectory)]);
    assert!(out.status.success(), "{}", stderr(&out));
    let ticks = std::fs::read_to_string(&trajectory)
        .expect("trajectory")
        .lines()
        .count();
    for how in [BrokenStderr::Full, BrokenStderr::Closed] {
        let sub = dir.join(format!("{how:?}"));
        std::fs::create_dir_all(&sub).expect("folder");
        let (table, csv, series, chart) = (
            sub.join("cube.tbl"),
            sub.join("forces.csv"),
            sub.join("series"),
            sub.join("chart"),
        );
        // The longest first: the chart runs while the others do.
        let Some(chart_run) =
            spawn_with_broken_stderr(&["chart", "--quick", "--out", s(&chart)], how)
        else {
            return;
        };
        let runs: Vec<(Vec<&str>, i32)> = vec![
            (
                vec![
                    "tables",
                    "build",
                    &mesh,
                    "--young",
                    "5000",
                    "--poisson",
                    "0.45",
                    "--fix",
                    "z<0.001",
                    "-o",
                    s(&table),
                ],
                0,
            ),
            (
                vec![
                    "session",
                    "run",
                    "built-in",
                    "--trajectory",
                    s(&trajectory),
                    "--out",
                    s(&csv),
                    "--vtk",
                    s(&series),
                ],
                0,
            ),
            (
                vec![
                    "bench",
                    &mesh,
                    "--young",
                    "5000",
                    "--poisson",
                    "0.45",
                    "--density",
                    "1000",
                    "--fix",
                    "z<0.001",
                    "--models",
                    "linear",
                    "--integrators",
                    "symplectic",
                    "--precision",
                    "f32",
                    "--samples",
                    "1",
                    "--warmup",
                    "0",
                    "--sample-ms",
                    "1",
                ],
                0,
            ),
            // An error: its one line cannot be shown, its status can.
            (
                vec![
                    "tables",
                    "build",
                    "missing.msh",
                    "--young",
                    "5000",
                    "--poisson",
                    "0.45",
                    "--fix",
                    "z<0.001",
                    "-o",
                    s(&table),
                ],
                2,
            ),
        ];
        for (args, code) in runs {
            let child = spawn_with_broken_stderr(&args, how).expect("/dev/full");
            let out = child.wait_with_output().expect("wait");
            assert_eq!(out.status.code(), Some(code), "{how:?} {args:?}");
            if args[0] == "bench" {
                let rows = String::from_utf8_lossy(&out.stdout);
                assert!(rows.contains("step linear/symplectic"), "{rows}");
            }
        }
        let info = palpate(&["tables", "info", s(&table)]);
        assert!(info.status.success(), "{how:?}: {}", stderr(&info));
        let lines = std::fs::read_to_string(&csv).expect("csv").lines().count();
        assert_eq!(lines, ticks, "{how:?}: a header and a line per tick");
        assert!(series.join("session.pvd").is_file(), "{how:?}");
        let out = chart_run.wait_with_output().expect("wait");
        assert_eq!(out.status.code(), Some(0), "{how:?} chart");
        for file in ["study.json", "report.md", "index.html"] {
            assert!(chart.join(file).is_file(), "{how:?}: chart {file}");
        }
        assert_eq!(temporaries(&sub), Vec::<PathBuf>::new(), "{how:?}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `chart --out` onto a folder palpate did not write (a person's
/// `report.md` and `index.html`) is refused before any work, the files
/// untouched; `scene tables --out-dir` likewise. A folder holding only an
/// earlier `scene tables`' three files is replaced as a whole (the marker
/// written), as is one the previous run marked.
#[test]
fn chart_and_scene_tables_refuse_a_folder_palpate_did_not_write() {
    let dir = fresh_dir("foreign-folders");
    let mine = dir.join("mine");
    std::fs::create_dir(&mine).expect("folder");
    for file in ["report.md", "index.html"] {
        std::fs::write(mine.join(file), "keep\n").expect("file");
    }
    let out = palpate(&["chart", "--quick", "--out", s(&mine)]);
    assert_one_line_error(&out, &["palpate did not write", "choose a new folder"]);
    let out = palpate(&["scene", "tables", "built-in-hybrid", "--out-dir", s(&mine)]);
    assert_one_line_error(&out, &["palpate did not write"]);
    for file in ["report.md", "index.html"] {
        assert_eq!(
            std::fs::read_to_string(mine.join(file)).expect("kept"),
            "keep\n"
        );
    }
    assert_eq!(std::fs::read_dir(&mine).expect("folder").count(), 2);

    // An earlier version's set (no marker): replaced whole, then marked.
    let tables = dir.join("tables");
    std::fs::create_dir(&tables).expect("folder");
    for file in ["precomputed.bin", "dynamic.bin", "interface.bin"] {
        std::fs::write(tables.join(file), "old").expect("file");
    }
    for _ in 0..2 {
        let out = palpate(&[
            "scene",
            "tables",
            "built-in-hybrid",
            "--out-dir",
            s(&tables),
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
        for file in ["precomputed.bin", "dynamic.bin", "interface.bin"] {
            let bytes = std::fs::read(tables.join(file)).expect("table");
            assert!(bytes.len() > 3, "{file} replaced");
        }
        assert!(tables.join(".palpate-series").is_file());
    }
    assert_eq!(temporaries(&dir), Vec::<PathBuf>::new());
    std::fs::remove_dir_all(&dir).ok();
}

/// `session run --out /dev/null` (and a pipe) works, as the README says:
/// an output that is not a regular file is written in place, never synced
/// (`fsync` of a device fails with EINVAL).
#[test]
fn a_session_run_to_dev_null_or_a_pipe_succeeds() {
    let dir = fresh_dir("dev-null");
    let trajectory = dir.join("poke.csv");
    let out = palpate(&["session", "generate", "poke", "-o", s(&trajectory)]);
    assert!(out.status.success(), "{}", stderr(&out));
    let out = palpate(&[
        "session",
        "run",
        "built-in",
        "--trajectory",
        s(&trajectory),
        "--out",
        "/dev/null",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let out = palpate(&[
        "session",
        "run",
        "built-in",
        "--trajectory",
        s(&trajectory),
        "--out",
        "/dev/stdout",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let csv = String::from_utf8_lossy(&out.stdout);
    assert!(csv.starts_with("t,fx,fy,fz,contacts,status\n"), "{csv}");
    assert_eq!(csv.lines().count(), 1002, "a header and 1001 ticks");
    std::fs::remove_dir_all(&dir).ok();
}

/// The temporaries a killed run leaves (a process that no longer runs) are
/// removed by the next run into the same place, which says so on stderr;
/// those of a process that still runs (this test's) are left.
#[test]
fn the_next_run_sweeps_what_killed_runs_left() {
    let dir = fresh_dir("sweep");
    let trajectory = dir.join("poke.csv");
    let out = palpate(&["session", "generate", "poke", "-o", s(&trajectory)]);
    assert!(out.status.success(), "{}", stderr(&out));
    // A process that has ended: its ID names no running process.
    let mut ended = palpate_command(&["--version"])
        .stdout(Stdio::null())
        .spawn()
        .expect("spawn");
    let dead = ended.id();
    ended.wait().expect("wait");
    let live = std::process::id();
    let stale_csv = dir.join(format!(".forces.csv.palpate-tmp.{dead}.0"));
    let stale_series = dir.join(format!(".series.palpate-tmp.{dead}.3"));
    let running = dir.join(format!(".series.palpate-tmp.{live}.0"));
    std::fs::write(&stale_csv, "t,fx\n").expect("stale file");
    std::fs::create_dir(&stale_series).expect("stale folder");
    std::fs::write(stale_series.join("frame_0.vtk"), vec![b'x'; 4096]).expect("frame");
    std::fs::create_dir(&running).expect("live folder");
    let out = palpate(&[
        "session",
        "run",
        "built-in",
        "--trajectory",
        s(&trajectory),
        "--out",
        s(&dir.join("forces.csv")),
        "--vtk",
        s(&dir.join("series")),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    for name in [&stale_csv, &stale_series] {
        let name = name.file_name().expect("name").to_string_lossy();
        assert!(
            err.contains(&format!("removed {name} (")) && err.contains("was killed"),
            "{err}"
        );
    }
    assert!(err.contains("4.1 kB"), "the folder's size: {err}");
    assert!(!stale_csv.exists() && !stale_series.exists());
    assert!(running.is_dir(), "a running process's folder is kept");
    std::fs::remove_dir_all(&dir).ok();
}
