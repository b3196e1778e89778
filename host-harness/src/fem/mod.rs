//! Linear P1 finite elements: element stiffness and global assembly.
//!
//! Everything here follows `MODELS.md` §1 (the linear P1 tetrahedron) and
//! Cotin et al., INRIA RR-3510 §4. SI units throughout (m, N, Pa).

pub mod assembly;
pub mod element;
pub mod material;
pub mod static_solve;

pub(crate) mod llt;
