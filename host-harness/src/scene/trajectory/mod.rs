//! Tool trajectories: where each tool point is over time, from a CSV file or a generator.
//!
//! File format: a header line, then one sample per line with as many fields as the header. Two
//! headers are accepted:
//! - `t,tool,x,y,z` ([`HEADER`]): time (s), tool point index (0-based integer), position (m);
//! - `t,tool,x,y,z,jaw_m,cut` ([`TOOL_HEADER`]): the same, then the tool columns:
//!   - `jaw_m`: a grasper's jaw opening, m, finite and ≥ 0 (the distance between its two jaws,
//!     placed by the scene at the tool point ± `jaw_m`/2 along its jaw axis); ignored by other
//!     tool kinds;
//!   - `cut`: exactly `0` or `1` (after the blanks around it are trimmed); `1` enables a
//!     cutter's blade. Ignored by other tool kinds.
//!
//! A file without the tool columns reads as `jaw_m = 0`, `cut = 0` on every line. One record per
//! line (CSV quoting applies within a line); fields may be padded with blanks; blank lines and
//! lines starting with `#` are skipped. Line numbers are the file's physical lines, 1-based: the
//! header is line 1 when nothing precedes it.
//!
//! ```text
//! t,tool,x,y,z
//! 0.0,0,0.06,0.06,0.07
//! 0.0,1,0.07,0.06,0.07
//! 0.5,0,0.06,0.06,0.055
//! 0.5,1,0.07,0.06,0.055
//! ```
//!
//! ```text
//! t,tool,x,y,z,jaw_m,cut
//! 0.0,0,0.06,0.06,0.07,0.012,0
//! 0.45,0,0.06,0.06,0.061,0.012,0
//! 0.75,0,0.06,0.06,0.061,0.0045,0
//! ```
//!
//! (a grasper's centre going down, then its jaws closing from 12 to 4.5 mm; a cutter's lines
//! would have `jaw_m = 0` and `cut = 1` while its blade is to cut).
//!
//! Between samples, `jaw_m` is interpolated linearly like the position
//! ([`Trajectory::tools_at`]); `cut` is sample-and-hold: at time `t` a tool point's blade is
//! enabled if its latest sample at or before `t` says `1` (before its first sample, the first
//! sample's value), so a blade switches exactly at a sample's time, never between samples.
//!
//! Rules checked by [`Trajectory::read`] (each error names the file and the line):
//! - every value is finite; `jaw_m` is ≥ 0; `cut` is `0` or `1`; every coordinate and `jaw_m`
//!   is within ±`MAX_TOOL_COORDINATE_M` (1 km: in range of the kernel's f32 with room);
//! - time never decreases from one line to the next, whatever the tool point: the file is one
//!   time-ordered stream, as a device log is. Samples of different tool points may share a time,
//!   and so may two samples of the same point: that is a jump (see [`Trajectory::positions_at`]);
//! - every time is within ±[`MAX_TRAJECTORY_TIME_S`](crate::limits::MAX_TRAJECTORY_TIME_S) (2³² s) and the samples span at most
//!   [`MAX_TRAJECTORY_SPAN_S`](crate::limits::MAX_TRAJECTORY_SPAN_S) (one hour) from the earliest to the latest, so that a session's
//!   tick count is bounded (`crate::limits` says why); the error names the line that goes beyond
//!   and the line it is too far from;
//! - the tool index is below the scene's tool point count, and every tool point has at least one
//!   sample;
//! - the header first, then exactly as many fields per line as the header has (5 or 7: a file
//!   does not mix them), numbers that parse; one record per line (a carriage return inside a
//!   line, outside quotes, would end the record: refused).
//!
//! [`Trajectory::read_unchecked`] is the lenient reader for robustness tests: it keeps non-finite
//! values, negative jaw openings and backward times (reporting each such line as a finding) so
//! that they can be fed to the kernel, which must fault and output zero force; a finite time out
//! of range or beyond the span is an error there too (it would only make the run unbounded), and
//! so is a `cut` other than `0` or `1` (there is no value to keep).
//!
//! A file is read whole, at most [`MAX_TRAJECTORY_FILE_BYTES`](crate::limits::MAX_TRAJECTORY_FILE_BYTES) (`crate::limits::read_bounded`).

use std::io;
use std::path::Path;

mod error;
mod read;

pub use error::{FileProblem, LineProblem, TrajectoryError};

/// The header line's fields, in order, of a file without the tool columns.
pub const HEADER: [&str; 5] = ["t", "tool", "x", "y", "z"];

/// The header line's fields, in order, of a file with the tool columns `jaw_m` and `cut`.
pub const TOOL_HEADER: [&str; 7] = ["t", "tool", "x", "y", "z", "jaw_m", "cut"];

