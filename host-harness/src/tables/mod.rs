//! Offline tables: compliance computation and the table file writer.

pub mod cg;
pub mod compliance;
