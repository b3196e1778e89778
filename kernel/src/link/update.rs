//! Host → controller: a physics update, what the controller's haptic loop
//! needs until the next one (Cotin 1999 §4: the local contact model between
//! physics updates). Per tool point near the surface, one [`Region`]: the
//! surface triangles near it (their vertices' positions and velocities at
//! the update) and the local contact model ([`LocalContact`]: the contact
//! stiffness `K_c`, and for a contact the tissue held at the update its
//! normal, tool position, force and extrapolation state).
//!
//! Payload layout (little-endian, every real an `f32`):
//!
//! | Bytes | Field |
//! |---|---|
//! | 4 | `tick`: the haptic tick after which the update was computed |
//! | 2 | `period_ticks`: ticks of the physics period it closes (≥ 1) |
//! | 1 | region count (≤ `P`) |
//! | 1 | reserved, 0 |
//! | per region: 1 | tool point (< `P`, each at most once) |
//! | 1 | flags: bit 0 held contact, bit 1 grip (only with bit 0) |
//! | 1, 1 | vertex count (≤ `NV`), triangle count (≤ `NT`) |
//! | 80 | `K_c` (9, row-major, N/m), normal (3), tool position (3, m), force on the tissue (3, N), `α`, offset (N) |
//! | 24 × vertices | position (3, m), velocity (3, m/s) |
//! | 3 × triangles | vertex indices into the region's list, counter-clockwise seen from outside |
//!
//! Size: [`update_payload_bytes`]; at the kernel's defaults
//! ([`LINK_REGIONS`], [`LINK_VERTICES`], [`LINK_TRIANGLES`]) the worst frame
//! is [`MAX_UPDATE_FRAME_BYTES`] = 982 bytes.

use core::fmt;

use super::frame::{EncodeError, FRAME_OVERHEAD_BYTES, FrameKind, Reader, Writer, write_frame};
use crate::MAX_CONTACTS;

/// Default regions per update: one per tool point, [`MAX_CONTACTS`].
pub const LINK_REGIONS: usize = MAX_CONTACTS;

/// Default vertices per region: a triangle and its three edge neighbours.
pub const LINK_VERTICES: usize = 6;

/// Default triangles per region: a triangle and its three edge neighbours.
pub const LINK_TRIANGLES: usize = 4;

/// Update payload bytes before the regions.
pub const UPDATE_HEADER_BYTES: usize = 8;

/// A region's bytes before its vertices: ids, counts and the local
/// contact model (20 reals).
pub const REGION_FIXED_BYTES: usize = 4 + 20 * 4;

/// Bytes per region vertex (position and velocity).
pub const VERTEX_BYTES: usize = 24;

/// Bytes per region triangle.
pub const TRIANGLE_BYTES: usize = 3;

/// Largest update payload with `regions` regions of `vertices` vertices
/// and `triangles` triangles, bytes.
pub const fn update_payload_bytes(regions: usize, vertices: usize, triangles: usize) -> usize {
    UPDATE_HEADER_BYTES
        + regions * (REGION_FIXED_BYTES + vertices * VERTEX_BYTES + triangles * TRIANGLE_BYTES)
}

/// Largest update frame at the default capacities, bytes (982: at 100
/// updates a second, 98.2 kB/s, under the 100 kB/s of a 1 Mbit/s serial
/// link with 10 bits per byte).
pub const MAX_UPDATE_FRAME_BYTES: usize =
    update_payload_bytes(LINK_REGIONS, LINK_VERTICES, LINK_TRIANGLES) + FRAME_OVERHEAD_BYTES;

/// A surface vertex near a tool at the update.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RegionVertex {
    /// Position, m.
    pub position_m: [f32; 3],
    /// Velocity, m/s (the controller extrapolates the position with it).
    pub velocity_m_s: [f32; 3],
}

