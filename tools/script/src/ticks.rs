//! Recorded haptic ticks: a session's tool inputs tick by tick and the
//! settings of the loop that runs them, in a flat little-endian word format
//! that the host writes (`palpate budget --record`) and a `no_std` program
//! reads in place from flash (`tools/cycles-m4f`), and the one line per
//! tick that both print for the tick's output ([`write_tick`]), so that a
//! target's run can be compared with the host's byte for byte.
//!
//! # Format (version 1; every word a little-endian `u32`, f32 as its bits)
//! - [`HEADER_WORDS`] header words: [`MAGIC`], [`VERSION`], tool points `P`
//!   (`1..=MAX_CONTACTS`), tick count `N`, physics period in ticks (0: no
//!   physics update), then [`Settings`]: the loop's radius (m), period (s),
//!   force clamp (N), slew limit (N/s); a flag (1: a dynamic tissue) and
//!   its [`DynamicParams`] (law, penalty flag and `γ` (N), damping (1/s),
//!   gravity (m/s², 3 words), displacement bound (m), kinetic-energy bound
//!   (J)) and [`PhysicsConfig`] (extrapolation, integrator, `dt_s` (s),
//!   substeps, cut capacity (tets), cut force (N), tearing flag, three
//!   threshold flags and values, tearing capacity (tets)); unused words are
//!   zero.
//! - `N × P` tool inputs of [`TOOL_WORDS`] words each, tick-major: the
//!   position (m, 3 words), the action (0 touch, 1 grip, 2 cut), the
//!   blade (m, 3 words, zero unless cutting), a zero word.
//!
//! # Tick line
//! `tick <k> force <fx> <fy> <fz> status <status> contacts <c> refused <r>
//! cut-refused <0|1> work <tests> <walk> <solves>`: the device force (N,
//! f32 bit patterns in hex), the supervisor's status (`Debug`), the
//! contact and refusal counts, and the tick's work counters.

use core::fmt;

use nalgebra::Vector3;
use palpate_kernel::MAX_CONTACTS;
use palpate_kernel::haptic::{
    ForceOutput, LoopConfig, SafetyLimits, TickCounters, ToolAction, ToolInput,
};
use palpate_kernel::tensor_mass::{
    DynamicParams, ElasticLaw, Extrapolation, Integrator, Limits, PhysicsConfig, StvkForm,
    TearThresholds, Tearing,
};

use crate::replay::hex;

/// First word of a recording: `PTK1` in ASCII, little-endian.
pub const MAGIC: u32 = u32::from_le_bytes(*b"PTK1");
/// Format version.
pub const VERSION: u32 = 1;
/// Words before the first tool input.
pub const HEADER_WORDS: usize = 5 + SETTINGS_WORDS;
/// Words per tool input.
pub const TOOL_WORDS: usize = 8;
/// Words of [`Settings`].
const SETTINGS_WORDS: usize = 4 + 1 + DYNAMIC_WORDS + PHYSICS_WORDS;
/// Words of [`DynamicParams`].
const DYNAMIC_WORDS: usize = 9;
/// Words of [`PhysicsConfig`].
const PHYSICS_WORDS: usize = 14;

/// The loop a recording runs on: its settings, and for a dynamic (or
/// hybrid) tissue the tensor-mass model's parameters and physics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// The haptic loop's settings.
    pub loop_config: LoopConfig<f32>,
    /// The tensor-mass model's parameters and physics, `None` for the
    /// pre-computed tissue.
    pub dynamic: Option<(DynamicParams<f32>, PhysicsConfig<f32>)>,
}

/// The header of a recording.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Header {
    /// Tool points per tick, `1..=MAX_CONTACTS`.
    pub points: usize,
    /// Ticks recorded.
    pub ticks: usize,
    /// A physics update after every this many ticks (0: none).
    pub physics_every: u32,
    /// The loop's settings.
    pub settings: Settings,
}

