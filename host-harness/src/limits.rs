//! The harness's bounds on its inputs and runs (nothing unbounded: every input-sized allocation and run is checked first), each in one place: every one is
//! checked before the work it bounds starts, so that a typo or a hostile file gives a one-line
//! error instead of filling the disk or the memory. README.md lists them ("Limits").
//!
//! - Sessions: [`MAX_HAPTIC_HZ`], [`MAX_TRAJECTORY_SPAN_S`], [`MAX_TRAJECTORY_TIME_S`] and the
//!   tick count they imply, [`MAX_SESSION_TICKS`] (checked by the scene, the trajectory readers
//!   and `session::run::tick_count`); `session serve`: [`MAX_FILLED_TICKS`], [`PEER_TIMEOUT`].
//! - Files: [`MAX_MESH_FILE_BYTES`], [`MAX_TABLE_FILE_BYTES`], [`MAX_TRAJECTORY_FILE_BYTES`],
//!   [`MAX_SCENE_FILE_BYTES`], [`MAX_SEQUENCE_FILE_BYTES`], read through [`read_bounded`] (a
//!   table through its header first: `table::load::TableFile::read`).
//! - Table builds: the estimate of `table::estimate` against [`MAX_TABLE_FILE_BYTES`], an optional
//!   `--max-table-bytes` and the memory available ([`mem_available_bytes`]).
//! - `palpate bench`: [`MAX_BENCH_SAMPLES`] and [`MAX_BENCH_SAMPLE_S`] per measurement, and the
//!   run's estimated duration against [`MAX_BENCH_ESTIMATE_S`] (`bench::run::check`), before any
//!   table is built; its pre-computed table is checked as any table build.
//! - Offline runs (`dynamic run`, `dynamic critical-dt`, plain or `--scene`): their tet-steps
//!   against [`MAX_RUN_TET_STEPS`] ([`check_tet_steps`]), before the tables are built.
//! - `palpate chart`: its work bound (`chart::Matrix::tet_step_bound` and the volume
//!   experiments') against [`MAX_CHART_TET_STEPS`].

use std::fs::File;
use std::io::{self, Read};
use std::path::Path;

/// Most tet-steps (one tet's force evaluation) `palpate chart` may run, counted with every
/// relaxation at its step cap: 2·10¹⁰.
///
/// A St Venant-Kirchhoff step with the penalty costs about 20–60 ns per tet (measured on the
/// chart's 3×15 cylinder, f64), so the bound is 7–20 minutes of worst case on one core; the
/// full matrix's bound is under half of it (9.38·10⁹ with the hybrid), and its relaxations settle
/// far below their cap. A matrix made larger in code (more meshes, finer ones), or a `--mesh` whose
/// tet count makes it larger, is refused before it starts.
pub const MAX_CHART_TET_STEPS: u64 = 20_000_000_000;

/// Most tet-steps (one tet's force evaluation per step) of one offline run of the tensor-mass
/// or hybrid model: `dynamic run` (`--steps` × tets), `dynamic critical-dt` (its bisection's
/// `tensor_mass::stability::CRITICAL_DT_STEPS` × tets, for a hybrid twice: the coupled model and its region alone):
/// 5·10⁹.
///
/// At the host's 20–60 ns per tet-step ([`SECONDS_PER_TET_STEP`] is the upper figure) that is
/// 2–5 minutes; `critical-dt` on a 6 144-tet cylinder is 3.7·10⁸. A 40³-cell box (384 000 tets)
/// is 2.3·10¹⁰ for `critical-dt`, refused; `--steps 18446744073709551615` is refused whatever
/// the mesh. Use a coarser mesh or fewer steps above it.
pub const MAX_RUN_TET_STEPS: u64 = 5_000_000_000;

/// Most multiply-adds of a compliance computed by conjugate gradients (`tables build --solver
/// cg`), estimated before the first solve (`table::compliance::check_cg_work`): 10¹².
///
/// CG is the check of the default sparse Cholesky, for small meshes: it solves `3S` systems
/// (`S` touchable vertices) of a few hundred iterations each, where Cholesky factorizes once.
/// At about [`SECONDS_PER_MULTIPLY_ADD`] the limit is about 20 minutes; the 40³-cell box
/// (7 921 touchable vertices) is about 10¹⁴, refused, where its run went past two minutes with
/// nothing printed.
pub const MAX_CG_MULTIPLY_ADDS: u64 = 1_000_000_000_000;

/// Upper figure of one sparse multiply-add's time on the host, s (the printed duration of the
/// CG estimate).
pub const SECONDS_PER_MULTIPLY_ADD: f64 = 1e-9;

