//! [`TensorMassModel::with_split`]: a model's per-tet force pass split into
//! parts ([`super::split`]), kept apart from the model's file and the
//! split pass's so that neither imports the other.

use super::model::TensorMassModel;
use super::split::SplitBuffers;
use super::state::StateError;
use crate::Real;

impl<'a, 's, T: Real> TensorMassModel<'a, 's, T> {
    /// The same model with its per-tet force pass split into
    /// `dispatch.parts()` parts whenever a step's [`crate::math::Dispatch`] has more than
    /// one (the corner gradients by blocks of tets, then each vertex gathering
    /// its corners in tet order: the same results for any number of parts), on
    /// `buffers` ([`SplitBuffers::lengths`]). Fails on a buffer of the wrong
    /// length. Cost: two passes over the tets (the corner lists).
    pub fn with_split(mut self, mut buffers: SplitBuffers<'s, T>) -> Result<Self, StateError> {
        buffers.prepare(&self.table)?;
        self.split = Some(buffers);
        Ok(self)
    }
}
