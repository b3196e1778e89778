//! Generates the C header of the palpate-ffi crate (`ffi/include/palpate.h`)
//! with cbindgen, configured by `ffi/cbindgen.toml`, and compares it with
//! the committed one: exit 0 when equal, 1 with the first differing line
//! otherwise. `PALPATE_BLESS=1` writes the generated header instead (through
//! a temporary file and a rename). Run by `tools/ffi-check.sh`.

use std::path::Path;
use std::process::ExitCode;

fn main() -> ExitCode {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let crate_dir = root.join("ffi");
    let header = crate_dir.join("include/palpate.h");
    let config = match cbindgen::Config::from_file(crate_dir.join("cbindgen.toml")) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("ffi/cbindgen.toml: {e}");
            return ExitCode::FAILURE;
        }
    };
    let bindings = match cbindgen::Builder::new()
        .with_crate(&crate_dir)
        .with_config(config)
        .generate()
    {
        Ok(b) => b,
        Err(e) => {
            eprintln!("cbindgen: {e}");
            return ExitCode::FAILURE;
        }
    };
    let mut generated = Vec::new();
    bindings.write(&mut generated);
    let generated = match String::from_utf8(generated) {
        Ok(g) => g,
        Err(e) => {
            eprintln!("cbindgen wrote non-UTF-8 output: {e}");
            return ExitCode::FAILURE;
        }
    };
    if std::env::var_os("PALPATE_BLESS").is_some_and(|v| v == "1") {
        let tmp = header.with_extension("h.tmp");
        if let Err(e) =
            std::fs::write(&tmp, &generated).and_then(|()| std::fs::rename(&tmp, &header))
        {
            eprintln!("{}: {e}", header.display());
            return ExitCode::FAILURE;
        }
        println!("wrote ffi/include/palpate.h");
        return ExitCode::SUCCESS;
    }
    let committed = std::fs::read_to_string(&header).unwrap_or_default();
    if committed == generated {
        println!(
            "ffi/include/palpate.h is up to date ({} lines)",
            generated.lines().count()
        );
        return ExitCode::SUCCESS;
    }
    let line = committed
        .lines()
        .zip(generated.lines())
        .position(|(a, b)| a != b)
        .unwrap_or_else(|| committed.lines().count().min(generated.lines().count()));
    eprintln!(
        "FAIL: ffi/include/palpate.h differs from what ffi/src generates (first at line {}):\n  committed: {}\n  generated: {}\nregenerate it: PALPATE_BLESS=1 tools/ffi-check.sh",
        line + 1,
        committed.lines().nth(line).unwrap_or("(end of file)"),
        generated.lines().nth(line).unwrap_or("(end of file)"),
    );
    ExitCode::FAILURE
}
