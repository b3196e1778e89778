//! Helpers shared by the process-level tests (every module of this test
//! binary): running the `palpate` binary, finding the reference data,
//! per-module temporary paths, the one-line error check and building the
//! reference cube's table.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

/// A `Command` for the `palpate` binary under test with `args`, for the
/// caller to redirect or spawn.
pub fn palpate_command(args: &[&str]) -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_palpate"));
    command.args(args);
    command
}

/// Runs `palpate args` to its end and returns its status, stdout and stderr.
pub fn palpate(args: &[&str]) -> Output {
    palpate_command(args).output().expect("run palpate")
}

/// Runs `palpate args` with `input` on its standard input (a pipe).
pub fn palpate_with_stdin(args: &[&str], input: &[u8]) -> Output {
    let mut child = palpate_command(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run palpate");
    let mut stdin = child.stdin.take().expect("stdin");
    // The reader may stop early (and close the pipe): a write error is fine.
    let _ = stdin.write_all(input);
    drop(stdin);
    child.wait_with_output().expect("wait")
}

/// The path of `rel` under the workspace's `tests/reference/`, as a string
/// (ready to pass as an argument).
pub fn reference(rel: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/reference")
        .join(rel)
        .display()
        .to_string()
}

/// The path `name` in the calling test module's own temporary folder
/// (`palpate-cli-<module file>-<process id>`, created if missing: the
/// modules' tests run in one process and may use the same file names).
/// The file itself is not created. The first call removes the folders of
/// earlier runs whose process is gone ([`remove_stale_folders`]).
#[track_caller]
pub fn temp(name: &str) -> PathBuf {
    static STALE_REMOVED: std::sync::Once = std::sync::Once::new();
    STALE_REMOVED.call_once(remove_stale_folders);
    let module = Path::new(core::panic::Location::caller().file())
        .file_stem()
        .and_then(|stem| stem.to_str())
        .expect("a test module's file name");
    let dir = std::env::temp_dir().join(format!(
        "palpate-{}-{module}-{}",
        env!("CARGO_CRATE_NAME"),
        std::process::id()
    ));
    std::fs::create_dir_all(&dir).expect("temp folder");
    dir.join(name)
}

/// Removes the temporary folders (`palpate-cli-<module>-<process id>`) of
/// earlier test runs whose process no longer runs: the test harness has no
/// hook after the last test, so each run leaves its outputs (hundreds of
/// MB with the chart's and the sessions') until the next run clears them.
/// Where `/proc` does not list processes nothing is removed.
fn remove_stale_folders() {
    let proc_root = Path::new("/proc");
    if !proc_root.join("self").exists() {
        return;
    }
    let prefix = format!("palpate-{}-", env!("CARGO_CRATE_NAME"));
    let Ok(entries) = std::fs::read_dir(std::env::temp_dir()) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(pid) = name
            .to_str()
            .filter(|n| n.starts_with(&prefix))
            .and_then(|n| n.rsplit('-').next())
            .filter(|pid| pid.parse::<u32>().is_ok())
        else {
            continue;
        };
        if pid != std::process::id().to_string() && !proc_root.join(pid).exists() {
            let _ = std::fs::remove_dir_all(entry.path());
        }
    }
}

/// An empty folder of its own for test `name` (under [`temp`]'s folder of
/// the calling module; removed first if a previous use left it).
#[track_caller]
pub fn fresh_dir(name: &str) -> PathBuf {
    let dir = temp(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("test folder");
    dir
}

/// `bytes` (a process's output) as text, invalid UTF-8 replaced.
pub fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// The standard error of `out` as text.
pub fn stderr(out: &Output) -> String {
    text(&out.stderr)
}

/// The hint clap prints after an argument-parsing error (a value parser's
/// refusal, for example), below the one `error: …` line.
const CLAP_HINT: &str = "For more information, try '--help'.";

/// The command-line error contract: exit status 2; exactly one stderr line
/// starting with `error: `, and it is the last non-empty line (`tables
/// build` may print its size estimate before it; clap's [`CLAP_HINT`] may
/// follow it); that line contains every one of `needles`; no panic.
pub fn assert_one_line_error(out: &Output, needles: &[&str]) {
    let err = stderr(out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    let errors: Vec<&str> = err.lines().filter(|l| l.starts_with("error: ")).collect();
    assert_eq!(errors.len(), 1, "one `error: ` line: {err}");
    let mut lines = err.lines().filter(|l| !l.trim().is_empty());
    let last = match lines.next_back() {
        Some(CLAP_HINT) => lines.next_back(),
        last => last,
    }
    .unwrap_or_default();
    assert_eq!(last, errors[0], "the error line is the last: {err}");
    for needle in needles {
        assert!(last.contains(needle), "the error lacks '{needle}': {err}");
    }
}

/// Runs `tables build MESH --young YOUNG --poisson 0.45 --fix z<0.001
/// --quiet -o TABLE`, then `extra` arguments; does not check the outcome.
pub fn build_table(mesh: &str, table: &str, young: &str, extra: &[&str]) -> Output {
    let mut args = vec![
        "tables",
        "build",
        mesh,
        "--young",
        young,
        "--poisson",
        "0.45",
        "--fix",
        "z<0.001",
        "--quiet",
        "-o",
        table,
    ];
    args.extend_from_slice(extra);
    palpate(&args)
}

/// [`build_table`] of the reference cube (`meshes/cube.msh`, base fixed:
/// `z<0.001`) into `table`.
pub fn build_cube(table: &Path, young: &str, extra: &[&str]) -> Output {
    build_table(
        &reference("meshes/cube.msh"),
        &table.display().to_string(),
        young,
        extra,
    )
}

/// Builds the reference cube's table (E = 5000 Pa, f32 unless `extra` says
/// otherwise; see [`build_cube`]) into `table` and asserts it succeeded.
pub fn build_cube_table(table: &Path, extra: &[&str]) {
    let out = build_cube(table, "5000", extra);
    assert!(out.status.success(), "{}", stderr(&out));
}
