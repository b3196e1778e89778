//! Controller → host: the tool points of the last haptic ticks, a batch
//! per frame (the host's physics follows every tick's contacts, so it needs
//! every tick's tool positions, not the last one).
//!
//! Payload layout (little-endian, every real an `f32`):
//!
//! | Bytes | Field |
//! |---|---|
//! | 4 | `first_tick`: the haptic tick of the first sample |
//! | 1 | samples (1..=`S`), one per tick from `first_tick` on |
//! | 1 | tool points (= `P`) |
//! | 13 × samples × points | position (3, m), action (0 touch, 1 grip, 2 cut) |
//! | 12 × points | each point's blade vector at the last sample, m (zero when not cutting) |
//!
//! A cutting sample's blade is the batch's last (a blade turns little in
//! one batch; the host's physics update reads the blade of its last tick).
//! Size: [`command_payload_bytes`]; at the defaults ([`LINK_SAMPLES`] ticks
//! of [`super::LINK_REGIONS`] points) a frame is
//! [`MAX_COMMAND_FRAME_BYTES`] = 588 bytes, sent every 10 ticks.

use nalgebra::Vector3;

use super::frame::{EncodeError, FRAME_OVERHEAD_BYTES, FrameKind, Reader, write_frame};
use super::update::{LINK_REGIONS, PayloadError};
use crate::haptic::{ToolAction, ToolInput};

/// Default samples per command: 10 ticks (10 ms at 1 kHz).
pub const LINK_SAMPLES: usize = 10;

/// Command payload bytes before the samples.
pub const COMMAND_HEADER_BYTES: usize = 6;

/// Bytes per tool point per sample.
pub const SAMPLE_BYTES: usize = 13;

/// Largest command payload of `samples` ticks of `points` tool points,
/// bytes.
pub const fn command_payload_bytes(samples: usize, points: usize) -> usize {
    COMMAND_HEADER_BYTES + samples * points * SAMPLE_BYTES + points * 12
}

/// Largest command frame at the defaults, bytes (588: 58.8 kB/s at one
/// frame per 10 ms, on the other direction of the serial link).
pub const MAX_COMMAND_FRAME_BYTES: usize =
    command_payload_bytes(LINK_SAMPLES, LINK_REGIONS) + FRAME_OVERHEAD_BYTES;

/// A batch of at most `S` ticks of `P` tool points.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Command<const P: usize, const S: usize> {
    /// The haptic tick of the first sample.
    pub first_tick: u32,
    /// One sample per tick, each the `P` tool points.
    pub samples: heapless::Vec<[ToolInput<f32>; P], S>,
}

fn action_byte(a: &ToolAction<f32>) -> u8 {
    match a {
        ToolAction::Touch => 0,
        ToolAction::Grip => 1,
        ToolAction::Cut { .. } => 2,
    }
}

impl<const P: usize, const S: usize> Command<P, S> {
    /// An empty batch starting at tick `first_tick`.
    pub fn new(first_tick: u32) -> Self {
        Self {
            first_tick,
            samples: heapless::Vec::new(),
        }
    }

    /// This batch's payload bytes.
    pub fn payload_bytes(&self) -> usize {
        command_payload_bytes(self.samples.len(), P)
    }

    /// Writes it as frame `sequence` to the start of `out`; returns the
    /// frame's length, bytes. An empty batch, or a non-finite position or
    /// blade, is out of range.
    pub fn encode(&self, sequence: u32, out: &mut [u8]) -> Result<usize, EncodeError> {
        let last = self.samples.last().ok_or(EncodeError::OutOfRange)?;
        let finite = |v: &Vector3<f32>| v.iter().all(|x| x.is_finite());
        let blades = last.map(|t| match t.action {
            ToolAction::Cut { blade_m } => blade_m,
            _ => Vector3::zeros(),
        });
        let all_finite = self.samples.iter().flatten().all(|t| finite(&t.position_m))
            && blades.iter().all(finite);
        if !all_finite {
            return Err(EncodeError::OutOfRange);
        }
        write_frame(
            out,
            FrameKind::Command,
            sequence,
            self.payload_bytes(),
            |w| {
                w.u32(self.first_tick)?;
                w.u8(u8::try_from(self.samples.len()).ok()?)?;
                w.u8(u8::try_from(P).ok()?)?;
                for t in self.samples.iter().flatten() {
                    w.vec3(t.position_m.into())?;
                    w.u8(action_byte(&t.action))?;
                }
                blades.iter().try_for_each(|b| w.vec3((*b).into()))
            },
        )
    }

    /// The batch in `payload`, validated.
    pub fn decode(payload: &[u8]) -> Result<Self, PayloadError> {
        let short = PayloadError::Short;
        let range = PayloadError::OutOfRange;
        let mut r = Reader::new(payload);
        let first_tick = r.u32().ok_or(short)?;
        let samples = usize::from(r.u8().ok_or(short)?);
        let points = usize::from(r.u8().ok_or(short)?);
        if samples == 0 || samples > S || points != P {
            return Err(range);
        }
        if r.remaining() < command_payload_bytes(samples, P) - COMMAND_HEADER_BYTES {
            return Err(short);
        }
        let mut codes = [[0u8; P]; S];
        let mut command = Self::new(first_tick);
        for codes in codes.iter_mut().take(samples) {
            let mut sample = [ToolInput::touch(Vector3::zeros()); P];
            for (t, code) in sample.iter_mut().zip(codes.iter_mut()) {
                t.position_m = r.vec3().ok_or(range)?.into();
                *code = r.u8().ok_or(short)?;
            }
            command.samples.push(sample).map_err(|_| range)?;
        }
        let mut blades = [Vector3::zeros(); P];
        for b in &mut blades {
            *b = r.vec3().ok_or(range)?.into();
        }
        if r.remaining() != 0 {
            return Err(PayloadError::BadLength);
        }
        for (sample, codes) in command.samples.iter_mut().zip(&codes) {
            for ((t, code), blade_m) in sample.iter_mut().zip(codes).zip(&blades) {
                t.action = match code {
                    0 => ToolAction::Touch,
                    1 => ToolAction::Grip,
                    2 => ToolAction::Cut { blade_m: *blade_m },
                    _ => return Err(range),
                };
            }
        }
        Ok(command)
    }
}
