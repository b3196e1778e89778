//! The dynamic tensor-mass model as a tissue for the haptic loop
//! (RR-3510 §5; Cotin 1999 §4; MODELS.md §6).
//!
//! Coupling (imposed displacement with barycentric weights, Cotin 1999 §4;
//! MODELS.md §6): at each physics update, each contact point is moved by
//! `gap · n` onto the tool sphere. The displacement is shared out over its
//! triangle's movable vertices as the minimum-norm solution of
//! `Σ w_i u_i = d`, `Δu_i = s_i d` with `s_i = w_i / Σ_k w_k²`, and those
//! vertices are held ([`TensorMassModel::impose`]); vertices no contact
//! holds any more are released. The model is then stepped and the surface
//! re-binned ([`DeformingSurface::rebin`]). `n` is the triangle's normal at
//! rest, which keeps the force direction and the held displacement steady
//! while the dimple under the tool tilts the deformed triangles. The tool is
//! frictionless and the force on the hand is the work-conjugate of the
//! contact point's displacement: the normal part of `Σ_i s_i f_i` over the
//! held vertices' elastic forces. A vertex's share goes to zero as the
//! contact point reaches the opposite edge, so sliding onto the next
//! triangle changes the held set without a jump in the displacement field.
//! Near a fixed vertex the shares would grow without bound, so a contact
//! with `Σ w² < MIN_MOVABLE_WEIGHT2` over the movable vertices is refused.
//!
//! What a probe's vertices held when its contact was made is given back:
//! the shift `s_i gap n` moves them from where they are, which for a
//! contact made with the tissue away from rest (found from inside the
//! surface after a rebound, tissue another tool pushed onto the probe)
//! keeps that state's tangential displacements and tilt for good, and the
//! force settles short of the static one (measured: 0.33 mN instead of
//! 2.8 mN on a soft cantilever). So each update also moves each of its
//! vertices (held by this contact alone) [`GIVE_BACK`] of the way to its
//! target `s_i D n`, `D = Σ_j w_j u_j·n + gap` the tool's displacement
//! along the rest normal from the contact point at rest: the held state
//! converges to the static answer's, the contact point stays on the tool
//! (`Σ w_i s_i = 1`), and the give-back, a tenth of the offset per update,
//! reaches the hand through the usual extrapolation and its spread
//! correction, never in one jump. A grip keeps its vector as it is.
//!
//! Force between physics updates (extrapolation from the local contact
//! stiffness and the tool's motion, Cotin 1999 §6): each tick sends
//! `F = (n · F_update − α k · gap + blend · offset) n`. `gap` is the tool's
//! motion along the held normal since the update (zero right after it, and
//! independent of which triangle tracking has reached since), and
//! `k = Σ_ij s_i s_j n · K_ij n` comes from the model's current vertex and
//! edge tensors (RR-3510 §5.1). With the rest of the mesh frozen, moving the
//! held vertices by `s_i gap n` changes the force by exactly `−k gap n`, so
//! `α = 1` with no blend ([`Extrapolation::Instantaneous`]) is the model's
//! own force until the next step (exact for the linear law; for St
//! Venant-Kirchhoff `K` is the rest tangent). But the free vertices then
//! relax during the step, so the instantaneous stiffness overshoots and the
//! force drops at every update (a saw-tooth at the physics rate).
//! [`Extrapolation::Secant`] (the default) scales it by the ratio the
//! tissue showed over the last period, `α = n · ΔF / (−k · gap)` clamped to
//! `[0, 1]` (kept when the tool moved less than [`SECANT_MIN_MOTION_M`]; a
//! new contact starts from zero force at `α = 1`), and spreads what an
//! update corrects over the next period: the difference between the force
//! sent on the last tick before the update and the update's force decays
//! linearly to zero over as many ticks as the last period had (`1 − j/k`
//! of it at the `j`-th of `k` ticks), so an update's correction reaches the
//! device in `k` equal steps instead of one jump; the price is that it
//! arrives over one physics period instead of at once. (The offset is
//! taken from the force the tissue last requested, before the supervisor.)
//!
//! Grasping (MODELS.md §6): a held contact ([`Contact::grip_offset_m`])
//! imposes the full vector [`Contact::displacement_m`] on its triangle's
//! vertices with the same shares, and the hand feels the full vector
//! `Σ s_i f_i` at the update, extrapolated with the contact's 3×3
//! stiffness `K_c = Σ_ij s_i s_j K_ij` (`α = 1`): `F = F_update − K_c (tip −
//! tip_update)`. A held contact may pull.
//!
//! Cutting and tearing (Picinbono 2001 §3.1; MODELS.md §3): at each update,
//! first each enabled [`Blade`] removes the tets it touches, and the tet
//! its sphere presses into once it pushes with
//! [`PhysicsConfig::cut_force_n`] (until then the sphere is a probe: the
//! resistance the hand feels ahead of the blade), at most
//! [`PhysicsConfig::cut_capacity_tets`] per update over all blades (the
//! rest at the next updates: nothing is lost, the scan finds them again);
//! after the steps, tets past the [`Tearing`] thresholds are removed, at
//! most its capacity. The removed tets' faces update the deforming surface
//! ([`DeformingSurface::remove_tets`]) before it is re-binned, so the
//! faces they expose are touchable from this update on. A contact whose
//! triangle left the surface is not imposed nor held (its vertices are
//! released), and tracking drops it at the next tick: a grasp torn off
//! loses its hold, and its force falls through the supervisor's slew limit.
//! [`DynamicTissue::removed`] lists the tets the last update removed, in
//! removal order (a replay repeats them exactly).

