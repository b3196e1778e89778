//! See `super`: the bounds probes. Every input and run is bounded before the
//! work starts (`palpate::limits`): a trajectory's span and times, the
//! haptic rate and the tick count; table and mesh files (header first, size
//! before reading, bounded reads of pipes and devices); a table's size and
//! its build's memory, estimated from the mesh's counts
//! (`palpate::table::estimate`). These run in process; the probes that need
//! the binary (`precomputed solve /dev/zero`, a piped table, a run under a
//! memory limit) are in `host-harness/tests/cli/robustness/bounds.rs`.

use core::time::Duration;
use std::path::{Path, PathBuf};
use std::time::Instant;

use palpate::chart::{GivenMesh, Matrix};
use palpate::fem::material::Material;
use palpate::fix::{FixPredicate, fixed_vertices};
use palpate::hybrid::estimate::{HybridEstimate, PrecomputedRegion};
use palpate::hybrid::{HybridOptions, RegionSplit, build_hybrid, check_hybrid};
use palpate::limits::{
    MAX_HAPTIC_HZ, MAX_MESH_FILE_BYTES, MAX_SESSION_TICKS, MAX_TABLE_FILE_BYTES,
    MAX_TRAJECTORY_SPAN_S, MAX_TRAJECTORY_TIME_S, parse_mem_available, read_bounded,
};
use palpate::limits::{MAX_POSITION_LINE_BYTES, MAX_RUN_TET_STEPS, MAX_ZONE_PATH_SEGMENTS};
use palpate::mesh::generate::box_mesh;
use palpate::mesh::{MeshReport, TetMesh, boundary_surface, read_mesh};
use palpate::scene::zones::merge_collinear;
use palpate::scene::{MeshSource, Scene, Trajectory};
use palpate::session::options::check_scene_table;
use palpate::session::run::{run_session, tick_count};
use palpate::table::build::{BuildOptions, build_with_limits};
use palpate::table::compliance::{Solver, check_cg_work};
use palpate::table::estimate::{SizeLimits, TableEstimate};
use palpate::table::file::Precision;
use palpate::table::load::TableFile;
use palpate::tensor_mass::evaluate::{positions_file_bytes, read_positions_csv};
use palpate::tensor_mass::stability::{CRITICAL_DT_STEPS, critical_dt_of_mesh};
use palpate_kernel::table::format::{HEADER_LEN, RawHeader};
use palpate_kernel::tensor_mass::Integrator;

/// How soon a refusal "before any work" must come: the refusals below take well under a second
/// alone, and the work they refuse takes minutes (or aborts on its allocation), so a generous
/// bound tells the two apart on a shared, loaded machine without timing anything finely (these
/// runs once took over 1 s with other builds beside them).
const REFUSED_WITHIN: Duration = Duration::from_secs(10);

/// An empty folder of its own for test `name`.
fn fresh_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "palpate-robustness-bounds-{name}-{}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("test folder");
    dir
}

fn traj_err(text: &str) -> String {
    match Trajectory::from_csv_str(text, "traj.csv", 1) {
        Ok(t) => panic!("expected an error, got {} samples", t.samples().len()),
        Err(e) => e.to_string(),
    }
}

fn lenient_err(text: &str) -> String {
    match Trajectory::from_csv_str_unchecked(text, "traj.csv", 1) {
        Ok((t, _)) => panic!("expected an error, got {} samples", t.samples().len()),
        Err(e) => e.to_string(),
    }
}

const GENERATED: &str = "generated = { box = [0.1, 0.1, 0.05], cells = [2, 2, 1] }\n\
    fix = [\"z<0.001\"]\nmaterial = { young_pa = 3000, poisson = 0.45 }\n";

/// `haptic_hz = 1e7` was accepted. Now anything above 10 kHz is refused,
/// naming the key; 10 kHz itself is accepted.
#[test]
fn haptic_rate_above_ten_khz_is_refused_naming_the_key() {
    let err = Scene::from_toml_str_named(
        &format!("{GENERATED}rates = {{ haptic_hz = 1e7 }}\n"),
        "fast.toml",
        Path::new(""),
    )
    .expect_err("1e7 Hz refused")
    .to_string();
    assert_eq!(
        err,
        "fast.toml: [rates] haptic_hz = 10000000: above 10000 Hz (MAX_HAPTIC_HZ): haptic devices servo at 1 to 10 kHz"
    );
    let scene = Scene::from_toml_str(
        &format!("{GENERATED}rates = {{ haptic_hz = 10000 }}\n"),
        Path::new(""),
    )
    .expect("10 kHz accepted");
    assert_eq!(scene.rates.haptic_hz, MAX_HAPTIC_HZ);
    // A scene changed in code is checked again by validate.
    let mut scene = Scene::built_in();
    scene.rates.haptic_hz = 20_000.0;
    assert!(scene.validate().is_err());
}

