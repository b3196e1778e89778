//! Offline tables: compliance computation (Cotin RR-3510 §4), tensor-mass
//! arrays (RR-3510 §5), the table file writer and reader, and the
//! `tables build` pipeline.

pub mod build;
pub mod cg;
pub mod collision;
pub mod compliance;
pub mod file;
pub mod load;
pub mod tensor_mass;