/// A recording refused by [`Recording::parse`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RecordingError {
    /// Fewer bytes than the header, or not the magic word.
    NotARecording,
    /// Another format version.
    Version(u32),
    /// Tool points out of `1..=MAX_CONTACTS`.
    Points(u32),
    /// A word of the header that is not one of its codes (the word's index).
    Code(usize),
    /// The length is not the header plus the declared ticks.
    Length {
        /// Bytes expected.
        expected: usize,
        /// Bytes found.
        found: usize,
    },
    /// A tool input's action is not 0, 1 or 2 (its tick).
    Action(usize),
}

impl fmt::Display for RecordingError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NotARecording => f.write_str("not a tick recording (magic PTK1)"),
            Self::Version(v) => write!(f, "recording version {v}, this reader reads {VERSION}"),
            Self::Points(p) => write!(f, "{p} tool points, expected 1..={MAX_CONTACTS}"),
            Self::Code(i) => write!(f, "header word {i}: not a known code"),
            Self::Length { expected, found } => {
                write!(
                    f,
                    "recording of {found} bytes, its header declares {expected}"
                )
            }
            Self::Action(k) => write!(f, "tick {k}: a tool action is not 0, 1 or 2"),
        }
    }
}

impl core::error::Error for RecordingError {}

/// A validated recording, read in place.
#[derive(Clone, Copy, Debug)]
pub struct Recording<'a> {
    header: Header,
    ticks: &'a [u8],
}

impl<'a> Recording<'a> {
    /// Checks `bytes` (magic, version, codes, length, every action) and
    /// returns the view.
    pub fn parse(bytes: &'a [u8]) -> Result<Self, RecordingError> {
        let (head, ticks) = bytes
            .split_at_checked(4 * HEADER_WORDS)
            .ok_or(RecordingError::NotARecording)?;
        let mut words = [0u32; HEADER_WORDS];
        for (i, w) in words.iter_mut().enumerate() {
            *w = word(head, i);
        }
        let header = Header::from_words(&words)?;
        let expected = 4 * TOOL_WORDS * header.points * header.ticks;
        if ticks.len() != expected {
            return Err(RecordingError::Length {
                expected: expected + head.len(),
                found: bytes.len(),
            });
        }
        let recording = Self { header, ticks };
        for k in 0..header.ticks {
            let tick = recording.tick_words(k);
            if tick.chunks_exact(4 * TOOL_WORDS).any(|t| word(t, 3) > 2) {
                return Err(RecordingError::Action(k));
            }
        }
        Ok(recording)
    }

    /// The header.
    pub fn header(&self) -> &Header {
        &self.header
    }

    fn tick_words(&self, k: usize) -> &'a [u8] {
        let n = 4 * TOOL_WORDS * self.header.points;
        self.ticks.get(k * n..(k + 1) * n).unwrap_or(&[])
    }

    /// The tool inputs of tick `k` for a loop of `P` tool points: `None`
    /// past the last tick or when `P` is not the recording's.
    pub fn tick<const P: usize>(&self, k: usize) -> Option<[ToolInput<f32>; P]> {
        if P != self.header.points || k >= self.header.ticks {
            return None;
        }
        let words = self.tick_words(k);
        let mut tools = [ToolInput::touch(Vector3::zeros()); P];
        for (tool, t) in tools.iter_mut().zip(words.chunks_exact(4 * TOOL_WORDS)) {
            let f = |i| f32::from_bits(word(t, i));
            *tool = ToolInput {
                position_m: Vector3::new(f(0), f(1), f(2)),
                action: match word(t, 3) {
                    0 => ToolAction::Touch,
                    1 => ToolAction::Grip,
                    _ => ToolAction::Cut {
                        blade_m: Vector3::new(f(4), f(5), f(6)),
                    },
                },
            };
        }
        Some(tools)
    }
}

/// Word `i` of `bytes` (0 past the end).
fn word(bytes: &[u8], i: usize) -> u32 {
    match bytes.get(4 * i..4 * i + 4) {
        Some(&[a, b, c, d]) => u32::from_le_bytes([a, b, c, d]),
        _ => 0,
    }
}

