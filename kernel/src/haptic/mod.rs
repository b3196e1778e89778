//! Tool contact and the fixed-timestep haptic loop (Cotin 1999 §4;
//! MODELS.md §6): the collision index of a pre-computed table, contact
//! detection and tracking, and the safety supervisor on the force output.

pub mod contact;
pub mod haptic_loop;
pub mod safety;
pub mod surface;