use core::fmt;

mod extrapolate;

pub use extrapolate::{LocalModel, correction_blend, penalty_on_hand};
mod held;
mod removal;
mod update;

use nalgebra::{Matrix3, Vector3};

use super::cut::TearThresholds;
use super::surface::{DeformingSurface, NonFinitePosition, SurfaceBufferError, SurfaceBuffers};
use super::{Integrator, StepError, TensorMassModel};
use crate::contact::{Contact, Refusal, Supports, SurfaceGeometry, Tissue};
use crate::math::{Dispatch, Portable};
use crate::table::{TriangleIndex, VertexIndex};
use crate::{MAX_CONTACTS, Real};

/// Least `Σ w_i²` over a contact triangle's movable vertices for the
/// tissue to hold it: below it (a contact point near a fixed vertex) the
/// shares `w_i / Σ w²` would exceed 3 and grow without bound, so the
/// contact is refused, as the pre-computed model refuses an ill-conditioned
/// one. With all three vertices movable `Σ w² ≥ 1/3`.
pub const MIN_MOVABLE_WEIGHT2: f64 = 1.0 / 9.0;

/// Most model steps per physics update (a compile-time bound on the
/// update's loop; `PhysicsConfig::substeps` above it is refused).
pub const MAX_SUBSTEPS: u32 = 10_000;

/// Part of what separates a probe's held vertices from their target (their
/// shares of the tool's displacement along the rest normal, from rest)
/// that each physics update gives back, on top of the tick's gap: a
/// contact made with the tissue away from rest (found from inside the
/// surface after a rebound, or pushed by another tool) holds its vertices
/// where it found them, and would otherwise keep that offset, and a force
/// short of the static one, for good. A tenth per update returns 99.5 % of
/// it in 50 updates and moves the held vertices by at most a tenth of it at
/// once (no force jump).
pub const GIVE_BACK: f64 = 0.1;

/// Least normal tool motion over a physics period, m, for a new secant
/// stiffness ratio (below it the ratio is noise: kept from before).
pub const SECANT_MIN_MOTION_M: f64 = 1e-6;

/// Most tets one physics update removes on purpose, per kind (cutting,
/// tearing): the largest [`PhysicsConfig::cut_capacity_tets`] and
/// [`Tearing::capacity_tets`].
pub const MAX_REMOVAL_CAPACITY: u32 = 64;

/// Most tets one physics update removes in all: each kind stops at its
/// capacity, plus the at most 4 tets the last removal leaves hanging
/// (`remove_tet`), plus one pressed tet per blade.
pub const MAX_REMOVED_PER_UPDATE: usize = 2 * (MAX_REMOVAL_CAPACITY as usize + 4) + MAX_CONTACTS;

/// An enabled blade at a physics update (MODELS.md §6; built by the
/// haptic loop from a [`crate::haptic::ToolAction::Cut`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blade<T> {
    /// The tool point.
    pub tool: usize,
    /// One end of the blade (the tool point), m.
    pub from_m: Vector3<T>,
    /// The other end, m.
    pub to_m: Vector3<T>,
    /// The blade's half-thickness (the tool sphere's radius), m: tets with
    /// a vertex this close to the segment are cut.
    pub radius_m: T,
    /// The surface triangle the tool sphere touches, if any: its tet is cut
    /// too once the sphere pushes it with [`PhysicsConfig::cut_force_n`]
    /// (the tissue ahead of the blade).
    pub pressing: Option<TriangleIndex>,
}

/// The enabled blades of one update, at most one per tool point.
pub type Blades<T> = heapless::Vec<Blade<T>, MAX_CONTACTS>;

