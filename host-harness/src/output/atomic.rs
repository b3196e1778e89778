//! Outputs written whole or not at all: every file and folder the CLI writes
//! goes through this module.
//!
//! Guarantees of [`AtomicFile`] (a file output, e.g. `tables build -o`,
//! `session run --out`, `session generate -o`):
//!
//! - Nothing is written to the output's path until [`AtomicFile::commit`]:
//!   the bytes go to a temporary file beside it (same folder, so the same
//!   file system), named `.NAME.palpate-tmp.PID.N`.
//! - `commit` flushes, `sync_all`s the temporary file, renames it over the
//!   output in one step (the old file, if any, is replaced whole) and then
//!   syncs the folder where the platform allows. A reader sees the old
//!   file or the complete new one, never a mix, a truncated or an empty file.
//! - On any error, or when the `AtomicFile` is dropped without `commit`
//!   (an error path returning early, a panic unwinding), the temporary file
//!   is removed and the old output is left byte-identical. A process killed
//!   outright (`SIGKILL`, power loss) cannot clean up: it leaves the old
//!   output intact and at most a hidden `.NAME.palpate-tmp.*` file beside it.
//! - An existing output keeps its permissions; an output that is a
//!   symbolic link to a file has the file it points to replaced (the link
//!   stays).
//! - An existing output that is not a regular file (`/dev/null`,
//!   `/dev/full`, a named pipe) cannot be replaced by a rename: it is
//!   written in place (no temporary file, no sync: such files cannot be
//!   synced), and nothing above holds for it.
//! - Every error names the output as given on the command line and keeps
//!   the I/O error's kind (`{output}: cannot write: No space left on
//!   device (os error 28)`).
//!
//! Guarantees of [`SeriesDir`] (a folder of files written together: the VTK
//! series of `demo --out` and `session run --vtk`, the three tables of
//! `scene tables --out-dir`, the charts and report of `chart --out`; see
//! [`FolderKind`]):
//!
//! - The files are written into a fresh temporary sibling folder
//!   (`.NAME.palpate-tmp.PID.N`); `commit` writes the marker file
//!   [`SERIES_MARKER`], syncs every file and the folder, and renames it
//!   into place. The folder under the output's name is the old one or the
//!   complete new one, never old and new frames mixed.
//! - An existing folder is replaced only if a previous palpate run wrote it
//!   (it holds [`SERIES_MARKER`]), if it is empty, or if it holds only files
//!   named as palpate versions before the marker wrote them into such a
//!   folder ([`FolderKind::is_legacy_file`]: `frame_*.vtk` and `*.pvd` of a
//!   series, the three `.bin` of hybrid tables; none for a chart, whose
//!   `report.md` and `index.html` are names a person's folder holds too).
//!   Anything else is refused before any work starts, as is an output path
//!   that is an existing file.
//! - Replacing renames the old folder aside (`.NAME.palpate-old.PID.N`),
//!   renames the new one in and removes the old one. A crash between those
//!   two renames leaves both folders whole under their hidden names.
//! - Dropped without `commit`, the temporary folder is removed.
//!
//! Stale temporary files and folders ([`sweep_stale`]): a run killed
//! outright leaves its `.NAME.palpate-tmp.PID.N` (a VTK series of a long
//! run can be hundreds of MB). The next [`AtomicFile`] or [`SeriesDir`]
//! for the same output removes those of its own name whose process `PID`
//! no longer runs on this machine (Linux: no `/proc/PID`; elsewhere nothing
//! is swept), and the `.NAME.palpate-old.PID.N` of a replaced folder when
//! the folder itself is in place (else that old copy may be the only whole
//! one, and stays), and says so on standard error. A folder shared between
//! machines is not supported (a process ID names a process of one machine).
//!
//! And [`refuse_input`], [`refuse_inside`]: an output that is one of the
//! command's inputs (same file by canonical path, and on unix by device and
//! inode, so hard links count) or a path inside a folder that will be
//! replaced is refused with a one-line error naming both.

use core::sync::atomic::{AtomicU64, Ordering};
use std::fs::{self, File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Component, Path, PathBuf};

use super::stderr;
use crate::limits::human_bytes;

