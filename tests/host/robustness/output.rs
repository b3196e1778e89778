//! See `super`: the output probes. Every output is written to a temporary
//! file or folder beside it and renamed into place only when complete
//! (`palpate::output::atomic`); an output that is an input is refused.
//! These run in process; the probes that need the binary (a killed run, a
//! closed or full standard output) are in
//! `host-harness/tests/cli/robustness/output.rs`.

use std::io::{self, Write};
use std::path::{Path, PathBuf};

use palpate::fix::FixPredicate;
use palpate::output::atomic::{
    self, AtomicFile, SERIES_MARKER, SeriesDir, TEMP_TAG, refuse_input, refuse_inside,
};
use palpate::scene::{Generator, MeshSource, Poke, Scene};
use palpate::session::run::{run_session, run_session_to_files};

/// An empty folder of its own for test `name`.
fn fresh_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "palpate-robustness-output-{name}-{}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("test folder");
    dir
}

/// The temporary files and folders left in `dir` (none, after any error).
fn leftovers(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .expect("read test folder")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(TEMP_TAG) || n.contains(".palpate-old."))
        .collect()
}

/// The built-in scene on a coarse block (4 × 4 × 2 cells: builds in
/// milliseconds), a VTK frame every 100 ticks.
fn small_scene() -> Scene {
    let mut scene = Scene::built_in();
    scene.mesh = MeshSource::GeneratedBox {
        size_m: [0.12, 0.12, 0.06],
        cells: [4, 4, 2],
    };
    scene.rates.physics_every = 100;
    scene.validate().expect("valid scene");
    scene
}

/// A folder as a previous run left it: the marker, frames 0..=20 and the
/// collection, each file's text naming it as old.
fn previous_series(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    std::fs::create_dir_all(dir).expect("series folder");
    let mut files = vec![(dir.join(SERIES_MARKER), b"marker".to_vec())];
    for i in 0..=20 {
        let path = dir.join(format!("frame_{i:06}.vtk"));
        files.push((path, format!("old frame {i}\n").into_bytes()));
    }
    files.push((dir.join("session.pvd"), b"old collection\n".to_vec()));
    for (path, bytes) in &files {
        std::fs::write(path, bytes).expect("old file");
    }
    files
}

/// Every file of `files` still holds its bytes.
fn assert_unchanged(files: &[(PathBuf, Vec<u8>)]) {
    for (path, bytes) in files {
        let now = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert_eq!(&now, bytes, "{} changed", path.display());
    }
}

/// A writer that passes `budget` bytes on, then fails as a full disk does.
struct FailAfter<W> {
    inner: W,
    budget: usize,
}

impl<W: Write> Write for FailAfter<W> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        if self.budget == 0 {
            return Err(io::Error::new(
                io::ErrorKind::StorageFull,
                "injected: no space left on device",
            ));
        }
        let n = self.inner.write(&buf[..buf.len().min(self.budget)])?;
        self.budget -= n;
        Ok(n)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.inner.flush()
    }
}

/// A write that fails after the output is open and bytes have reached the
/// temporary file on disk (a full disk in the middle of a session): the
/// error comes back, and dropping the uncommitted output removes the
/// temporary file; the previous file is byte-identical.
#[test]
fn an_injected_write_failure_leaves_the_old_file_and_no_temporary() {
    let dir = fresh_dir("injected");
    let path = dir.join("forces.csv");
    let old = b"t,fx,fy,fz,contacts,status\n0,1,2,3,0,ok\n".to_vec();
    std::fs::write(&path, &old).expect("old output");

    let mut file = AtomicFile::create(&path).expect("open output");
    let temp = file.temp_path().expect("a temporary file").to_path_buf();
    assert_eq!(temp.parent(), Some(dir.as_path()), "beside the output");
    // More than the buffer: these bytes are on disk, in the temporary file.
    file.write_all(&vec![b'#'; 200_000]).expect("first bytes");
    assert!(std::fs::metadata(&temp).expect("temporary file").len() >= 100_000);
    assert_eq!(
        std::fs::read(&path).expect("output"),
        old,
        "untouched so far"
    );

    let scene = small_scene();
    let trajectory = Poke::default().trajectory().expect("poke");
    let mut failing = FailAfter {
        inner: &mut file,
        budget: 10_000,
    };
    let err = run_session(&scene, &trajectory, &mut failing, None).expect_err("disk full");
    assert!(format!("{err:#}").contains("injected"), "{err:#}");
    drop(file);

    assert_eq!(std::fs::read(&path).expect("output"), old, "byte-identical");
    assert!(!temp.exists(), "temporary file removed");
    assert_eq!(leftovers(&dir), Vec::<String>::new());
    std::fs::remove_dir_all(&dir).ok();
}