/// The local contact model of a region at the update (the dynamic
/// tissue's [`crate::tensor_mass::HeldContact`] on the wire).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LocalContact {
    /// `K_c = Σ_ij s_i s_j K_ij`, N/m, row-major: of the held contact, or
    /// without one of the region's nearest triangle at the tool's
    /// projection (the penalty of a contact made before the next update).
    pub stiffness_tensor_n_per_m: [f32; 9],
    /// The held triangle's unit normal at rest (held contact only).
    pub normal: [f32; 3],
    /// The tool point's position at the update, m (held contact only).
    pub tip_m: [f32; 3],
    /// The force the tool applies to the tissue after the update, N (held
    /// contact only).
    pub force_n: [f32; 3],
    /// Extrapolation stiffness ratio `α`, in `[0, 1]`.
    pub scale: f32,
    /// Normal force sent just before the update minus the update's, N
    /// (decays to zero over the next period).
    pub offset_n: f32,
}

/// What the controller needs near one tool point.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Region<const NV: usize, const NT: usize> {
    /// The tool point.
    pub tool: u8,
    /// The tissue held a contact of this tool point at the update.
    pub held: bool,
    /// That contact is a grip (only with `held`).
    pub grip: bool,
    /// The local contact model.
    pub contact: LocalContact,
    /// The surface vertices near the tool.
    pub vertices: heapless::Vec<RegionVertex, NV>,
    /// The surface triangles near the tool (indices into `vertices`,
    /// counter-clockwise seen from outside).
    pub triangles: heapless::Vec<[u8; 3], NT>,
}

/// A physics update for `P` tool points, at most `NV` vertices and `NT`
/// triangles per region.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Update<const P: usize, const NV: usize, const NT: usize> {
    /// The haptic tick after which it was computed (the first tick it
    /// applies to is `tick + 1`).
    pub tick: u32,
    /// Ticks of the physics period it closes (≥ 1).
    pub period_ticks: u16,
    /// One region per tool point near the surface.
    pub regions: heapless::Vec<Region<NV, NT>, P>,
}

/// Why a payload is not an update (or a command, [`super::Command`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PayloadError {
    /// The payload ends before its counts say.
    Short,
    /// Bytes left after the last field the counts say.
    BadLength,
    /// A count above its capacity, a tool point repeated or out of range,
    /// a triangle's vertex out of its region, a non-finite real, `α` out of
    /// `[0, 1]`, a zero period, an unknown action or flag.
    OutOfRange,
}

impl fmt::Display for PayloadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Short => "payload shorter than its counts",
            Self::BadLength => "bytes after the payload's last field",
            Self::OutOfRange => "a count, index, flag or real out of range",
        })
    }
}

impl core::error::Error for PayloadError {}

const FLAG_HELD: u8 = 1;
const FLAG_GRIP: u8 = 2;

impl<const P: usize, const NV: usize, const NT: usize> Update<P, NV, NT> {
    /// This update's payload bytes.
    pub fn payload_bytes(&self) -> usize {
        UPDATE_HEADER_BYTES
            + self
                .regions
                .iter()
                .map(|r| {
                    REGION_FIXED_BYTES
                        + r.vertices.len() * VERTEX_BYTES
                        + r.triangles.len() * TRIANGLE_BYTES
                })
                .sum::<usize>()
    }

    /// Writes it as frame `sequence` to the start of `out`; returns the
    /// frame's length, bytes.
    pub fn encode(&self, sequence: u32, out: &mut [u8]) -> Result<usize, EncodeError> {
        let bytes = self.payload_bytes();
        write_frame(out, FrameKind::Update, sequence, bytes, |w| {
            w.u32(self.tick)?;
            w.u16(self.period_ticks)?;
            w.u8(u8::try_from(self.regions.len()).ok()?)?;
            w.u8(0)?;
            self.regions.iter().try_for_each(|r| write_region(w, r))
        })
    }

    /// The update in `payload`, validated (the controller's only check).
    pub fn decode(payload: &[u8]) -> Result<Self, PayloadError> {
        let mut r = Reader::new(payload);
        let short = PayloadError::Short;
        let tick = r.u32().ok_or(short)?;
        let period_ticks = r.u16().ok_or(short)?;
        let count = usize::from(r.u8().ok_or(short)?);
        let reserved = r.u8().ok_or(short)?;
        if period_ticks == 0 || reserved != 0 || count > P {
            return Err(PayloadError::OutOfRange);
        }
        let mut update = Self {
            tick,
            period_ticks,
            regions: heapless::Vec::new(),
        };
        let mut seen = 0u32;
        for _ in 0..count {
            let region = read_region::<NV, NT>(&mut r)?;
            let bit = 1u32.checked_shl(u32::from(region.tool)).unwrap_or(0);
            if usize::from(region.tool) >= P || seen & bit != 0 {
                return Err(PayloadError::OutOfRange);
            }
            seen |= bit;
            update
                .regions
                .push(region)
                .map_err(|_| PayloadError::OutOfRange)?;
        }
        if r.remaining() != 0 {
            return Err(PayloadError::BadLength);
        }
        Ok(update)
    }

