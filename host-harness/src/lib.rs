//! Palpate host harness: mesh input, offline tables, scripted runs, reports.

pub mod fem;
pub mod mesh;
pub mod tables;