/// Upper figure of one tet-step's time on the host, s (the printed duration of an estimate).
pub const SECONDS_PER_TET_STEP: f64 = 60e-9;

/// An offline run whose estimate is longer than this, s, prints it on stderr before it starts
/// (shorter runs print nothing: their output is the contract).
pub const PRINT_ESTIMATE_ABOVE_S: f64 = 10.0;

/// Checks the work of an offline run, `tets` × `steps` tet-steps, against
/// [`MAX_RUN_TET_STEPS`] before it starts: refused above it with the figures and `instead` (what
/// to do); printed on stderr (`what`: estimate) when longer than [`PRINT_ESTIMATE_ABOVE_S`].
pub fn check_tet_steps(what: &str, tets: u64, steps: u64, instead: &str) -> anyhow::Result<()> {
    let work = tets.saturating_mul(steps);
    let seconds = work as f64 * SECONDS_PER_TET_STEP;
    let figures = format!(
        "{tets} tets x {steps} steps = {work:.3e} tet-steps, up to about {seconds:.0} s",
        work = work as f64
    );
    if work > MAX_RUN_TET_STEPS {
        anyhow::bail!(
            "{what}: {figures}: above the limit of {MAX_RUN_TET_STEPS:.0e} tet-steps \
             (MAX_RUN_TET_STEPS): refused before starting; {instead}",
            MAX_RUN_TET_STEPS = MAX_RUN_TET_STEPS as f64
        );
    }
    if seconds > PRINT_ESTIMATE_ABOVE_S {
        crate::output::stderr::line(&format!("{what}: estimate: {figures}"));
    }
    Ok(())
}

/// Most segments of a `path` zone (summed over its tool points, after the samples on one
/// straight segment are merged into it): 10 000.
///
/// The partition tests the tets near each segment (`partition::geometry`), about 0.5 ms a
/// segment for a 2 cm radius on the built-in block: 10 000 segments are seconds. A straight
/// move sampled at 1 kHz is one segment; a recorded device log at 1 kHz is one segment a
/// sample (a minute is 60 000): resample it more coarsely for a zone, a sample every millimetre
/// or so.
pub const MAX_ZONE_PATH_SEGMENTS: usize = 10_000;

/// Largest haptic rate a scene accepts (`[rates] haptic_hz`), Hz.
///
/// Haptic devices servo at 1 kHz (the default, and what the kernel's budget is measured at);
/// the fastest desktop devices and research rigs run at 4–10 kHz. Above that the tick (100 µs)
/// leaves no room for the loop's work on a Cortex-M4F (the budget's static bound is 600–5200 µs
/// at 168 MHz), and a typo such as `1e7` would multiply a session's ticks and output by 10⁴.
pub const MAX_HAPTIC_HZ: f64 = 10_000.0;

/// Longest trajectory, s: from its earliest to its latest sample time, one hour.
///
/// A surgical training session or a recorded device log lasts minutes, an hour at most; a
/// session runs one tick per haptic period over the whole span and writes a CSV line per tick,
/// so without a bound one sample at `t = 1e9` meant 10¹² ticks (a disk filled in minutes). An
/// hour at [`MAX_HAPTIC_HZ`] is [`MAX_SESSION_TICKS`] ticks, about 2 GB of CSV; at the default
/// 1 kHz, about 200 MB. Split a longer log into several trajectories.
pub const MAX_TRAJECTORY_SPAN_S: f64 = 3600.0;

/// Largest magnitude of a trajectory's tool coordinate or jaw opening (`x`, `y`, `z`,
/// `jaw_m`), m: 1 km.
///
/// The kernel runs in f32, whose largest value is 3.4·10³⁸: a position of 1e39 m became
/// infinite and faulted every tick. A surgical scene spans well under a metre; 1 km leaves room
/// for a mesh placed in a larger frame while keeping every product of the contact search
/// (squared distances, 10⁶ m²) far inside f32. A trajectory in millimetres of a mesh in metres
/// still reads (up to 1 km); the scene's mesh and its trajectory share units.
pub const MAX_TOOL_COORDINATE_M: f64 = 1000.0;

/// Largest magnitude of a trajectory time, s: 2³² s (136 years, so Unix timestamps from a
/// device log fit).
///
/// Up to there, consecutive `f64` times are at most 0.95 µs apart, under a hundredth of the
/// shortest tick (100 µs at [`MAX_HAPTIC_HZ`]): tick times stay distinct and in order. At
/// `t = 1e300` adding a tick leaves the time unchanged.
pub const MAX_TRAJECTORY_TIME_S: f64 = 4_294_967_296.0;

