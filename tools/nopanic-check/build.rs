//! Puts the firmware example's `memory.x` (QEMU mps2-an386) on the linker
//! path, and copies the table named by `PALPATE_TABLE` to
//! `$OUT_DIR/table.bin` (`tools/nopanic-check.sh` builds it).

use std::path::PathBuf;

fn main() {
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("OUT_DIR"));
    std::fs::copy("../firmware-m4f/memory.x", out.join("memory.x")).expect("copy memory.x");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=../firmware-m4f/memory.x");
    println!("cargo:rerun-if-env-changed=PALPATE_TABLE");
    let Some(table) = std::env::var_os("PALPATE_TABLE") else {
        panic!(
            "set PALPATE_TABLE to a table built by `palpate tables build` (see tools/nopanic-check.sh)"
        );
    };
    println!("cargo:rerun-if-changed={}", table.to_string_lossy());
    std::fs::copy(&table, out.join("table.bin"))
        .unwrap_or_else(|e| panic!("PALPATE_TABLE={}: {e}", table.to_string_lossy()));
}
