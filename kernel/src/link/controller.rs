//! The controller's side of the link: the haptic loop ticks from the latest
//! physics update a host sent ([`super::Update`]), extrapolating the force
//! between updates with the tissue's own local contact model
//! ([`LocalModel`], the in-process dynamic loop's), and says in a
//! [`LinkStatus`] how fresh that update is.
//!
//! Per tool point and tick, from the update's region of that point:
//! - a contact the tissue held at the update: [`LocalModel::force_on_hand`]
//!   with the correction blend of [`correction_blend`], exactly the
//!   in-process loop's force between updates; a probe lets go when the
//!   force would pull (the in-process release), a grip holds while the
//!   action is `Grip`;
//! - otherwise a contact made since the update: the region's triangles
//!   extrapolated with their vertices' velocities, `p + v τ` (`τ` the time
//!   since the update), a sphere of the tool radius pressing one of them
//!   (centre's projection inside it, depth at most
//!   [`PENETRATION_DEPTH_RADII`] radii) gets [`penalty_on_hand`] with the
//!   region's `K_c`, counted from where it started pushing (a contact
//!   found inside starts from zero force).
//!
//! Faults: frames are taken only in order (an update whose tick is not
//! newer than the current one is dropped, duplicates and reordered frames
//! included, [`LinkCounters::out_of_order`]); a frame the reader rejects
//! counts in [`LinkCounters::corrupt`], a valid frame with an invalid
//! payload or a tick not yet run in [`LinkCounters::rejected`], skipped
//! sequence numbers in [`LinkCounters::gaps`]. Up to
//! [`ControllerConfig::extrapolate_ticks`] past the period the update
//! closes, the force is extrapolated as usual ([`LinkStatus::Extrapolating`]);
//! after that the last extrapolated force fades linearly to zero over
//! [`ControllerConfig::ramp_ticks`], the supervisor's slew limit on top
//! ([`LinkStatus::StaleRamping`]), then [`LinkStatus::Lost`] until an update
//! comes; the model's force then fades back in over as many ticks (and at
//! the first update). No allocation; every loop is bounded by the const
//! capacities.

use nalgebra::{Matrix3, Vector3};

use super::command::Command;
use super::frame::{EncodeError, FrameKind, FrameReader, FrameView, MAX_FRAME_BYTES};
use super::update::{Region, Update};
use crate::contact::PENETRATION_DEPTH_RADII;
use crate::haptic::{
    BadLimits, OutputStatus, SafetyFault, SafetyLimits, Supervisor, ToolAction, ToolInput,
};
use crate::tensor_mass::{LocalModel, correction_blend, penalty_on_hand};

/// Receive buffer of a controller, bytes: two largest frames.
pub const RX_BYTES: usize = 2 * MAX_FRAME_BYTES;

/// How fresh the update the force comes from is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LinkStatus {
    /// Within the physics period the latest update closes.
    Fresh,
    /// The next update is late (or lost): the latest one is extrapolated,
    /// for at most [`ControllerConfig::extrapolate_ticks`] past its period.
    Extrapolating,
    /// The latest update is too old: the force ramps to zero through the
    /// slew limit.
    StaleRamping,
    /// No usable update (none yet, or the ramp ended): zero force.
    #[default]
    Lost,
}

impl LinkStatus {
    /// Its name in CSV and logs.
    pub const fn name(self) -> &'static str {
        match self {
            Self::Fresh => "fresh",
            Self::Extrapolating => "extrapolating",
            Self::StaleRamping => "stale-ramping",
            Self::Lost => "lost",
        }
    }
}

/// What the link delivered and dropped, since the controller was built.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LinkCounters {
    /// Updates accepted.
    pub accepted: u32,
    /// Frame starts the reader dropped (bad magic, length, kind or CRC).
    pub corrupt: u32,
    /// Valid frames with an invalid payload, a command, or an update
    /// stamped with a tick not yet run.
    pub rejected: u32,
    /// Updates not newer than the current one (duplicates, reordered).
    pub out_of_order: u32,
    /// Sequence numbers skipped between accepted frames (frames lost).
    pub gaps: u32,
    /// Ticks not sent to the host: the batch was full (the caller did not
    /// take [`Controller::command_frame`]).
    pub unsent: u32,
}