/// One line of a trajectory: tool point `tool` is at `position_m` at time `t_s`, with the jaw
/// opening `jaw_m` and the blade enabled if `cut`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Time, s.
    pub t_s: f64,
    /// Tool point index, 0-based.
    pub tool: usize,
    /// Position `[x, y, z]`, m.
    pub position_m: [f64; 3],
    /// A grasper's jaw opening, m, finite and ≥ 0 in a checked trajectory (ignored by other tool
    /// kinds); 0 in a file without the tool columns.
    pub jaw_m: f64,
    /// Whether a cutter's blade is enabled from this sample on (ignored by other tool kinds);
    /// false in a file without the tool columns.
    pub cut: bool,
}

impl Sample {
    /// The sample's position, jaw opening and blade.
    pub fn tool_state(&self) -> ToolState {
        ToolState {
            position_m: self.position_m,
            jaw_m: self.jaw_m,
            cut: self.cut,
        }
    }

    /// Whether writing the sample needs the tool columns: a `jaw_m` other than `+0` (bit for
    /// bit: `-0` too) or `cut`.
    fn needs_tool_columns(&self) -> bool {
        self.jaw_m.to_bits() != 0.0f64.to_bits() || self.cut
    }
}

/// A tool point's state at one time ([`Trajectory::tools_at`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToolState {
    /// Position `[x, y, z]`, m.
    pub position_m: [f64; 3],
    /// A grasper's jaw opening, m (linear between samples).
    pub jaw_m: f64,
    /// Whether a cutter's blade is enabled (sample-and-hold).
    pub cut: bool,
}

/// A time-ordered list of samples of `tool_count` tool points.
///
/// Invariants: `1 ≤ tool_count ≤ MAX_TOOL_POINTS`; every sample's tool index is below
/// `tool_count`; every tool point has at least one sample; a trajectory without the tool columns
/// has `jaw_m = +0` and `cut = false` in every sample. For a checked trajectory (every
/// constructor but the `*_unchecked` readers) also: every value is finite, every `jaw_m` is ≥ 0
/// and times never decrease in sample order.
#[derive(Clone, Debug, PartialEq)]
pub struct Trajectory {
    /// All samples, in file order.
    samples: Vec<Sample>,
    /// Per tool point, its `(t_s, state)` in file order.
    tracks: Vec<Vec<(f64, ToolState)>>,
    /// Whether it has the `jaw_m,cut` columns ([`Trajectory::has_tool_columns`]).
    tool_columns: bool,
}

/// State on a track at `t_s` (see [`Trajectory::tools_at`]): position and jaw opening linear
/// between samples, the blade's `cut` held from the latest sample at or before `t_s` (the first
/// before it). A track is never empty in a [`Trajectory`]; an empty one gives NaN and no cut.
pub(crate) fn state_on(track: &[(f64, ToolState)], t_s: f64) -> ToolState {
    let i = track.partition_point(|&(t, _)| t <= t_s);
    let before = i.checked_sub(1).and_then(|j| track.get(j));
    match (before, track.get(i)) {
        // At a sample's own time, that sample (even if the next one is not finite).
        (Some(&(t0, s0)), _) if t_s == t0 => s0,
        (Some(&(t0, s0)), Some(&(t1, s1))) => {
            let s = (t_s - t0) / (t1 - t0);
            let lerp = |a: f64, b: f64| a + (b - a) * s;
            ToolState {
                position_m: [0, 1, 2].map(|k| lerp(s0.position_m[k], s1.position_m[k])),
                jaw_m: lerp(s0.jaw_m, s1.jaw_m),
                cut: s0.cut,
            }
        }
        (Some(&(_, s)), None) | (None, Some(&(_, s))) => s,
        (None, None) => ToolState {
            position_m: [f64::NAN; 3],
            jaw_m: f64::NAN,
            cut: false,
        },
    }
}

impl Trajectory {
    /// Number of tool points: [`Trajectory::positions_at`] returns this many positions.
    pub fn tool_count(&self) -> usize {
        self.tracks.len()
    }

    /// Whether the trajectory has the tool columns `jaw_m,cut`: read from a file with the
    /// 7-field header, or built from samples that need them (or asked to have them).
    /// [`Trajectory::write_csv`] writes them if and only if it has.
    pub fn has_tool_columns(&self) -> bool {
        self.tool_columns
    }

    /// All samples, in file order.
    pub fn samples(&self) -> &[Sample] {
        &self.samples
    }

    /// Earliest finite sample time, s (0 if there is none, which only an unchecked trajectory
    /// can have).
    pub fn start_s(&self) -> f64 {
        let t = self.finite_times().fold(f64::INFINITY, f64::min);
        if t.is_finite() { t } else { 0.0 }
    }