/// One sample at `t = 1e9` after one at 0 ran 10¹² ticks (670 MB of output
/// in a minute, until the disk filled). Now a trajectory spans at most an
/// hour; the error names the line and the line it is too far from, in the
/// checked and the lenient reader alike.
#[test]
fn trajectory_span_beyond_one_hour_is_refused_naming_the_line() {
    let far = "t,tool,x,y,z\n0,0,0,0,0\n1e9,0,0,0,0\n";
    let expected = "traj.csv: line 3: time 1000000000 s is 1000000000 s from line 2 at 0 s: \
                    a trajectory spans at most 3600 s (MAX_TRAJECTORY_SPAN_S); split a longer one";
    assert_eq!(traj_err(far), expected);
    assert_eq!(lenient_err(far), expected);
    // Exactly an hour is accepted, a microsecond more is not.
    let hour = Trajectory::from_csv_str("t,tool,x,y,z\n0,0,0,0,0\n3600,0,0,0,0\n", "h", 1)
        .expect("one hour");
    assert_eq!(hour.end_s() - hour.start_s(), MAX_TRAJECTORY_SPAN_S);
    assert!(traj_err("t,tool,x,y,z\n0,0,0,0,0\n3600.000001,0,0,0,0\n").contains("line 3"));
    // Lenient: a time going back far below the earliest is measured from the latest.
    assert_eq!(
        lenient_err("t,tool,x,y,z\n0,0,0,0,0\n3000,0,0,0,0\n-1000,0,0,0,0\n"),
        "traj.csv: line 4: time -1000 s is 4000 s from line 3 at 3000 s: \
         a trajectory spans at most 3600 s (MAX_TRAJECTORY_SPAN_S); split a longer one"
    );
    // Non-finite times stay findings of the lenient reader, not span errors.
    let (t, findings) =
        Trajectory::from_csv_str_unchecked("t,tool,x,y,z\n0,0,0,0,0\ninf,0,0,0,0\n", "r", 1)
            .expect("lenient");
    assert_eq!((t.samples().len(), findings.len()), (2, 1));
}

/// `t = 1e300` wrapped the tick count to "0 ticks" with exit 0. A time
/// beyond ±2³² s is refused (its resolution would be coarser than a tick);
/// a Unix timestamp is accepted.
#[test]
fn trajectory_time_out_of_range_is_refused() {
    let expected = "traj.csv: line 3: time 1e300 s is out of range: \
                    a trajectory time is within ±4294967296 s (MAX_TRAJECTORY_TIME_S)";
    let text = "t,tool,x,y,z\n0,0,0,0,0\n1e300,0,0,0,0\n";
    assert_eq!(traj_err(text), expected);
    assert_eq!(lenient_err(text), expected);
    assert!(traj_err("t,tool,x,y,z\n-1e10,0,0,0,0\n").contains("line 2: time -1e10 s"));
    let unix = Trajectory::from_csv_str(
        "t,tool,x,y,z\n1764060000,0,0,0,0\n1764060060.5,0,0,0,0\n",
        "log.csv",
        1,
    )
    .expect("Unix timestamps");
    assert_eq!(unix.end_s() - unix.start_s(), 60.5);
    assert!(unix.end_s() < MAX_TRAJECTORY_TIME_S);
}