/// Controller settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControllerConfig {
    /// Radius of each tool point's sphere, m.
    pub radius_m: f32,
    /// Haptic period, s.
    pub dt_s: f32,
    /// Output limits (the slew limit bounds every ramp).
    pub limits: SafetyLimits<f32>,
    /// Ticks past the end of the latest update's period during which it
    /// is still extrapolated, before the force ramps to zero.
    pub extrapolate_ticks: u32,
    /// Ticks of a full fade: after the timeout the force fades linearly to
    /// zero over this many ticks (from the last extrapolated force), and
    /// when updates return (or at the first) it fades back in over as
    /// many; the slew limit applies on top (≥ 1).
    pub ramp_ticks: u32,
    /// The agreed physics schedule: a command batch is sent at least every
    /// this many ticks, at the ticks the host's updates close.
    pub update_every_ticks: u32,
}

/// What the device receives each tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinkOutput {
    /// Force on the hand, N (after the supervisor).
    pub force_n: Vector3<f32>,
    /// The supervisor's status.
    pub status: OutputStatus,
    /// The link's.
    pub link: LinkStatus,
    /// Tool points in contact.
    pub contacts: u8,
    /// Ticks since the latest update (`u32::MAX` without one).
    pub ticks_since_update: u32,
}

/// A tool point's contact on the controller.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
enum Touch {
    /// No contact.
    #[default]
    Free,
    /// The contact the tissue held at the update (a grip or not).
    Held { grip: bool },
    /// A contact made since, on region triangle `triangle`, pushing from
    /// `entry_gap_m` on.
    Pressing { triangle: usize, entry_gap_m: f32 },
}

/// The controller: `P` tool points, at most `NV` vertices and `NT`
/// triangles per region, command batches of `S` ticks.
pub struct Controller<const P: usize, const NV: usize, const NT: usize, const S: usize> {
    config: ControllerConfig,
    supervisor: Supervisor<f32>,
    reader: FrameReader<RX_BYTES>,
    update: Option<Update<P, NV, NT>>,
    last_sequence: Option<u32>,
    touches: [Touch; P],
    previous: Option<[ToolInput<f32>; P]>,
    tick: u32,
    batch: Command<P, S>,
    sent: u32,
    counters: LinkCounters,
    /// The fade: the model's force is sent times `gain / ramp_ticks`.
    gain: u32,
    /// The last force requested while the update was live, N (what a
    /// stale link fades out).
    last_live_n: Vector3<f32>,
}

impl<const P: usize, const NV: usize, const NT: usize, const S: usize> Controller<P, NV, NT, S> {
    /// A controller at tick 0 with no update (zero force, [`LinkStatus::Lost`]).
    pub fn new(config: ControllerConfig) -> Result<Self, BadLimits> {
        let ok = |x: f32| x.is_finite() && x > 0.0;
        if !(ok(config.radius_m)
            && ok(config.dt_s)
            && config.update_every_ticks > 0
            && config.ramp_ticks > 0)
        {
            return Err(BadLimits);
        }
        Ok(Self {
            config,
            supervisor: Supervisor::new(config.limits)?,
            reader: FrameReader::new(),
            update: None,
            last_sequence: None,
            touches: [Touch::Free; P],
            previous: None,
            tick: 0,
            batch: Command::new(0),
            sent: 0,
            counters: LinkCounters::default(),
            gain: 0,
            last_live_n: Vector3::zeros(),
        })
    }

    /// The counters.
    pub fn counters(&self) -> LinkCounters {
        LinkCounters {
            corrupt: self.reader.corrupt(),
            ..self.counters
        }
    }

    /// The latest update accepted.
    pub fn update(&self) -> Option<&Update<P, NV, NT>> {
        self.update.as_ref()
    }

    /// The tick the next [`Self::tick`] computes.
    pub fn next_tick(&self) -> u32 {
        self.tick
    }

