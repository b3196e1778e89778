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
use super::tool::{ToolAction, ToolInput};
use crate::contact::{Contact, ContactRefs, ContactSet, ContactWork, Refusal, Tissue, lend};
use crate::hybrid::HybridTissue;
use crate::math::{Dispatch, Portable};
use crate::precomputed::{ContactSolution, PrecomputedTissue};
use crate::tensor_mass::{Blade, Blades, DynamicTissue, PhysicsError, StepReport};
use crate::{MAX_CONTACTS, Real};

/// What the device receives each tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ForceOutput<T> {
    /// Force on the hand, N (after the supervisor).
    pub force_n: Vector3<T>,
    /// Ok, clamped, faulted with the reason, or a tool point inside the
    /// body with no contact ([`OutputStatus::ToolInside`]).
    pub status: OutputStatus,
    /// Tool points in contact.
    pub contacts: u8,
    /// Tool points whose new contact was refused this tick (capacity `M`
    /// reached, or a contact set the model refused); never silently dropped.
    pub refused: u8,
    /// An enabled blade touches a tissue that cannot be cut (the
    /// pre-computed model): it acts as a probe, and says so.
    pub cut_refused: bool,
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
    actions: [ToolAction<T>; P],
    contacts: [Option<Contact<T>>; P],
    /// Bit `p`: tool point `p`'s centre was inside the body with no
    /// contact at the last tick ([`OutputStatus::ToolInside`]). Bits, not
    /// an array: the C interface's loop handles have a fixed size.
    inside: u8,
    /// Bit `p`: look for tool point `p` inside the body at the next tick if
    /// no contact is made (it lost its contact).
    recheck: u8,
    counters: TickCounters,
}

/// The loop over the pre-computed model.
pub type PrecomputedLoop<'a, T, const P: usize, const M: usize> =
    HapticLoop<T, PrecomputedTissue<'a, T, M>, P, M>;

/// The loop over the dynamic tensor-mass model.
pub type DynamicLoop<'a, 's, T, const P: usize, const M: usize, D = Portable> =
    HapticLoop<T, DynamicTissue<'a, 's, T, P, D>, P, M>;

