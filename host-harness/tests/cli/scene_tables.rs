//! `palpate scene tables` and `palpate scene replay-hybrid` on the firmware's hybrid scene
//! (`tools/firmware-m4f/hybrid-scene.toml`): the three tables of each precision, the replay of
//! the firmware's sequence on them, and each bad input as one line and exit status 2.

use std::path::{Path, PathBuf};

use crate::common::{assert_one_line_error, fresh_dir, palpate, stderr, text};
use palpate::hybrid::owned::with_hybrid_files;
use palpate::table::load::TableFile;
use palpate_kernel::table::format::TableKind;

/// `rel` under the workspace's `tools/firmware-m4f/`, as a string.
fn firmware(rel: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tools/firmware-m4f")
        .join(rel)
        .display()
        .to_string()
}

/// Runs `scene tables` on the firmware scene into a fresh folder `name`.
fn tables(name: &str, precision: &str) -> PathBuf {
    let dir = fresh_dir(name).join("out");
    let out = palpate(&[
        "scene",
        "tables",
        &firmware("hybrid-scene.toml"),
        "--out-dir",
        &dir.display().to_string(),
        "--precision",
        precision,
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    dir
}

fn read(dir: &Path) -> [TableFile; 3] {
    ["precomputed.bin", "dynamic.bin", "interface.bin"]
        .map(|f| TableFile::read(&dir.join(f)).expect("table"))
}

#[test]
fn writes_three_tables_that_belong_together_in_each_precision() {
    for precision in ["f32", "f64"] {
        let dir = tables(&format!("tables-{precision}"), precision);
        let files = read(&dir);
        let kinds = files.each_ref().map(|f| f.kind());
        assert_eq!(
            kinds,
            [
                Some(TableKind::Precomputed),
                Some(TableKind::TensorMass),
                Some(TableKind::Interface)
            ]
        );
        // The kernel couples them (vertex numbering, connection nodes, rest positions).
        let counts = match precision {
            "f32" => with_hybrid_files(
                files.each_ref(),
                palpate_script::hybrid::params(palpate_kernel::tensor_mass::ElasticLaw::Linear),
                |h| {
                    (
                        h.interface().vertex_count(),
                        h.interface().connection_count(),
                    )
                },
            ),
            _ => with_hybrid_files(
                files.each_ref(),
                palpate_kernel::tensor_mass::DynamicParams::linear(20.0, 0.01),
                |h| {
                    (
                        h.interface().vertex_count(),
                        h.interface().connection_count(),
                    )
                },
            ),
        }
        .expect("coupled");
        // The top corner cell: 8 vertices, all but the box's corner connection nodes.
        assert_eq!(counts, (64, 7));
        // No temporary file left beside them: the three and the marker of
        // a folder palpate wrote (the next run replaces it whole).
        let mut names: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        assert_eq!(
            names,
            [
                ".palpate-series",
                "dynamic.bin",
                "interface.bin",
                "precomputed.bin"
            ]
        );
    }
}

#[test]
fn replay_hybrid_prints_one_line_per_step_the_same_twice() {
    let dir = tables("replay", "f32").display().to_string();
    let sequence = firmware("hybrid-sequence.txt");
    let run = || palpate(&["scene", "replay-hybrid", &dir, &sequence]);
    let (first, second) = (run(), run());
    assert!(first.status.success(), "{}", stderr(&first));
    assert_eq!(first.stdout, second.stdout);
    let lines = text(&first.stdout);
    let steps = std::fs::read_to_string(&sequence)
        .unwrap()
        .lines()
        .filter(|l| !l.split('#').next().unwrap_or("").trim().is_empty())
        .count();
    assert_eq!(lines.lines().count(), steps);
    for (i, line) in lines.lines().enumerate() {
        assert!(line.starts_with(&format!("step {i} ")), "{line}");
    }
    assert!(
        lines.contains(" error contact 0: vertex 5 is fixed"),
        "{lines}"
    );
    assert!(lines.lines().filter(|l| l.contains(" ke 0x")).count() >= steps - 2);
}

#[test]
fn a_scene_that_is_not_a_hybrid_is_one_line() {
    let dir = fresh_dir("not-hybrid").display().to_string();
    for scene in ["built-in", "built-in-dynamic"] {
        let out = palpate(&["scene", "tables", scene, "--out-dir", &dir]);
        assert_one_line_error(&out, &[scene, "not a hybrid"]);
    }
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0);
}

#[test]
fn an_output_that_is_an_input_is_refused_before_any_work() {
    let dir = fresh_dir("input");
    // The scene itself, named as one of the outputs.
    let scene = dir.join("interface.bin");
    let toml = std::fs::read_to_string(firmware("hybrid-scene.toml"))
        .unwrap()
        .replace("mesh/box.node", &firmware("mesh/box.node"));
    std::fs::write(&scene, &toml).unwrap();
    let out = palpate(&[
        "scene",
        "tables",
        &scene.display().to_string(),
        "--out-dir",
        &dir.display().to_string(),
    ]);
    assert_one_line_error(
        &out,
        &["interface.bin is inside --out-dir", "replaced as a whole"],
    );
    assert_eq!(std::fs::read_to_string(&scene).unwrap(), toml);
    assert!(!dir.join("precomputed.bin").exists());
}

#[test]
fn replay_hybrid_without_tables_is_one_line() {
    let dir = fresh_dir("no-tables").display().to_string();
    let out = palpate(&[
        "scene",
        "replay-hybrid",
        &dir,
        &firmware("hybrid-sequence.txt"),
    ]);
    assert_one_line_error(&out, &["precomputed.bin"]);
}