    /// Clears a latched fault; the force restarts from zero.
    pub fn reset(&mut self) {
        self.supervisor.reset();
        self.touches = [Touch::Free; P];
    }

    /// Takes bytes received from the host, and every update they complete.
    pub fn receive(&mut self, mut bytes: &[u8]) {
        while !bytes.is_empty() {
            let taken = self.reader.push(bytes);
            bytes = bytes.get(taken..).unwrap_or(&[]);
            while let Some(frame) = self.reader.next_frame() {
                let (kind, sequence) = (frame.kind, frame.sequence);
                let decoded = match kind {
                    FrameKind::Update => Update::decode(frame.payload).ok(),
                    FrameKind::Command => None,
                };
                self.take(sequence, decoded);
            }
        }
    }

    /// Takes one checked frame (what [`Self::receive`] does per frame).
    pub fn accept_frame(&mut self, frame: &FrameView<'_>) {
        let decoded = match frame.kind {
            FrameKind::Update => Update::decode(frame.payload).ok(),
            FrameKind::Command => None,
        };
        self.take(frame.sequence, decoded);
    }

    /// The ordering rules on a decoded frame (module docs).
    fn take(&mut self, sequence: u32, update: Option<Update<P, NV, NT>>) {
        let c = &mut self.counters;
        // Not run yet: a stamp at or after the next tick.
        let Some(update) = update.filter(|u| ahead(self.tick, u.tick)) else {
            c.rejected = c.rejected.saturating_add(1);
            return;
        };
        if self
            .update
            .as_ref()
            .is_some_and(|u| !ahead(update.tick, u.tick))
        {
            c.out_of_order = c.out_of_order.saturating_add(1);
            return;
        }
        if let Some(last) = self.last_sequence {
            let skipped = sequence.wrapping_sub(last).wrapping_sub(1);
            if skipped < u32::MAX / 2 {
                c.gaps = c.gaps.saturating_add(skipped);
            }
        }
        c.accepted = c.accepted.saturating_add(1);
        self.last_sequence = Some(sequence);
        for (p, touch) in self.touches.iter_mut().enumerate() {
            *touch = match update.region(p) {
                Some(r) if r.held => Touch::Held { grip: r.grip },
                _ => Touch::Free,
            };
        }
        self.update = Some(update);
    }

    /// One haptic tick with each tool point's sphere centre (m) and action.
    pub fn tick(&mut self, tools: &[ToolInput<f32>; P]) -> LinkOutput {
        let tick = self.tick;
        self.tick = tick.wrapping_add(1);
        if self.record(tick, tools).is_err() {
            self.counters.unsent = self.counters.unsent.saturating_add(1);
        }
        let since = self
            .update
            .as_ref()
            .map_or(u32::MAX, |u| tick.wrapping_sub(u.tick));
        let period = self
            .update
            .as_ref()
            .map_or(1, |u| u32::from(u.period_ticks));
        let finite = tools
            .iter()
            .all(|t| t.position_m.iter().all(|x| x.is_finite()));
        let live = since <= period.saturating_add(self.config.extrapolate_ticks);
        let ramp = self.config.ramp_ticks;
        self.gain = if live {
            self.gain.saturating_add(1).min(ramp)
        } else {
            self.gain.saturating_sub(1)
        };
        // Exactly 1 at full gain: the model's force unchanged.
        let gain = self.gain as f32 / ramp as f32;
        let requested = match &self.update {
            _ if !finite => Err(SafetyFault::NonFiniteInput),
            Some(update) if live => {
                let at = Tick {
                    config: &self.config,
                    since,
                    period,
                    previous: self.previous.as_ref(),
                };
                let model = at.forces(update, tools, &mut self.touches);
                self.last_live_n = model;
                Ok(model * gain)
            }
            _ => Ok(self.last_live_n * gain),
        };
        if !(live && finite) {
            self.touches = [Touch::Free; P];
        }
        self.previous = Some(*tools);
        let (force_n, status) = self.supervisor.output(requested, self.config.dt_s);
        let link = if live && since <= period {
            LinkStatus::Fresh
        } else if live {
            LinkStatus::Extrapolating
        } else if self.update.is_some() && (self.gain > 0 || force_n != Vector3::zeros()) {
            LinkStatus::StaleRamping
        } else {
            LinkStatus::Lost
        };
        LinkOutput {
            force_n,
            status,
            link,
            contacts: self.touches.iter().filter(|t| **t != Touch::Free).count() as u8,
            ticks_since_update: since,
        }
    }

