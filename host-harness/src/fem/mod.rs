//! Finite elements on the host: the linear P1 element, global assembly and
//! the direct solves; the hyperelastic elements (St Venant-Kirchhoff,
//! compressible neo-Hookean on P1 and P2 tets: [`hyperelastic`], [`stvk`],
//! [`neo_hookean`], [`neo_hookean_p2`])
//! and their Newton static solver ([`newton`]); the incompressibility
//! penalty of the tensor-mass models ([`penalty`]).
//!
//! Everything here follows `MODELS.md` §1 (the linear P1 tetrahedron) and
//! Cotin et al., INRIA RR-3510 §4. SI units throughout (m, N, Pa).

pub mod assembly;
pub mod element;
pub mod hyperelastic;
pub mod material;
pub mod neo_hookean;
pub mod neo_hookean_p2;
pub mod newton;
pub mod penalty;
pub mod static_solve;
pub mod stvk;

pub(crate) mod llt;
