//! Offline tables: compliance computation and the table file writer.
<<<<<<< HEAD
pub mod build;
pub mod file;
pub mod load;
=======

pub mod cg;
pub mod compliance;
>>>>>>> fem