    /// Adds this tick's tool points to the batch for the host.
    fn record(&mut self, tick: u32, tools: &[ToolInput<f32>; P]) -> Result<(), EncodeError> {
        if self.batch.samples.is_empty() {
            self.batch.first_tick = tick;
        }
        self.batch
            .samples
            .push(*tools)
            .map_err(|_| EncodeError::OutOfRange)
    }

    /// The command frame to send after this tick, if the batch is full or
    /// the tick closes a physics period of the agreed schedule: written to
    /// `out`, its length returned; `Ok(0)` when nothing is due.
    pub fn command_frame(&mut self, out: &mut [u8]) -> Result<usize, EncodeError> {
        let closes = self.tick.is_multiple_of(self.config.update_every_ticks);
        let full = self.batch.samples.len() >= S;
        if self.batch.samples.is_empty() || !(full || closes) {
            return Ok(0);
        }
        let n = self.batch.encode(self.sent, out)?;
        self.sent = self.sent.wrapping_add(1);
        self.batch.samples.clear();
        Ok(n)
    }
}

/// One tick's view for the forces: `since` ticks after the latest update,
/// whose period had `period` ticks, the tool points of the tick before.
struct Tick<'a, const P: usize> {
    config: &'a ControllerConfig,
    since: u32,
    period: u32,
    previous: Option<&'a [ToolInput<f32>; P]>,
}

impl<const P: usize> Tick<'_, P> {
    /// The force on the hand of every tool point from `update`, each
    /// point's contact in `touches` carried to the next tick.
    fn forces<const NV: usize, const NT: usize>(
        &self,
        update: &Update<P, NV, NT>,
        tools: &[ToolInput<f32>; P],
        touches: &mut [Touch; P],
    ) -> Vector3<f32> {
        let blend = correction_blend::<f32>(self.since, self.period);
        let tau_s = self.config.dt_s * self.since as f32;
        let mut total = Vector3::zeros();
        for (p, (tool, touch)) in tools.iter().zip(touches.iter_mut()).enumerate() {
            let Some(region) = update.region(p) else {
                *touch = Touch::Free;
                continue;
            };
            let before = self.previous.and_then(|t| t.get(p));
            let was_grip = before.is_some_and(|t| t.action == ToolAction::Grip);
            let (force, next) = match *touch {
                Touch::Held { grip } => {
                    let gripping = tool.action == ToolAction::Grip;
                    let grip = gripping && (grip || !was_grip);
                    held_force(region, &tool.position_m, grip, blend)
                }
                Touch::Free | Touch::Pressing { .. } => {
                    let local = Local {
                        region,
                        tau_s,
                        radius_m: self.config.radius_m,
                    };
                    local.press(*touch, &tool.position_m, before.map(|t| &t.position_m))
                }
            };
            *touch = next;
            total += force;
        }
        total
    }
}

/// `later` is after `earlier` on the wrapping tick clock.
fn ahead(later: u32, earlier: u32) -> bool {
    let d = later.wrapping_sub(earlier);
    d != 0 && d < u32::MAX / 2
}

/// The held contact's force and what it becomes: released (free, no
/// force) when a probe's force would pull.
fn held_force<const NV: usize, const NT: usize>(
    region: &Region<NV, NT>,
    tip_m: &Vector3<f32>,
    grip: bool,
    blend: f32,
) -> (Vector3<f32>, Touch) {
    let c = &region.contact;
    let model = LocalModel::new(
        c.normal.into(),
        c.tip_m.into(),
        c.force_n.into(),
        Matrix3::from_row_slice(&c.stiffness_tensor_n_per_m),
        c.scale,
        c.offset_n,
    );
    let force = model.force_on_hand(tip_m, grip, blend);
    if !grip && force.dot(&model.normal) < 0.0 {
        return (Vector3::zeros(), Touch::Free);
    }
    (force, Touch::Held { grip })
}

