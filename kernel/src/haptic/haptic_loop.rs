//! The fixed-timestep haptic loop (Cotin 1999; MODELS.md §6): each tick
//! reads the tool points, detects and tracks contacts on the tissue's
//! surface, solves the contact forces and passes the device force through
//! the safety supervisor.
//!
//! Force between physics updates, per tissue model:
//! - [`PrecomputedTissue`]: the contact solve *is* the local contact
//!   stiffness applied to the tool's current displacement (`g = C⁻¹ d`,
//!   exact for the linear model) and costs well under a microsecond, so it
//!   runs every tick; what runs at the lower physics rate (every
//!   `physics_every` ticks, by the caller) is the deformation field,
//!   [`PrecomputedTissue::solution`] into `PrecomputedModel::displacements`.
//! - [`DynamicTissue`]: the model steps at the physics rate
//!   ([`HapticLoop::physics_update`]); in between, each tick extrapolates
//!   the last update's force with the local contact stiffness and the
//!   tool's motion since (see `dynamic_tissue`).

use nalgebra::Vector3;

use super::contact::{ContactWork, ToolContact};
use super::dynamic_tissue::{DynamicTissue, PhysicsError};
use super::safety::{BadLimits, OutputStatus, SafetyFault, SafetyLimits, Supervisor};
use super::tissue::{ContactTarget, PrecomputedTissue, Refusal, Tissue};
use crate::tensor_mass::StepReport;
use crate::{MAX_CONTACTS, Real};

/// What the device receives each tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ForceOutput<T> {
    /// Force on the hand, N (after the supervisor).
    pub force_n: Vector3<T>,
    /// Ok, clamped, or faulted with the reason.
    pub status: OutputStatus,
    /// Tool points in contact.
    pub contacts: u8,
    /// Tool points whose new contact was refused this tick (capacity `M`
    /// reached, or a contact set the model refused); never silently dropped.
    pub refused: u8,
}

/// Per-tick work counters (for timing budgets: deterministic counts).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TickCounters {
    /// Detection and tracking work.
    pub contact: ContactWork,
    /// Contact solves (1, or more when a contact is released or refused).
    pub solves: u32,
}

/// Loop settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LoopConfig<T> {
    /// Radius of each tool point's sphere, m.
    pub radius_m: T,
    /// Haptic period, s (1 kHz: 1e-3).
    pub dt_s: T,
    /// Output limits.
    pub limits: SafetyLimits<T>,
}

/// Why a loop was not built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LoopError {
    /// Radius or period not finite and positive.
    BadConfig,
    /// Safety limits out of range.
    BadLimits(BadLimits),
}

impl core::fmt::Display for LoopError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::BadConfig => f.write_str("tool radius and haptic period must be finite and > 0"),
            Self::BadLimits(e) => e.fmt(f),
        }
    }
}

impl core::error::Error for LoopError {}

/// The haptic loop over tissue `B`: `P` tool points, at most `M`
/// simultaneous contacts.
pub struct HapticLoop<T: Real, B, const P: usize, const M: usize> {
    tissue: B,
    config: LoopConfig<T>,
    supervisor: Supervisor<T>,
    previous_m: Option<[Vector3<T>; P]>,
    contacts: [Option<ToolContact<T>>; P],
    counters: TickCounters,
}

/// The loop over the pre-computed model.
pub type PrecomputedLoop<'a, T, const P: usize, const M: usize> =
    HapticLoop<T, PrecomputedTissue<'a, T, M>, P, M>;

/// The loop over the dynamic tensor-mass model.
pub type DynamicLoop<'a, 's, T, const P: usize, const M: usize> =
    HapticLoop<T, DynamicTissue<'a, 's, T, P>, P, M>;

