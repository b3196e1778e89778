//! Offline tables (the host side of `palpate_kernel::table`): the one build
//! pipeline for both kinds ([`build`], taking [`options`]), the compliance
//! computation of the pre-computed model (Cotin RR-3510 §4; [`compliance`],
//! [`cg`]), the tensor-mass arrays (RR-3510 §5; [`tensor_mass`]), the
//! collision index ([`collision`]), the compressed compliance ([`compress`]:
//! 16-bit codes, dropped far-field blocks, the error measured at build time; [`hmatrix`]: the hierarchical
//! compliance),
//! the table file writer ([`mod@file`], floats of a [`precision`]) and reader
//! ([`load`]), the size and memory estimate checked before a build
//! ([`estimate`]), and what `tables info` reports beyond the sections
//! ([`report`], [`info_json`]).

pub mod build;
pub mod cg;
pub mod collision;
pub mod compliance;
pub mod compress;
pub mod estimate;
pub mod file;
pub mod hmatrix;
pub mod info_json;
pub mod load;
pub mod options;
pub mod precision;
pub mod report;
pub mod tensor_mass;