/// Most ticks of one session: a trajectory of [`MAX_TRAJECTORY_SPAN_S`] at [`MAX_HAPTIC_HZ`],
/// plus its first tick (36 000 001). A validated scene and trajectory never exceed it; the tick
/// count is computed with checked arithmetic against it all the same (a lenient trajectory, a
/// scene changed in code).
pub const MAX_SESSION_TICKS: usize = (MAX_TRAJECTORY_SPAN_S * MAX_HAPTIC_HZ) as usize + 1;

/// Most ticks `session serve` fills with a controller's last tool points when its ticks skip
/// ahead (a command lost on the line): 1 s at 1 kHz. More is an error naming the peer.
pub const MAX_FILLED_TICKS: u32 = 1000;

/// A controller of `session serve` silent this long is gone (the connection is closed with an
/// error naming the peer).
pub const PEER_TIMEOUT: core::time::Duration = core::time::Duration::from_secs(10);

/// Largest VTK series `session run --vtk` writes, bytes: 8 GiB (estimated before the run from
/// the frame count and an upper bound on one ASCII frame's size).
///
/// A series is for looking at in ParaView: a frame per physics update of the built-in block is
/// about 0.2 MB, so one second at 1 kHz physics is about 200 MB and an hour-long session would
/// write most of a terabyte. Above the bound, update the physics less often
/// (`[rates] physics_every`), shorten the trajectory or leave out `--vtk`.
pub const MAX_VTK_SERIES_BYTES: u64 = 8 << 30;

/// Upper bound on one legacy ASCII VTK frame of the harness's writer, bytes: a header, two
/// lines of three `f64` per vertex (position and displacement, at most 25 characters a number
/// with its separator) and a cell line plus a cell type per tet (at most 46 and 3 characters).
pub fn vtk_frame_bytes(vertices: usize, tets: usize) -> u64 {
    200 + 150 * vertices as u64 + 49 * tets as u64
}

/// Longest `palpate bench` run, estimated before it starts, s: one hour.
///
/// A run times every measurement for about `(calibration + warm-up + samples) × sample` (each
/// sample at least one call); the estimate takes each call at
/// `bench::run::ESTIMATE_SECONDS_PER_BYTE` per byte it reads, about three times the slowest pass
/// measured, so that the estimate is an upper bound. The default run (6 models, 4 integrators,
/// f32 and f64, 21 samples of 10 ms) is about 60 measurements, 20 s on a 6000-tet mesh; an hour is
/// reached near 10⁷ tets, or with `--samples` in the thousands. Time fewer `--models`,
/// `--integrators` or precisions, or fewer samples, above it.
pub const MAX_BENCH_ESTIMATE_S: f64 = 3600.0;

/// Most samples of one `palpate bench` measurement (`--samples` + `--warmup`): 10 000. A
/// median and quartiles settle within a few dozen samples; the bound catches a typo before the
/// estimate multiplies it.
pub const MAX_BENCH_SAMPLES: usize = 10_000;

/// Longest sample of `palpate bench` (`--sample-ms`), s: 10 s. A sample is a batch of calls
/// timed together; the default is 10 ms.
pub const MAX_BENCH_SAMPLE_S: f64 = 10.0;

/// Largest mesh file (each of a TetGen pair), bytes: 2 GiB.
///
/// An ASCII mesh takes about 290 bytes per vertex with its ~6 tets, so 2 GiB is about 7 million
/// vertices, the order of a scene's generated-mesh cap (10 million vertices) and far beyond what
/// either model runs at haptic rates. The parsed mesh costs about as much memory again.
pub const MAX_MESH_FILE_BYTES: u64 = 2 << 30;

/// Largest table file, bytes: 4 GiB; `tables build` refuses to write a larger table and every
/// reader refuses a larger file (its header's declared length) before reading past the header.
///
/// A firmware table must fit the controller's flash (a few MB); a host f32 table of 4 GiB already
/// holds the compliance of about 8 000 touchable vertices against 10 000 interior ones, whose
/// build needs about 4 times that in memory (see `table::estimate`). Reading `/dev/zero` or a
/// 1 GB file of garbage as a table once cost its whole size twice before the magic was checked.
pub const MAX_TABLE_FILE_BYTES: u64 = 4 << 30;

/// Largest trajectory file, bytes: 1 GiB.
///
/// A one-hour log of 4 tool points sampled at 1 kHz is about 0.7 GB of CSV; the samples cost
/// about 1.5 times the file again in memory.
pub const MAX_TRAJECTORY_FILE_BYTES: u64 = 1 << 30;