/// Tearing at each physics update (MODELS.md §3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tearing<T> {
    /// The thresholds.
    pub thresholds: TearThresholds<T>,
    /// Most tets removed per update (in `1..=MAX_REMOVAL_CAPACITY`).
    pub capacity_tets: u32,
}

/// How the force is extrapolated between physics updates (module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Extrapolation {
    /// `K_c`: the model's force with the rest of the mesh frozen.
    Instantaneous,
    /// `α K_c`, `α` the secant ratio of the last period, and each update's
    /// correction spread over the next period.
    #[default]
    Secant,
}

/// How the dynamic model is stepped at each physics update.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhysicsConfig<T> {
    /// The force between updates.
    pub extrapolation: Extrapolation,
    /// The explicit integrator.
    pub integrator: Integrator,
    /// Step, s (finite, > 0; below the integrator's critical step).
    pub dt_s: T,
    /// Steps per physics update (in `1..=MAX_SUBSTEPS`; the physics period
    /// is `substeps · dt_s`).
    pub substeps: u32,
    /// Most tets the blades remove per update, over all blades (in
    /// `1..=MAX_REMOVAL_CAPACITY`).
    pub cut_capacity_tets: u32,
    /// The push of a blade's sphere, N, at which the tet it presses into
    /// gives way (finite, > 0): below it the sphere is a probe, so the hand
    /// feels the tissue ahead of the blade build up to this force, then
    /// give.
    pub cut_force_n: T,
    /// Tearing, or none.
    pub tearing: Option<Tearing<T>>,
}

impl<T: Real> PhysicsConfig<T> {
    /// Secant extrapolation, `substeps` steps of `dt_s` (s) with
    /// `integrator` per update, a cut capacity of 8 tets per update, no
    /// tearing.
    pub fn new(integrator: Integrator, dt_s: T, substeps: u32) -> Self {
        Self {
            extrapolation: Extrapolation::Secant,
            integrator,
            dt_s,
            substeps,
            cut_capacity_tets: 8,
            cut_force_n: T::of_f64(0.2),
            tearing: None,
        }
    }
}

/// Why a dynamic tissue was not built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DynamicTissueError {
    /// A surface buffer has the wrong length.
    Surface(SurfaceBufferError),
    /// The force scratch buffer is not one entry per vertex.
    ForceBuffer {
        /// Vertices of the table.
        expected: usize,
        /// Entries given.
        found: usize,
    },
    /// `dt_s` not finite and positive, `substeps` not in
    /// `1..=MAX_SUBSTEPS`, a removal capacity not in
    /// `1..=MAX_REMOVAL_CAPACITY`, or a cut force not finite and > 0.
    BadPhysics,
}

impl fmt::Display for DynamicTissueError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Surface(e) => e.fmt(f),
            Self::ForceBuffer { expected, found } => {
                write!(f, "force buffer: length {found}, expected {expected}")
            }
            Self::BadPhysics => {
                f.write_str("physics dt_s must be finite and > 0, substeps in 1..=MAX_SUBSTEPS, removal capacities in 1..=MAX_REMOVAL_CAPACITY, the cut force finite and > 0")
            }
        }
    }
}

impl core::error::Error for DynamicTissueError {}

/// Why a physics update failed: the tissue is faulted until reset (the
/// loop's next tick latches a model fault, zero force).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PhysicsError {
    /// The step failed or diverged.
    Step(StepError),
    /// The surface could not be re-binned.
    Surface(NonFinitePosition),
    /// An imposed displacement was not finite.
    NonFiniteContact {
        /// The tool point.
        tool: usize,
    },
}

impl fmt::Display for PhysicsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Step(e) => write!(f, "step: {e}"),
            Self::Surface(e) => write!(f, "surface: {e}"),
            Self::NonFiniteContact { tool } => {
                write!(f, "tool point {tool}: non-finite contact displacement")
            }
        }
    }
}

impl core::error::Error for PhysicsError {}

/// What a tool point's contact held at the last physics update.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeldContact<T> {
    /// The contact at the update, in the rest frame: its `normal` is the
    /// held triangle's unit normal at rest (the direction of the force and
    /// of the held displacement), `tip_m` the tool sphere's centre at the
    /// update (the contact point then touches it), and `force_n` the force
    /// the tool applies to the tissue after the update, `−Σ s_i f_i` over the
    /// held vertices' elastic forces, N.
    pub contact: Contact<T>,
    /// Each vertex's share `s_i` of the contact point's displacement.
    pub shares: [T; 3],
    /// `k = n · K_c n` of the held vertices along `normal`, N/m.
    pub stiffness_n_per_m: T,
    /// `K_c = Σ_ij s_i s_j K_ij` of the held vertices, N/m (computed once
    /// per update: the tensors change only by cuts).
    pub stiffness_tensor_n_per_m: Matrix3<T>,
    /// Extrapolation stiffness ratio `α`, in `[0, 1]`.
    pub scale: T,
    /// Normal force sent just before the update minus the update's, N
    /// (decays to zero over the next period; zero when instantaneous).
    pub offset_n: T,
}

