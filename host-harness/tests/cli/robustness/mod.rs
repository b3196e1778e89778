//! The process-level robustness probes, one module per kind, as in the
//! in-process side (`tests/host/robustness/`).

mod bounds;
mod output;
mod results;