/// The tick count is computed in checked arithmetic against
/// `MAX_SESSION_TICKS` (an hour at 10 kHz, plus the first tick): reached
/// exactly by the longest trajectory at the highest rate, an error beyond
/// and for a period that is not a finite positive number, never a wrapped
/// or saturated count.
#[test]
fn tick_count_is_checked() {
    let hour = Trajectory::from_csv_str("t,tool,x,y,z\n0,0,0,0,0\n3600,0,0,0,0\n", "h", 1)
        .expect("one hour");
    assert_eq!(
        tick_count(&hour, 1.0 / MAX_HAPTIC_HZ).expect("an hour at 10 kHz"),
        MAX_SESSION_TICKS
    );
    assert_eq!(MAX_SESSION_TICKS, 36_000_001);
    assert_eq!(tick_count(&hour, 1e-3).expect("1 kHz"), 3_600_001);
    let err = tick_count(&hour, 1e-7).expect_err("10 MHz").to_string();
    assert!(err.contains("MAX_SESSION_TICKS"), "{err}");
    for tick_s in [0.0, -1e-3, f64::NAN, f64::INFINITY, 1e-320] {
        assert!(tick_count(&hour, tick_s).is_err(), "{tick_s}");
    }
    let single = Trajectory::from_csv_str("t,tool,x,y,z\n5,0,0,0,0\n", "s", 1).expect("one");
    assert_eq!(tick_count(&single, 1e-3).expect("one tick"), 1);
}

/// A scene changed in code past the rate limit (not validated again) is
/// still refused by the session, before the mesh is built or a line is
/// written.
#[test]
fn session_refuses_an_unbounded_run_before_any_work() {
    let mut scene = Scene::built_in();
    scene.rates.haptic_hz = 1e7;
    let hour = Trajectory::from_csv_str("t,tool,x,y,z\n0,0,0,0,0\n3600,0,0,0,0\n", "h", 1)
        .expect("one hour");
    let mut out = Vec::new();
    let started = Instant::now();
    let err = format!(
        "{:#}",
        run_session(&scene, &hour, &mut out, None).expect_err("refused")
    );
    assert!(err.contains("MAX_SESSION_TICKS"), "{err}");
    assert!(out.is_empty(), "nothing written");
    assert!(started.elapsed() < REFUSED_WITHIN);
}

