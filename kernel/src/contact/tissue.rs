//! What the haptic loop asks of a tissue model (MODELS.md §6): a surface to
//! touch and, each tick, the forces of a set of contacts. Two models answer:
//! [`crate::precomputed::PrecomputedTissue`] (Cotin 1999, quasi-static,
//! solved every tick) and [`crate::tensor_mass::DynamicTissue`]
//! (tensor-mass, stepped at the physics rate, force extrapolated in between).

use nalgebra::Vector3;

use super::{Contact, SurfaceGeometry};
use crate::Real;

/// Why a contact set was not solved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Refusal {
    /// Contact `q` of the set cannot be held: drop it and solve again.
    Contact(usize),
    /// The model is faulted or its result is not finite.
    Fault,
}

/// A tissue model the haptic loop drives.
pub trait Tissue<T: Real, const M: usize> {
    /// `f` of the surface as it stands now: a tissue that keeps its
    /// surface lends it (no copy per tick), one whose surface moves
    /// assembles it from its current buffers.
    fn with_geometry<R>(&self, f: impl FnOnce(&SurfaceGeometry<'_, T>) -> R) -> R;
    /// Whether a tracked contact with signed gap `gap_m` (m) stays before
    /// the solve (the solve then releases adhesive contacts).
    fn keeps(&self, gap_m: T) -> bool;
    /// Solves contact set `set` (at most `M`, in tool-point order; the
    /// loop's own records, [`super::ContactRefs`]): writes each contact's
    /// [`Contact::force_n`] and returns the force on the hand (the
    /// tissue's reaction on the tool), N. Bounded.
    fn solve(&mut self, set: &mut [&mut Contact<T>]) -> Result<Vector3<T>, Refusal>;
    /// Called once at the start of every tick (a clock for models that
    /// extrapolate between physics updates).
    fn begin_tick(&mut self) {}
    /// Whether an enabled blade cuts this tissue (the tensor-mass model) or
    /// only touches it (the pre-computed model).
    fn can_cut(&self) -> bool {
        false
    }
    /// Forgets the last solution (a fault dropped every contact).
    fn forget(&mut self);
    /// Back to rest with no contact.
    fn reset(&mut self);
}