/// The dynamic model, its deforming surface and what each of the `P` tool
/// points holds; the model's steps run through `D` ([`Dispatch`]: the
/// kernel's own [`Portable`] unless a host says otherwise with
/// [`DynamicTissue::with_dispatch`]).
pub struct DynamicTissue<'a, 's, T: Real, const P: usize, D: Dispatch = Portable> {
    model: TensorMassModel<'a, 's, T>,
    surface: DeformingSurface<'a, 's, T>,
    forces_n: &'s mut [[T; 3]],
    physics: PhysicsConfig<T>,
    held: [Option<HeldContact<T>>; P],
    removed: heapless::Vec<u32, MAX_REMOVED_PER_UPDATE>,
    fault: Option<PhysicsError>,
    /// Ticks since the last update, and in the period before it (≥ 1).
    ticks_since_update: u32,
    period_ticks: u32,
    dispatch: D,
}

impl<'a, 's, T: Real, const P: usize> DynamicTissue<'a, 's, T, P> {
    /// The tissue of `model` (its current state), with the surface buffers
    /// and a force scratch buffer of one entry per vertex; its steps run
    /// portable.
    pub fn new(
        model: TensorMassModel<'a, 's, T>,
        surface: SurfaceBuffers<'s, T>,
        forces_n: &'s mut [[T; 3]],
        physics: PhysicsConfig<T>,
    ) -> Result<Self, DynamicTissueError> {
        let n = model.table().vertex_count();
        if forces_n.len() != n {
            return Err(DynamicTissueError::ForceBuffer {
                expected: n,
                found: forces_n.len(),
            });
        }
        let capacity = 1..=MAX_REMOVAL_CAPACITY;
        if !(physics.dt_s.finite()
            && physics.dt_s > T::zero()
            && (1..=MAX_SUBSTEPS).contains(&physics.substeps)
            && capacity.contains(&physics.cut_capacity_tets)
            && physics.cut_force_n.finite()
            && physics.cut_force_n > T::zero()
            && physics
                .tearing
                .is_none_or(|t| capacity.contains(&t.capacity_tets)))
        {
            return Err(DynamicTissueError::BadPhysics);
        }
        let surface =
            DeformingSurface::new(&model, surface).map_err(DynamicTissueError::Surface)?;
        Ok(Self {
            model,
            surface,
            forces_n,
            physics,
            held: [None; P],
            removed: heapless::Vec::new(),
            fault: None,
            ticks_since_update: 0,
            period_ticks: 1,
            dispatch: Portable,
        })
    }
}

impl<'a, 's, T: Real, const P: usize, D: Dispatch> DynamicTissue<'a, 's, T, P, D> {
    /// The same tissue with its model's steps run through `dispatch` (a
    /// host's run-time CPU-feature dispatch; same results).
    pub fn with_dispatch<E: Dispatch>(self, dispatch: E) -> DynamicTissue<'a, 's, T, P, E> {
        DynamicTissue {
            model: self.model,
            surface: self.surface,
            forces_n: self.forces_n,
            physics: self.physics,
            held: self.held,
            removed: self.removed,
            fault: self.fault,
            ticks_since_update: self.ticks_since_update,
            period_ticks: self.period_ticks,
            dispatch,
        }
    }

    /// The tets the last physics update removed (blades, then tearing, each
    /// with the tets it left hanging), in removal order.
    pub fn removed(&self) -> &[u32] {
        &self.removed
    }

    /// The dynamic model, to pass it a coupled region's forces (the
    /// hybrid tissue).
    pub(crate) fn model_mut(&mut self) -> &mut TensorMassModel<'a, 's, T> {
        &mut self.model
    }

    /// The model.
    pub fn model(&self) -> &TensorMassModel<'a, 's, T> {
        &self.model
    }

    /// The deforming surface.
    pub fn surface(&self) -> &DeformingSurface<'a, 's, T> {
        &self.surface
    }

    /// What each tool point held at the last physics update.
    pub fn held(&self) -> &[Option<HeldContact<T>>; P] {
        &self.held
    }

