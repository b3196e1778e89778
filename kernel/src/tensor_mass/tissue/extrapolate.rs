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

    /// `K_c` (N/m) of a contact point with barycentric `weights` on the
    /// triangle of `vertices` (the stiffness a contact made there before
    /// the next update starts with).
    pub fn local_stiffness(&self, vertices: &[VertexIndex; 3], weights: [T; 3]) -> Matrix3<T> {
        self.contact_stiffness(vertices, &self.shares_at(vertices, weights))
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
                None => penalty_on_hand(&t.normal, &k, t.gap_m - t.entry_gap_m),
            };
        };
        let blend = correction_blend(self.ticks_since_update, self.period_ticks);
        h.local_model()
            .force_on_hand(&t.tip_m, t.grip_offset_m.is_some(), blend)
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

/// The local contact model of a contact held at a physics update (Cotin
/// 1999 §4; module docs of the parent): what the force on the hand is
/// extrapolated from until the next update. The dynamic tissue's ticks and
/// a controller across a link ([`crate::link`]) both use it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalModel<T> {
    /// The held triangle's unit normal at rest (the force's direction).
    pub normal: Vector3<T>,
    /// The tool point's position at the update, m.
    pub tip_m: Vector3<T>,
    /// The force the tool applies to the tissue after the update, N.
    pub force_n: Vector3<T>,
    /// `k = n · K_c n`, N/m.
    pub stiffness_n_per_m: T,
    /// `K_c = Σ_ij s_i s_j K_ij`, N/m.
    pub stiffness_tensor_n_per_m: Matrix3<T>,
    /// Extrapolation stiffness ratio `α`, in `[0, 1]`.
    pub scale: T,
    /// Normal force sent just before the update minus the update's, N.
    pub offset_n: T,
}

impl<T: Real> LocalModel<T> {
    /// The model of a contact with unit `normal`, the tool at `tip_m` (m)
    /// and `force_n` on the tissue (N) at the update, contact stiffness
    /// `tensor` (N/m), ratio `scale` and `offset_n` (N); `k = n · K_c n`.
    pub fn new(
        normal: Vector3<T>,
        tip_m: Vector3<T>,
        force_n: Vector3<T>,
        tensor: Matrix3<T>,
        scale: T,
        offset_n: T,
    ) -> Self {
        Self {
            normal,
            tip_m,
            force_n,
            stiffness_n_per_m: normal.dot(&(tensor * normal)),
            stiffness_tensor_n_per_m: tensor,
            scale,
            offset_n,
        }
    }

    /// The force on the hand, N, with the tool at `tip_m` (m) and `blend`
    /// of the update's correction left ([`correction_blend`]): a probe's
    /// `F = (n · F_update − α k gap + blend · offset) n`, `gap` the tool's
    /// motion along `n` since the update; a grip's
    /// `F = F_update − K_c (tip − tip_update)`, the full vector (module docs
    /// of the parent; `F_update` on the hand, the opposite of
    /// [`Self::force_n`]).
    pub fn force_on_hand(&self, tip_m: &Vector3<T>, grip: bool, blend: T) -> Vector3<T> {
        let motion = tip_m - self.tip_m;
        if grip {
            return -self.force_n - self.stiffness_tensor_n_per_m * motion;
        }
        let n = self.normal;
        let gap = motion.dot(&n);
        n * (-self.force_n.dot(&n) - self.scale * self.stiffness_n_per_m * gap
            + blend * self.offset_n)
    }
}

impl<T: Real> HeldContact<T> {
    /// Its local contact model.
    pub fn local_model(&self) -> LocalModel<T> {
        LocalModel {
            normal: self.contact.normal,
            tip_m: self.contact.tip_m,
            force_n: self.contact.force_n,
            stiffness_n_per_m: self.stiffness_n_per_m,
            stiffness_tensor_n_per_m: self.stiffness_tensor_n_per_m,
            scale: self.scale,
            offset_n: self.offset_n,
        }
    }
}

/// The force on the hand, N, of a contact made since the last update:
/// `F = −(n · K_c n) gap n` with `gap` (m, negative pressing) counted from
/// where the contact started pushing, `K_c` (N/m) of its triangle.
pub fn penalty_on_hand<T: Real>(normal: &Vector3<T>, tensor: &Matrix3<T>, gap_m: T) -> Vector3<T> {
    normal * (-normal.dot(&(tensor * normal)) * gap_m)
}

/// What is left of an update's correction `ticks_since_update` ticks after
/// it, the last period having had `period_ticks` ticks: `1 − j/k`, zero from
/// the next update's tick on (corrections never accumulate).
pub fn correction_blend<T: Real>(ticks_since_update: u32, period_ticks: u32) -> T {
    let ticks = T::of_f64(f64::from(ticks_since_update));
    let period = T::of_f64(f64::from(period_ticks));
    let remaining = T::one() - ticks / period;
    if remaining > T::zero() {
        remaining
    } else {
        T::zero()
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
