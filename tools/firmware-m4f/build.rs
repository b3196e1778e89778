//! Puts `memory.x` on the linker path and copies the tables where
//! `include_table!` links them into flash: by default the pre-computed table
//! named by `PALPATE_TABLE` to `$OUT_DIR/table.bin`; with the `hybrid`
//! feature the three tables in the folder named by `PALPATE_HYBRID_TABLES`
//! (`precomputed.bin`, `dynamic.bin`, `interface.bin`), and passes the
//! tensor-mass law named by `PALPATE_HYBRID_LAW` (default `linear`) to the
//! crate. `tools/firmware-check.sh` builds the tables with the host CLI and
//! sets the variables.

use std::path::PathBuf;

fn main() {
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("OUT_DIR"));
    std::fs::copy("memory.x", out.join("memory.x")).expect("copy memory.x");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=sequence.txt");
    println!("cargo:rerun-if-changed=hybrid-sequence.txt");
    let (var, command, files): (_, _, &[(&str, &str)]) =
        if std::env::var_os("CARGO_FEATURE_HYBRID").is_some() {
            (
                "PALPATE_HYBRID_TABLES",
                "a folder written by `palpate scene tables`",
                &[
                    ("precomputed.bin", "precomputed.bin"),
                    ("dynamic.bin", "dynamic.bin"),
                    ("interface.bin", "interface.bin"),
                ],
            )
        } else {
            (
                "PALPATE_TABLE",
                "a table built by `palpate tables build`",
                &[("", "table.bin")],
            )
        };
    println!("cargo:rerun-if-env-changed={var}");
    // The hybrid's tensor-mass law (a name of `palpate_script::hybrid::LAWS`;
    // src/hybrid.rs refuses another one on a `#` line).
    println!("cargo:rerun-if-env-changed=PALPATE_HYBRID_LAW");
    let law = std::env::var("PALPATE_HYBRID_LAW").unwrap_or_else(|_| "linear".into());
    println!("cargo:rustc-env=PALPATE_HYBRID_LAW={law}");
    if std::env::var_os("CARGO_FEATURE_HYBRID").is_none() {
        precomputed_replay(&out);
    }
    let Some(path) = std::env::var_os(var).map(PathBuf::from) else {
        panic!("set {var} to {command} (see tools/firmware-check.sh)");
    };
    for (from, to) in files {
        // "": the variable names the file itself.
        let from = if from.is_empty() {
            path.clone()
        } else {
            path.join(from)
        };
        println!("cargo:rerun-if-changed={}", from.display());
        std::fs::copy(&from, out.join(to))
            .unwrap_or_else(|e| panic!("{var}: {}: {e}", from.display()));
    }
}

/// The pre-computed replay's sequence and vertex count: `PALPATE_SEQUENCE`
/// (default `sequence.txt`) copied to `$OUT_DIR/sequence.txt`, and
/// `PALPATE_VERTICES` (default 64, `mesh/box`'s) written as the constant
/// `VERTICES` to `$OUT_DIR/vertices.rs` (the displacement buffer's length).
fn precomputed_replay(out: &std::path::Path) {
    println!("cargo:rerun-if-env-changed=PALPATE_SEQUENCE");
    println!("cargo:rerun-if-env-changed=PALPATE_VERTICES");
    let sequence = std::env::var_os("PALPATE_SEQUENCE")
        .map_or_else(|| PathBuf::from("sequence.txt"), PathBuf::from);
    println!("cargo:rerun-if-changed={}", sequence.display());
    std::fs::copy(&sequence, out.join("sequence.txt"))
        .unwrap_or_else(|e| panic!("PALPATE_SEQUENCE: {}: {e}", sequence.display()));
    let vertices: usize = std::env::var("PALPATE_VERTICES")
        .map_or(Ok(64), |v| v.parse())
        .expect("PALPATE_VERTICES: a vertex count");
    std::fs::write(
        out.join("vertices.rs"),
        format!("/// Vertices of the table's mesh (`PALPATE_VERTICES`).\nconst VERTICES: usize = {vertices};\n"),
    )
    .expect("write vertices.rs");
}
