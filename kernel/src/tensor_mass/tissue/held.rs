//! The held-triangle bookkeeping of a physics update (module docs of the
//! parent): the contacts a cut took off, the release of what no contact
//! holds, the displacements imposed (with the give-back of what a probe
//! held when it was made), and what each contact holds after the steps.

use nalgebra::Vector3;

use super::extrapolate::carried;
use super::{DynamicTissue, Extrapolation, GIVE_BACK, HeldContact, PhysicsError};
use crate::Real;
use crate::contact::{Contact, ContactSet};
use crate::math::Dispatch;
use crate::table::VertexIndex;
use crate::tensor_mass::StepError;

/// One vertex's move of a contact: the vertex (`None`: a slot unused),
/// its displacement before the update and its shift, m.
type Move<T> = (Option<VertexIndex>, Vector3<T>, Vector3<T>);

impl<T: Real, const P: usize, D: Dispatch> DynamicTissue<'_, '_, T, P, D> {
    /// `true` when vertex `v` belongs to one contact of `set` only (its
    /// target is then that contact's alone).
    fn held_once(&self, v: VertexIndex, set: &[Contact<T>]) -> bool {
        set.iter().filter(|t| t.vertices.contains(&v)).count() == 1
    }

    /// `true` while contact `t`'s triangle is on the surface.
    fn on_surface(&self, t: &Contact<T>) -> bool {
        self.surface.tet_of(t.triangle).is_some()
    }

    /// A contact whose triangle the cut took holds nothing from now on:
    /// its `shares` are zeroed, so its vertices are released and nothing
    /// is imposed for it.
    #[inline(always)]
    pub(super) fn drop_cut_off<const M: usize>(
        &self,
        set_now: &ContactSet<T, M>,
        shares: &mut [[T; 3]; M],
    ) {
        for (t, s) in set_now.iter().zip(shares.iter_mut()) {
            if !self.on_surface(t) {
                *s = [T::zero(); 3];
            }
        }
    }

    /// Releases what no current contact holds (a vertex whose share fell
    /// to zero at the contact point's far edge included) of what the
    /// contacts held at the last update (`previous`).
    #[inline(always)]
    pub(super) fn release_unheld<const M: usize>(
        &mut self,
        previous: &[Option<HeldContact<T>>; P],
        set_now: &ContactSet<T, M>,
        shares: &[[T; 3]; M],
    ) {
        for held in previous.iter().flatten() {
            for &v in &held.contact.vertices {
                let holds = |(t, s): (&Contact<T>, &[T; 3])| {
                    t.vertices
                        .iter()
                        .zip(s)
                        .any(|(&u, &s)| u == v && s != T::zero())
                };
                if !set_now.iter().zip(shares).any(holds) {
                    // A fixed vertex was never imposed: nothing to release.
                    let _ = self.model.release(v.as_u32());
                }
            }
        }
    }

    /// Impose: move each contact point by its displacement (gap · n, or a
    /// grip's vector), shared out over its triangle's vertices
    /// (`Self::moves`); a vertex two contacts share gets the sum of both
    /// shifts from where it was (at most 3M entries, 9M² sums).
    #[inline(always)]
    pub(super) fn impose_contacts<const M: usize>(
        &mut self,
        set_now: &ContactSet<T, M>,
        shares: &[[T; 3]; M],
    ) -> Result<(), PhysicsError> {
        let moves = self.moves(set_now, shares)?;
        for (t, slots) in set_now.iter().zip(&moves) {
            for &(v, from, _) in slots {
                let Some(v) = v else { continue };
                let shift = moves
                    .iter()
                    .flatten()
                    .filter(|(w, _, _)| *w == Some(v))
                    .fold(Vector3::zeros(), |a, (_, _, s)| a + s);
                self.model
                    .impose(v.as_u32(), from + shift)
                    .map_err(|_| PhysicsError::NonFiniteContact { tool: t.tool })?;
            }
        }
        Ok(())
    }

