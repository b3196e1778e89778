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

use super::safety::{BadLimits, OutputStatus, SafetyFault, SafetyLimits, Supervisor};
use crate::contact::{Contact, ContactSet, ContactWork, Refusal, Tissue};
use crate::precomputed::{ContactSolution, PrecomputedTissue};
use crate::tensor_mass::{DynamicTissue, PhysicsError, StepReport};
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
    contacts: [Option<Contact<T>>; P],
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
    pub fn contacts(&self) -> &[Option<Contact<T>>; P] {
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
    /// [`crate::contact::SurfaceGeometry::detect`] and `track`), then at
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
        let mut set = self.contact_set();
        // Solve; release adhesive contacts (pulling, g·n > 0) or contacts
        // the model refuses, and solve again. Each pass removes one.
        for _ in 0..=P {
            self.counters.solves = self.counters.solves.saturating_add(1);
            let dropped = match self.tissue.solve(&mut set) {
                Ok(device_force_n) => {
                    let adhesive = set
                        .iter()
                        .find(|c| c.force_n.dot(&c.normal) > T::zero())
                        .map(|c| c.tool);
                    let Some(tool) = adhesive else {
                        return self.output(Ok(device_force_n), dt, refused);
                    };
                    tool
                }
                Err(Refusal::Contact(q)) => {
                    refused = refused.saturating_add(1);
                    let Some(c) = set.get(q) else { break };
                    c.tool
                }
                Err(Refusal::Fault) => break,
            };
            self.drop_contact(dropped);
            set.retain(|c| c.tool != dropped);
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
                    .filter(|c| self.tissue.keeps(c.gap_m)),
                None => self
                    .previous_m
                    .as_ref()
                    .and_then(|prev| prev.get(p))
                    .and_then(|from| surface.detect(p, from, tip, radius, work)),
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

    /// The active contacts (at most `M` after tracking and detection, in
    /// tool-point order).
    fn contact_set(&self) -> ContactSet<T, M> {
        let mut set = ContactSet::new();
        for c in self.contacts.iter().flatten() {
            // Tracking and detection keep at most M: never refused here.
            let _ = set.push(*c);
        }
        set
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
    pub fn solution(&self) -> Option<&ContactSolution<T, M>> {
        self.tissue.solution()
    }
}

impl<T: Real, const P: usize, const M: usize> DynamicLoop<'_, '_, T, P, M> {
    /// One physics update of the dynamic model with the current contacts at
    /// the last tick's tool positions (call it every `physics_every` ticks,
    /// after the tick). On failure the next tick latches a model fault
    /// (zero force) until [`Self::reset`].
    pub fn physics_update(&mut self) -> Result<StepReport<T>, PhysicsError> {
        let set = self.contact_set();
        self.tissue.update(&set)
    }
}