/// The first robustness probe: `session run --out` over previous results with a
/// missing mesh, or a `fix` that matches no vertex (an error after the mesh
/// is read), once truncated the CSV at the start. Now both the CSV and the
/// VTK folder of the previous run keep every byte, and nothing is left
/// beside them.
#[test]
fn a_failed_session_keeps_the_previous_csv_and_series() {
    let dir = fresh_dir("failed-session");
    let csv = dir.join("forces.csv");
    let old_csv = b"t,fx,fy,fz,contacts,status\nprevious results\n".to_vec();
    std::fs::write(&csv, &old_csv).expect("old csv");
    let vtk = dir.join("frames");
    let old_series = previous_series(&vtk);
    let trajectory = Poke::default().trajectory().expect("poke");

    let mut missing_mesh = small_scene();
    missing_mesh.mesh = MeshSource::File(dir.join("missing.msh"));
    let mut bad_fix = small_scene();
    bad_fix.fix = vec!["z<-1".parse::<FixPredicate>().expect("predicate")];
    for (scene, needle) in [(missing_mesh, "missing.msh"), (bad_fix, "no vertex")] {
        let err = run_session_to_files(&scene, &trajectory, &csv, Some(&vtk))
            .expect_err("the session fails");
        assert!(format!("{err:#}").contains(needle), "{err:#}");
        assert_eq!(std::fs::read(&csv).expect("csv"), old_csv, "{needle}");
        assert_unchanged(&old_series);
        assert_eq!(leftovers(&dir), Vec::<String>::new(), "{needle}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A successful session replaces the CSV whole and the VTK folder whole:
/// the previous run's 21 frames are gone, not mixed with the 11 new ones
/// (1001 ticks, a frame every 100), the collection lists the new frames
/// only, the marker is there for the next run, and nothing is left beside.
#[test]
fn a_successful_session_replaces_csv_and_series_whole() {
    let dir = fresh_dir("successful-session");
    let csv = dir.join("forces.csv");
    std::fs::write(&csv, "previous results\n").expect("old csv");
    let vtk = dir.join("frames");
    previous_series(&vtk);
    let scene = small_scene();
    let trajectory = Poke::default().trajectory().expect("poke");

    for run in 0..2 {
        let summary = run_session_to_files(&scene, &trajectory, &csv, Some(&vtk)).expect("session");
        assert_eq!((summary.ticks, summary.frames), (1001, 11), "run {run}");
        let text = std::fs::read_to_string(&csv).expect("csv");
        assert_eq!(text.lines().next(), Some("t,fx,fy,fz,contacts,status"));
        assert_eq!(text.lines().count(), 1002);
        let mut names: Vec<String> = std::fs::read_dir(&vtk)
            .expect("series")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        let mut expected: Vec<String> = (0..11).map(|i| format!("frame_{i:06}.vtk")).collect();
        expected.insert(0, SERIES_MARKER.to_string());
        expected.push("session.pvd".to_string());
        assert_eq!(names, expected, "run {run}");
        let pvd = std::fs::read_to_string(vtk.join("session.pvd")).expect("pvd");
        assert_eq!(pvd.matches("<DataSet").count(), 11);
        assert!(pvd.contains("frame_000010.vtk") && !pvd.contains("frame_000011"));
        assert_eq!(leftovers(&dir), Vec::<String>::new(), "run {run}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `--vtk` onto an existing file is a clear one-line error (once "File
/// exists (os error 17)"), a folder palpate did not write is refused before
/// any work (its files intact), an empty folder is accepted; a series
/// dropped before its commit leaves nothing behind.
#[test]
fn a_vtk_path_that_is_a_file_or_a_foreign_folder_is_refused() {
    let dir = fresh_dir("vtk-refusals");
    let file = dir.join("notes.txt");
    std::fs::write(&file, "keep me\n").expect("file");
    let msg = SeriesDir::create(&file).expect_err("a file").to_string();
    assert!(
        msg.contains("notes.txt") && msg.contains("is not a folder"),
        "{msg}"
    );
    assert!(!msg.contains("os error 17") && !msg.contains('\n'), "{msg}");

    let foreign = dir.join("results");
    std::fs::create_dir(&foreign).expect("folder");
    std::fs::write(foreign.join("paper.tex"), "keep me too\n").expect("file");
    std::fs::write(foreign.join("frame_000001.vtk"), "not ours\n").expect("file");
    let msg = SeriesDir::create(&foreign)
        .expect_err("foreign")
        .to_string();
    assert!(msg.contains("palpate did not write"), "{msg}");
    assert!(msg.contains("paper.tex"), "{msg}");

    let csv = dir.join("forces.csv");
    std::fs::write(&csv, "previous\n").expect("csv");
    let trajectory = Poke::default().trajectory().expect("poke");
    let err = run_session_to_files(&small_scene(), &trajectory, &csv, Some(&foreign))
        .expect_err("refused");
    assert!(
        format!("{err:#}").contains("palpate did not write"),
        "{err:#}"
    );
    assert_eq!(std::fs::read_to_string(&csv).expect("csv"), "previous\n");
    assert_eq!(
        std::fs::read_to_string(foreign.join("paper.tex")).expect("kept"),
        "keep me too\n"
    );
    assert_eq!(std::fs::read_to_string(&file).expect("kept"), "keep me\n");

    let empty = dir.join("empty");
    std::fs::create_dir(&empty).expect("folder");
    let series = SeriesDir::create(&empty).expect("an empty folder is fine");
    std::fs::write(series.dir().join("frame_000000.vtk"), "new\n").expect("frame");
    assert!(std::fs::read_dir(&empty).expect("empty").next().is_none());
    drop(series);
    assert!(std::fs::read_dir(&empty).expect("empty").next().is_none());
    assert_eq!(leftovers(&dir), Vec::<String>::new());
    std::fs::remove_dir_all(&dir).ok();
}

/// An output that is one of the inputs is refused with one line naming
/// both: the same path, a `..` detour, a hard link and a symbolic link
/// (device and inode); another file, a new file, are fine. An output inside
/// the VTK folder (replaced as a whole) is refused too.
#[test]
fn an_output_that_is_an_input_is_refused() {
    let dir = fresh_dir("output-is-input");
    let input = dir.join("poke.csv");
    std::fs::write(&input, "t,tool,x,y,z\n").expect("input");
    std::fs::create_dir(dir.join("sub")).expect("sub");
    let detour = dir.join("sub").join("..").join("poke.csv");
    let mut same = vec![input.clone(), detour];
    #[cfg(unix)]
    {
        let hard = dir.join("hard.csv");
        std::fs::hard_link(&input, &hard).expect("hard link");
        let soft = dir.join("soft.csv");
        std::os::unix::fs::symlink(&input, &soft).expect("symlink");
        same.extend([hard, soft]);
    }
    for output in &same {
        let msg = refuse_input(
            ("--out", output.as_path()),
            &[("--trajectory", input.as_path())],
        )
        .expect_err("refused")
        .to_string();
        assert!(
            msg.contains(&format!("--out {}", output.display()))
                && msg.contains(&format!("--trajectory {}", input.display()))
                && msg.contains("refusing to overwrite an input")
                && !msg.contains('\n'),
            "{msg}"
        );
    }
    assert_eq!(
        std::fs::read_to_string(&input).expect("input"),
        "t,tool,x,y,z\n"
    );
    let other = dir.join("other.csv");
    std::fs::write(&other, "x\n").expect("other");
    refuse_input(
        ("--out", other.as_path()),
        &[("--trajectory", input.as_path())],
    )
    .expect("another file");
    refuse_input(
        ("--out", dir.join("new.csv").as_path()),
        &[("--trajectory", input.as_path())],
    )
    .expect("a new file");

    let vtk = dir.join("frames");
    let msg = refuse_inside(
        ("--vtk", vtk.as_path()),
        &[("--out", vtk.join("forces.csv").as_path())],
    )
    .expect_err("inside")
    .to_string();
    assert!(msg.contains("is inside --vtk"), "{msg}");
    refuse_inside(("--vtk", vtk.as_path()), &[("--out", other.as_path())]).expect("outside");
    std::fs::remove_dir_all(&dir).ok();
}

/// The file mechanism itself: a commit replaces the old file whole and
/// keeps its mode; through a symbolic link the file it points to is
/// replaced and the link stays; an output in a missing folder or onto a
/// folder is a one-line error naming it; a full device names the output.
#[test]
fn atomic_files_replace_whole_and_name_the_output_in_errors() {
    let dir = fresh_dir("atomic-file");
    let path = dir.join("table.bin");
    std::fs::write(&path, b"old table").expect("old");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt as _;
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o640)).expect("mode");
        atomic::write_file(&path, b"new table").expect("write");
        let mode = std::fs::metadata(&path).expect("meta").permissions().mode();
        assert_eq!(mode & 0o777, 0o640);
        let link = dir.join("link.bin");
        std::os::unix::fs::symlink(&path, &link).expect("symlink");
        atomic::write_file(&link, b"through the link").expect("write");
        assert!(
            std::fs::symlink_metadata(&link)
                .expect("link")
                .file_type()
                .is_symlink()
        );
        assert_eq!(std::fs::read(&path).expect("target"), b"through the link");
    }
    atomic::write_file(&path, b"newest").expect("write");
    assert_eq!(std::fs::read(&path).expect("new"), b"newest");

    let missing = dir.join("no-such-dir").join("x.csv");
    let msg = AtomicFile::create(&missing)
        .expect_err("missing")
        .to_string();
    assert!(
        msg.starts_with(&format!("{}: cannot write: ", missing.display())),
        "{msg}"
    );
    let msg = AtomicFile::create(&dir).expect_err("a folder").to_string();
    assert!(msg.contains("is a folder"), "{msg}");
    assert_eq!(leftovers(&dir), Vec::<String>::new());

    let full = Path::new("/dev/full");
    if full.exists() {
        let trajectory = Poke::default().trajectory().expect("poke");
        let err =
            run_session_to_files(&small_scene(), &trajectory, full, None).expect_err("disk full");
        let msg = format!("{err:#}");
        assert!(msg.starts_with("/dev/full: cannot write: "), "{msg}");
        assert!(!msg.contains('\n'), "{msg}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// The ID of a process that has ended (a child that exited): no process
/// runs under it (until the system reuses it, far later).
fn ended_process_id() -> u32 {
    let mut child = std::process::Command::new("true")
        .spawn()
        .expect("spawn true");
    let id = child.id();
    child.wait().expect("wait");
    id
}

/// The sweep's rule: a temporary of this output whose process has ended is
/// stale; one of this process, of another output's name, or of a name not
/// of palpate's pattern is not; a replaced folder's old copy is stale only
/// while the folder is in place (else it may be the only whole copy).
#[test]
fn only_temporaries_of_ended_runs_of_this_output_are_stale() {
    if !Path::new("/proc/self").exists() {
        return; // no process table to ask: nothing is swept
    }
    let dir = fresh_dir("stale");
    let target = dir.join("series");
    let dead = ended_process_id();
    let live = std::process::id();
    let names = [
        format!(".series{TEMP_TAG}{dead}.0"),
        format!(".series{TEMP_TAG}{live}.0"),
        format!(".other{TEMP_TAG}{dead}.0"),
        format!(".series{TEMP_TAG}{dead}.x"),
        format!(".series{TEMP_TAG}notapid.0"),
        format!(".series{}{dead}.1", atomic::OLD_TAG),
    ];
    for name in &names {
        std::fs::create_dir(dir.join(name)).expect("folder");
    }
    let stale = |expected: &[&String]| {
        let expected: Vec<PathBuf> = expected.iter().map(|n| dir.join(n)).collect();
        assert_eq!(atomic::stale_temporaries(&target), expected);
    };
    // The folder absent: its old copy is kept.
    stale(&[&names[0]]);
    std::fs::create_dir(&target).expect("folder");
    stale(&[&names[5], &names[0]]);
    atomic::sweep_stale(&target, &target);
    stale(&[]);
    for (i, name) in names.iter().enumerate() {
        assert_eq!(dir.join(name).exists(), ![0, 5].contains(&i), "{name}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `scene tables`' and `chart`'s folders: a folder holding only the hybrid
/// tables of an earlier palpate is replaced whole; a chart's names in a
/// folder without the marker are a person's (refused); a file in the
/// folder's place is named with what needs the folder.
#[test]
fn folder_kinds_accept_their_own_earlier_folders_only() {
    use palpate::output::atomic::FolderKind;
    let dir = fresh_dir("kinds");
    let tables = dir.join("tables");
    std::fs::create_dir(&tables).expect("folder");
    for name in ["precomputed.bin", "dynamic.bin", "interface.bin"] {
        std::fs::write(tables.join(name), "old").expect("file");
    }
    let folder = SeriesDir::of_kind(&tables, FolderKind::HybridTables).expect("earlier tables");
    std::fs::write(folder.dir().join("precomputed.bin"), "new").expect("file");
    folder.commit().expect("commit");
    let mut names: Vec<String> = std::fs::read_dir(&tables)
        .expect("folder")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [SERIES_MARKER, "precomputed.bin"],
        "the set replaced whole"
    );
    assert!(SeriesDir::of_kind(&tables, FolderKind::VtkSeries).is_ok());

    let report = dir.join("report");
    std::fs::create_dir(&report).expect("folder");
    std::fs::write(report.join("report.md"), "mine").expect("file");
    let err = SeriesDir::of_kind(&report, FolderKind::Chart).expect_err("a person's folder");
    assert!(err.to_string().contains("palpate did not write"), "{err}");
    let file = dir.join("a-file");
    std::fs::write(&file, "mine").expect("file");
    let err = SeriesDir::of_kind(&file, FolderKind::HybridTables).expect_err("a file");
    assert!(
        err.to_string().contains("the hybrid tables needs a folder"),
        "{err}"
    );
    assert_eq!(leftovers(&dir), Vec::<String>::new());
    std::fs::remove_dir_all(&dir).ok();
}

/// An output that is not a regular file is written in place and `prepare`
/// does not sync it (a device's `fsync` fails with EINVAL).
#[test]
fn an_output_written_in_place_prepares_and_commits() {
    let null = Path::new("/dev/null");
    if !null.exists() {
        return;
    }
    let mut file = AtomicFile::create(null).expect("/dev/null");
    assert_eq!(file.temp_path(), None);
    file.write_all(b"t,fx\n").expect("write");
    file.prepare().expect("prepare in place");
    file.commit().expect("commit in place");
}