impl<T: Real, B: Tissue<T, M>, const P: usize, const M: usize> HapticLoop<T, B, P, M> {
    /// A loop at rest (no contact, zero force) over `tissue`.
    pub fn new(tissue: B, config: LoopConfig<T>) -> Result<Self, LoopError> {
        const {
            assert!(
                P >= 1 && P <= MAX_CONTACTS,
                "tool points P must be in 1..=MAX_CONTACTS"
            );
            assert!(M >= 1 && M <= P, "contact capacity M must be in 1..=P");
        };
        let ok = |x: T| x.finite() && x > T::zero();
        if !(ok(config.radius_m) && ok(config.dt_s)) {
            return Err(LoopError::BadConfig);
        }
        Ok(Self {
            tissue,
            config,
            supervisor: Supervisor::new(config.limits).map_err(LoopError::BadLimits)?,
            previous_m: None,
            contacts: [None; P],
            counters: TickCounters::default(),
        })
    }

    /// The tissue.
    pub fn tissue(&self) -> &B {
        &self.tissue
    }

    /// Each tool point's contact.
    pub fn contacts(&self) -> &[Option<ToolContact<T>>; P] {
        &self.contacts
    }

    /// The last tick's work.
    pub fn counters(&self) -> &TickCounters {
        &self.counters
    }

    /// Clears a latched fault and every contact and puts the tissue back at
    /// rest; the force ramps up from zero at the slew limit.
    pub fn reset(&mut self) {
        self.supervisor.reset();
        self.contacts = [None; P];
        self.previous_m = None;
        self.tissue.reset();
    }

    /// One haptic tick with the tool points at `tool_m` (sphere centres, m).
    /// Bounded: detection and tracking per point (see
    /// [`super::contact::SurfaceGeometry::detect`] and `track`), then at
    /// most `P + 1` contact solves of at most `M` contacts.
    pub fn tick(&mut self, tool_m: &[Vector3<T>; P]) -> ForceOutput<T> {
        self.counters = TickCounters::default();
        self.tissue.begin_tick();
        let dt = self.config.dt_s;
        if !tool_m.iter().all(|p| p.iter().all(|x| x.finite())) {
            self.contacts = [None; P];
            self.previous_m = None;
            self.tissue.forget();
            return self.output(Err(SafetyFault::NonFiniteInput), dt, 0);
        }
        if self.supervisor.fault().is_some() {
            // Latched: no contact is held (a physics update releases them).
            self.contacts = [None; P];
            self.tissue.forget();
            self.previous_m = Some(*tool_m);
            return self.output(Err(SafetyFault::ModelFault), dt, 0);
        }
        let mut refused = self.track_and_detect(tool_m);
        let (mut set, mut m) = self.targets(tool_m, &mut refused);
        // Solve; release adhesive contacts (pulling, g·n > 0) or contacts
        // the model refuses, and solve again. Each pass removes one.
        for _ in 0..=P {
            self.counters.solves = self.counters.solves.saturating_add(1);
            let active = set.get(..m).unwrap_or(&[]);
            let dropped = match self.tissue.solve(active) {
                Ok(solved) => {
                    let adhesive = active
                        .iter()
                        .zip(&solved.tissue_forces_n)
                        .position(|(t, g)| g.dot(&t.normal) > T::zero());
                    let Some(q) = adhesive else {
                        return self.output(Ok(solved.device_force_n), dt, refused);
                    };
                    q
                }
                Err(Refusal::Contact(q)) => {
                    refused = refused.saturating_add(1);
                    q
                }
                Err(Refusal::Fault) => break,
            };
            if let Some(t) = set.get(dropped) {
                self.drop_contact(t.tool);
            }
            m = remove_at(&mut set, m, dropped);
        }
        self.contacts = [None; P];
        self.tissue.forget();
        self.output(Err(SafetyFault::ModelFault), dt, refused)
    }

