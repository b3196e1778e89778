//! Puts the firmware example's `memory.x` (QEMU mps2-an386) on the linker
//! path, and copies the pre-computed table named by `PALPATE_TABLE` to
//! `$OUT_DIR/table.bin`, its compressed versions named by
//! `PALPATE_TABLE_F16` and `PALPATE_TABLE_Q16` to `$OUT_DIR/table-f16.bin`
//! and `$OUT_DIR/table-q16.bin`, and the tensor-mass table named by
//! `PALPATE_TENSOR_TABLE` to `$OUT_DIR/tensor_table.bin`, and the hybrid's
//! three tables in the folder `PALPATE_HYBRID_TABLES` to `$OUT_DIR/hybrid/`
//! (`tools/nopanic-check.sh` builds them all).

use std::path::PathBuf;

fn main() {
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("OUT_DIR"));
    std::fs::copy("../firmware-m4f/memory.x", out.join("memory.x")).expect("copy memory.x");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=../firmware-m4f/memory.x");
    for (var, file, command) in [
        ("PALPATE_TABLE", "table.bin", "`palpate tables build`"),
        (
            "PALPATE_TABLE_F16",
            "table-f16.bin",
            "`palpate tables build --compress f16`",
        ),
        (
            "PALPATE_TABLE_Q16",
            "table-q16.bin",
            "`palpate tables build --compress q16`",
        ),
        (
            "PALPATE_TENSOR_TABLE",
            "tensor_table.bin",
            "`palpate tables build --model tensor-mass`",
        ),
    ] {
        println!("cargo:rerun-if-env-changed={var}");
        let Some(table) = std::env::var_os(var) else {
            panic!("set {var} to a table built by {command} (see tools/nopanic-check.sh)");
        };
        println!("cargo:rerun-if-changed={}", table.to_string_lossy());
        std::fs::copy(&table, out.join(file))
            .unwrap_or_else(|e| panic!("{var}={}: {e}", table.to_string_lossy()));
    }
    // The hybrid's three tables, from the folder `palpate scene tables` wrote.
    let var = "PALPATE_HYBRID_TABLES";
    println!("cargo:rerun-if-env-changed={var}");
    let Some(dir) = std::env::var_os(var).map(PathBuf::from) else {
        panic!(
            "set {var} to a folder written by `palpate scene tables` (see tools/nopanic-check.sh)"
        );
    };
    std::fs::create_dir_all(out.join("hybrid")).expect("create $OUT_DIR/hybrid");
    for file in ["precomputed.bin", "dynamic.bin", "interface.bin"] {
        let table = dir.join(file);
        println!("cargo:rerun-if-changed={}", table.display());
        std::fs::copy(&table, out.join("hybrid").join(file))
            .unwrap_or_else(|e| panic!("{var}: {}: {e}", table.display()));
    }
}
