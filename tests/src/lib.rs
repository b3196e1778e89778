//! Shared helpers for the workspace integration tests: where the independent
//! reference data lives and how to read it.

use std::path::PathBuf;

/// `../shared/reference/` beside the checkout (present in CI too).
pub fn reference_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/reference")
}

/// Small hand-written test files committed with the tests (`tests/data/`).
pub fn data_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("data")
}