/// The loop over the hybrid model.
pub type HybridLoop<'a, 's, T, const P: usize, const M: usize, D = Portable> =
    HapticLoop<T, HybridTissue<'a, 's, T, P, M, D>, P, M>;

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
            actions: [ToolAction::Touch; P],
            contacts: [None; P],
            inside: 0,
            recheck: 0,
            counters: TickCounters::default(),
        })
    }

    /// The tissue.
    pub fn tissue(&self) -> &B {
        &self.tissue
    }

    /// Each tool point's contact, with the force the last tick's solve
    /// wrote ([`Contact::force_n`]).
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
        self.actions = [ToolAction::Touch; P];
        self.inside = 0;
        self.recheck = 0;
        self.tissue.reset();
    }

    /// One haptic tick of probes at `tool_m` (sphere centres, m):
    /// [`Self::tick_tools`] with every action [`ToolAction::Touch`].
    pub fn tick(&mut self, tool_m: &[Vector3<T>; P]) -> ForceOutput<T> {
        self.tick_tools(&tool_m.map(ToolInput::touch))
    }

    /// One haptic tick with each tool point's sphere centre (m) and action.
    /// Bounded: detection and tracking per point (see
    /// [`crate::contact::SurfaceGeometry::detect`] and `track`), then at
    /// most `P + 1` contact solves of at most `M` contacts.
    pub fn tick_tools(&mut self, tools: &[ToolInput<T>; P]) -> ForceOutput<T> {
        self.counters = TickCounters::default();
        self.tissue.begin_tick();
        let dt = self.config.dt_s;
        let tool_m = tools.map(|t| t.position_m);
        let finite = |v: &Vector3<T>| v.iter().all(|x| x.finite());
        let blades_finite = tools.iter().all(|t| match t.action {
            ToolAction::Cut { blade_m } => finite(&blade_m),
            _ => true,
        });
        if !(tool_m.iter().all(finite) && blades_finite) {
            self.contacts = [None; P];
            self.previous_m = None;
            self.actions = [ToolAction::Touch; P];
            self.inside = 0;
            self.recheck = 0;
            self.tissue.forget();
            return self.output(Err(SafetyFault::NonFiniteInput), dt, 0);
        }
        if self.supervisor.fault().is_some() {
            // Latched: no contact is held (a physics update releases them).
            self.contacts = [None; P];
            self.tissue.forget();
            self.previous_m = Some(tool_m);
            self.actions = [ToolAction::Touch; P];
            self.inside = 0;
            self.recheck = 0;
            return self.output(Err(SafetyFault::ModelFault), dt, 0);
        }
        let mut refused = self.track_and_detect(tools);
        // The active contacts, lent to the solve in tool-point order (no
        // copy of them); those it releases are dropped after it.
        // Tracking and detection keep at most M.
        let mut set: ContactRefs<'_, T, M> = lend(self.contacts.iter_mut().flatten());
        let mut dropped = [false; P];
        // Solve; release adhesive contacts (pulling, g·n > 0) or contacts
        // the model refuses, and solve again. Each pass removes one.
        let mut solved = None;
        for _ in 0..=P {
            self.counters.solves = self.counters.solves.saturating_add(1);
            let tool = match self.tissue.solve(&mut set) {
                Ok(device_force_n) => {
                    let adhesive = set
                        .iter()
                        .find(|c| c.grip_offset_m.is_none() && c.force_n.dot(&c.normal) > T::zero())
                        .map(|c| c.tool);
                    let Some(tool) = adhesive else {
                        solved = Some(device_force_n);
                        break;
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
            if let Some(d) = dropped.get_mut(tool) {
                *d = true;
            }
            set.retain(|c| c.tool != tool);
        }
        // The loan ends here (the set's drop would hold it to the end).
        drop(set);
        if let Some(device_force_n) = solved {
            for (p, (slot, &d)) in self.contacts.iter_mut().zip(&dropped).enumerate() {
                if d {
                    *slot = None;
                    self.recheck |= bit(p);
                }
            }
            return self.output(Ok(device_force_n), dt, refused);
        }
        self.contacts = [None; P];
        self.tissue.forget();
        self.output(Err(SafetyFault::ModelFault), dt, refused)
    }

    /// Tracks existing contacts (a grip closing on one holds it, a grip
    /// opening lets it go) and detects new ones from the motion segment or
    /// the penetration where the tool stands; returns how many new
    /// contacts the capacity `M` refused.
    ///
    /// A tool point left with no contact is then looked for inside the body
    /// ([`crate::contact::SurfaceGeometry::centre_inside`], one more walk
    /// of the 27 grid cells around it) when it may have got deeper than the
    /// penetration test looks without the sweep seeing it cross the
    /// surface: at its first tick (no earlier position), after a motion of
    /// more than a grid cell on an axis (the sweep tests only the
    /// triangles around the motion's two ends), and at the tick after it
    /// lost a contact or was inside. Where the surface near it does not say
    /// (no face over the centre within the walk), a point inside stays
    /// inside and any other is outside. A point inside adds no force and
    /// the output says so ([`OutputStatus::ToolInside`]).
    fn track_and_detect(&mut self, tools: &[ToolInput<T>; P]) -> u8 {
        let radius = self.config.radius_m;
        let Self {
            tissue,
            contacts,
            counters,
            previous_m,
            actions,
            inside,
            recheck,
            ..
        } = self;
        let refused = tissue.with_geometry(|surface| {
            let mut refused = 0u8;
            let mut active = 0usize;
            for (p, (tool, was)) in tools.iter().zip(actions.iter()).enumerate() {
                let Some(slot) = contacts.get_mut(p) else {
                    continue;
                };
                let tip = &tool.position_m;
                let gripping = tool.action == ToolAction::Grip;
                let closing = gripping && *was != ToolAction::Grip;
                let work = &mut counters.contact;
                let mut lost = false;
                match slot {
                    Some(c) => {
                        // Tracked in place (no copy of the contact record).
                        if !gripping {
                            c.grip_offset_m = None;
                        }
                        let kept = surface.track(c, tip, radius, work)
                            && (c.grip_offset_m.is_some() || tissue.keeps(c.gap_m));
                        if !kept {
                            *slot = None;
                            lost = true;
                        } else if closing {
                            c.grip();
                        }
                    }
                    None => {
                        let from = previous_m.as_ref().and_then(|prev| prev.get(p));
                        surface.detect_into(p, from, tip, radius, work, slot);
                    }
                }
                let mask = bit(p);
                let (was_inside, again) = (*inside & mask != 0, *recheck & mask != 0);
                *inside &= !mask;
                *recheck &= !mask;
                if slot.is_some() {
                    if active < M {
                        active += 1;
                    } else {
                        *slot = None;
                        refused = refused.saturating_add(1);
                        *recheck |= mask;
                    }
                    continue;
                }
                let from = previous_m.as_ref().and_then(|prev| prev.get(p));
                let cell_m = surface.index().cell_m();
                let jumped = from.is_none_or(|from| (tip - from).amax() > cell_m);
                let now_inside = if jumped || lost || again || was_inside {
                    let work = &mut counters.contact;
                    surface
                        .centre_inside(tip, radius, work)
                        .unwrap_or(was_inside)
                } else {
                    false
                };
                if now_inside {
                    *inside |= mask;
                }
            }
            refused
        });
        *previous_m = Some(tools.map(|t| t.position_m));
        *actions = tools.map(|t| t.action);
        refused
    }

    /// Pushes the active contacts (at most `M` after tracking and
    /// detection) to the empty `set`, in tool-point order (filled in place:
    /// a returned set is a copy of all `M` records on the firmware target).
    fn gather_contacts(&self, set: &mut ContactSet<T, M>) {
        for c in self.contacts.iter().flatten() {
            // Tracking and detection keep at most M: never refused here.
            let _ = set.push(*c);
        }
    }

    fn output(
        &mut self,
        requested: Result<Vector3<T>, SafetyFault>,
        dt: T,
        refused: u8,
    ) -> ForceOutput<T> {
        let (force_n, mut status) = self.supervisor.output(requested, dt);
        if !matches!(status, OutputStatus::Faulted(_)) && self.inside != 0 {
            status = OutputStatus::ToolInside;
        }
        let cutting = self
            .actions
            .iter()
            .zip(&self.contacts)
            .any(|(a, c)| matches!(a, ToolAction::Cut { .. }) && c.is_some());
        ForceOutput {
            force_n,
            status,
            contacts: self.contacts.iter().filter(|c| c.is_some()).count() as u8,
            refused,
            cut_refused: cutting && !self.tissue.can_cut(),
        }
    }
}

/// Tool point `p`'s bit in the loop's per-point masks (`p < P ≤
/// MAX_CONTACTS ≤ 8`).
fn bit(p: usize) -> u8 {
    const { assert!(MAX_CONTACTS <= 8, "one bit per tool point in a u8") };
    1u8.checked_shl(p as u32).unwrap_or(0)
}

impl<'a, T: Real, const P: usize, const M: usize> PrecomputedLoop<'a, T, P, M> {
    /// The last contact solution (for the deformation field at the physics
    /// rate), `None` before the first tick or after a fault.
    pub fn solution(&self) -> Option<&ContactSolution<T, M>> {
        self.tissue.solution()
    }
}

/// A tissue stepped at the physics rate, between ticks: the tensor-mass
/// model ([`DynamicTissue`]) and the hybrid ([`HybridTissue`]).
pub trait PhysicsTissue<T: Real, const M: usize>: Tissue<T, M> {
    /// The physics update for contact set `set` (the loop's current
    /// contacts at the last tick's tool positions) and the enabled
    /// `blades`. Bounded; on failure the tissue is faulted.
    fn update(
        &mut self,
        set: &ContactSet<T, M>,
        blades: &Blades<T>,
    ) -> Result<StepReport<T>, PhysicsError>;
}

impl<T: Real, const P: usize, const M: usize, D: Dispatch> PhysicsTissue<T, M>
    for DynamicTissue<'_, '_, T, P, D>
{
    fn update(
        &mut self,
        set: &ContactSet<T, M>,
        blades: &Blades<T>,
    ) -> Result<StepReport<T>, PhysicsError> {
        DynamicTissue::update(self, set, blades)
    }
}

impl<T: Real, const P: usize, const M: usize, D: Dispatch> PhysicsTissue<T, M>
    for HybridTissue<'_, '_, T, P, M, D>
{
    fn update(
        &mut self,
        set: &ContactSet<T, M>,
        blades: &Blades<T>,
    ) -> Result<StepReport<T>, PhysicsError> {
        HybridTissue::update(self, set, blades)
    }
}

impl<T: Real, B: PhysicsTissue<T, M>, const P: usize, const M: usize> HapticLoop<T, B, P, M> {
    /// One physics update of the dynamic model with the current contacts at
    /// the last tick's tool positions and the last tick's enabled blades
    /// (call it every `physics_every` ticks, after the tick). On failure the
    /// next tick latches a model fault (zero force) until [`Self::reset`].
    pub fn physics_update(&mut self) -> Result<StepReport<T>, PhysicsError> {
        let mut set = ContactSet::new();
        self.gather_contacts(&mut set);
        let mut blades = Blades::new();
        if let Some(tips) = &self.previous_m {
            for (p, ((tip, action), contact)) in tips
                .iter()
                .zip(&self.actions)
                .zip(&self.contacts)
                .enumerate()
            {
                if let ToolAction::Cut { blade_m } = *action {
                    // At most P blades, the capacity of `Blades`.
                    let _ = blades.push(Blade {
                        tool: p,
                        from_m: *tip,
                        to_m: tip + blade_m,
                        radius_m: self.config.radius_m,
                        pressing: contact.map(|c| c.triangle),
                    });
                }
            }
        }
        let result = PhysicsTissue::update(&mut self.tissue, &set, &blades);
        if result.is_ok() {
            // The update imposed every gap, a found-inside contact's too:
            // from now on its gap counts from touching.
            for c in self.contacts.iter_mut().flatten() {
                c.entry_gap_m = T::zero();
            }
        }
        result
    }
}