    /// Tracks existing contacts and detects new ones from the motion
    /// segment; returns how many new contacts the capacity `M` refused.
    fn track_and_detect(&mut self, tool_m: &[Vector3<T>; P]) -> u8 {
        let radius = self.config.radius_m;
        let surface = self.tissue.geometry();
        let mut refused = 0u8;
        let mut active = 0usize;
        for (p, tip) in tool_m.iter().enumerate() {
            let Some(slot) = self.contacts.get_mut(p) else {
                continue;
            };
            let work = &mut self.counters.contact;
            *slot = match slot {
                Some(c) => surface
                    .track(c, tip, radius, work)
                    .and_then(|(c, gap)| self.tissue.keeps(gap).then_some(c)),
                None => self
                    .previous_m
                    .as_ref()
                    .and_then(|prev| prev.get(p))
                    .and_then(|from| surface.detect(from, tip, radius, work)),
            };
            if slot.is_some() {
                if active < M {
                    active += 1;
                } else {
                    *slot = None;
                    refused = refused.saturating_add(1);
                }
            }
        }
        self.previous_m = Some(*tool_m);
        refused
    }

    fn drop_contact(&mut self, p: usize) {
        if let Some(slot) = self.contacts.get_mut(p) {
            *slot = None;
        }
    }

    /// The active contacts as targets (at most `M`, in tool-point order),
    /// with each contact point's signed gap to its tool sphere. A contact
    /// whose triangle cannot be read is dropped and counted in `refused`.
    fn targets(
        &mut self,
        tool_m: &[Vector3<T>; P],
        refused: &mut u8,
    ) -> ([ContactTarget<T>; M], usize) {
        let radius = self.config.radius_m;
        let surface = self.tissue.geometry();
        let mut set = [ContactTarget::placeholder(); M];
        let mut m = 0usize;
        for (p, (contact, tip)) in self.contacts.iter_mut().zip(tool_m).enumerate() {
            let Some(c) = contact else { continue };
            let (Some((vertices, normal)), Some(x)) =
                (surface.triangle(c.triangle), surface.point(c))
            else {
                *contact = None;
                *refused = refused.saturating_add(1);
                continue;
            };
            if let Some(slot) = set.get_mut(m) {
                *slot = ContactTarget {
                    tool: p,
                    contact: *c,
                    vertices,
                    normal,
                    gap_m: (tip - x).dot(&normal) - radius,
                    point_m: x,
                    tip_m: *tip,
                };
                m += 1;
            }
        }
        (set, m)
    }

    fn output(
        &mut self,
        requested: Result<Vector3<T>, SafetyFault>,
        dt: T,
        refused: u8,
    ) -> ForceOutput<T> {
        let (force_n, status) = self.supervisor.output(requested, dt);
        ForceOutput {
            force_n,
            status,
            contacts: self.contacts.iter().filter(|c| c.is_some()).count() as u8,
            refused,
        }
    }
}

impl<'a, T: Real, const P: usize, const M: usize> PrecomputedLoop<'a, T, P, M> {
    /// The last contact solution (for the deformation field at the physics
    /// rate), `None` before the first tick or after a fault.
    pub fn solution(&self) -> Option<&crate::ContactSolution<T, M>> {
        self.tissue.solution()
    }
}

impl<T: Real, const P: usize, const M: usize> DynamicLoop<'_, '_, T, P, M> {
    /// One physics update of the dynamic model with the current contacts at
    /// the last tick's tool positions (call it every `physics_every` ticks,
    /// after the tick). On failure the next tick latches a model fault
    /// (zero force) until [`Self::reset`].
    pub fn physics_update(&mut self) -> Result<StepReport<T>, PhysicsError> {
        let (set, m) = match self.previous_m {
            Some(tool) => self.targets(&tool, &mut 0),
            None => ([ContactTarget::placeholder(); M], 0),
        };
        self.tissue.update(set.get(..m).unwrap_or(&[]))
    }
}

/// Removes entry `q` of the first `len` entries of `items` (keeping their
/// order); returns the new length (`len` when `q` is not among them).
fn remove_at<E: Copy>(items: &mut [E], len: usize, q: usize) -> usize {
    if q >= len {
        return len;
    }
    for i in q..len.saturating_sub(1) {
        if let (Some(next), Some(slot)) = (items.get(i + 1).copied(), items.get_mut(i)) {
            *slot = next;
        }
    }
    len.saturating_sub(1)
}
