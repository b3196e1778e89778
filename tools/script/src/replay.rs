//! The scripted replay: one contact set per step through the kernel, one
//! output line per step (format in the crate docs).

use core::fmt::{self, Write};

use palpate_kernel::{ContactSolution, MAX_CONTACTS, PrecomputedModel};

use crate::parse::{ParseError, steps};

/// Why a replay stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReplayError {
    /// A sequence line could not be parsed.
    Parse {
        /// Line number, from 1.
        line: usize,
        /// What is wrong with it.
        error: ParseError,
    },
    /// The displacement buffer does not hold one entry per vertex.
    DisplacementBuffer {
        /// Entries the table needs.
        expected: usize,
        /// Entries the caller gave.
        found: usize,
    },
    /// The output sink refused a write.
    Output,
}

impl fmt::Display for ReplayError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Parse { line, error } => write!(f, "sequence line {line}: {error}"),
            Self::DisplacementBuffer { expected, found } => write!(
                f,
                "displacement buffer holds {found} vertices, the table has {expected}"
            ),
            Self::Output => f.write_str("output write failed"),
        }
    }
}

impl core::error::Error for ReplayError {}

impl From<fmt::Error> for ReplayError {
    fn from(_: fmt::Error) -> Self {
        Self::Output
    }
}

/// Runs every step of `sequence` on `model` (f32, the firmware precision) and
/// writes one line per step to `out`. `displacements` is scratch space for
/// the full displacement update, one entry per table vertex.
///
/// The whole sequence is parsed before anything is written, so a bad line
/// produces no partial output.
pub fn replay<W: Write>(
    model: &PrecomputedModel<'_, f32>,
    sequence: &str,
    displacements: &mut [[f32; 3]],
    out: &mut W,
) -> Result<(), ReplayError> {
    check_inputs(model.table().vertex_count(), sequence, displacements)?;
    for (index, (_, step)) in steps::<f32>(sequence).enumerate() {
        let Ok(contacts) = step else { continue };
        write!(out, "step {index}")?;
        match model.contact_forces::<MAX_CONTACTS>(&contacts) {
            Err(error) => writeln!(out, " error {error}")?,
            Ok(solution) => {
                write_forces(out, &solution)?;
                // The buffer length was checked above; this cannot fail.
                let umax = match model.displacements(&solution, displacements) {
                    Ok(()) => largest(displacements),
                    Err(_) => f32::NAN,
                };
                writeln!(out, " umax {}", hex(umax))?;
            }
        }
    }
    Ok(())
}

/// Writes ` device <fx> <fy> <fz> contacts <g0x> <g0y> <g0z> ...` (N, f32 bit
/// patterns) for `solution`.
pub(crate) fn write_forces<W: Write>(
    out: &mut W,
    solution: &ContactSolution<f32, MAX_CONTACTS>,
) -> fmt::Result {
    let f = solution.device_force_n();
    write!(
        out,
        " device {} {} {} contacts",
        hex(f.x),
        hex(f.y),
        hex(f.z)
    )?;
    for g in solution.contact_forces_n() {
        write!(out, " {} {} {}", hex(g.x), hex(g.y), hex(g.z))?;
    }
    Ok(())
}

/// The largest absolute displacement component of any vertex, m.
pub(crate) fn largest(displacements: &[[f32; 3]]) -> f32 {
    displacements
        .iter()
        .flatten()
        .fold(0.0f32, |m, u| m.max(u.abs()))
}

/// An f32 as its IEEE-754 bit pattern, `0x` and eight hex digits.
pub(crate) fn hex(x: f32) -> impl fmt::Display {
    struct Bits(u32);
    impl fmt::Display for Bits {
        fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            write!(f, "{:#010x}", self.0)
        }
    }
    Bits(x.to_bits())
}

/// The checks before a replay writes anything: `displacements` holds
/// `expected` entries (one per mesh vertex) and every line of `sequence`
/// parses.
pub(crate) fn check_inputs(
    expected: usize,
    sequence: &str,
    displacements: &[[f32; 3]],
) -> Result<(), ReplayError> {
    if displacements.len() != expected {
        return Err(ReplayError::DisplacementBuffer {
            expected,
            found: displacements.len(),
        });
    }
    if let Some((line, Err(error))) = steps::<f32>(sequence).find(|(_, s)| s.is_err()) {
        return Err(ReplayError::Parse { line, error });
    }
    Ok(())
}
