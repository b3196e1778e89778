//! The pre-computed quasi-static linear elastic model with multiple
//! simultaneous contacts (Cotin et al., RR-3510 §4; MODELS.md §2), and its
//! tissue adapter for the haptic loop ([`PrecomputedTissue`]).
//!
//! Given `m ≤ M` contact points `c_p`, each a touchable vertex or a point on a
//! surface triangle (barycentric weights `β^p_a` on vertices `v^p_a`), with
//! imposed displacements `d_p`, the point compliance is
//! `C_pq = Σ_a Σ_b β^p_a β^q_b C_{v^p_a v^q_b}` and the contact forces `g`
//! solve the SPD system `Σ_q C_pq g_q = d_p` (a block LDLᵀ in the tissue's
//! buffers, or on the stack).
//! The device receives `-Σ g_q`. The displacement of every vertex,
//! `u_n = Σ_q Σ_b β^q_b C_{n v^q_b} g_q`, is a separate call so the haptic
//! path can skip it. Superposing elementary deformations instead would
//! overshoot (the paper's figure); solving the coupled system does not.
//!
//! Optionally quasi-non-linear ([`QuasiNonLinear`], Cotin 1999 TVCG §3):
//! amplitudes of the linear forces and displacements remapped by fitted
//! polynomials.
//!
//! Depends on [`crate::math`], [`crate::table`] and [`crate::contact`].

mod constraint;
mod model;
mod remap;
mod tissue;

pub use constraint::{AsConstraint, Constraint, ContactError, ContactPoint};
pub use model::{ContactSolution, DisplacementError, PrecomputedModel};
pub use remap::{QuasiNonLinear, REMAP_DEGREE, Remap, RemapError};
pub use tissue::PrecomputedTissue;
