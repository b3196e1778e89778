//! Offline tables: compliance computation and the table file writer.
pub mod build;
pub mod file;
pub mod load;