/// The part of the name of every temporary file or folder: a temporary
/// output `NAME` is `.NAME.palpate-tmp.PID.N` in the output's folder.
pub const TEMP_TAG: &str = ".palpate-tmp.";

/// The part of the name of a replaced folder between the two renames of
/// [`SeriesDir::commit`]: `.NAME.palpate-old.PID.N`.
pub const OLD_TAG: &str = ".palpate-old.";

/// The marker file in a folder written by [`SeriesDir`]: such a folder may
/// be replaced by the next run.
pub const SERIES_MARKER: &str = ".palpate-series";

/// Distinguishes the temporary names of one process.
static COUNTER: AtomicU64 = AtomicU64::new(0);

/// `.NAME<tag>PID.N` beside `target` (which has a file name).
fn sibling(target: &Path, tag: &str) -> PathBuf {
    let name = target
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    target.with_file_name(format!(".{name}{tag}{}.{n}", std::process::id()))
}

/// `err` with `shown` and `action` in its message, of the same kind.
fn named(shown: &Path, action: &str, err: &io::Error) -> io::Error {
    io::Error::new(err.kind(), format!("{}: {action}: {err}", shown.display()))
}

/// A one-line error of kind `kind`.
fn refusal(kind: io::ErrorKind, message: String) -> io::Error {
    io::Error::new(kind, message)
}