    /// Each contact's vertex moves: its share of the contact's
    /// displacement, plus for a probe's vertex it alone holds the
    /// [`GIVE_BACK`] of what separates it from its target (module docs).
    /// A displacement is a tick's measurement: with no tick since the last
    /// update it has been imposed already, so a back-to-back update (a late
    /// physics thread catching up) holds the contacts where they are.
    #[inline(always)]
    fn moves<const M: usize>(
        &self,
        set_now: &ContactSet<T, M>,
        shares: &[[T; 3]; M],
    ) -> Result<[[Move<T>; 3]; M], PhysicsError> {
        let measured = if self.ticks_since_update > 0 {
            T::one()
        } else {
            T::zero()
        };
        let mut moves = [[(None, Vector3::zeros(), Vector3::zeros()); 3]; M];
        if set_now.is_empty() {
            return Ok(moves); // no contact: the field is not read (nor its fault)
        }
        let u = self
            .model
            .displacements_m()
            .map_err(|f| PhysicsError::Step(StepError::Faulted(f)))?;
        let at = |v: VertexIndex| {
            u.get(v.get())
                .map_or(Vector3::zeros(), |u| Vector3::new(u[0], u[1], u[2]))
        };
        for ((t, s), slots) in set_now.iter().zip(shares).zip(moves.iter_mut()) {
            let d = t.displacement_m() * measured;
            // A probe's target: its vertices at their shares of the tool's
            // displacement along the rest normal from the contact point at
            // rest, `D = Σ w_j u_j·n + gap` (module docs: what the contact
            // held when it was made is given back).
            let reach = t
                .vertices
                .iter()
                .zip(&t.weights)
                .fold(T::zero(), |a, (&v, &w)| a + w * at(v).dot(&t.normal));
            let target = t.normal * (reach + t.gap_m);
            let probe = t.grip_offset_m.is_none();
            for ((slot, &v), &share) in slots.iter_mut().zip(&t.vertices).zip(s) {
                if share != T::zero() {
                    let from = at(v);
                    let shift = d * share;
                    let back = if probe && self.held_once(v, set_now.as_slice()) {
                        (target * share - from - shift) * (T::of_f64(GIVE_BACK) * measured)
                    } else {
                        Vector3::zeros()
                    };
                    *slot = (Some(v), from, shift + back);
                }
            }
        }
        Ok(moves)
    }

    /// What each contact holds after the steps, from the force its held
    /// vertices resist (`Self::hold`); a contact torn off loses its hold.
    /// `sent`: what the last tick sent per tool point.
    #[inline(always)]
    pub(super) fn hold_contacts<const M: usize>(
        &mut self,
        previous: &[Option<HeldContact<T>>; P],
        set_now: &ContactSet<T, M>,
        shares: &[[T; 3]; M],
        sent: &[T; P],
    ) {
        self.model.elastic_forces_n(self.forces_n);
        for (t, &shares) in set_now.iter().zip(shares) {
            if !self.on_surface(t) {
                // Torn off: its hold is lost.
                for &v in &t.vertices {
                    let _ = self.model.release(v.as_u32());
                }
                continue;
            }
            self.hold(previous, t, shares, sent);
        }
    }

    /// What contact `t` (on the surface, with its vertices' `shares`)
    /// holds: the work-conjugate of the contact point's displacement,
    /// `Σ s_i f_i`, its stiffness, the extrapolation ratio from what it
    /// held at the last update (`previous`) and the offset from what the
    /// last tick sent (`sent`).
    #[inline(always)]
    fn hold(
        &mut self,
        previous: &[Option<HeldContact<T>>; P],
        t: &Contact<T>,
        shares: [T; 3],
        sent: &[T; P],
    ) {
        let tensor = self.contact_stiffness(&t.vertices, &shares);
        let stiffness_n_per_m = t.normal.dot(&(tensor * t.normal));
        let mut force_n = Vector3::zeros();
        for (&v, &share) in t.vertices.iter().zip(&shares) {
            if let Some(f) = self.forces_n.get(v.get()) {
                force_n += Vector3::new(f[0], f[1], f[2]) * share;
            }
        }
        // A new contact started touching (gap 0, zero force) at α = 1,
        // the tool then `gap` further along the normal.
        let before = carried(previous, t).unwrap_or(HeldContact {
            contact: Contact {
                tip_m: t.tip_m - t.normal * t.gap_m,
                force_n: Vector3::zeros(),
                ..*t
            },
            shares,
            stiffness_n_per_m,
            stiffness_tensor_n_per_m: tensor,
            scale: T::one(),
            offset_n: T::zero(),
        });
        let scale = self.secant_scale(&before, t, &force_n);
        let offset_n = match self.physics.extrapolation {
            Extrapolation::Instantaneous => T::zero(),
            Extrapolation::Secant => {
                sent.get(t.tool).copied().unwrap_or(T::zero()) - force_n.dot(&t.normal)
            }
        };
        if let Some(slot) = self.held.get_mut(t.tool) {
            *slot = Some(HeldContact {
                contact: Contact {
                    force_n: -force_n,
                    ..*t
                },
                shares,
                stiffness_n_per_m,
                stiffness_tensor_n_per_m: tensor,
                scale,
                offset_n,
            });
        }
    }
}