/// Longest line of a positions file (`stvk forces --deformed`: one `x,y,z` line per mesh
/// vertex), bytes: 256. Three `f64` written in full take at most 3 × 24 characters with their
/// separators; the rest is room for spaces. A positions file is refused past this many bytes
/// per vertex of its mesh (and past [`MAX_MESH_FILE_BYTES`]) before it is parsed: `/dev/zero`
/// given as one once grew the process to 23 GB.
pub const MAX_POSITION_LINE_BYTES: u64 = 256;

/// Largest contact-sequence file (`precomputed replay`), bytes: 256 MiB. A step of four
/// contacts is a line of about 160 bytes: a million steps fit.
pub const MAX_SEQUENCE_FILE_BYTES: u64 = 256 << 20;

/// Largest scene file, bytes: 1 MiB. A scene is a few dozen lines of TOML written by hand (the
/// mesh is a separate file).
pub const MAX_SCENE_FILE_BYTES: u64 = 1 << 20;

/// Reads the file at `path` whole, refusing more than `max_bytes` bytes; `kind` names the
/// limit in the message (`a mesh file`).
///
/// A regular file larger than `max_bytes` is refused from its size, before anything is read.
/// Anything else (a pipe, `/dev/zero`, a character device) is read through `take(max_bytes + 1)`
/// and refused once it yields more than `max_bytes`: its memory is bounded whatever it streams.
/// The error is an [`io::Error`] of kind [`io::ErrorKind::InvalidData`] saying so; the callers
/// put the file name in front, as for any read error.
pub fn read_bounded(path: &Path, max_bytes: u64, kind: &str) -> io::Result<Vec<u8>> {
    let file = File::open(path)?;
    let meta = file.metadata()?;
    let mut bytes = Vec::new();
    if meta.is_file() {
        if meta.len() > max_bytes {
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!(
                    "{} bytes, more than {max_bytes} bytes, the limit for {kind}",
                    meta.len()
                ),
            ));
        }
        // The size is known and bounded: one allocation (the file may still change meanwhile).
        bytes
            .try_reserve_exact(usize::try_from(meta.len()).unwrap_or(usize::MAX))
            .map_err(|e| io::Error::new(io::ErrorKind::OutOfMemory, e.to_string()))?;
    }
    file.take(max_bytes.saturating_add(1))
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > max_bytes {
        let what = if meta.is_file() {
            "a file that grew while read"
        } else {
            "not a regular file"
        };
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            format!(
                "{what}, and more than {max_bytes} bytes, the limit for {kind}: read stopped there"
            ),
        ));
    }
    Ok(bytes)
}

/// The memory available to a new allocation without swapping, bytes: `MemAvailable` of
/// `/proc/meminfo` (Linux 3.14 and later), or less if the process's cgroup (v2) has a memory
/// limit closer (`memory.max − memory.current`); `None` where neither is known (then the table
/// build checks only the size limits).
pub fn mem_available_bytes() -> Option<u64> {
    let system = std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|text| parse_mem_available(&text));
    match (system, cgroup_headroom_bytes()) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

/// `memory.max − memory.current` of this process's cgroup v2, if it has a limit.
fn cgroup_headroom_bytes() -> Option<u64> {
    let cgroup = std::fs::read_to_string("/proc/self/cgroup").ok()?;
    let path = cgroup.lines().find_map(|l| l.strip_prefix("0::"))?;
    let dir = Path::new("/sys/fs/cgroup").join(path.trim().trim_start_matches('/'));
    let read = |name: &str| std::fs::read_to_string(dir.join(name)).ok();
    let max: u64 = read("memory.max")?.trim().parse().ok()?;
    let current: u64 = read("memory.current")?.trim().parse().ok()?;
    Some(max.saturating_sub(current))
}

/// The `MemAvailable:  <n> kB` line of a `/proc/meminfo` text, in bytes.
pub fn parse_mem_available(meminfo: &str) -> Option<u64> {
    let line = meminfo
        .lines()
        .find_map(|l| l.strip_prefix("MemAvailable:"))?;
    let mut fields = line.split_whitespace();
    let value: u64 = fields.next()?.parse().ok()?;
    match fields.next() {
        Some("kB") => value.checked_mul(1024),
        None => Some(value),
        Some(_) => None,
    }
}

/// `bytes` for people: `1.5 GB (1500000000 bytes)`, decimal units.
pub fn human_bytes(bytes: u64) -> String {
    let b = bytes as f64;
    let short = if b >= 1e9 {
        format!("{:.1} GB", b / 1e9)
    } else if b >= 1e6 {
        format!("{:.1} MB", b / 1e6)
    } else if b >= 1e3 {
        format!("{:.1} kB", b / 1e3)
    } else {
        return format!("{bytes} bytes");
    };
    format!("{short} ({bytes} bytes)")
}
