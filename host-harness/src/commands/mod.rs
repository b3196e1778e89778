//! The `palpate` commands, one module per command group, each with its clap
//! types and its `run`; [`args`] holds the argument groups several share.

pub mod args;
pub mod budget;
pub mod demo;
pub mod dynamic;
pub mod experiment;
pub mod precomputed;
pub mod session;
pub mod stvk;
pub mod tables;