/// A table's fixed-size header is read first: `/dev/zero` and a 1 GB file
/// of zeros (which once cost twice their size before the magic was checked)
/// are refused at once; a header declaring more than the largest table file
/// or a length other than the file's is refused before the rest is read; a
/// good table reads back byte for byte.
#[test]
fn table_files_are_checked_from_their_header_first() {
    let dir = fresh_dir("table");
    let started = Instant::now();
    let err = TableFile::read(Path::new("/dev/zero"))
        .err()
        .expect("/dev/zero refused")
        .to_string();
    assert!(err.contains("not a Palpate table"), "{err}");
    let zeros = dir.join("zeros.tbl");
    let file = std::fs::File::create(&zeros).expect("create");
    file.set_len(1 << 30).expect("sparse 1 GiB");
    drop(file);
    let err = TableFile::read(&zeros)
        .err()
        .expect("zeros refused")
        .to_string();
    assert!(err.contains("not a Palpate table"), "{err}");
    assert!(started.elapsed() < REFUSED_WITHIN);

    let good = palpate_tests::reference_cube_table(Precision::F32);
    let bytes = good.bytes().to_vec();
    let path = dir.join("cube.tbl");
    std::fs::write(&path, &bytes).expect("write");
    assert_eq!(
        TableFile::read(&path).expect("good table").bytes(),
        &bytes[..]
    );
    // Truncated or padded: the header's length disagrees with the file's.
    std::fs::write(&path, &bytes[..bytes.len() - 100]).expect("write");
    let err = TableFile::read(&path).err().expect("truncated").to_string();
    assert!(err.contains("truncated or padded"), "{err}");
    // Shorter than a header.
    std::fs::write(&path, &bytes[..HEADER_LEN - 1]).expect("write");
    let err = TableFile::read(&path).err().expect("short").to_string();
    assert!(
        err.contains("shorter than the 112-byte table header"),
        "{err}"
    );
    // A header declaring 5 GiB, in a (sparse) file of that size.
    let at = core::mem::offset_of!(RawHeader, file_len);
    let mut header = bytes[..HEADER_LEN].to_vec();
    header[at..at + 8].copy_from_slice(&(5u64 << 30).to_le_bytes());
    std::fs::write(&path, &header).expect("write");
    std::fs::File::options()
        .write(true)
        .open(&path)
        .and_then(|f| f.set_len(5 << 30))
        .expect("sparse 5 GiB");
    let started = Instant::now();
    let err = TableFile::read(&path).err().expect("huge").to_string();
    assert!(
        err.contains(&format!(
            "the header declares 5368709120 bytes, above the largest table file, {MAX_TABLE_FILE_BYTES} bytes (MAX_TABLE_FILE_BYTES)"
        )),
        "{err}"
    );
    // `tables info` refuses it too (above the size it reads whole).
    assert!(TableFile::read_for_report(&path).is_err());
    assert!(started.elapsed() < REFUSED_WITHIN);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Meshes are read whole, but bounded: a regular file above the limit is
/// refused from its size before anything is read; a device or a pipe
/// (`/dev/zero`) is read through `take(max + 1)` and refused once it gives
/// more.
#[test]
fn mesh_files_are_bounded_before_reading() {
    let dir = fresh_dir("mesh");
    let big = dir.join("big.msh");
    let file = std::fs::File::create(&big).expect("create");
    file.set_len(MAX_MESH_FILE_BYTES + 1).expect("sparse file");
    drop(file);
    let started = Instant::now();
    let err = read_mesh(&big).expect_err("refused").to_string();
    assert!(
        err.ends_with(&format!(
            "big.msh: cannot read file: {} bytes, more than {MAX_MESH_FILE_BYTES} bytes, the limit for a mesh file (MAX_MESH_FILE_BYTES)",
            MAX_MESH_FILE_BYTES + 1
        )),
        "{err}"
    );
    assert!(started.elapsed() < REFUSED_WITHIN);
    // The bounded reader the mesh, trajectory and scene readers share.
    let err = read_bounded(Path::new("/dev/zero"), 1 << 20, "a test file").expect_err("refused");
    assert_eq!(
        err.to_string(),
        "not a regular file, and more than 1048576 bytes, the limit for a test file: read stopped there"
    );
    let small = dir.join("small.txt");
    std::fs::write(&small, b"12345").expect("write");
    assert_eq!(
        read_bounded(&small, 5, "x").expect("at the limit"),
        b"12345"
    );
    assert!(read_bounded(&small, 4, "x").is_err());
    let _ = std::fs::remove_dir_all(&dir);
}

/// `MemAvailable` of `/proc/meminfo`, in bytes.
#[test]
fn mem_available_is_parsed_in_bytes() {
    let text = "MemTotal:       24000000 kB\nMemFree:  1 kB\nMemAvailable:   123 kB\n";
    assert_eq!(parse_mem_available(text), Some(123 * 1024));
    assert_eq!(parse_mem_available("MemTotal: 5 kB\n"), None);
}

fn material() -> Material {
    Material::new(3000.0, 0.45).expect("material")
}

fn base() -> Vec<FixPredicate> {
    vec!["z<0.001".parse().expect("predicate")]
}

/// No limit but the table file's: what the estimate tests build with.
const UNLIMITED: SizeLimits = SizeLimits {
    max_table_bytes: None,
    available_bytes: None,
    print_estimate: false,
};

/// The estimate of `options` on `mesh`, and the real size of its table.
fn estimate_and_build(
    mesh: &TetMesh,
    report: &MeshReport,
    options: &BuildOptions,
) -> (TableEstimate, u64) {
    let (fixed, _) = fixed_vertices(&mesh.positions, &options.fix, &report.unreferenced_vertices);
    let estimate = TableEstimate::of_build(mesh, report, options, &fixed, &boundary_surface(mesh));
    let built = build_with_limits(mesh, report, options, &UNLIMITED).expect("build");
    (estimate, built.bytes.len() as u64)
}

/// The estimate against the real size of built tables. Pre-computed: never
/// below, above by less than `32·Vs + 16` bytes (the grid's cell count is
/// bounded, not known, before the build); measured on the reference cube,
/// a generated block and the reference liver, in f32 and f64. Tensor-mass:
/// exact on these meshes (solids without holes, where Euler's formula gives
/// the edge count).
#[test]
fn table_size_estimate_matches_built_tables() {
    let liver = read_mesh(&palpate_tests::reference_dir().join("meshes/liver.msh")).expect("liver");
    let meshes: Vec<(&str, TetMesh, MeshReport, Vec<FixPredicate>)> = vec![
        {
            let (m, r) =
                read_mesh(&palpate_tests::reference_dir().join("meshes/cube.msh")).expect("cube");
            ("cube", m, r, base())
        },
        (
            "block",
            box_mesh([8, 6, 3], [0.12, 0.09, 0.045]),
            MeshReport::default(),
            base(),
        ),
        {
            // The liver's lowest vertices fixed (9 of 181; SOFA's units).
            let lowest = liver
                .0
                .positions
                .iter()
                .map(|p| p[2])
                .fold(f64::INFINITY, f64::min);
            let fix = vec![format!("z<{}", lowest + 0.5).parse().expect("predicate")];
            ("liver", liver.0, liver.1, fix)
        },
    ];
    for (name, mesh, report, fix) in &meshes {
        for precision in [Precision::F32, Precision::F64] {
            let options =
                BuildOptions::precomputed(material(), fix.clone(), Solver::Cholesky, precision);
            let (estimate, real) = estimate_and_build(mesh, report, &options);
            // The grid's bounds: 8 cells per surface vertex (starts of 4
            // bytes), up to 4³ list cells per cell, 343 list entries per
            // surface triangle; and alignment.
            let slack = (8 * 4 + 8 * 64 * 4) * estimate.counts.surface_vertices
                + 343 * 4 * estimate.counts.surface_triangles
                + 32;
            println!(
                "{name} {precision:?} pre-computed: estimate {} real {real} (slack {slack}); peak {}",
                estimate.table_bytes, estimate.peak_bytes
            );
            assert!(
                estimate.table_bytes >= real && estimate.table_bytes - real < slack,
                "{name} {precision:?}: estimate {} real {real}",
                estimate.table_bytes
            );
            assert!(estimate.peak_bytes > 2 * estimate.table_bytes);
            let options = BuildOptions::tensor_mass(material(), 1000.0, fix.clone(), precision);
            let (estimate, real) = estimate_and_build(mesh, report, &options);
            println!(
                "{name} {precision:?} tensor-mass: estimate {} real {real}",
                estimate.table_bytes
            );
            assert_eq!(
                estimate.table_bytes, real,
                "{name} {precision:?} tensor-mass"
            );
        }
    }
}

/// A 40³-cell box (68 921 vertices, under the scene cap of 10 million)
/// aborted with "memory allocation of 33 830 337 528 bytes failed". Its
/// table is now estimated from the counts (501 240 880 blocks: 67 240 free
/// × 7 921 touchable vertices, 18 GB in f32) and refused in well under a
/// second (the fixed vertices, the surface and the estimate) before anything
/// of its size is allocated; as a scene too. Smaller tables are refused by the memory
/// available or by `--max-table-bytes` with the same one line.
#[test]
fn oversized_tables_are_refused_before_building() {
    let mesh = box_mesh([40, 40, 40], [0.4, 0.4, 0.4]);
    assert_eq!(mesh.positions.len(), 68_921);
    let options = BuildOptions::precomputed(material(), base(), Solver::Cholesky, Precision::F32);
    let report = MeshReport {
        source: "box40".into(),
        ..MeshReport::default()
    };
    let started = Instant::now();
    let err = build_with_limits(&mesh, &report, &options, &UNLIMITED)
        .expect_err("refused")
        .to_string();
    let elapsed = started.elapsed();
    println!("{err}\nrefused in {elapsed:?}");
    assert!(elapsed < REFUSED_WITHIN, "{elapsed:?}");
    assert!(!err.contains('\n'), "one line: {err}");
    for part in [
        "box40: the pre-computed table (501240880 compliance blocks: 67240 free x 7921 touchable vertices, f32) would be 18.1 GB (",
        "above the largest table file, 4.3 GB (4294967296 bytes) (MAX_TABLE_FILE_BYTES)",
        "refused before building",
        "tensor-mass",
        "a coarser mesh",
    ] {
        assert!(err.contains(part), "missing `{part}` in: {err}");
    }

    // The same box as a generated scene: refused by `session run` (and
    // `budget`, which builds through the same `SceneModel::tables`).
    let mut scene = Scene::built_in();
    scene.mesh = MeshSource::GeneratedBox {
        size_m: [0.4, 0.4, 0.4],
        cells: [40, 40, 40],
    };
    scene.validate().expect("under the generated-mesh cap");
    let poke = Trajectory::from_csv_str(
        "t,tool,x,y,z\n0,0,0.2,0.2,0.5\n0.01,0,0.2,0.2,0.5\n",
        "p",
        1,
    )
    .expect("trajectory");
    let started = Instant::now();
    let err = format!(
        "{:#}",
        run_session(&scene, &poke, &mut Vec::new(), None).expect_err("refused")
    );
    assert!(err.contains("would be 18.1 GB"), "{err}");
    assert!(started.elapsed() < REFUSED_WITHIN);
    let (mesh40, report40) = scene.load_mesh().expect("generated");
    let err = check_scene_table(&scene, &mesh40, &report40)
        .expect_err("refused")
        .to_string();
    assert!(
        err.starts_with("generated box 0.4 x 0.4 x 0.4 m, 40 x 40 x 40 cells: "),
        "{err}"
    );

    // A small block: refused by the memory available, or by a table limit.
    let mesh = box_mesh([6, 6, 3], [0.12, 0.12, 0.06]);
    let limits = SizeLimits {
        available_bytes: Some(1_000_000),
        ..UNLIMITED
    };
    let err = build_with_limits(&mesh, &report, &options, &limits)
        .expect_err("refused")
        .to_string();
    assert!(
        err.contains("only 1.0 MB (1000000 bytes) of memory is available (MemAvailable)"),
        "{err}"
    );
    let limits = SizeLimits {
        max_table_bytes: Some(1000),
        ..UNLIMITED
    };
    let err = build_with_limits(&mesh, &report, &options, &limits)
        .expect_err("refused")
        .to_string();
    assert!(
        err.contains("the table is above --max-table-bytes 1000 bytes"),
        "{err}"
    );
    // Within the limits it builds, to the estimated size.
    let (fixed, _) = fixed_vertices(&mesh.positions, &options.fix, &[]);
    let estimate =
        TableEstimate::of_build(&mesh, &report, &options, &fixed, &boundary_surface(&mesh));
    let limits = SizeLimits {
        max_table_bytes: Some(estimate.table_bytes),
        available_bytes: Some(estimate.peak_bytes),
        print_estimate: true,
    };
    let built = build_with_limits(&mesh, &report, &options, &limits).expect("at the limits");
    assert!(built.bytes.len() as u64 <= estimate.table_bytes);
}

/// The tets of `mesh` whose centroid lies in the box `[lo, hi]` (m).
fn tets_in(mesh: &TetMesh, lo: [f64; 3], hi: [f64; 3]) -> Vec<bool> {
    (0..mesh.tets.len())
        .map(|t| {
            let c = mesh.tet_centroid(t);
            (0..3).all(|i| c[i] > lo[i] && c[i] < hi[i])
        })
        .collect()
}

/// A 40³-cell box (68 921 vertices) with one 1-cm cell dynamic aborted
/// `session run`, `scene tables`, `dynamic run --scene` and `critical-dt
/// --scene` on a 32 GB allocation: the hybrid build skipped the size
/// estimate `tables build` makes. Now every table of the hybrid is estimated
/// first and the build is refused before any array is computed, naming the
/// table and the limit. The estimate's block count is the hand count: the
/// box's 7 921 free surface vertices less the 7 of the dynamic cell on the
/// surface (fixed as connection nodes or outside the region), against its
/// 67 240 free vertices less the cell's 8.
#[test]
fn a_hybrid_too_large_is_refused_before_building() {
    let mesh = box_mesh([40, 40, 40], [0.4; 3]);
    let report = MeshReport {
        source: "box40".into(),
        ..MeshReport::default()
    };
    let dynamic = tets_in(&mesh, [0.0, 0.0, 0.39], [0.01, 0.01, 0.4]);
    assert_eq!(dynamic.iter().filter(|&&d| d).count(), 6);
    let options = HybridOptions::new(
        Material::new(3000.0, 0.45).expect("material"),
        1000.0,
        vec!["z<0.001".parse().expect("predicate")],
        Precision::F32,
    );
    let err = match build_hybrid(&mesh, &report, &dynamic, &options) {
        Ok(_) => panic!("a 18 GB pre-computed table was built"),
        Err(e) => e.to_string(),
    };
    for needle in [
        "box40: ",
        "pre-computed region",
        "MAX_TABLE_FILE_BYTES",
        "refused before building",
        "coarser mesh",
    ] {
        assert!(err.contains(needle), "{needle:?} not in {err}");
    }
    let err_check = check_hybrid(&mesh, &report, &dynamic, &options)
        .expect_err("the check refuses it too")
        .to_string();
    assert_eq!(err_check, err);
    let fixed: Vec<bool> = mesh.positions.iter().map(|p| p[2] < 0.001).collect();
    let split = RegionSplit::new(&mesh, &fixed, &dynamic).expect("split");
    let region = PrecomputedRegion::of(&mesh, &split, &fixed);
    let estimate = HybridEstimate::of(&mesh, &split, &fixed, &region, 0.002, Precision::F32);
    let (s, f) = (7921u64 - 7, 67_240u64 - 8);
    assert_eq!(estimate.precomputed.counts.touchable, s);
    assert_eq!(estimate.precomputed.counts.free, f);
    assert_eq!(estimate.precomputed.blocks, s * (s + 1) / 2 + (f - s) * s);
    assert!(estimate.precomputed.table_bytes > MAX_TABLE_FILE_BYTES);
    assert_eq!(estimate.interface.counts.connections, 7);
}

/// `dynamic critical-dt` on that box ran past two minutes with nothing
/// printed, and `dynamic run --steps 18446744073709551615` was accepted: the
/// work (tets × steps) is checked against `MAX_RUN_TET_STEPS` before the
/// table is built.
#[test]
fn critical_dt_and_run_beyond_the_work_limit_are_refused_before_building() {
    let mesh = box_mesh([40, 40, 40], [0.4; 3]);
    let report = MeshReport::default();
    let options = BuildOptions::tensor_mass(
        Material::new(3000.0, 0.45).expect("material"),
        1000.0,
        vec!["z<0.001".parse().expect("predicate")],
        Precision::F64,
    );
    let err = critical_dt_of_mesh(&mesh, &report, &options, 0.0, Integrator::SymplecticEuler)
        .expect_err("refused")
        .to_string();
    assert!(
        err.contains("dynamic critical-dt: 384000 tets x 60500 steps"),
        "{err}"
    );
    assert!(err.contains("MAX_RUN_TET_STEPS"), "{err}");
    // 384 000 tets × 60 500 steps = 2.3e10, above the 5e9 of the limit.
    assert_eq!(CRITICAL_DT_STEPS, 60_500);
    let limit = format!("the limit of {:.0e} tet-steps", MAX_RUN_TET_STEPS as f64);
    assert!(err.contains(&limit), "{err}");
    let err = palpate::limits::check_tet_steps("dynamic run", 6, u64::MAX, "fewer")
        .expect_err("refused")
        .to_string();
    assert!(err.contains("MAX_RUN_TET_STEPS"), "{err}");
    palpate::limits::check_tet_steps("dynamic run", 6, 1000, "fewer").expect("small run");
}

/// `stvk forces --deformed /dev/zero` grew to 23 GB: a positions file is
/// read up to `MAX_POSITION_LINE_BYTES` per vertex of its mesh.
#[test]
fn a_positions_file_is_read_bounded_by_its_mesh() {
    let err = read_positions_csv(Path::new("/dev/zero"), 100)
        .expect_err("refused")
        .to_string();
    assert!(err.contains("MAX_POSITION_LINE_BYTES"), "{err}");
    assert_eq!(positions_file_bytes(100), 101 * MAX_POSITION_LINE_BYTES);
}

/// `tables info` read a 1 GiB file of garbage whole before checking its
/// header (12 s, 2 GB). The header is read first: a file whose header is
/// not a table's is reported from its header alone.
#[test]
fn tables_info_reads_the_header_first() {
    let dir = fresh_dir("info-header");
    let path = dir.join("garbage.tbl");
    let file = std::fs::File::create(&path).expect("file");
    file.set_len(1 << 30).expect("sparse 1 GiB");
    drop(file);
    let read = TableFile::read_for_report(&path).expect("reported");
    assert_eq!(read.bytes().len(), HEADER_LEN);
    let report = read.info("garbage.tbl").expect_err("not a table");
    assert!(!report.is_empty());
    std::fs::remove_dir_all(&dir).ok();
}

/// A `path` zone tested every tet near every segment: a trajectory sampled at
/// 1 kHz along a straight cut is thousands of segments. Samples on one
/// straight segment are merged into it; a path that stays above
/// `MAX_ZONE_PATH_SEGMENTS` is refused when the scene is read, naming the
/// zone.
#[test]
fn path_zones_are_merged_and_bounded() {
    // 7 201 samples 10 µm apart on a line: one merged segment per 1 024 samples at most.
    let line: Vec<[f64; 3]> = (0..7201)
        .map(|k| [0.03 + 1e-5 * k as f64, 0.06, 0.056])
        .collect();
    let merged = merge_collinear(&line, 1e-12 * 0.072);
    assert!(merged.len() <= 9, "{}", merged.len());
    assert_eq!(merged.first(), line.first());
    assert_eq!(merged.last(), line.last());
    // A zigzag keeps every corner.
    let zigzag: Vec<[f64; 3]> = (0..50)
        .map(|k| [1e-3 * k as f64, 1e-3 * (k % 2) as f64, 0.0])
        .collect();
    assert_eq!(merge_collinear(&zigzag, 1e-15), zigzag);

    let dir = fresh_dir("long-path");
    let mut csv = String::from("t,tool,x,y,z\n");
    for k in 0..=MAX_ZONE_PATH_SEGMENTS + 1 {
        let y = if k % 2 == 0 { 0.01 } else { 0.02 };
        csv.push_str(&format!(
            "{},0,{},{y},0.05\n",
            k as f64 * 1e-3,
            1e-5 * k as f64
        ));
    }
    std::fs::write(dir.join("log.csv"), csv).expect("trajectory");
    let scene = format!(
        "{GENERATED}[model]\nkind = \"dynamic\"\ndamping_per_s = 0\n[[zone]]\nkind = \"cut\"\nshape = \"path\"\n\
         trajectory = \"log.csv\"\nradius_m = 0.02\n"
    );
    let err = Scene::from_toml_str(&scene, &dir)
        .expect_err("refused")
        .to_string();
    assert!(err.contains("MAX_ZONE_PATH_SEGMENTS"), "{err}");
    assert!(err.contains("[[zone]] 1"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `palpate chart` failed late: an unwritable `--out` after the whole study,
/// a mesh too small for the hybrid at step 88 of 212. Both are checked
/// before the study starts.
#[test]
fn chart_preflight_refuses_before_the_study() {
    let given = GivenMesh {
        label: "one-cell".into(),
        mesh: box_mesh([1, 1, 1], [0.01; 3]),
        report: MeshReport::default(),
        fix: vec!["z<0.001".parse().expect("predicate")],
        load_on: Vec::new(),
        material: Material::new(3000.0, 0.45).expect("material"),
    };
    let dir = fresh_dir("chart-preflight");
    let bodies = Matrix::quick().on(given).bodies().expect("bodies");
    let err = palpate::chart::preflight(&bodies, &dir.join("out"))
        .expect_err("no hybrid")
        .to_string();
    assert!(err.contains("mesh one-cell: no hybrid model"), "{err}");
    let file = dir.join("file.txt");
    std::fs::write(&file, "keep").expect("file");
    let err = palpate::chart::preflight(&[], &file.join("out"))
        .expect_err("not a folder")
        .to_string();
    assert!(err.contains("is not a folder"), "{err}");
    palpate::chart::preflight(&[], &dir.join("new").join("out")).expect("writable");
    assert!(!dir.join("new").exists(), "the check creates nothing");
    std::fs::remove_dir_all(&dir).ok();
}

/// `tables build --solver cg` on the 40³ box ran past two minutes with
/// nothing printed. CG's work (`3S` solves of about `sqrt(dof)` products
/// with `A`) is estimated before its first solve and refused above
/// `MAX_CG_MULTIPLY_ADDS`: a 20³ box (a 0.5 GB table the size limits
/// accept) is 1.7·10¹² multiply-adds.
#[test]
fn compliance_by_cg_beyond_its_work_limit_is_refused() {
    let mesh = box_mesh([20, 20, 20], [0.2; 3]);
    let options = BuildOptions::precomputed(
        Material::new(3000.0, 0.45).expect("material"),
        vec!["z<0.001".parse().expect("predicate")],
        Solver::Cg,
        Precision::F32,
    );
    let err = build_with_limits(&mesh, &MeshReport::default(), &options, &UNLIMITED)
        .expect_err("refused");
    let err = format!("{err:#}");
    assert!(err.contains("MAX_CG_MULTIPLY_ADDS"), "{err}");
    check_cg_work(100, 600, 30_000).expect("a small mesh");
}
