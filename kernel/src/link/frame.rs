//! The frame around every message of the link: a 10-byte header, the
//! payload, a CRC-32 trailer, all little-endian.
//!
//! | Offset | Size | Field |
//! |---|---|---|
//! | 0 | 2 | magic `b"PL"` |
//! | 2 | 1 | version ([`LINK_VERSION`]) |
//! | 3 | 1 | kind ([`FrameKind`]) |
//! | 4 | 2 | payload length `L`, bytes (at most [`MAX_PAYLOAD_BYTES`]) |
//! | 6 | 4 | sequence number (per direction, +1 per frame, wraps) |
//! | 10 | `L` | payload |
//! | 10 + `L` | 4 | CRC-32 (ISO-HDLC, the table container's) of bytes `0..10 + L` |
//!
//! [`FrameView::parse`] checks a frame once (magic, version, kind, length,
//! CRC) and lends its payload; [`FrameReader`] reassembles frames from a
//! byte stream (a serial port, a socket) in a fixed buffer, resynchronising
//! on the next magic after a corrupted byte.

use core::fmt;

use crate::table::format::CRC32;

/// Magic bytes that open every frame.
pub const MAGIC: [u8; 2] = *b"PL";

/// Version of the frame and payload layouts.
pub const LINK_VERSION: u8 = 1;

/// Header bytes before the payload.
pub const HEADER_BYTES: usize = 10;

/// CRC bytes after the payload.
pub const CRC_BYTES: usize = 4;

/// Header and CRC: what a frame adds to its payload, bytes.
pub const FRAME_OVERHEAD_BYTES: usize = HEADER_BYTES + CRC_BYTES;

/// Largest payload a frame may declare, bytes (a bound on a receiver's
/// buffer, above every payload of [`super::update`] and [`super::command`]
/// at the kernel's capacities).
pub const MAX_PAYLOAD_BYTES: usize = 2048;

/// Largest frame, bytes.
pub const MAX_FRAME_BYTES: usize = MAX_PAYLOAD_BYTES + FRAME_OVERHEAD_BYTES;

/// What a frame carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameKind {
    /// Host → controller: a physics update ([`super::Update`]).
    Update,
    /// Controller → host: tool samples ([`super::Command`]).
    Command,
}

impl FrameKind {
    /// The kind's byte.
    pub const fn byte(self) -> u8 {
        match self {
            Self::Update => 1,
            Self::Command => 2,
        }
    }

    fn of_byte(b: u8) -> Option<Self> {
        match b {
            1 => Some(Self::Update),
            2 => Some(Self::Command),
            _ => None,
        }
    }
}

/// Why bytes are not a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameError {
    /// Fewer bytes than the frame needs (so far): `needed` in all.
    Short {
        /// Bytes the frame needs, header included.
        needed: usize,
    },
    /// The first two bytes are not [`MAGIC`].
    BadMagic,
    /// The declared payload length is above [`MAX_PAYLOAD_BYTES`].
    BadLength,
    /// The CRC does not match the bytes.
    CrcMismatch,
    /// An unknown version or kind.
    OutOfRange,
}

impl fmt::Display for FrameError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Short { needed } => write!(f, "short frame: {needed} bytes needed"),
            Self::BadMagic => f.write_str("bad magic"),
            Self::BadLength => write!(f, "payload length above {MAX_PAYLOAD_BYTES} bytes"),
            Self::CrcMismatch => f.write_str("CRC mismatch"),
            Self::OutOfRange => write!(f, "unknown version or kind (version {LINK_VERSION})"),
        }
    }
}

impl core::error::Error for FrameError {}

/// A checked frame: its kind, sequence number and payload.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameView<'a> {
    /// What it carries.
    pub kind: FrameKind,
    /// Its sequence number.
    pub sequence: u32,
    /// Its payload.
    pub payload: &'a [u8],
}

