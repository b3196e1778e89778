//! What the haptic loop asks of a tissue model (MODELS.md §6): a surface to
//! touch and, each tick, the force of a set of contacts. Two models answer:
//! [`PrecomputedTissue`] (Cotin 1999, quasi-static, solved every tick) and
//! [`super::dynamic_tissue::DynamicTissue`] (tensor-mass, stepped at the
//! physics rate, force extrapolated in between).

use nalgebra::Vector3;

use super::contact::{SurfaceGeometry, ToolContact};
use crate::precomputed::{Contact, ContactError, ContactSolution, PrecomputedModel};
use crate::table::PrecomputedTable;
use crate::{MAX_CONTACTS, Real};

/// One contact as the loop hands it to the tissue.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactTarget<T> {
    /// The tool point in contact.
    pub tool: usize,
    /// Where on the surface.
    pub contact: ToolContact<T>,
    /// The contact triangle's vertices.
    pub vertices: [u32; 3],
    /// Its unit outward normal.
    pub normal: Vector3<T>,
    /// Signed gap between the tool sphere and the contact point along the
    /// normal, m (negative while the sphere penetrates the tissue's
    /// current surface): the contact point's imposed displacement is
    /// `gap · normal`.
    pub gap_m: T,
    /// The contact point on the tissue's current surface, m.
    pub point_m: Vector3<T>,
    /// The tool sphere's centre, m.
    pub tip_m: Vector3<T>,
}

impl<T: Real> ContactTarget<T> {
    /// A target to overwrite (array filler).
    pub(crate) fn placeholder() -> Self {
        Self {
            tool: 0,
            contact: ToolContact {
                triangle: 0,
                weights: [T::zero(); 3],
            },
            vertices: [0; 3],
            normal: Vector3::zeros(),
            gap_m: T::zero(),
            point_m: Vector3::zeros(),
            tip_m: Vector3::zeros(),
        }
    }
}

/// A solved contact set.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Solved<T, const M: usize> {
    /// Force on the hand (the tissue's reaction on the tool), N.
    pub device_force_n: Vector3<T>,
    /// Force each target applies to the tissue, N (entry `q` for target
    /// `q`; `g · n > 0` is adhesive: the tool would pull).
    pub tissue_forces_n: [Vector3<T>; M],
}

/// Why a contact set was not solved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Refusal {
    /// Target `q` cannot be held: drop it and solve again.
    Contact(usize),
    /// The model is faulted or its result is not finite.
    Fault,
}

/// A tissue model the haptic loop drives.
pub trait Tissue<T: Real, const M: usize> {
    /// The surface as it stands now.
    fn geometry(&self) -> SurfaceGeometry<'_, T>;
    /// Whether a tracked contact with signed gap `gap_m` (m) stays before
    /// the solve (the solve then releases adhesive contacts).
    fn keeps(&self, gap_m: T) -> bool;
    /// The forces of contact set `set` (at most `M` targets). Bounded.
    fn solve(&mut self, set: &[ContactTarget<T>]) -> Result<Solved<T, M>, Refusal>;
    /// Called once at the start of every tick (a clock for models that
    /// extrapolate between physics updates).
    fn begin_tick(&mut self) {}
    /// Forgets the last solution (a fault dropped every contact).
    fn forget(&mut self);
    /// Back to rest with no contact.
    fn reset(&mut self);
}

/// The pre-computed model as a tissue: contacts are solved every tick with
/// the contact compliance (`g = C⁻¹ d`, Cotin 1999 §3), which is the local
/// contact stiffness applied to the tool's current displacement.
pub struct PrecomputedTissue<'a, T: Real, const M: usize> {
    model: PrecomputedModel<'a, T>,
    table: &'a PrecomputedTable<'a, T>,
    solution: Option<ContactSolution<T, M>>,
}

impl<'a, T: Real, const M: usize> PrecomputedTissue<'a, T, M> {
    /// The tissue of `table`, at rest.
    pub fn new(table: &'a PrecomputedTable<'a, T>) -> Self {
        const { assert!(M >= 1 && M <= MAX_CONTACTS, "M must be in 1..=MAX_CONTACTS") };
        Self {
            model: PrecomputedModel::new(*table),
            table,
            solution: None,
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

    fn solve(&mut self, set: &[ContactTarget<T>]) -> Result<Solved<T, M>, Refusal> {
        let mut contacts = [Contact::at_vertex(0, Vector3::zeros()); M];
        for (c, t) in contacts.iter_mut().zip(set) {
            *c = Contact::on_triangle(t.vertices, t.contact.weights, t.normal * t.gap_m);
        }
        let m = set.len().min(M);
        let solution = self
            .model
            .contact_forces::<M>(contacts.get(..m).unwrap_or(&[]))
            .map_err(|e| contact_index(&e).map_or(Refusal::Fault, Refusal::Contact))?;
        let mut tissue_forces_n = [Vector3::zeros(); M];
        for (g, s) in tissue_forces_n.iter_mut().zip(solution.contact_forces_n()) {
            *g = *s;
        }
        let solved = Solved {
            device_force_n: solution.device_force_n(),
            tissue_forces_n,
        };
        self.solution = Some(solution);
        Ok(solved)
    }

    fn forget(&mut self) {
        self.solution = None;
    }

    fn reset(&mut self) {
        self.solution = None;
    }
}

/// The index of the contact a [`ContactError`] names, if any.
fn contact_index(e: &ContactError) -> Option<usize> {
    match *e {
        ContactError::VertexOutOfRange { contact, .. }
        | ContactError::FixedVertex { contact, .. }
        | ContactError::NotOnSurface { contact, .. }
        | ContactError::BadWeights { contact }
        | ContactError::NonFiniteInput { contact }
        | ContactError::IllConditioned { contact } => Some(contact),
        ContactError::DuplicateContact { second, .. } => Some(second),
        ContactError::TooManyContacts { .. } | ContactError::NonFiniteResult => None,
    }
}