/// The folder holding `path` (`.` for a bare name).
fn parent_of(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Syncs a folder's entries to disk where the platform allows (a folder
/// cannot be opened for syncing everywhere); errors are ignored.
fn sync_folder(folder: &Path) {
    if let Ok(dir) = File::open(folder) {
        let _ = dir.sync_all();
    }
}

/// Where an output path really is: an existing path with its symbolic links
/// resolved, else `path` as given (it is created there).
fn real_target(path: &Path, shown: &Path) -> io::Result<PathBuf> {
    let real = match fs::canonicalize(path) {
        Ok(real) => real,
        Err(e) if e.kind() == io::ErrorKind::NotFound => path.to_path_buf(),
        Err(e) => return Err(named(shown, "cannot write", &e)),
    };
    match real.components().next_back() {
        Some(Component::Normal(_)) => Ok(real),
        _ => Err(refusal(
            io::ErrorKind::InvalidInput,
            format!("{}: not a file name", shown.display()),
        )),
    }
}

/// A file output written to a temporary file and renamed into place by
/// [`AtomicFile::commit`] (see the module's guarantees). Buffered: write
/// to it directly.
#[derive(Debug)]
pub struct AtomicFile {
    /// The output as given, for messages.
    shown: PathBuf,
    /// The path the output is renamed to.
    target: PathBuf,
    /// The temporary file; `None` once committed or when writing in place.
    temp: Option<PathBuf>,
    /// The open file; `None` once committed.
    writer: Option<BufWriter<File>>,
}

impl AtomicFile {
    /// Opens a temporary file beside `path` (or, for an existing non-regular
    /// file such as `/dev/null`, `path` itself). Nothing is written to
    /// `path` before [`Self::commit`]. An existing folder is refused.
    pub fn create(path: &Path) -> io::Result<Self> {
        let shown = path.to_path_buf();
        let target = real_target(path, &shown)?;
        let existing = match fs::metadata(&target) {
            Ok(meta) => Some(meta),
            Err(e) if e.kind() == io::ErrorKind::NotFound => None,
            Err(e) => return Err(named(&shown, "cannot write", &e)),
        };
        if let Some(meta) = &existing {
            if meta.is_dir() {
                return Err(refusal(
                    io::ErrorKind::InvalidInput,
                    format!("{}: is a folder, not a file", shown.display()),
                ));
            }
            if !meta.is_file() {
                // A device or a pipe: no rename can replace it.
                let file = OpenOptions::new()
                    .write(true)
                    .truncate(true)
                    .open(&target)
                    .map_err(|e| named(&shown, "cannot write", &e))?;
                return Ok(Self {
                    shown,
                    target,
                    temp: None,
                    writer: Some(BufWriter::with_capacity(1 << 16, file)),
                });
            }
        }
        sweep_stale(&target, &shown);
        let temp = sibling(&target, TEMP_TAG);
        let file = OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&temp)
            .map_err(|e| named(&shown, "cannot write", &e))?;
        if let Some(meta) = existing {
            // Best effort: the replacement keeps the old file's mode.
            let _ = file.set_permissions(meta.permissions());
        }
        Ok(Self {
            shown,
            target,
            temp: Some(temp),
            writer: Some(BufWriter::with_capacity(1 << 16, file)),
        })
    }

    /// The output's path as given.
    pub fn path(&self) -> &Path {
        &self.shown
    }

    /// The temporary file being written (`None` for an output written in
    /// place, or once committed).
    pub fn temp_path(&self) -> Option<&Path> {
        self.temp.as_deref()
    }

    /// Flushes and syncs what was written, so that only the rename of
    /// [`Self::commit`] is left to fail: call it before committing another
    /// output that must not be replaced if this one fails (a session's VTK
    /// series before its CSV). An output written in place (`/dev/null`, a
    /// pipe) is flushed only: such a file cannot be synced (`EINVAL`).
    pub fn prepare(&mut self) -> io::Result<()> {
        let in_place = self.temp.is_none();
        let writer = self
            .writer
            .as_mut()
            .ok_or_else(|| io::Error::other("internal: output already committed"))?;
        let synced = writer.flush().and_then(|()| {
            if in_place {
                Ok(())
            } else {
                writer.get_ref().sync_all()
            }
        });
        synced.map_err(|e| named(&self.shown, "cannot write", &e))
    }

    /// Flushes and syncs the temporary file and renames it over the output,
    /// then syncs the folder. On error the temporary file is removed and the
    /// old output is untouched.
    pub fn commit(mut self) -> io::Result<()> {
        let Some(writer) = self.writer.take() else {
            return Ok(());
        };
        let file = writer
            .into_inner()
            .map_err(|e| named(&self.shown, "cannot write", e.error()))?;
        let Some(temp) = self.temp.as_deref() else {
            return Ok(()); // written in place
        };
        file.sync_all()
            .map_err(|e| named(&self.shown, "cannot write", &e))?;
        drop(file);
        fs::rename(temp, &self.target).map_err(|e| named(&self.shown, "cannot replace", &e))?;
        self.temp = None;
        sync_folder(parent_of(&self.target));
        Ok(())
    }

    /// The open writer (it exists until `commit`, which takes `self`).
    fn writer(&mut self) -> io::Result<&mut BufWriter<File>> {
        self.writer
            .as_mut()
            .ok_or_else(|| io::Error::other("internal: output already committed"))
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let result = self.writer()?.write(buf);
        result.map_err(|e| named(&self.shown, "cannot write", &e))
    }

    fn write_all(&mut self, buf: &[u8]) -> io::Result<()> {
        let result = self.writer()?.write_all(buf);
        result.map_err(|e| named(&self.shown, "cannot write", &e))
    }

    fn flush(&mut self) -> io::Result<()> {
        let result = self.writer()?.flush();
        result.map_err(|e| named(&self.shown, "cannot write", &e))
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if let Some(temp) = self.temp.take() {
            // Close before removing; the buffered bytes are discarded.
            if let Some(writer) = self.writer.take() {
                let (file, _) = writer.into_parts();
                drop(file);
            }
            let _ = fs::remove_file(temp);
        }
    }
}

/// Writes `bytes` to `path` through an [`AtomicFile`]: the old file or the
/// new one, never a part.
pub fn write_file(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let mut file = AtomicFile::create(path)?;
    file.write_all(bytes)?;
    file.commit()
}

/// What a [`SeriesDir`] holds: how messages name it and which files of a
/// folder without [`SERIES_MARKER`] an earlier palpate wrote.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FolderKind {
    /// A VTK series (`demo --out`, `session run --vtk`).
    VtkSeries,
    /// A hybrid scene's three tables (`scene tables --out-dir`).
    HybridTables,
    /// The speed/accuracy study's charts, report and JSON (`chart --out`).
    Chart,
}

