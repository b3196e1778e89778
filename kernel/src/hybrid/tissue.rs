//! The hybrid model as a tissue for the haptic loop (RR-3510 §6.2;
//! MODELS.md §6): contacts on the tensor-mass region are held and imposed
//! at the physics rate, their force extrapolated in between
//! ([`crate::tensor_mass::DynamicTissue`], which this wraps); contacts on
//! the pre-computed region are solved every tick with the compliance `C⁰`
//! (connection nodes held) for their gap beyond the surface, which stands
//! at the background the connection nodes give it (so the gap is the
//! displacement [`CondensedRegion::contact_forces`] solves for a scripted
//! constraint given from rest), and their forces reach the connection
//! nodes at the next physics update.
//! Both touch one surface, the whole mesh's ([`HybridSurface`]).

use core::fmt;

use nalgebra::Vector3;

use super::region::{CondensedRegion, HybridBuffers, HybridError};
use super::surface::{HybridSurface, HybridSurfaceBuffers, SlotRegion};
use crate::contact::{
    Contact, ContactRefs, ContactSet, Refusal, Supports, SurfaceGeometry, Tissue, lend,
};
use crate::math::{Dispatch, Portable};
use crate::precomputed::ContactSolution;
use crate::table::{InterfaceTable, PrecomputedTable, VertexIndex};
use crate::tensor_mass::{
    Blade, Blades, DynamicTissue, DynamicTissueError, PhysicsConfig, PhysicsError, StepError,
    StepReport, SurfaceBufferError, SurfaceBuffers, TensorMassModel,
};
use crate::{MAX_CONTACTS, Real};

/// Why a hybrid tissue was not built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HybridTissueError {
    /// The tables or the coupling buffers do not belong together.
    Coupling(HybridError),
    /// The tensor-mass region's tissue refused its buffers or physics.
    Dynamic(DynamicTissueError),
    /// A hybrid surface buffer has the wrong length.
    Surface(SurfaceBufferError),
}

impl fmt::Display for HybridTissueError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Coupling(e) => e.fmt(f),
            Self::Dynamic(e) => write!(f, "dynamic region: {e}"),
            Self::Surface(e) => write!(f, "hybrid surface: {e}"),
        }
    }
}

impl core::error::Error for HybridTissueError {}

/// The tensor-mass region's tissue, the condensed pre-computed region, the
/// whole surface and the last solution of the pre-computed contacts.
///
/// `D`: where the tensor-mass region's steps run ([`Self::with_dispatch`];
/// portable by default).
pub struct HybridTissue<'a, 's, T: Real, const P: usize, const M: usize, D: Dispatch = Portable> {
    dynamic: DynamicTissue<'a, 's, T, P, D>,
    region: CondensedRegion<'a, 's, T>,
    surface: HybridSurface<'s, T>,
    solution: Option<ContactSolution<T, M>>,
    fault: Option<PhysicsError>,
}

impl<'a, 's, T: Real, const P: usize, const M: usize> HybridTissue<'a, 's, T, P, M> {
    /// Couples `model` (the tensor-mass region, at rest) to the pre-computed
    /// region ([`CondensedRegion::couple`]), wraps it in its tissue
    /// ([`DynamicTissue::new`] with `surface`, `forces_n` and `physics`)
    /// and builds the whole surface over `buffers`.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        mut model: TensorMassModel<'a, 's, T>,
        surface: SurfaceBuffers<'s, T>,
        forces_n: &'s mut [[T; 3]],
        physics: PhysicsConfig<T>,
        precomputed: PrecomputedTable<'a, T>,
        interface: InterfaceTable<'a, T>,
        coupling: HybridBuffers<'s, T>,
        buffers: HybridSurfaceBuffers<'s, T>,
    ) -> Result<Self, HybridTissueError> {
        const { assert!(M >= 1 && M <= MAX_CONTACTS, "M must be in 1..=MAX_CONTACTS") };
        let mut region = CondensedRegion::couple(&mut model, precomputed, interface, coupling)
            .map_err(HybridTissueError::Coupling)?;
        let dynamic = DynamicTissue::new(model, surface, forces_n, physics)
            .map_err(HybridTissueError::Dynamic)?;
        let touchable = precomputed.touchable_count();
        // A model at rest is not faulted.
        let _ = region.update_background(dynamic.model(), touchable);
        let surface = HybridSurface::new(
            &region,
            dynamic.model(),
            dynamic.surface().triangles(),
            buffers,
        )
        .map_err(HybridTissueError::Surface)?;
        Ok(Self {
            dynamic,
            region,
            surface,
            solution: None,
            fault: None,
        })
    }
}