/// A region's surface extrapolated to `tau_s` after its update.
struct Local<'r, const NV: usize, const NT: usize> {
    region: &'r Region<NV, NT>,
    tau_s: f32,
    radius_m: f32,
}

impl<const NV: usize, const NT: usize> Local<'_, NV, NT> {
    /// Region triangle `i` at `τ`: its outward unit normal and a vertex.
    fn plane(&self, i: usize) -> Option<([Vector3<f32>; 3], Vector3<f32>)> {
        let tri = self.region.triangles.get(i)?;
        let at = |v: u8| {
            self.region
                .vertices
                .get(usize::from(v))
                .map(|v| Vector3::from(v.position_m) + Vector3::from(v.velocity_m_s) * self.tau_s)
        };
        let corners = [at(tri[0])?, at(tri[1])?, at(tri[2])?];
        let [a, b, c] = corners;
        let n = (b - a).cross(&(c - a)).try_normalize(0.0)?;
        Some((corners, n))
    }

    /// The gap (m, negative pressing) of a sphere at `tip_m` on triangle
    /// `i` and its normal, if the centre projects inside it and is at most
    /// [`PENETRATION_DEPTH_RADII`] radii behind its surface.
    fn gap(&self, i: usize, tip_m: &Vector3<f32>) -> Option<(f32, Vector3<f32>)> {
        let ([a, b, c], n) = self.plane(i)?;
        let d = (tip_m - a).dot(&n);
        let q = tip_m - n * d;
        let inside = [(a, b), (b, c), (c, a)]
            .iter()
            .all(|(u, v)| (v - u).cross(&(q - u)).dot(&n) >= 0.0);
        let deep = -(PENETRATION_DEPTH_RADII as f32) * self.radius_m;
        (inside && d - self.radius_m >= deep).then_some((d - self.radius_m, n))
    }

    /// The penalty force of a tool point at `tip_m` (from `from_m` last
    /// tick) with contact `touch`, and its contact after this tick.
    fn press(
        &self,
        touch: Touch,
        tip_m: &Vector3<f32>,
        from_m: Option<&Vector3<f32>>,
    ) -> (Vector3<f32>, Touch) {
        let count = self.region.triangles.len();
        let kept = match touch {
            Touch::Pressing {
                triangle,
                entry_gap_m,
            } => self
                .gap(triangle, tip_m)
                .filter(|(g, _)| *g < 0.0)
                .map(|(g, n)| (triangle, g, n, entry_gap_m)),
            _ => None,
        };
        let found = kept.or_else(|| {
            (0..count)
                .filter_map(|i| self.gap(i, tip_m).map(|(g, n)| (i, g, n)))
                .filter(|(_, g, _)| *g < 0.0)
                .min_by(|x, y| x.1.total_cmp(&y.1))
                .map(|(i, g, n)| {
                    // Pressed from outside: pushes from touching; found
                    // inside: from where it is (zero force).
                    let before = from_m.and_then(|f| self.gap(i, f)).map(|(g, _)| g);
                    let entry = before.filter(|b| *b < 0.0).map_or(0.0, |_| g);
                    (i, g, n, entry)
                })
        });
        let Some((triangle, gap, n, entry_gap_m)) = found else {
            return (Vector3::zeros(), Touch::Free);
        };
        let k = Matrix3::from_row_slice(&self.region.contact.stiffness_tensor_n_per_m);
        let depth = gap - entry_gap_m;
        if depth >= 0.0 {
            // Not pushing (yet): no force, the contact kept.
            return (
                Vector3::zeros(),
                Touch::Pressing {
                    triangle,
                    entry_gap_m: entry_gap_m.max(gap),
                },
            );
        }
        (
            penalty_on_hand(&n, &k, depth),
            Touch::Pressing {
                triangle,
                entry_gap_m,
            },
        )
    }
}