impl FolderKind {
    /// What the folder holds, for messages: `the VTK series`.
    pub fn what(self) -> &'static str {
        match self {
            Self::VtkSeries => "the VTK series",
            Self::HybridTables => "the hybrid tables",
            Self::Chart => "the chart",
        }
    }

    /// Whether a file `name` is one palpate versions before the marker wrote
    /// into such a folder: a folder holding only these may be replaced.
    pub fn is_legacy_file(self, name: &str) -> bool {
        match self {
            Self::VtkSeries => {
                (name.starts_with("frame_") && name.ends_with(".vtk")) || name.ends_with(".pvd")
            }
            Self::HybridTables => {
                matches!(name, "precomputed.bin" | "dynamic.bin" | "interface.bin")
            }
            Self::Chart => false,
        }
    }
}

/// A folder of files written together (a VTK series, hybrid tables, a
/// chart), built in a temporary sibling folder and renamed into place by
/// [`SeriesDir::commit`] (see the module's guarantees).
#[derive(Debug)]
pub struct SeriesDir {
    /// The output folder as given, for messages.
    shown: PathBuf,
    /// What it holds.
    kind: FolderKind,
    /// The path the folder is renamed to.
    target: PathBuf,
    /// The temporary folder; `None` once committed.
    temp: Option<PathBuf>,
}

impl SeriesDir {
    /// [`Self::of_kind`] for a VTK series.
    pub fn create(path: &Path) -> io::Result<Self> {
        Self::of_kind(path, FolderKind::VtkSeries)
    }

    /// Checks that `path` is absent or a folder palpate may replace (for
    /// `kind`), sweeps stale temporaries of it ([`sweep_stale`]) and
    /// creates the temporary folder beside it (and `path`'s missing parent
    /// folders). Nothing under `path` changes before [`Self::commit`].
    pub fn of_kind(path: &Path, kind: FolderKind) -> io::Result<Self> {
        let shown = path.to_path_buf();
        let target = real_target(path, &shown)?;
        check_replaceable(&target, &shown, kind)?;
        let parent = parent_of(&target);
        fs::create_dir_all(parent).map_err(|e| named(&shown, "cannot create", &e))?;
        sweep_stale(&target, &shown);
        let temp = sibling(&target, TEMP_TAG);
        fs::create_dir(&temp).map_err(|e| named(&shown, "cannot create", &e))?;
        Ok(Self {
            shown,
            kind,
            target,
            temp: Some(temp),
        })
    }

    /// The output folder as given.
    pub fn path(&self) -> &Path {
        &self.shown
    }

    /// The temporary folder the files are written into until `commit`.
    pub fn dir(&self) -> &Path {
        self.temp.as_deref().unwrap_or(&self.target)
    }

    /// Writes the marker, syncs every file and the folder, and renames the
    /// folder into place, replacing the old one (which is checked again).
    /// On error the temporary folder is removed and the old one kept.
    pub fn commit(mut self) -> io::Result<()> {
        let Some(temp) = self.temp.clone() else {
            return Ok(());
        };
        let shown = self.shown.clone();
        let err = |e: io::Error| named(&shown, "cannot write", &e);
        let mut marker = File::create(temp.join(SERIES_MARKER)).map_err(err)?;
        marker
            .write_all(b"Written by palpate: the next run writing here replaces this folder.\n")
            .map_err(err)?;
        drop(marker);
        for entry in fs::read_dir(&temp).map_err(err)? {
            let path = entry.map_err(err)?.path();
            if path.is_file() {
                File::open(&path).and_then(|f| f.sync_all()).map_err(err)?;
            }
        }
        sync_folder(&temp);
        check_replaceable(&self.target, &self.shown, self.kind)?;
        let old = sibling(&self.target, OLD_TAG);
        let replacing = match fs::rename(&self.target, &old) {
            Ok(()) => true,
            Err(e) if e.kind() == io::ErrorKind::NotFound => false,
            Err(e) => return Err(named(&self.shown, "cannot replace", &e)),
        };
        if let Err(e) = fs::rename(&temp, &self.target) {
            if replacing {
                let _ = fs::rename(&old, &self.target);
            }
            return Err(named(&self.shown, "cannot replace", &e));
        }
        self.temp = None;
        if replacing {
            let _ = fs::remove_dir_all(&old);
        }
        sync_folder(parent_of(&self.target));
        Ok(())
    }
}