impl<'a, 's, T: Real, const P: usize, const M: usize, D: Dispatch>
    HybridTissue<'a, 's, T, P, M, D>
{
    /// The same tissue with its tensor-mass region's steps run through
    /// `dispatch` ([`DynamicTissue::with_dispatch`]; same results).
    pub fn with_dispatch<E: Dispatch>(self, dispatch: E) -> HybridTissue<'a, 's, T, P, M, E> {
        HybridTissue {
            dynamic: self.dynamic.with_dispatch(dispatch),
            region: self.region,
            surface: self.surface,
            solution: self.solution,
            fault: self.fault,
        }
    }

    /// The interface part of [`Self::update`] alone: the pre-computed
    /// region's touchable background at the tensor-mass region's current
    /// displacements ([`CondensedRegion::update_background`]), for timing
    /// it; the next update recomputes it anyway.
    pub fn update_background(&mut self) -> Result<(), crate::tensor_mass::Fault> {
        let touchable = self.region.precomputed().table().touchable_count();
        self.region
            .update_background(self.dynamic.model(), touchable)
    }

    /// The tensor-mass region's tissue (its model, removed tets, holds).
    pub fn dynamic(&self) -> &DynamicTissue<'a, 's, T, P, D> {
        &self.dynamic
    }

    /// The condensed pre-computed region.
    pub fn region(&self) -> &CondensedRegion<'a, 's, T> {
        &self.region
    }

    /// The whole surface.
    pub fn surface(&self) -> &HybridSurface<'s, T> {
        &self.surface
    }

    /// The last solution of the contacts on the pre-computed region.
    pub fn solution(&self) -> Option<&ContactSolution<T, M>> {
        self.solution.as_ref()
    }

    /// A fault of the last physics update, the tensor-mass region's
    /// included.
    pub fn fault(&self) -> Option<PhysicsError> {
        self.fault.or(self.dynamic.fault())
    }

    /// Contact `c` (on the whole surface) in the tensor-mass region's
    /// numbering; `None` for a contact on the pre-computed region.
    fn to_dynamic(&self, c: &Contact<T>) -> Option<Contact<T>> {
        let SlotRegion::Dynamic(triangle) = self.surface.region_of(c.triangle)? else {
            return None;
        };
        let interface = self.region.interface();
        let count = self.dynamic.model().table().vertex_count();
        let local = |v: VertexIndex| {
            interface
                .dynamic_vertex(v.as_u32())
                .and_then(|d| VertexIndex::new(d, count))
        };
        let [a, b, d] = c.vertices;
        let (Some(a), Some(b), Some(d)) = (local(a), local(b), local(d)) else {
            return None;
        };
        Some(Contact {
            triangle,
            vertices: [a, b, d],
            ..*c
        })
    }

    /// The physics update (see [`crate::haptic::PhysicsTissue`]): the
    /// pre-computed contacts' last forces passed to the connection nodes,
    /// the tensor-mass region's update with its contacts and blades, the
    /// touchable background and the whole surface rebuilt.
    pub fn update(
        &mut self,
        set: &ContactSet<T, M>,
        blades: &Blades<T>,
    ) -> Result<StepReport<T>, PhysicsError> {
        if let Some(fault) = self.fault {
            return Err(fault);
        }
        let result = self.try_update(set, blades);
        if let Err(e) = result {
            self.fault = Some(e);
        }
        result
    }

    fn try_update(
        &mut self,
        set: &ContactSet<T, M>,
        blades: &Blades<T>,
    ) -> Result<StepReport<T>, PhysicsError> {
        self.region
            .pass_contact_forces(self.dynamic.model_mut(), self.solution.as_ref());
        let mut local: ContactSet<T, M> = ContactSet::new();
        for c in set.iter().filter_map(|c| self.to_dynamic(c)) {
            // At most as many as `set` holds.
            let _ = local.push(c);
        }
        let mut local_blades = Blades::new();
        for blade in blades {
            let pressing = blade
                .pressing
                .and_then(|t| match self.surface.region_of(t) {
                    Some(SlotRegion::Dynamic(d)) => Some(d),
                    _ => None,
                });
            // As many as `blades` holds.
            let _ = local_blades.push(Blade { pressing, ..*blade });
        }
        // The whole surface is binned below: the region's own is not.
        let report = self.dynamic.update_unbinned(&local, &local_blades)?;
        let touchable = self.region.precomputed().table().touchable_count();
        self.region
            .update_background(self.dynamic.model(), touchable)
            .map_err(|f| PhysicsError::Step(StepError::Faulted(f)))?;
        self.surface
            .rebuild(
                &self.region,
                self.dynamic.model(),
                self.dynamic.surface().triangles(),
            )
            .map_err(PhysicsError::Surface)?;
        Ok(report)
    }
}

