//! TetGen reader: the input is the `.node` file, a NUL byte, then the `.ele` file (no NUL:
//! all of it is the `.node` file and the `.ele` file is empty). No input panics; an accepted
//! mesh satisfies the `TetMesh` invariants; an error names the source.
#![no_main]

use libfuzzer_sys::fuzz_target;
use palpate::mesh::read_tetgen;

fuzz_target!(|data: &[u8]| {
    let (node, ele) = match data.iter().position(|&b| b == 0) {
        Some(i) => (&data[..i], &data[i + 1..]),
        None => (data, &[][..]),
    };
    match read_tetgen(node, ele, "fuzz-input") {
        Ok((mesh, report)) => palpate_fuzz::check_mesh(&mesh, &report),
        Err(err) => assert!(err.to_string().starts_with("fuzz-input"), "{err}"),
    }
});
