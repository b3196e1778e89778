//! The process-level tests of the `palpate` binary, one test binary:
//! `cargo test -p palpate --test cli`, a part by its module path
//! (`cargo test -p palpate --test cli -- robustness::output`). One binary
//! links the harness and its dependencies once: as one binary per file (ten)
//! they took twice the compile work (32 s of CPU against 16 s) and ran one
//! after another, each waiting for its own slowest test.
//!
//! - [`contract`]: the command-line contract (README.md): exact commands,
//!   JSON shapes, exit status 2 with a one-line error for bad input;
//! - [`bench`], [`chart`], [`dynamic_scene`], [`remap`], [`scene_plan`],
//!   [`scene_tables`]: one command group each;
//! - [`robustness`]: the process-level robustness probes (bounded runs,
//!   output safety, wrong results and messages), beside the in-process
//!   ones of `tests/host/robustness/`.

mod common;

mod bench;
mod chart;
mod contract;
mod dynamic_scene;
mod forces;
mod remap;
mod robustness;
mod scene_plan;
mod scene_tables;