impl Drop for SeriesDir {
    fn drop(&mut self) {
        if let Some(temp) = self.temp.take() {
            let _ = fs::remove_dir_all(temp);
        }
    }
}

/// `Ok` when `target` is absent, or a folder palpate may replace: it holds
/// the marker, nothing, or only `kind`'s legacy files. Refuses a file and
/// any other folder.
fn check_replaceable(target: &Path, shown: &Path, kind: FolderKind) -> io::Result<()> {
    let meta = match fs::metadata(target) {
        Ok(meta) => meta,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(named(shown, "cannot write", &e)),
    };
    if !meta.is_dir() {
        return Err(refusal(
            io::ErrorKind::AlreadyExists,
            format!(
                "{}: exists and is not a folder: {} needs a folder (a new one, or one palpate wrote)",
                shown.display(),
                kind.what()
            ),
        ));
    }
    if target.join(SERIES_MARKER).is_file() {
        return Ok(());
    }
    let entries = fs::read_dir(target).map_err(|e| named(shown, "cannot read", &e))?;
    for entry in entries {
        let entry = entry.map_err(|e| named(shown, "cannot read", &e))?;
        let is_file = entry.file_type().is_ok_and(|t| t.is_file());
        if !(is_file && kind.is_legacy_file(&entry.file_name().to_string_lossy())) {
            return Err(refusal(
                io::ErrorKind::AlreadyExists,
                format!(
                    "{}: folder exists and holds files palpate did not write ({} missing, {} found): \
                     refusing to replace it; choose a new folder or remove it",
                    shown.display(),
                    SERIES_MARKER,
                    entry.file_name().to_string_lossy()
                ),
            ));
        }
    }
    Ok(())
}

/// Creates the working folder `path` (and its missing parents), named
/// `label` in messages (`--work-dir`): a path that is a file is refused in
/// one line, not with the system's "File exists".
pub fn work_folder(label: &str, path: &Path) -> io::Result<()> {
    if fs::metadata(path).is_ok_and(|m| !m.is_dir()) {
        return Err(refusal(
            io::ErrorKind::AlreadyExists,
            format!(
                "{label} {}: is a file, not a folder: give a folder (created if missing)",
                path.display()
            ),
        ));
    }
    fs::create_dir_all(path).map_err(|e| named(path, &format!("{label}: cannot create"), &e))
}

/// Whether process `pid` runs on this machine: `None` where that cannot be
/// told (no `/proc`).
fn process_runs(pid: u32) -> Option<bool> {
    let proc = Path::new("/proc");
    proc.join("self")
        .exists()
        .then(|| proc.join(pid.to_string()).exists())
}

/// The bytes under `path` (a file, or a folder's files), for messages.
fn bytes_under(path: &Path) -> u64 {
    match fs::symlink_metadata(path) {
        Ok(meta) if meta.is_dir() => fs::read_dir(path)
            .map(|entries| entries.flatten().map(|e| bytes_under(&e.path())).sum())
            .unwrap_or(0),
        Ok(meta) => meta.len(),
        Err(_) => 0,
    }
}

/// The stale temporaries of `target` (module docs): in its folder, each
/// `.NAME.palpate-tmp.PID.N`, and each `.NAME.palpate-old.PID.N` when
/// `target` exists, whose `PID` is not this process and runs no more.
pub fn stale_temporaries(target: &Path) -> Vec<PathBuf> {
    let Some(name) = target.file_name().map(|n| n.to_string_lossy().into_owned()) else {
        return Vec::new();
    };
    let Ok(entries) = fs::read_dir(parent_of(target)) else {
        return Vec::new();
    };
    let in_place = fs::symlink_metadata(target).is_ok();
    let own = std::process::id();
    let mut stale: Vec<PathBuf> = entries
        .flatten()
        .filter(|entry| {
            let entry_name = entry.file_name().to_string_lossy().into_owned();
            let rest = entry_name
                .strip_prefix(&format!(".{name}{TEMP_TAG}"))
                .or_else(|| {
                    in_place
                        .then(|| entry_name.strip_prefix(&format!(".{name}{OLD_TAG}")))
                        .flatten()
                });
            let pid = rest
                .and_then(|r| r.split_once('.'))
                .and_then(|(pid, n)| n.parse::<u64>().is_ok().then_some(pid))
                .and_then(|pid| pid.parse::<u32>().ok());
            pid.is_some_and(|pid| pid != own && process_runs(pid) == Some(false))
        })
        .map(|entry| entry.path())
        .collect();
    stale.sort();
    stale
}

