//! The hybrid elastic model (Cotin, Delingette, Ayache, RR-3510 §6.2,
//! figure 5): a mesh split into a pre-computed region (quasi-static linear
//! elasticity, RR-3510 §4) and a tensor-mass region (dynamic, cuttable,
//! RR-3510 §5), sharing the connection nodes.
//!
//! The paper's loop, each step: the tensor-mass region imposes the
//! connection nodes' displacements `u_c` on the pre-computed region, which
//! returns the forces on them. Here the pre-computed region is condensed
//! offline onto the connection nodes ([`crate::table::InterfaceTable`]):
//! with `K_ii` its stiffness with the connection nodes held, the force it
//! returns is `−S u_c + Hᵀ f` (`S = K_cc − K_ci K_ii⁻¹ K_ic`, the Schur
//! complement; `H = −K_ii⁻¹ K_ic`; `f` its load and tool contacts), and its
//! displacement is `u_i = K_ii⁻¹ f + H u_c`. Both are exact static
//! condensation, so the hybrid's steady state is the global linear solve of
//! the whole mesh when the laws agree. The force is evaluated with the
//! tensor-mass forces at every force evaluation of the integrator (not
//! frozen over a step), at `9c²` multiply-adds.
//!
//! Contacts on the pre-computed region are solved with its compliance
//! `C⁰ = K_ii⁻¹` (connection nodes held) against the tool displacement less
//! the displacement the connection nodes and the load give the contact
//! point: the contacts and the connection nodes are one system, with no
//! superposition between them.
//!
//! Depends on [`crate::table`], [`crate::precomputed`] and
//! [`crate::tensor_mass`].

mod model;
mod region;
mod surface;
mod tissue;

pub use model::HybridModel;
pub use region::{CondensedRegion, FieldError, HybridBuffers, HybridError};
pub use surface::{HybridSurface, HybridSurfaceBuffers, HybridSurfaceLengths, SlotRegion};
pub use tissue::{HybridTissue, HybridTissueError};
