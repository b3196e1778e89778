//! Every workspace integration test, in one binary whose modules mirror the
//! source tree: `kernel::…` (the `no_std` kernel), `host::…` (the harness),
//! `tools::…` (the shared script crate). Each module states the independent
//! truth it checks against; the shared readers of the reference data are in
//! `src/lib.rs`.

mod host {
    mod bench;
    mod compliance;
    mod dispatch;
    mod experiment;
    mod fem;
    mod materials;
    mod mesh;
    mod mesh_regions;
    mod partition;
    mod robustness;
    mod session;
    mod session_generate_tools;
    mod session_hybrid;
    mod session_run;
    mod session_scene_tools;
    mod session_stability;
    mod session_tools;
    mod session_trajectory_tools;
    mod stability;
}

mod kernel {
    mod haptic;
    mod haptic_dynamic;
    mod haptic_tools;
    mod hybrid;
    mod layers;
    mod precomputed;
    mod stvk;
    mod stvk_terms;
    mod table;
    mod tensor_mass;
}

mod tools {
    mod script;
}
