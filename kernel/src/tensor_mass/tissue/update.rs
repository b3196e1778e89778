//! The physics update of a [`DynamicTissue`] (module docs of the parent):
//! its stages in order, each a function of its own (inlined: the update
//! is one function in the compiled code).

use super::{Blades, DynamicTissue, PhysicsError};
use crate::Real;
use crate::contact::ContactSet;
use crate::math::Dispatch;
use crate::tensor_mass::{StepError, StepReport};

impl<T: Real, const P: usize, D: Dispatch> DynamicTissue<'_, '_, T, P, D> {
    /// The physics update for contact set `set` (the loop's current
    /// contacts at the current tool position) and the enabled `blades`:
    /// cut, release, impose, step `substeps` times, tear, read the held
    /// forces, re-bin (module docs). Bounded by the cut scans (one pass over
    /// the tets per blade, one for tearing), the model's step and the
    /// re-bin. On failure the tissue is faulted.
    pub fn update<const M: usize>(
        &mut self,
        set: &ContactSet<T, M>,
        blades: &Blades<T>,
    ) -> Result<StepReport<T>, PhysicsError> {
        self.update_binning(set, blades, true)
    }

    /// [`Self::update`] without the re-bin of this tissue's surface: for a
    /// wrapper that bins a surface of its own over these triangles (the
    /// hybrid's whole surface, which checks the positions too). The faces a
    /// cut exposes are brought up to date all the same; the grid, planes and
    /// positions of this surface stay as they were.
    pub(crate) fn update_unbinned<const M: usize>(
        &mut self,
        set: &ContactSet<T, M>,
        blades: &Blades<T>,
    ) -> Result<StepReport<T>, PhysicsError> {
        self.update_binning(set, blades, false)
    }

    /// [`Self::try_update`], the tissue faulted (nothing held) on failure.
    fn update_binning<const M: usize>(
        &mut self,
        set: &ContactSet<T, M>,
        blades: &Blades<T>,
        rebin: bool,
    ) -> Result<StepReport<T>, PhysicsError> {
        let result = self.try_update(set, blades, rebin);
        if let Err(e) = result {
            self.fault = Some(e);
            self.held = [None; P];
        }
        result
    }

    /// The update's stages: each contact in the rest frame with its
    /// shares ([`Self::rest_frame_set`]) and what the last tick sent for
    /// it ([`Self::sent_per_tool`]); the blades' cuts (`Self::cut`), the
    /// contacts they cut off (`Self::drop_cut_off`); the release of what
    /// no contact holds any more (`Self::release_unheld`); the imposed
    /// displacements (`Self::impose_contacts`); the steps
    /// ([`Self::substeps`]); tearing (`Self::tear`); what each contact holds
    /// now (`Self::hold_contacts`); the re-bin ([`Self::rebin_if`]).
    fn try_update<const M: usize>(
        &mut self,
        set: &ContactSet<T, M>,
        blades: &Blades<T>,
        rebin: bool,
    ) -> Result<StepReport<T>, PhysicsError> {
        // A faulted update removes nothing (the log is this update's).
        self.removed.clear();
        if let Some(fault) = self.fault {
            return Err(fault);
        }
        let mut set_now: ContactSet<T, M> = ContactSet::new();
        let mut shares = [[T::zero(); 3]; M];
        self.rest_frame_set(set, &mut set_now, &mut shares);
        let sent = self.sent_per_tool(&set_now, &shares);
        self.cut(blades);
        self.expose(0);
        self.drop_cut_off(&set_now, &mut shares);
        let previous = self.held;
        self.release_unheld(&previous, &set_now, &shares);
        self.held = [None; P];
        self.impose_contacts(&set_now, &shares)?;
        let report = self.substeps()?;
        self.tear();
        self.hold_contacts(&previous, &set_now, &shares, &sent);
        self.rebin_if(rebin)?;
        self.period_ticks = self.ticks_since_update.max(1);
        self.ticks_since_update = 0;
        report.ok_or(PhysicsError::Step(StepError::BadTimeStep))
    }

    /// Each contact of `set` in the rest frame into `set_now`, with its
    /// shares into `shares` (computed once per update).
    #[inline(always)]
    fn rest_frame_set<const M: usize>(
        &self,
        set: &ContactSet<T, M>,
        set_now: &mut ContactSet<T, M>,
        shares: &mut [[T; 3]; M],
    ) {
        for (t, s) in set.iter().zip(shares.iter_mut()) {
            let t = self.in_rest_frame(t);
            *s = self.shares(&t);
            let _ = set_now.push(t);
        }
    }

    /// What the last tick sent along each contact's normal, per tool point
    /// (the corrections' reference), read before a cut changes the
    /// tensors.
    #[inline(always)]
    fn sent_per_tool<const M: usize>(
        &self,
        set_now: &ContactSet<T, M>,
        shares: &[[T; 3]; M],
    ) -> [T; P] {
        let mut sent = [T::zero(); P];
        for (t, s) in set_now.iter().zip(shares) {
            if let Some(x) = sent.get_mut(t.tool) {
                *x = self.extrapolate(t, s).dot(&t.normal);
            }
        }
        sent
    }

    /// The model's `substeps` steps; the last step's report (`None` for
    /// none, which a checked configuration rules out).
    #[inline(always)]
    fn substeps(&mut self) -> Result<Option<StepReport<T>>, PhysicsError> {
        let mut report = None;
        for _ in 0..self.physics.substeps {
            report = Some(
                self.model
                    .step_with(self.dispatch, self.physics.integrator, self.physics.dt_s)
                    .map_err(PhysicsError::Step)?,
            );
        }
        Ok(report)
    }

    /// The surface re-binned at the model's displacements, when `rebin`.
    #[inline(always)]
    fn rebin_if(&mut self, rebin: bool) -> Result<(), PhysicsError> {
        if rebin {
            let u = self
                .model
                .displacements_m()
                .map_err(|f| PhysicsError::Step(StepError::Faulted(f)))?;
            self.surface.rebin(u).map_err(PhysicsError::Surface)?;
        }
        Ok(())
    }
}