impl<'a> FrameView<'a> {
    /// The frame at the start of `bytes` (checked: magic, length, version,
    /// kind, CRC) and its length in bytes.
    pub fn parse(bytes: &'a [u8]) -> Result<(Self, usize), FrameError> {
        let short = |needed| FrameError::Short { needed };
        let header = bytes.get(..HEADER_BYTES);
        if bytes.get(..2).is_some_and(|m| m != MAGIC)
            || bytes.first().is_some_and(|&b| b != MAGIC[0])
        {
            return Err(FrameError::BadMagic);
        }
        let header = header.ok_or(short(HEADER_BYTES))?;
        let mut r = Reader::new(header);
        let (_, version, kind) = (r.u16(), r.u8(), r.u8());
        let length = usize::from(r.u16().unwrap_or(u16::MAX));
        let sequence = r.u32().unwrap_or(0);
        if length > MAX_PAYLOAD_BYTES {
            return Err(FrameError::BadLength);
        }
        let total = HEADER_BYTES + length + CRC_BYTES;
        let body = bytes.get(..HEADER_BYTES + length).ok_or(short(total))?;
        let crc = bytes
            .get(HEADER_BYTES + length..total)
            .and_then(|c| Reader::new(c).u32())
            .ok_or(short(total))?;
        if crc::Crc::<u32>::new(&CRC32).checksum(body) != crc {
            return Err(FrameError::CrcMismatch);
        }
        let kind = kind.and_then(FrameKind::of_byte);
        let (Some(kind), Some(LINK_VERSION)) = (kind, version) else {
            return Err(FrameError::OutOfRange);
        };
        let payload = body.get(HEADER_BYTES..).ok_or(short(total))?;
        Ok((
            Self {
                kind,
                sequence,
                payload,
            },
            total,
        ))
    }
}

/// Why a message was not encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EncodeError {
    /// The output buffer is smaller than the frame (`needed` bytes).
    BufferTooSmall {
        /// Bytes the frame needs.
        needed: usize,
    },
    /// A count above the message's capacity or a value the layout cannot
    /// hold.
    OutOfRange,
}

impl fmt::Display for EncodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BufferTooSmall { needed } => write!(f, "output buffer below {needed} bytes"),
            Self::OutOfRange => f.write_str("a count or value out of the layout's range"),
        }
    }
}

impl core::error::Error for EncodeError {}

/// Writes a frame of `kind` and `sequence` around the `payload_bytes`
/// bytes `payload` writes into its [`Writer`] (which must write exactly
/// that many) to the start of `out`; returns the frame's length.
pub(crate) fn write_frame(
    out: &mut [u8],
    kind: FrameKind,
    sequence: u32,
    payload_bytes: usize,
    payload: impl FnOnce(&mut Writer<'_>) -> Option<()>,
) -> Result<usize, EncodeError> {
    let total = HEADER_BYTES + payload_bytes + CRC_BYTES;
    let length = u16::try_from(payload_bytes)
        .ok()
        .filter(|&l| usize::from(l) <= MAX_PAYLOAD_BYTES)
        .ok_or(EncodeError::OutOfRange)?;
    let frame = out
        .get_mut(..total)
        .ok_or(EncodeError::BufferTooSmall { needed: total })?;
    let (body, crc) = frame
        .split_at_mut_checked(HEADER_BYTES + payload_bytes)
        .ok_or(EncodeError::OutOfRange)?;
    let mut w = Writer::new(body);
    w.bytes(&MAGIC)
        .and_then(|()| w.u8(LINK_VERSION))
        .and_then(|()| w.u8(kind.byte()))
        .and_then(|()| w.u16(length))
        .and_then(|()| w.u32(sequence))
        .and_then(|()| payload(&mut w))
        .filter(|()| w.at == HEADER_BYTES + payload_bytes)
        .ok_or(EncodeError::OutOfRange)?;
    let sum = crc::Crc::<u32>::new(&CRC32).checksum(body);
    copy(crc, &sum.to_le_bytes());
    Ok(total)
}

/// Reassembles frames from a byte stream in a buffer of `N` bytes (at
/// least [`MAX_FRAME_BYTES`] to take every frame): [`Self::push`] the bytes
/// received, then take the frames with [`Self::next_frame`]. Bytes that
/// cannot open a frame (a bad magic, a bad length, a CRC mismatch, an
/// unknown kind) are dropped one at a time up to the next magic, each
/// dropped frame start counted in [`Self::corrupt`].
#[derive(Clone, Debug)]
pub struct FrameReader<const N: usize> {
    buffer: [u8; N],
    len: usize,
    consumed: usize,
    corrupt: u32,
    overflowed: u32,
}

impl<const N: usize> Default for FrameReader<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> FrameReader<N> {
    /// An empty reader.
    pub const fn new() -> Self {
        Self {
            buffer: [0; N],
            len: 0,
            consumed: 0,
            corrupt: 0,
            overflowed: 0,
        }
    }

    /// Appends received bytes; returns how many were taken (the rest did
    /// not fit: push them again after taking frames). A full buffer that
    /// holds no frame start is emptied (counted in [`Self::overflowed`]).
    pub fn push(&mut self, bytes: &[u8]) -> usize {
        self.compact();
        if self.len == N {
            self.len = 0;
            self.overflowed = self.overflowed.saturating_add(1);
        }
        let free = self.buffer.get_mut(self.len..).unwrap_or(&mut []);
        let taken = free.len().min(bytes.len());
        copy(free, bytes);
        self.len += taken;
        taken
    }

    /// The next complete, checked frame, `None` until one is complete.
    pub fn next_frame(&mut self) -> Option<FrameView<'_>> {
        loop {
            let pending = self.buffer.get(self.consumed..self.len)?;
            if pending.is_empty() {
                return None;
            }
            match FrameView::parse(pending) {
                // One parse (and one CRC) per frame: the view borrows the
                // buffer, the count of consumed bytes is another field.
                Ok((frame, total)) => {
                    self.consumed += total;
                    return Some(frame);
                }
                Err(FrameError::Short { needed }) if needed <= N => return None,
                Err(_) => {
                    // Not a frame here: skip to the next possible magic.
                    self.corrupt = self.corrupt.saturating_add(1);
                    let skip = pending
                        .iter()
                        .skip(1)
                        .position(|&b| b == MAGIC[0])
                        .map_or(pending.len(), |i| i + 1);
                    self.consumed += skip;
                }
            }
        }
    }

    /// Frame starts dropped as corrupted (bad magic, length, CRC, kind).
    pub fn corrupt(&self) -> u32 {
        self.corrupt
    }

    /// Times a full buffer without a frame was emptied.
    pub fn overflowed(&self) -> u32 {
        self.overflowed
    }

    /// Moves the unread bytes to the front.
    fn compact(&mut self) {
        if self.consumed > 0 {
            let unread = self.len.saturating_sub(self.consumed);
            for i in 0..unread {
                if let Some(&b) = self.buffer.get(i + self.consumed)
                    && let Some(to) = self.buffer.get_mut(i)
                {
                    *to = b;
                }
            }
            self.len = unread;
            self.consumed = 0;
        }
    }
}

