//! Every workspace integration test, in one binary whose modules mirror the
//! source tree: `kernel::…` (the `no_std` kernel), `host::…` (the harness),
//! `ffi::…` (the C ABI), `tools::…` (the shared script crate, the C
//! example's sequence, the documents' links). Each module states the independent
//! truth it checks against; the shared readers of the reference data are in
//! `src/lib.rs`.

// The C ABI (`ffi/`, crate `palpate-ffi`), called as C calls it: raw
// pointers to handles and buffers, hence `unsafe` (each call says why it is
// sound).
#[allow(unsafe_code)]
mod ffi {
    mod dynamic_loop;
    mod error;
    mod hybrid_loop;
    mod precomputed_loop;
    mod solve;
    mod status;
    mod table;
}

mod host {
    mod bench;
    mod budget_sites;
    mod chart;
    mod compliance;
    mod demo;
    mod dispatch;
    mod experiment;
    mod fem;
    mod fix;
    mod materials;
    mod mesh;
    mod mesh_regions;
    mod neo_hookean;
    mod neo_hookean_kernel;
    mod neo_hookean_p2;
    mod neo_hookean_reference;
    mod newton;
    mod output;
    mod partition;
    mod remap;
    mod robustness;
    mod scene_tables;
    mod session;
    mod session_generate_tools;
    mod session_hybrid;
    mod session_run;
    mod session_scene_tools;
    mod session_serve;
    mod session_stability;
    mod session_tools;
    mod session_trajectory_tools;
    mod stability;
    mod table_compress;
    mod table_hmatrix;
    mod table_info;
    mod threads;
}

mod kernel {
    mod candidates;
    mod corotational;
    mod haptic;
    mod haptic_dynamic;
    mod haptic_settle;
    mod haptic_tools;
    mod hybrid;
    mod hybrid_hmatrix;
    mod layers;
    mod link;
    mod link_controller;
    mod neo_hookean;
    mod polar;
    mod precomputed;
    mod remap;
    mod stvk;
    mod stvk_terms;
    mod table;
    mod table_compressed;
    mod tensor_mass;
}

mod tools {
    mod docs_links;
    mod firmware_c;
    mod house;
    mod script;
    mod script_ticks;
}
