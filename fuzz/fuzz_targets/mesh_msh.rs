//! Gmsh MSH reader (2.2 and 4.1, ASCII and binary): no input panics; an accepted mesh
//! satisfies the `TetMesh` invariants; an error names the source.
#![no_main]

use libfuzzer_sys::fuzz_target;
use palpate::mesh::{MeshFormat, read_mesh_bytes};

fuzz_target!(|data: &[u8]| {
    match read_mesh_bytes(data, MeshFormat::Msh, "fuzz-input") {
        Ok((mesh, report)) => palpate_fuzz::check_mesh(&mesh, &report),
        Err(err) => assert!(err.to_string().starts_with("fuzz-input"), "{err}"),
    }
});