impl<T: Real, const P: usize, const M: usize, D: Dispatch> Tissue<T, M>
    for HybridTissue<'_, '_, T, P, M, D>
{
    fn with_geometry<R>(&self, f: impl FnOnce(&SurfaceGeometry<'_, T>) -> R) -> R {
        f(&self.surface.geometry(Supports::Hybrid {
            precomputed: self.region.precomputed().table(),
            dynamic: self.dynamic.model().table(),
            interface: self.region.interface(),
        }))
    }

    /// The tensor-mass surface follows a held contact, and the pre-computed
    /// surface moves with the connection nodes: a contact stays until its
    /// force would pull (the solve).
    fn keeps(&self, _gap_m: T) -> bool {
        true
    }

    /// The tensor-mass region's contacts by its tissue, the pre-computed
    /// region's by the condensed solve; the hand feels their sum.
    fn solve(&mut self, set: &mut [&mut Contact<T>]) -> Result<Vector3<T>, Refusal> {
        if self.fault().is_some() || set.len() > M {
            return Err(Refusal::Fault);
        }
        // The tensor-mass region's contacts in its own frame (copies), the
        // pre-computed region's as they are; each sub-set's place in `set`.
        let mut dynamic_set: ContactSet<T, M> = ContactSet::new();
        let mut dynamic_index: heapless::Vec<usize, M> = heapless::Vec::new();
        let mut precomputed_index: heapless::Vec<usize, M> = heapless::Vec::new();
        for (q, c) in set.iter().enumerate() {
            // Each sub-set holds at most as many as `set`.
            match self.to_dynamic(c) {
                Some(local) => {
                    let _ = dynamic_set.push(local);
                    let _ = dynamic_index.push(q);
                }
                None => {
                    let _ = precomputed_index.push(q);
                }
            }
        }
        let mut device_force_n = Vector3::zeros();
        if !dynamic_set.is_empty() {
            let mut local: ContactRefs<'_, T, M> = lend(&mut dynamic_set);
            device_force_n += Tissue::<T, M>::solve(&mut self.dynamic, &mut local)
                .map_err(|r| remap(r, &dynamic_index))?;
            drop(local);
            for (c, &q) in dynamic_set.iter().zip(&dynamic_index) {
                if let Some(original) = set.get_mut(q) {
                    original.force_n = c.force_n;
                }
            }
        }
        self.solution = None;
        if !precomputed_index.is_empty() {
            // The surface stands at the background: a contact's gap is
            // already the displacement beyond it, what `C⁰` answers.
            // Lent in their order (`precomputed_index` increases).
            let mut next = precomputed_index.iter().peekable();
            let picked = set
                .iter_mut()
                .enumerate()
                .filter_map(|(q, c)| next.next_if(|&&i| i == q).map(|_| &mut **c));
            let mut precomputed_set: ContactRefs<'_, T, M> = lend(picked);
            let solution = self
                .region
                .precomputed()
                .contact_forces::<M>(precomputed_set.as_slice())
                .map_err(|e| {
                    e.contact().map_or(Refusal::Fault, |i| {
                        remap(Refusal::Contact(i), &precomputed_index)
                    })
                })?;
            for (g, c) in solution.contact_forces_n().iter().zip(&mut precomputed_set) {
                c.force_n = *g;
            }
            device_force_n += solution.device_force_n();
            self.solution = Some(solution);
        }
        Ok(device_force_n)
    }

    fn begin_tick(&mut self) {
        Tissue::<T, M>::begin_tick(&mut self.dynamic);
    }

    fn can_cut(&self) -> bool {
        true
    }

    fn forget(&mut self) {
        self.solution = None;
        Tissue::<T, M>::forget(&mut self.dynamic);
    }

    /// Back to rest: the tensor-mass region's reset, no pre-computed
    /// contact, the background at the load's, the surface rebuilt.
    fn reset(&mut self) {
        Tissue::<T, M>::reset(&mut self.dynamic);
        self.region.reset(self.dynamic.model_mut());
        let touchable = self.region.precomputed().table().touchable_count();
        let _ = self
            .region
            .update_background(self.dynamic.model(), touchable);
        self.solution = None;
        self.fault = None;
        // Rest positions of validated tables are finite.
        let _ = self.surface.rebuild(
            &self.region,
            self.dynamic.model(),
            self.dynamic.surface().triangles(),
        );
    }
}

/// A refusal of contact `i` of a sub-set as a refusal of the whole set's
/// contact `index[i]`.
fn remap(refusal: Refusal, index: &[usize]) -> Refusal {
    match refusal {
        Refusal::Contact(i) => index
            .get(i)
            .map_or(Refusal::Fault, |&q| Refusal::Contact(q)),
        Refusal::Fault => Refusal::Fault,
    }
}