    /// The region of tool point `tool`, if any.
    pub fn region(&self, tool: usize) -> Option<&Region<NV, NT>> {
        self.regions.iter().find(|r| usize::from(r.tool) == tool)
    }
}

fn write_region<const NV: usize, const NT: usize>(
    w: &mut Writer<'_>,
    r: &Region<NV, NT>,
) -> Option<()> {
    let flags = (u8::from(r.held) * FLAG_HELD) | (u8::from(r.held && r.grip) * FLAG_GRIP);
    w.u8(r.tool)?;
    w.u8(flags)?;
    w.u8(u8::try_from(r.vertices.len()).ok()?)?;
    w.u8(u8::try_from(r.triangles.len()).ok()?)?;
    let c = &r.contact;
    c.stiffness_tensor_n_per_m
        .iter()
        .try_for_each(|&x| w.f32(x))?;
    w.vec3(c.normal)?;
    w.vec3(c.tip_m)?;
    w.vec3(c.force_n)?;
    w.f32(c.scale)?;
    w.f32(c.offset_n)?;
    for v in &r.vertices {
        w.vec3(v.position_m)?;
        w.vec3(v.velocity_m_s)?;
    }
    r.triangles.iter().try_for_each(|t| w.bytes(t))
}

fn read_region<const NV: usize, const NT: usize>(
    r: &mut Reader<'_>,
) -> Result<Region<NV, NT>, PayloadError> {
    let short = PayloadError::Short;
    let range = PayloadError::OutOfRange;
    let tool = r.u8().ok_or(short)?;
    let flags = r.u8().ok_or(short)?;
    let nv = usize::from(r.u8().ok_or(short)?);
    let nt = usize::from(r.u8().ok_or(short)?);
    let held = flags & FLAG_HELD != 0;
    let grip = flags & FLAG_GRIP != 0;
    if flags & !(FLAG_HELD | FLAG_GRIP) != 0 || (grip && !held) || nv > NV || nt > NT {
        return Err(range);
    }
    // A real is short when the bytes end, out of range when not finite.
    let real = |r: &mut Reader<'_>| -> Result<f32, PayloadError> {
        if r.remaining() < 4 {
            return Err(short);
        }
        r.f32().ok_or(range)
    };
    let vec3 = |r: &mut Reader<'_>| -> Result<[f32; 3], PayloadError> {
        Ok([real(r)?, real(r)?, real(r)?])
    };
    let mut k = [0.0; 9];
    for x in &mut k {
        *x = real(r)?;
    }
    let contact = LocalContact {
        stiffness_tensor_n_per_m: k,
        normal: vec3(r)?,
        tip_m: vec3(r)?,
        force_n: vec3(r)?,
        scale: real(r)?,
        offset_n: real(r)?,
    };
    if !(0.0..=1.0).contains(&contact.scale) {
        return Err(range);
    }
    let mut region = Region {
        tool,
        held,
        grip,
        contact,
        vertices: heapless::Vec::new(),
        triangles: heapless::Vec::new(),
    };
    for _ in 0..nv {
        let v = RegionVertex {
            position_m: vec3(r)?,
            velocity_m_s: vec3(r)?,
        };
        region.vertices.push(v).map_err(|_| range)?;
    }
    for _ in 0..nt {
        let t = [
            r.u8().ok_or(short)?,
            r.u8().ok_or(short)?,
            r.u8().ok_or(short)?,
        ];
        if t.iter().any(|&i| usize::from(i) >= nv) {
            return Err(range);
        }
        region.triangles.push(t).map_err(|_| range)?;
    }
    Ok(region)
}
