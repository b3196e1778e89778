//! The force sent between physics updates (module docs of the parent): the
//! contact stiffness, the extrapolation from the last update's held force,
//! and the secant ratio of the last period.

use nalgebra::{Matrix3, Vector3};

use super::{DynamicTissue, Extrapolation, HeldContact, SECANT_MIN_MOTION_M};
use crate::Real;
use crate::contact::Contact;
use crate::math::Dispatch;
use crate::table::VertexIndex;

impl<T: Real, const P: usize, D: Dispatch> DynamicTissue<'_, '_, T, P, D> {
    /// `K_c = Σ_ij s_i s_j K_ij` (N/m): the change of the force on the hand
    /// per metre of displacement of the contact point, shared out as `s`
    /// over `vertices` (module docs); `n · K_c n` is the normal stiffness.
    /// Cost: 9 tensor reads and 6 edge look-ups.
    pub(super) fn contact_stiffness(
        &self,
        vertices: &[VertexIndex; 3],
        shares: &[T; 3],
    ) -> Matrix3<T> {
        let mut k = Matrix3::zeros();
        for (&i, &si) in vertices.iter().zip(shares) {
            for (&j, &sj) in vertices.iter().zip(shares) {
                if si == T::zero() || sj == T::zero() {
                    continue;
                }
                let kij = if i == j {
                    self.model
                        .vertex_tensors()
                        .get(i.get())
                        .map(|kij| Matrix3::from_row_slice(kij))
                } else {
                    self.model
                        .edge_tensor(i.as_u32(), j.as_u32())
                        .map(|kij| Matrix3::from_row_slice(&kij))
                };
                if let Some(kij) = kij {
                    k += kij * (si * sj);
                }
            }
        }
        k
    }

    /// The force sent for contact `t` (in the rest frame, with its vertices'
    /// `shares`) at this tick, on the hand, N (module docs). With a held
    /// triangle the motion is the tool's since the update, whatever
    /// triangle tracking has reached since; a new contact uses its own
    /// triangle and imposed displacement. A probe's force is along the held
    /// normal (positive pushing the tool out); a grip's is the full vector.
    pub(super) fn extrapolate(&self, t: &Contact<T>, shares: &[T; 3]) -> Vector3<T> {
        let Some(h) = carried(&self.held, t) else {
            let k = self.contact_stiffness(&t.vertices, shares);
            return match t.grip_offset_m {
                Some(_) => -(k * (t.displacement_m() - t.normal * t.entry_gap_m)),
                None => t.normal * (-t.normal.dot(&(k * t.normal)) * (t.gap_m - t.entry_gap_m)),
            };
        };
        let motion = t.tip_m - h.contact.tip_m;
        if t.grip_offset_m.is_some() {
            return -h.contact.force_n - h.stiffness_tensor_n_per_m * motion;
        }
        // 1 − j/period at the j-th tick after the update: zero by the next
        // one, so corrections never accumulate.
        let ticks = T::of_f64(f64::from(self.ticks_since_update));
        let period = T::of_f64(f64::from(self.period_ticks));
        let remaining = T::one() - ticks / period;
        let blend = if remaining > T::zero() {
            remaining
        } else {
            T::zero()
        };
        let n = h.contact.normal;
        let gap = motion.dot(&n);
        n * (-h.contact.force_n.dot(&n) - h.scale * h.stiffness_n_per_m * gap + blend * h.offset_n)
    }

    /// The extrapolation ratio after an update that changed the force on
    /// the hand from `before`'s to `force_n` while the tool moved from
    /// `before`'s tip to `t.tip_m` (a new contact's `before` is zero force at
    /// `α = 1`, the tool's motion its gap).
    pub(super) fn secant_scale(
        &self,
        before: &HeldContact<T>,
        t: &Contact<T>,
        force_n: &Vector3<T>,
    ) -> T {
        let n = before.contact.normal;
        let motion = (t.tip_m - before.contact.tip_m).dot(&n);
        if self.physics.extrapolation == Extrapolation::Instantaneous
            || motion.abs() < T::of_f64(SECANT_MIN_MOTION_M)
        {
            return before.scale;
        }
        let predicted = -before.stiffness_n_per_m * motion;
        let measured = (force_n + before.contact.force_n).dot(&n);
        let ratio = measured / predicted;
        if !ratio.finite() {
            before.scale
        } else if ratio < T::zero() {
            T::zero()
        } else if ratio > T::one() {
            T::one()
        } else {
            ratio
        }
    }
}

/// What tool point `t.tool` held at the last update, if its contact is
/// still on or next to that triangle (they share a vertex).
pub(super) fn carried<T: Real, const P: usize>(
    held: &[Option<HeldContact<T>>; P],
    t: &Contact<T>,
) -> Option<HeldContact<T>> {
    held.get(t.tool)
        .copied()
        .flatten()
        .filter(|h| h.contact.vertices.iter().any(|v| t.vertices.contains(v)))
}