/// The words of one tool input (see the module docs).
pub fn tool_words(tool: &ToolInput<f32>) -> [u32; TOOL_WORDS] {
    let p = tool.position_m;
    let (action, blade) = match tool.action {
        ToolAction::Touch => (0, Vector3::zeros()),
        ToolAction::Grip => (1, Vector3::zeros()),
        ToolAction::Cut { blade_m } => (2, blade_m),
    };
    [
        p.x.to_bits(),
        p.y.to_bits(),
        p.z.to_bits(),
        action,
        blade.x.to_bits(),
        blade.y.to_bits(),
        blade.z.to_bits(),
        0,
    ]
}

impl Header {
    /// The header's words (see the module docs).
    pub fn words(&self) -> [u32; HEADER_WORDS] {
        let c = &self.settings.loop_config;
        let head = [
            MAGIC,
            VERSION,
            self.points as u32,
            self.ticks as u32,
            self.physics_every,
            c.radius_m.to_bits(),
            c.dt_s.to_bits(),
            c.limits.max_force_n.to_bits(),
            c.limits.max_slew_n_per_s.to_bits(),
        ];
        let (flag, params, physics) = match &self.settings.dynamic {
            Some((params, physics)) => (1, params_words(params), physics_words(physics)),
            None => (0, [0; DYNAMIC_WORDS], [0; PHYSICS_WORDS]),
        };
        let mut w = [0u32; HEADER_WORDS];
        let all = head.into_iter().chain([flag]).chain(params).chain(physics);
        for (w, x) in w.iter_mut().zip(all) {
            *w = x;
        }
        w
    }

    fn from_words(w: &[u32; HEADER_WORDS]) -> Result<Self, RecordingError> {
        let r = Words(w);
        if r.at(0) != MAGIC {
            return Err(RecordingError::NotARecording);
        }
        if r.at(1) != VERSION {
            return Err(RecordingError::Version(r.at(1)));
        }
        let points = r.at(2);
        if !(1..=MAX_CONTACTS as u32).contains(&points) {
            return Err(RecordingError::Points(points));
        }
        let loop_config = LoopConfig {
            radius_m: r.f32(5),
            dt_s: r.f32(6),
            limits: SafetyLimits {
                max_force_n: r.f32(7),
                max_slew_n_per_s: r.f32(8),
            },
        };
        let dynamic = match r.at(9) {
            0 => None,
            1 => Some((r.params(10)?, r.physics(10 + DYNAMIC_WORDS)?)),
            _ => return Err(RecordingError::Code(9)),
        };
        Ok(Self {
            points: points as usize,
            ticks: r.at(3) as usize,
            physics_every: r.at(4),
            settings: Settings {
                loop_config,
                dynamic,
            },
        })
    }
}

fn params_words(p: &DynamicParams<f32>) -> [u32; DYNAMIC_WORDS] {
    let law = match p.law {
        ElasticLaw::Linear => 0,
        ElasticLaw::StVenantKirchhoff(StvkForm::PerTet) => 1,
        ElasticLaw::StVenantKirchhoff(StvkForm::Tensors) => 2,
        ElasticLaw::Corotational => 3,
        ElasticLaw::NeoHookean => 4,
    };
    let (penalty, gamma) = option_words(p.incompressibility_n);
    [
        law,
        penalty,
        gamma,
        p.damping_per_s.to_bits(),
        p.gravity_m_s2.x.to_bits(),
        p.gravity_m_s2.y.to_bits(),
        p.gravity_m_s2.z.to_bits(),
        p.limits.max_displacement_m.to_bits(),
        p.limits.max_kinetic_energy_j.to_bits(),
    ]
}

fn physics_words(p: &PhysicsConfig<f32>) -> [u32; PHYSICS_WORDS] {
    let extrapolation = match p.extrapolation {
        Extrapolation::Instantaneous => 0,
        Extrapolation::Secant => 1,
    };
    let integrator = Integrator::ALL
        .iter()
        .position(|i| *i == p.integrator)
        .unwrap_or(0) as u32;
    let none = TearThresholds {
        volume_change: None,
        mean_elongation: None,
        max_elongation: None,
    };
    let (tearing, thresholds, capacity) = match &p.tearing {
        Some(t) => (1, t.thresholds, t.capacity_tets),
        None => (0, none, 0),
    };
    let (volume, volume_change) = option_words(thresholds.volume_change);
    let (mean, mean_elongation) = option_words(thresholds.mean_elongation);
    let (max, max_elongation) = option_words(thresholds.max_elongation);
    [
        extrapolation,
        integrator,
        p.dt_s.to_bits(),
        p.substeps,
        p.cut_capacity_tets,
        p.cut_force_n.to_bits(),
        tearing,
        volume,
        volume_change,
        mean,
        mean_elongation,
        max,
        max_elongation,
        capacity,
    ]
}