    /// The fault of the last physics update, if any (cleared by reset).
    pub fn fault(&self) -> Option<PhysicsError> {
        self.fault
    }

    /// `true` for a vertex the tool can move (not fixed by the table).
    fn movable(&self, v: VertexIndex) -> bool {
        !self.model.table().is_fixed_vertex(v)
    }

    /// Each vertex's share of the contact point's displacement, the
    /// minimum-norm solution of `Σ w_i u_i = d`: `s_i = w_i / Σ_k w_k²`
    /// over the movable vertices, 0 for a fixed one; all 0 when
    /// `Σ_k w_k² < MIN_MOVABLE_WEIGHT2` (the solve refuses such a contact).
    fn shares(&self, t: &Contact<T>) -> [T; 3] {
        self.shares_at(&t.vertices, t.weights)
    }

    /// [`Self::shares`] of a point with barycentric `w` on the triangle of
    /// `vertices`.
    #[inline(always)]
    fn shares_at(&self, vertices: &[VertexIndex; 3], w: [T; 3]) -> [T; 3] {
        let movable = vertices.map(|v| self.movable(v));
        let norm2 = w
            .iter()
            .zip(&movable)
            .filter(|(_, m)| **m)
            .fold(T::zero(), |a, (w, _)| a + *w * *w);
        let mut s = [T::zero(); 3];
        if norm2 >= T::of_f64(MIN_MOVABLE_WEIGHT2) {
            for ((s, w), m) in s.iter_mut().zip(&w).zip(&movable) {
                if *m {
                    *s = *w / norm2;
                }
            }
        }
        s
    }

    /// `t` with the normal of its triangle at rest and the gap measured
    /// along it (module docs: the rest normal keeps the force direction
    /// and the held translation steady while the dimple under the tool
    /// tilts the deformed triangles).
    fn in_rest_frame(&self, t: &Contact<T>) -> Contact<T> {
        let rest = self.model.table().rest_positions();
        let at = |v: VertexIndex| rest.get(v.get()).map(|p| Vector3::new(p[0], p[1], p[2]));
        let [a, b, c] = t.vertices.map(at);
        let normal = match (a, b, c) {
            (Some(a), Some(b), Some(c)) => (b - a).cross(&(c - a)).try_normalize(T::zero()),
            _ => None,
        }
        .unwrap_or(t.normal);
        Contact {
            normal,
            gap_m: t.gap_m + (t.tip_m - t.point_m).dot(&(normal - t.normal)),
            ..*t
        }
    }
}

impl<T: Real, const P: usize, const M: usize, D: Dispatch> Tissue<T, M>
    for DynamicTissue<'_, '_, T, P, D>
{
    fn with_geometry<R>(&self, f: impl FnOnce(&SurfaceGeometry<'_, T>) -> R) -> R {
        f(&self
            .surface
            .geometry(Supports::TensorMass(self.model.table())))
    }

    /// The surface follows a held contact, so the gap says nothing about
    /// leaving: a contact stays until its force would pull (the solve).
    fn keeps(&self, _gap_m: T) -> bool {
        true
    }

    /// `F_q = (n · F_update − α k · gap + blend · offset) n` per contact
    /// (module docs); the force of the last update carries over while the
    /// contact stays on or next to the triangle it held (they share a
    /// vertex).
    fn solve(&mut self, set: &mut [&mut Contact<T>]) -> Result<Vector3<T>, Refusal> {
        if self.fault.is_some() || self.model.fault().is_some() {
            return Err(Refusal::Fault);
        }
        let mut device_force_n = Vector3::zeros();
        for (q, c) in set.iter_mut().enumerate() {
            let t = self.in_rest_frame(c);
            let shares = self.shares(&t);
            if shares == [T::zero(); 3] {
                return Err(Refusal::Contact(q));
            }
            let force_n = self.extrapolate(&t, &shares);
            device_force_n += force_n;
            c.force_n = -force_n;
        }
        Ok(device_force_n)
    }

    fn can_cut(&self) -> bool {
        true
    }

    fn begin_tick(&mut self) {
        self.ticks_since_update = self.ticks_since_update.saturating_add(1);
    }

    fn forget(&mut self) {}

    /// Back to rest: the model's reset (every tet alive again), nothing
    /// held, the surface uncut and at rest.
    fn reset(&mut self) {
        self.model.reset();
        self.surface.reset_faces();
        self.removed.clear();
        self.held = [None; P];
        self.fault = None;
        self.ticks_since_update = 0;
        self.period_ticks = 1;
        // Rest positions come from a validated table: finite.
        let _ = self.surface.rebin(&[]);
    }
}
