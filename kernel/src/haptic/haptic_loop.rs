//! The fixed-timestep haptic loop over the pre-computed model (Cotin 1999;
//! MODELS.md §6): each tick reads the tool points, detects and tracks
//! contacts, solves the contact forces and passes the device force through
//! the safety supervisor.
//!
//! Force between physics updates: with the pre-computed model the contact
//! solve *is* the local contact stiffness applied to the tool's current
//! displacement (`g = C⁻¹ d`, exact for the linear model), and it costs well
//! under a microsecond, so it runs every tick; what runs at the lower
//! physics rate (every `physics_every` ticks, by the caller) is the
//! deformation field, [`HapticLoop::solution`] into
//! `PrecomputedModel::displacements`. The force is therefore continuous
//! across physics updates: it never waits for them.

use nalgebra::Vector3;

use super::contact::{ContactWork, SurfaceGeometry, ToolContact};
use super::safety::{BadLimits, OutputStatus, SafetyFault, SafetyLimits, Supervisor};
use crate::precomputed::{Contact, ContactError, ContactSolution, PrecomputedModel};
use crate::table::PrecomputedTable;
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

/// The haptic loop: `P` tool points, at most `M` simultaneous contacts.
pub struct HapticLoop<'a, T: Real, const P: usize, const M: usize> {
    model: PrecomputedModel<'a, T>,
    surface: SurfaceGeometry<'a, T>,
    config: LoopConfig<T>,
    supervisor: Supervisor<T>,
    previous_m: Option<[Vector3<T>; P]>,
    contacts: [Option<ToolContact<T>>; P],
    solution: Option<ContactSolution<T, M>>,
    counters: TickCounters,
}

impl<'a, T: Real, const P: usize, const M: usize> HapticLoop<'a, T, P, M> {
    /// A loop at rest (no contact, zero force) over `table`.
    pub fn new(
        table: &'a PrecomputedTable<'a, T>,
        config: LoopConfig<T>,
    ) -> Result<Self, LoopError> {
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
            model: PrecomputedModel::new(*table),
            surface: SurfaceGeometry::new(table),
            config,
            supervisor: Supervisor::new(config.limits).map_err(LoopError::BadLimits)?,
            previous_m: None,
            contacts: [None; P],
            solution: None,
            counters: TickCounters::default(),
        })
    }

    /// The model.
    pub fn model(&self) -> &PrecomputedModel<'a, T> {
        &self.model
    }

    /// Each tool point's contact.
    pub fn contacts(&self) -> &[Option<ToolContact<T>>; P] {
        &self.contacts
    }

    /// The last contact solution (for the deformation field at the physics
    /// rate), `None` before the first tick or after a fault.
    pub fn solution(&self) -> Option<&ContactSolution<T, M>> {
        self.solution.as_ref()
    }

    /// The last tick's work.
    pub fn counters(&self) -> &TickCounters {
        &self.counters
    }

    /// Clears a latched fault and every contact; the force ramps up from
    /// zero at the slew limit.
    pub fn reset(&mut self) {
        self.supervisor.reset();
        self.contacts = [None; P];
        self.previous_m = None;
        self.solution = None;
    }

    /// One haptic tick with the tool points at `tool_m` (sphere centres, m).
    /// Bounded: detection and tracking per point (see
    /// [`SurfaceGeometry::detect`], [`SurfaceGeometry::track`]), then at
    /// most `P + 1` contact solves of at most `M` contacts.
    pub fn tick(&mut self, tool_m: &[Vector3<T>; P]) -> ForceOutput<T> {
        self.counters = TickCounters::default();
        let dt = self.config.dt_s;
        if !tool_m.iter().all(|p| p.iter().all(|x| x.finite())) {
            self.contacts = [None; P];
            self.previous_m = None;
            self.solution = None;
            return self.output(Err(SafetyFault::NonFiniteInput), dt, 0);
        }
        if self.supervisor.fault().is_some() {
            self.previous_m = Some(*tool_m);
            return self.output(Err(SafetyFault::ModelFault), dt, 0);
        }
        let radius = self.config.radius_m;
        let mut refused = 0u8;
        // Track existing contacts; detect new ones from the motion segment.
        let mut active = 0usize;
        for (p, tip) in tool_m.iter().enumerate() {
            let Some(slot) = self.contacts.get_mut(p) else {
                continue;
            };
            let work = &mut self.counters.contact;
            *slot = match slot {
                Some(c) => self
                    .surface
                    .track(c, tip, radius, work)
                    .and_then(|(c, gap)| (gap < T::zero()).then_some(c)),
                None => self
                    .previous_m
                    .as_ref()
                    .and_then(|prev| prev.get(p))
                    .and_then(|from| self.surface.detect(from, tip, radius, work)),
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
        // Solve; release adhesive contacts (pulling, g·n > 0) or contacts
        // the model refuses, and solve again. Each pass removes one.
        for _ in 0..=P {
            self.counters.solves = self.counters.solves.saturating_add(1);
            match self.solve(tool_m) {
                Ok((solution, None)) => {
                    let force = solution.device_force_n();
                    self.solution = Some(solution);
                    return self.output(Ok(force), dt, refused);
                }
                Ok((_, Some(adhesive))) => {
                    if let Some(slot) = self.contacts.get_mut(adhesive) {
                        *slot = None;
                    }
                }
                Err(Refusal::Contact(p)) => {
                    if let Some(slot) = self.contacts.get_mut(p) {
                        *slot = None;
                    }
                    refused = refused.saturating_add(1);
                }
                Err(Refusal::Fault) => break,
            }
        }
        self.contacts = [None; P];
        self.solution = None;
        self.output(Err(SafetyFault::ModelFault), dt, refused)
    }

    /// The contact set of the active contacts, solved; `Some(p)` names the
    /// first adhesive contact's tool point.
    fn solve(
        &self,
        tool_m: &[Vector3<T>; P],
    ) -> Result<(ContactSolution<T, M>, Option<usize>), Refusal> {
        let radius = self.config.radius_m;
        let mut set = [Contact::at_vertex(0, Vector3::zeros()); M];
        let mut owner = [0usize; M];
        let mut normals = [Vector3::zeros(); M];
        let mut m = 0usize;
        for (p, (contact, tip)) in self.contacts.iter().zip(tool_m).enumerate() {
            let Some(c) = contact else { continue };
            let (Some((vertices, normal)), Some(x)) =
                (self.surface.triangle(c.triangle), self.surface.point(c))
            else {
                return Err(Refusal::Contact(p));
            };
            let gap = (tip - x).dot(&normal) - radius;
            if let (Some(s), Some(o), Some(nrm)) =
                (set.get_mut(m), owner.get_mut(m), normals.get_mut(m))
            {
                *s = Contact::on_triangle(vertices, c.weights, normal * gap);
                *o = p;
                *nrm = normal;
                m += 1;
            }
        }
        let solution = self
            .model
            .contact_forces::<M>(set.get(..m).unwrap_or(&[]))
            .map_err(|e| match contact_index(&e) {
                Some(q) => Refusal::Contact(owner.get(q).copied().unwrap_or(0)),
                None => Refusal::Fault,
            })?;
        let adhesive = solution
            .contact_forces_n()
            .iter()
            .zip(&normals)
            .position(|(g, n)| g.dot(n) > T::zero())
            .and_then(|q| owner.get(q).copied());
        Ok((solution, adhesive))
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

/// Why a contact set could not be solved.
enum Refusal {
    /// The contact of this tool point is at fault: drop it and retry.
    Contact(usize),
    /// No contact to blame (non-finite result).
    Fault,
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
