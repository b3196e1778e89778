//! The `palpate` commands, one module per command group, each with its clap
//! types and its `run`; [`args`] holds the argument groups several share;
//! every command prints through [`stdout`] and writes its files through
//! `palpate::output::atomic`.

pub mod args;
pub mod bench;
pub mod budget;
pub mod chart;
pub mod demo;
pub mod dynamic;
pub mod experiment;
pub mod forces;
pub mod precomputed;
pub mod remap;
pub mod scene;
pub mod session;
pub mod stdout;
pub mod stvk;
pub mod tables;

/// The files a mesh path reads: the path, or for TetGen (`.node`/`.ele`)
/// both files of the pair. An output must not be one of them.
pub fn mesh_files(path: &std::path::Path) -> Vec<std::path::PathBuf> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("node" | "ele") => vec![path.with_extension("node"), path.with_extension("ele")],
        _ => vec![path.to_path_buf()],
    }
}