/// Little-endian reads from a byte slice; `None` past its end.
pub(crate) struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    pub(crate) fn new(bytes: &'a [u8]) -> Self {
        Self { bytes, at: 0 }
    }

    fn take<const K: usize>(&mut self) -> Option<[u8; K]> {
        let b = self.bytes.get(self.at..self.at + K)?;
        self.at += K;
        b.try_into().ok()
    }

    pub(crate) fn u8(&mut self) -> Option<u8> {
        self.take::<1>().map(|[b]| b)
    }

    pub(crate) fn u16(&mut self) -> Option<u16> {
        self.take().map(u16::from_le_bytes)
    }

    pub(crate) fn u32(&mut self) -> Option<u32> {
        self.take().map(u32::from_le_bytes)
    }

    /// A finite `f32`; `None` past the end or for NaN and infinities.
    pub(crate) fn f32(&mut self) -> Option<f32> {
        self.take()
            .map(f32::from_le_bytes)
            .filter(|x| x.is_finite())
    }

    pub(crate) fn vec3(&mut self) -> Option<[f32; 3]> {
        Some([self.f32()?, self.f32()?, self.f32()?])
    }

    /// Bytes left unread.
    pub(crate) fn remaining(&self) -> usize {
        self.bytes.len().saturating_sub(self.at)
    }
}

/// Little-endian writes into a byte slice; `None` past its end.
pub(crate) struct Writer<'a> {
    bytes: &'a mut [u8],
    at: usize,
}

impl<'a> Writer<'a> {
    pub(crate) fn new(bytes: &'a mut [u8]) -> Self {
        Self { bytes, at: 0 }
    }

    pub(crate) fn bytes(&mut self, b: &[u8]) -> Option<()> {
        let to = self.bytes.get_mut(self.at..)?.get_mut(..b.len())?;
        copy(to, b);
        self.at += b.len();
        Some(())
    }

    pub(crate) fn u8(&mut self, x: u8) -> Option<()> {
        self.bytes(&[x])
    }

    pub(crate) fn u16(&mut self, x: u16) -> Option<()> {
        self.bytes(&x.to_le_bytes())
    }

    pub(crate) fn u32(&mut self, x: u32) -> Option<()> {
        self.bytes(&x.to_le_bytes())
    }

    pub(crate) fn f32(&mut self, x: f32) -> Option<()> {
        self.bytes(&x.to_le_bytes())
    }

    pub(crate) fn vec3(&mut self, v: [f32; 3]) -> Option<()> {
        v.iter().try_for_each(|&x| self.f32(x))
    }
}

/// Copies `from` into the start of `to`, as many bytes as both hold (no
/// length check that could panic).
fn copy(to: &mut [u8], from: &[u8]) {
    for (t, f) in to.iter_mut().zip(from) {
        *t = *f;
    }
}
