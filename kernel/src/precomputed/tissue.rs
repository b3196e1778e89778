//! The pre-computed model as a tissue for the haptic loop (Cotin 1999 §3;
//! MODELS.md §6): contacts are solved every tick with the contact compliance
//! (`g = C⁻¹ d`), which is the local contact stiffness applied to the tool's
//! current displacement.

use nalgebra::Vector3;

use super::model::SolveBuffers;
use super::{ContactSolution, PrecomputedModel, QuasiNonLinear};
use crate::contact::{Contact, Refusal, SurfaceGeometry, Tissue};
use crate::table::PrecomputedTable;
use crate::{MAX_CONTACTS, Real};

/// The pre-computed model as a tissue, with the last contact solution (for
/// the deformation field at the physics rate) and the solve's working
/// memory (a re-solve after a release reads no table block again).
pub struct PrecomputedTissue<'a, T: Real, const M: usize> {
    model: PrecomputedModel<'a, T>,
    /// The rest surface (kept: building it copies the table's collision
    /// index, about 150 cycles a tick on the Cortex-M4F).
    surface: SurfaceGeometry<'a, T>,
    /// The last solution, valid when `solved`.
    solution: ContactSolution<T, M>,
    solved: bool,
    buffers: SolveBuffers<T, M>,
}

impl<'a, T: Real, const M: usize> PrecomputedTissue<'a, T, M> {
    /// The tissue of `table`, at rest.
    pub fn new(table: &'a PrecomputedTable<'a, T>) -> Self {
        const { assert!(M >= 1 && M <= MAX_CONTACTS, "M must be in 1..=MAX_CONTACTS") };
        Self {
            model: PrecomputedModel::new(*table),
            surface: SurfaceGeometry::new(table),
            solution: ContactSolution::empty(),
            solved: false,
            buffers: SolveBuffers::new(),
        }
    }

    /// The quasi-non-linear tissue ([`PrecomputedModel::with_remap`]).
    pub fn with_remap(self, remap: QuasiNonLinear<T>) -> Self {
        Self {
            model: self.model.with_remap(remap),
            ..self
        }
    }

    /// The model.
    pub fn model(&self) -> &PrecomputedModel<'a, T> {
        &self.model
    }

    /// The last contact solution (for the deformation field at the physics
    /// rate), `None` before the first solve or after a fault.
    pub fn solution(&self) -> Option<&ContactSolution<T, M>> {
        self.solved.then_some(&self.solution)
    }
}

impl<T: Real, const M: usize> Tissue<T, M> for PrecomputedTissue<'_, T, M> {
    fn with_geometry<R>(&self, f: impl FnOnce(&SurfaceGeometry<'_, T>) -> R) -> R {
        f(&self.surface)
    }

    /// The rest surface does not move: a contact whose sphere no longer
    /// reaches it has left.
    fn keeps(&self, gap_m: T) -> bool {
        gap_m < T::zero()
    }

    fn solve(&mut self, set: &mut [&mut Contact<T>]) -> Result<Vector3<T>, Refusal> {
        self.solved = false;
        self.model
            .solve_into(&*set, &mut self.buffers, &mut self.solution)
            .map_err(|e| e.contact().map_or(Refusal::Fault, Refusal::Contact))?;
        self.solved = true;
        for (c, g) in set.iter_mut().zip(self.solution.contact_forces_n()) {
            c.force_n = *g;
        }
        Ok(self.solution.device_force_n())
    }

    fn forget(&mut self) {
        self.solved = false;
        self.buffers.clear();
    }

    fn reset(&mut self) {
        self.forget();
    }
}