/// A flag word and a value word (0 when `None`).
fn option_words(x: Option<f32>) -> (u32, u32) {
    x.map_or((0, 0), |x| (1, x.to_bits()))
}

/// The header's words, read by index (0 past the end: the header array is
/// [`HEADER_WORDS`] long, every index below is in it).
struct Words<'w>(&'w [u32; HEADER_WORDS]);

impl Words<'_> {
    fn at(&self, i: usize) -> u32 {
        self.0.get(i).copied().unwrap_or(0)
    }

    fn f32(&self, i: usize) -> f32 {
        f32::from_bits(self.at(i))
    }

    /// A flag word at `i` and a value word after it.
    fn option(&self, i: usize) -> Result<Option<f32>, RecordingError> {
        match self.at(i) {
            0 => Ok(None),
            1 => Ok(Some(self.f32(i + 1))),
            _ => Err(RecordingError::Code(i)),
        }
    }

    fn params(&self, at: usize) -> Result<DynamicParams<f32>, RecordingError> {
        Ok(DynamicParams {
            law: match self.at(at) {
                0 => ElasticLaw::Linear,
                1 => ElasticLaw::StVenantKirchhoff(StvkForm::PerTet),
                2 => ElasticLaw::StVenantKirchhoff(StvkForm::Tensors),
                3 => ElasticLaw::Corotational,
                4 => ElasticLaw::NeoHookean,
                _ => return Err(RecordingError::Code(at)),
            },
            incompressibility_n: self.option(at + 1)?,
            damping_per_s: self.f32(at + 3),
            gravity_m_s2: Vector3::new(self.f32(at + 4), self.f32(at + 5), self.f32(at + 6)),
            limits: Limits {
                max_displacement_m: self.f32(at + 7),
                max_kinetic_energy_j: self.f32(at + 8),
            },
        })
    }

    fn physics(&self, at: usize) -> Result<PhysicsConfig<f32>, RecordingError> {
        let tearing = match self.at(at + 6) {
            0 => None,
            1 => Some(Tearing {
                thresholds: TearThresholds {
                    volume_change: self.option(at + 7)?,
                    mean_elongation: self.option(at + 9)?,
                    max_elongation: self.option(at + 11)?,
                },
                capacity_tets: self.at(at + 13),
            }),
            _ => return Err(RecordingError::Code(at + 6)),
        };
        Ok(PhysicsConfig {
            extrapolation: match self.at(at) {
                0 => Extrapolation::Instantaneous,
                1 => Extrapolation::Secant,
                _ => return Err(RecordingError::Code(at)),
            },
            integrator: *Integrator::ALL
                .get(self.at(at + 1) as usize)
                .ok_or(RecordingError::Code(at + 1))?,
            dt_s: self.f32(at + 2),
            substeps: self.at(at + 3),
            cut_capacity_tets: self.at(at + 4),
            cut_force_n: self.f32(at + 5),
            tearing,
        })
    }
}

/// Writes the line of tick `k` (see the module docs) and a newline.
pub fn write_tick<W: fmt::Write>(
    out: &mut W,
    k: usize,
    output: &ForceOutput<f32>,
    counters: &TickCounters,
) -> fmt::Result {
    let f = output.force_n;
    writeln!(
        out,
        "tick {k} force {} {} {} status {:?} contacts {} refused {} cut-refused {} work {} {} {}",
        hex(f.x),
        hex(f.y),
        hex(f.z),
        output.status,
        output.contacts,
        output.refused,
        u8::from(output.cut_refused),
        counters.contact.triangles_tested,
        counters.contact.walk_steps,
        counters.solves
    )
}
