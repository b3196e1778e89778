//! The pre-computed model as a tissue for the haptic loop (Cotin 1999 §3;
//! MODELS.md §6): contacts are solved every tick with the contact compliance
//! (`g = C⁻¹ d`), which is the local contact stiffness applied to the tool's
//! current displacement.

use nalgebra::Vector3;

use super::model::ComplianceMemo;
use super::{ContactSolution, PrecomputedModel, QuasiNonLinear};
use crate::contact::{ContactSet, Refusal, SurfaceGeometry, Tissue};
use crate::table::PrecomputedTable;
use crate::{MAX_CONTACTS, Real};

/// The pre-computed model as a tissue, with the last contact solution (for
/// the deformation field at the physics rate) and its point compliances (a
/// re-solve after a release reads no table block again).
pub struct PrecomputedTissue<'a, T: Real, const M: usize> {
    model: PrecomputedModel<'a, T>,
    table: &'a PrecomputedTable<'a, T>,
    solution: Option<ContactSolution<T, M>>,
    memo: ComplianceMemo<T, M>,
}

impl<'a, T: Real, const M: usize> PrecomputedTissue<'a, T, M> {
    /// The tissue of `table`, at rest.
    pub fn new(table: &'a PrecomputedTable<'a, T>) -> Self {
        const { assert!(M >= 1 && M <= MAX_CONTACTS, "M must be in 1..=MAX_CONTACTS") };
        Self {
            model: PrecomputedModel::new(*table),
            table,
            solution: None,
            memo: ComplianceMemo::new(),
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
        self.solution.as_ref()
    }
}

impl<T: Real, const M: usize> Tissue<T, M> for PrecomputedTissue<'_, T, M> {
    fn geometry(&self) -> SurfaceGeometry<'_, T> {
        SurfaceGeometry::new(self.table)
    }

    /// The rest surface does not move: a contact whose sphere no longer
    /// reaches it has left.
    fn keeps(&self, gap_m: T) -> bool {
        gap_m < T::zero()
    }

    fn solve(&mut self, set: &mut ContactSet<T, M>) -> Result<Vector3<T>, Refusal> {
        let solution = self
            .model
            .contact_forces_memo(set.as_slice(), &mut self.memo)
            .map_err(|e| e.contact().map_or(Refusal::Fault, Refusal::Contact))?;
        for (c, g) in set.iter_mut().zip(solution.contact_forces_n()) {
            c.force_n = *g;
        }
        let device_force_n = solution.device_force_n();
        self.solution = Some(solution);
        Ok(device_force_n)
    }

    fn forget(&mut self) {
        self.solution = None;
        self.memo.clear();
    }

    fn reset(&mut self) {
        self.forget();
    }
}
