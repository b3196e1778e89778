//! Tool contact and the fixed-timestep haptic loop (Cotin 1999 §4;
//! MODELS.md §6): collision indexes (table-built for the pre-computed
//! model, re-binned for a deforming one), contact detection and tracking,
//! the tissue models the loop drives, and the safety supervisor on the
//! force output.

pub mod contact;
pub mod deforming;
pub mod dynamic_tissue;
pub mod haptic_loop;
pub mod safety;
pub mod surface;
pub mod tissue;
