//! Tracking ([`SurfaceGeometry::track`]): a contact moved with its tool
//! across triangle edges (frictionless sliding), or kept where it is held.

use nalgebra::Vector3;

use super::{ContactWork, SurfaceGeometry, clamp_weights};
use crate::Real;
use crate::contact::Contact;

/// Triangle edges crossed at most per tick while sliding (a bound on the
/// walk; a contact that would slide further stops at the last triangle).
pub const MAX_WALK_STEPS: u32 = 8;

impl<'a, T: Real> SurfaceGeometry<'a, T> {
    /// Moves `contact` with a sphere now at `tip_m` (m): the projection of
    /// the sphere's lowest point `tip − r n` onto the surface, walking to
    /// the neighbouring triangle across any edge it falls outside of (at
    /// most [`MAX_WALK_STEPS`]; never straight back, which over a concave
    /// fold would swing between the two triangles). Moves `contact` in
    /// place (no copy of it), with its signed gap (negative while the
    /// sphere penetrates), and returns `true`. A held contact
    /// ([`Contact::grip_offset_m`]) keeps its triangle and weights (its
    /// point is where the surface has them now). `false`, with `contact`
    /// unchanged, when the triangle has left the surface (a cut or a tear
    /// removed its tet).
    pub fn track(
        &self,
        contact: &mut Contact<T>,
        tip_m: &Vector3<T>,
        radius_m: T,
        work: &mut ContactWork,
    ) -> bool {
        let tolerance = T::WEIGHT_TOLERANCE;
        let mut triangle = contact.triangle;
        let Some(mut face) = self.face(triangle) else {
            return false;
        };
        if contact.grip_offset_m.is_some() {
            self.place(contact, triangle, &face, contact.weights, tip_m, radius_m);
            return true;
        }
        let mut came_from = None;
        // The weights on the current triangle (each step moves to the next
        // and weighs again).
        let mut w = self.tracked_weights(triangle, tip_m);
        for _ in 0..MAX_WALK_STEPS {
            let Some(out) = (0..3).find(|&i| w.get(i).is_some_and(|&x| x < -tolerance)) else {
                break;
            };
            // Cross the edge opposite corner `out` to the triangle sharing it.
            let (Some(&j), Some(&k)) = (
                face.vertices.get((out + 1) % 3),
                face.vertices.get((out + 2) % 3),
            ) else {
                break;
            };
            let shared = self.index.across(triangle, j, k);
            // Back where it came from: the point lies over a concave fold
            // between the two (a dimple's valley); stay, clamped to the edge.
            if shared == came_from {
                break;
            }
            let Some(next) = shared.and_then(|t| self.face(t).map(|f| (t, f))) else {
                break;
            };
            work.walk_steps = work.walk_steps.saturating_add(1);
            came_from = Some(triangle);
            (triangle, face) = next;
            w = self.tracked_weights(triangle, tip_m);
        }
        self.place(contact, triangle, &face, clamp_weights(w), tip_m, radius_m);
        true
    }
}
