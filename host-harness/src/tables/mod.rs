//! Offline tables: compliance computation and the table file writer.
pub mod file;