    /// Latest finite sample time, s (0 if there is none, which only an unchecked trajectory can
    /// have). A session runs until then; every position holds afterwards.
    pub fn end_s(&self) -> f64 {
        let t = self.finite_times().fold(f64::NEG_INFINITY, f64::max);
        if t.is_finite() { t } else { 0.0 }
    }

    fn finite_times(&self) -> impl Iterator<Item = f64> + '_ {
        self.samples.iter().map(|s| s.t_s).filter(|t| t.is_finite())
    }

    /// Every tool point's position (m) at time `t_s`, by linear interpolation between the tool
    /// point's own samples:
    /// - between its samples `(t0, p0)` and `(t1, p1)` with `t0 < t_s < t1`:
    ///   `p0 + (p1 − p0)·(t_s − t0)/(t1 − t0)`; at `t_s = t0` exactly `p0`;
    /// - before its first sample: the first sample; at or after its last: the last (hold);
    /// - two samples at the same time are a jump: from that time on the later one applies.
    ///
    /// Linear, not sample-and-hold, so that a trajectory sampled slower than the haptic rate
    /// does not feed the force loop steps (each a force spike); generated trajectories are
    /// piecewise linear, and reproduced exactly. A NaN `t_s` gives the first samples. On an
    /// unchecked trajectory non-finite samples propagate (NaN or infinite positions, for the
    /// kernel to refuse) and times out of order give a deterministic but unspecified mix of
    /// samples; nothing panics.
    pub fn positions_at(&self, t_s: f64) -> Vec<[f64; 3]> {
        self.tracks
            .iter()
            .map(|tr| state_on(tr, t_s).position_m)
            .collect()
    }

    /// [`Trajectory::positions_at`] into `out`, without allocating: fills
    /// `min(out.len(), tool_count)` entries.
    pub fn positions_at_into(&self, t_s: f64, out: &mut [[f64; 3]]) {
        for (o, tr) in out.iter_mut().zip(&self.tracks) {
            *o = state_on(tr, t_s).position_m;
        }
    }

    /// Every tool point's state at time `t_s`: its position exactly as
    /// [`Trajectory::positions_at`], its jaw opening `jaw_m` interpolated by the same rule (linear
    /// between samples, held before the first and after the last, a jump at two samples of the
    /// same time), and its `cut` sample-and-hold: the `cut` of its latest sample at or before
    /// `t_s` (of the last of several at that time; before its first sample, the first's). A NaN
    /// `t_s` gives the first samples.
    pub fn tools_at(&self, t_s: f64) -> Vec<ToolState> {
        self.tracks.iter().map(|tr| state_on(tr, t_s)).collect()
    }

    /// [`Trajectory::tools_at`] into `out`, without allocating: fills
    /// `min(out.len(), tool_count)` entries.
    pub fn tools_at_into(&self, t_s: f64, out: &mut [ToolState]) {
        for (o, tr) in out.iter_mut().zip(&self.tracks) {
            *o = state_on(tr, t_s);
        }
    }

    /// Write the trajectory as CSV: the header, then every sample in order; with the tool
    /// columns ([`TOOL_HEADER`], `cut` as `0` or `1`) if [`Trajectory::has_tool_columns`],
    /// without ([`HEADER`]) otherwise. Numbers use Rust's shortest round-trip format, so reading
    /// the output back gives the same bits (non-finite values are written `NaN`, `inf`, `-inf`,
    /// which [`Trajectory::read_unchecked`] reads back).
    pub fn write_csv<W: io::Write>(&self, mut out: W) -> io::Result<()> {
        if self.tool_columns {
            writeln!(out, "{}", TOOL_HEADER.join(","))?;
            for s in &self.samples {
                let [x, y, z] = s.position_m;
                let cut = u8::from(s.cut);
                writeln!(out, "{},{},{x},{y},{z},{},{cut}", s.t_s, s.tool, s.jaw_m)?;
            }
        } else {
            writeln!(out, "{}", HEADER.join(","))?;
            for s in &self.samples {
                let [x, y, z] = s.position_m;
                writeln!(out, "{},{},{x},{y},{z}", s.t_s, s.tool)?;
            }
        }
        out.flush()
    }

    /// [`Trajectory::write_csv`] to a file (created or truncated).
    pub fn write_csv_file(&self, path: &Path) -> Result<(), TrajectoryError> {
        let io_error = |err| TrajectoryError::Io {
            file: path.display().to_string(),
            action: "write",
            err,
        };
        let file = std::fs::File::create(path).map_err(io_error)?;
        self.write_csv(io::BufWriter::new(file)).map_err(io_error)
    }
}
