//! Puts `memory.x` on the linker path and links the recordings named by
//! `PALPATE_CYCLES_RECORDINGS`: folders written by `palpate budget --record`
//! (`tools/cycles-check.sh` writes one per contact count, `m1` … `m4`),
//! separated by `:`. Their tables must be byte-identical (the same scene):
//! the first folder's are copied to `$OUT_DIR` where `include_table!` links
//! them, `table.bin` (pre-computed or, with `--features dynamic`, tensor-mass)
//! or, with `--features hybrid`, `precomputed.bin`, `dynamic.bin` and
//! `interface.bin`. Every run of every folder's `runs.txt` becomes an entry of
//! `$OUT_DIR/runs.rs`'s `RUNS`: its label `<folder name>/<trajectory>`, its
//! static bound (cycles) and its `.ticks` recording.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

const VAR: &str = "PALPATE_CYCLES_RECORDINGS";

fn main() {
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("OUT_DIR"));
    std::fs::copy("memory.x", out.join("memory.x")).expect("copy memory.x");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-env-changed={VAR}");
    let Some(folders) = std::env::var_os(VAR) else {
        panic!(
            "set {VAR} to folders written by `palpate budget --record` (see tools/cycles-check.sh)"
        );
    };
    let folders: Vec<PathBuf> = std::env::split_paths(&folders).collect();
    let tables: &[(&str, &str)] = if std::env::var_os("CARGO_FEATURE_HYBRID").is_some() {
        &[
            ("table.precomputed", "precomputed.bin"),
            ("table.dynamic", "dynamic.bin"),
            ("table.interface", "interface.bin"),
        ]
    } else {
        &[("table", "table.bin")]
    };
    let first = folders
        .first()
        .unwrap_or_else(|| panic!("{VAR} names no folder"));
    for (from, to) in tables {
        let bytes = read(&first.join(from));
        for other in &folders[1..] {
            if read(&other.join(from)) != bytes {
                panic!(
                    "{VAR}: {} and {} hold different tables",
                    first.display(),
                    other.display()
                );
            }
        }
        std::fs::write(out.join(to), bytes).expect("write table");
    }
    let mut runs = String::from("/// The recorded runs (build.rs).\nstatic RUNS: &[Run] = &[\n");
    for folder in &folders {
        let name = folder
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let list = String::from_utf8(read(&folder.join("runs.txt"))).expect("runs.txt: UTF-8");
        for line in list.lines() {
            let [trajectory, _ticks, bound] = line.split(' ').collect::<Vec<_>>()[..] else {
                panic!(
                    "{}: `{line}`: expected `<trajectory> <ticks> <bound>`",
                    folder.display()
                );
            };
            let ticks = folder.join(format!("{trajectory}.ticks"));
            println!("cargo:rerun-if-changed={}", ticks.display());
            let _ = writeln!(
                runs,
                "    Run {{ label: {:?}, bound_cycles: {bound}, ticks: include_bytes!({:?}) }},",
                format!("{name}/{trajectory}"),
                ticks.canonicalize().expect("ticks path")
            );
        }
    }
    runs.push_str("];\n");
    std::fs::write(out.join("runs.rs"), runs).expect("write runs.rs");
}

fn read(path: &Path) -> Vec<u8> {
    println!("cargo:rerun-if-changed={}", path.display());
    std::fs::read(path).unwrap_or_else(|e| panic!("{VAR}: {}: {e}", path.display()))
}
