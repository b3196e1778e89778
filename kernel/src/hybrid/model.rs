//! [`HybridModel`]: the tensor-mass region and the condensed pre-computed
//! region together, for scripted runs (steady states, stable steps); the
//! haptic loop's tissue is [`super::HybridTissue`].

use crate::Real;
use crate::precomputed::{AsConstraint, ContactError, ContactSolution};
use crate::table::{InterfaceTable, PrecomputedTable};
use crate::tensor_mass::{Fault, Integrator, StepError, StepReport, TensorMassModel};

use super::region::{CondensedRegion, FieldError, HybridBuffers, HybridError};

/// The hybrid model over three validated tables: the tensor-mass region's
/// (in its model), the pre-computed region's and the interface
/// ([`CondensedRegion::couple`] checks they belong together).
pub struct HybridModel<'a, 's, T: Real> {
    dynamic: TensorMassModel<'a, 's, T>,
    region: CondensedRegion<'a, 's, T>,
}

impl<'a, 's, T: Real> HybridModel<'a, 's, T> {
    /// Couples `dynamic` to the pre-computed region ([`CondensedRegion::couple`]).
    pub fn new(
        mut dynamic: TensorMassModel<'a, 's, T>,
        precomputed: PrecomputedTable<'a, T>,
        interface: InterfaceTable<'a, T>,
        buffers: HybridBuffers<'s, T>,
    ) -> Result<Self, HybridError> {
        let region = CondensedRegion::couple(&mut dynamic, precomputed, interface, buffers)?;
        Ok(Self { dynamic, region })
    }

    /// The tensor-mass region (state, fault, tensors).
    pub fn dynamic(&self) -> &TensorMassModel<'a, 's, T> {
        &self.dynamic
    }

    /// The tensor-mass region, to impose, release, load or cut it.
    pub fn dynamic_mut(&mut self) -> &mut TensorMassModel<'a, 's, T> {
        &mut self.dynamic
    }

    /// The condensed pre-computed region.
    pub fn region(&self) -> &CondensedRegion<'a, 's, T> {
        &self.region
    }

    /// The interface table.
    pub fn interface(&self) -> &InterfaceTable<'a, T> {
        self.region.interface()
    }

    /// Advances the tensor-mass region by `dt_s` with `integrator`, the
    /// pre-computed region's force on the connection nodes included in
    /// every force evaluation ([`TensorMassModel::step`]).
    pub fn step(&mut self, integrator: Integrator, dt_s: T) -> Result<StepReport<T>, StepError> {
        self.dynamic.step(integrator, dt_s)
    }

    /// Back to rest: both regions.
    pub fn reset(&mut self) {
        self.dynamic.reset();
        self.region.reset(&mut self.dynamic);
    }

    /// [`CondensedRegion::update_background`].
    pub fn update_background(&mut self, rows: usize) -> Result<(), Fault> {
        self.region.update_background(&self.dynamic, rows)
    }

    /// [`CondensedRegion::pass_contact_forces`].
    pub fn pass_contact_forces<const M: usize>(
        &mut self,
        solution: Option<&ContactSolution<T, M>>,
    ) {
        self.region.pass_contact_forces(&mut self.dynamic, solution);
    }

    /// [`CondensedRegion::contact_forces`].
    pub fn contact_forces<const M: usize>(
        &self,
        contacts: &[impl AsConstraint<T>],
    ) -> Result<ContactSolution<T, M>, ContactError> {
        self.region.contact_forces(&self.dynamic, contacts)
    }

    /// [`CondensedRegion::displacements`].
    pub fn displacements<const M: usize>(
        &self,
        solution: Option<&ContactSolution<T, M>>,
        out: &mut [[T; 3]],
    ) -> Result<(), FieldError> {
        self.region.displacements(&self.dynamic, solution, out)
    }
}
