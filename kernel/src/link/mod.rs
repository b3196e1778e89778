//! The link between a host that runs the physics and a controller that runs
//! the haptic loop (Cotin 1999 §4: the local contact model between physics
//! updates, split across a serial link or a socket).
//!
//! - [`frame`]: the frame around every message (magic, version, kind,
//!   length, sequence number, CRC-32), its checked view and a stream
//!   reassembler in a fixed buffer;
//! - [`update`]: host → controller, a physics update: per tool point near
//!   the surface, the surface triangles near it (positions and velocities)
//!   and the local contact model (`K_c`, the held contact's force);
//! - [`command`]: controller → host, the tool points of the last ticks;
//! - [`controller`]: the controller's haptic loop between updates, its
//!   link status and counters.
//!
//! `no_std`, no allocation, no panic: capacities are const generics, and a
//! payload is decoded once into a fixed-size value, validated (a small error
//! enum per operation: [`frame::FrameError`], [`update::PayloadError`],
//! [`frame::EncodeError`]).
//!
//! Link budget at the defaults, 1 Mbit/s serial, 10 bits per byte (8N1),
//! 100 kB/s each way: an update frame is at most
//! [`update::MAX_UPDATE_FRAME_BYTES`] = 982 bytes (4 regions of 6 vertices
//! and 4 triangles), 98.2 kB/s at 100 updates a second, 29.5 kB/s at 30;
//! a probe's frame (one region) is 262 bytes. A command frame is at most
//! [`command::MAX_COMMAND_FRAME_BYTES`] = 588 bytes per 10 ticks, 58.8 kB/s.

pub mod command;
pub mod controller;
pub mod frame;
pub mod update;

pub use command::{Command, LINK_SAMPLES};
pub use controller::{Controller, ControllerConfig, LinkCounters, LinkOutput, LinkStatus};
pub use frame::{EncodeError, FrameError, FrameKind, FrameReader, FrameView};
pub use update::{
    LINK_REGIONS, LINK_TRIANGLES, LINK_VERTICES, LocalContact, PayloadError, Region, RegionVertex,
    Update,
};
