//! Contact-script syntax and the scripted replay runner, shared by the host
//! CLI (`palpate precomputed solve`/`replay`, `palpate scene replay-hybrid`: the
//! [`hybrid`] module) and the Cortex-M4F firmware, so
//! that both parse the same text and print the same bytes.
//!
//! `no_std`, no `alloc`: the firmware parses its sequence from flash.
//!
//! # Contact syntax
//! - vertex contact: `V:dx,dy,dz` (mesh vertex index, imposed displacement in m);
//! - triangle contact: `A,B,C@ba,bb,bc:dx,dy,dz` (three mesh vertices,
//!   barycentric weights, imposed displacement in m).
//!
//! # Sequence syntax
//! One step per line: zero or more contacts separated by blanks. A line `-`
//! is a step with no contact. `#` starts a comment; blank lines are skipped
//! (they are not steps).
//!
//! # Replay output (one line per step, f32 bit patterns in hex)
//! - `step <i> device <fx> <fy> <fz> contacts <g0x> <g0y> <g0z> ... umax <u>`
//!   where `umax` is the largest absolute displacement component of any
//!   vertex, m;
//! - `step <i> error <message>` when the kernel refuses the contact set.
#![no_std]
#![forbid(unsafe_code)]
#![deny(missing_docs)]
#![warn(
    clippy::panic,
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing
)]

pub mod hybrid;
mod parse;
mod replay;
pub mod ticks;

pub use parse::{
    ParseError, StepContacts, parse_contact, parse_step, parse_vector, parse_vertex_vector, steps,
};
pub use replay::{ReplayError, replay};