/// Removes [`stale_temporaries`] of `target` and says so on standard
/// error, naming the output as `shown`; one that cannot be removed is
/// named and left.
pub fn sweep_stale(target: &Path, shown: &Path) {
    for path in stale_temporaries(target) {
        let bytes = bytes_under(&path);
        let removed = if path.is_dir() {
            fs::remove_dir_all(&path)
        } else {
            fs::remove_file(&path)
        };
        let name = path.file_name().unwrap_or_default().to_string_lossy();
        stderr::line(&match removed {
            Ok(()) => format!(
                "note: {}: removed {name} ({}), left by a palpate run that was killed",
                shown.display(),
                human_bytes(bytes)
            ),
            Err(e) => format!(
                "note: {}: cannot remove {name}, left by a palpate run that was killed: {e}",
                shown.display()
            ),
        });
    }
}

/// Whether `a` and `b` name the same existing file: the same device and
/// inode on unix (hard links, symbolic links, `..` detours alike), else the
/// same canonical path. `false` when either does not exist.
pub fn same_file(a: &Path, b: &Path) -> bool {
    let (Ok(ma), Ok(mb)) = (fs::metadata(a), fs::metadata(b)) else {
        return false;
    };
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt as _;
        if (ma.dev(), ma.ino()) == (mb.dev(), mb.ino()) {
            return true;
        }
    }
    let _ = (ma, mb);
    matches!((fs::canonicalize(a), fs::canonicalize(b)), (Ok(x), Ok(y)) if x == y)
}

/// Refuses to write `output` (a `(label, path)`: `("-o", path)`) over one
/// of `inputs` (each `(label, path)`: `("the mesh", path)`), before any work:
/// `-o m.msh is the same file as the mesh m.msh: refusing to overwrite an
/// input`.
pub fn refuse_input(output: (&str, &Path), inputs: &[(&str, &Path)]) -> io::Result<()> {
    let (out_label, out_path) = output;
    for (label, input) in inputs {
        if same_file(out_path, input) {
            return Err(refusal(
                io::ErrorKind::InvalidInput,
                format!(
                    "{out_label} {} is the same file as {label} {}: refusing to overwrite an input",
                    out_path.display(),
                    input.display()
                ),
            ));
        }
    }
    Ok(())
}

/// `path` made absolute, with the symbolic links of its longest existing
/// part resolved (the rest appended as given).
fn resolved(path: &Path) -> PathBuf {
    let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let mut existing = absolute.as_path();
    let mut rest = Vec::new();
    loop {
        if let Ok(real) = fs::canonicalize(existing) {
            return rest.iter().rev().fold(real, |p, c| p.join(c));
        }
        match (existing.parent(), existing.file_name()) {
            (Some(parent), Some(name)) => {
                rest.push(name.to_os_string());
                existing = parent;
            }
            _ => return absolute,
        }
    }
}

/// Refuses `paths` (each `(label, path)`) that are or lie inside `folder`
/// (`(label, path)`), an output folder replaced as a whole: `--out d/x.csv
/// is inside --vtk d, which is replaced as a whole: choose another folder`.
pub fn refuse_inside(folder: (&str, &Path), paths: &[(&str, &Path)]) -> io::Result<()> {
    let (folder_label, folder_path) = folder;
    if fs::metadata(folder_path).is_ok_and(|m| !m.is_dir()) {
        return Ok(()); // not a folder: SeriesDir::create refuses it
    }
    let real_folder = resolved(folder_path);
    for (label, path) in paths {
        if resolved(path).starts_with(&real_folder) {
            return Err(refusal(
                io::ErrorKind::InvalidInput,
                format!(
                    "{label} {} is inside {folder_label} {}, which is replaced as a whole: \
                     choose another folder",
                    path.display(),
                    folder_path.display()
                ),
            ));
        }
    }
    Ok(())
}
