//! Why a trajectory could not be read: what is wrong with a line ([`LineProblem`]) or with the
//! file as a whole ([`FileProblem`]), and the error that names the file ([`TrajectoryError`]).

use std::io;

use crate::limits::{MAX_TOOL_COORDINATE_M, MAX_TRAJECTORY_SPAN_S, MAX_TRAJECTORY_TIME_S};
use crate::output::number::time_s;
use crate::scene::tool::MAX_TOOL_POINTS;

/// What is wrong with one line.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LineProblem {
    /// The first line is not a header.
    #[error("expected the header `t,tool,x,y,z` or `t,tool,x,y,z,jaw_m,cut`, found `{0}`")]
    MissingHeader(String),
    /// Not exactly 5 fields in a file whose header is `t,tool,x,y,z`.
    #[error("expected 5 fields t,tool,x,y,z, found {0}")]
    ColumnCount(usize),
    /// Not exactly 7 fields in a file whose header is `t,tool,x,y,z,jaw_m,cut` (every line of
    /// such a file has the tool columns).
    #[error("expected 7 fields t,tool,x,y,z,jaw_m,cut as the header, found {0}")]
    ToolColumnCount(usize),
    /// A coordinate, time or jaw opening that does not parse as a number.
    #[error("{column} = `{text}` is not a number")]
    NotANumber {
        /// `t`, `x`, `y`, `z` or `jaw_m`.
        column: &'static str,
        /// The field as written.
        text: String,
    },
    /// A tool field that is not a non-negative integer.
    #[error("tool = `{0}` is not a tool point index (an integer >= 0)")]
    BadToolIndex(String),
    /// A cut field that is not `0` or `1`.
    #[error("cut = `{0}` is not 0 or 1")]
    BadCut(String),
    /// NaN or infinite time, coordinate or jaw opening.
    #[error("non-finite {column} = {value}")]
    NonFinite {
        /// `t`, `x`, `y`, `z` or `jaw_m`.
        column: &'static str,
        /// The value read.
        value: f64,
    },
    /// A finite coordinate or jaw opening beyond ±[`MAX_TOOL_COORDINATE_M`].
    #[error(
        "{column} = {value:e} m is out of range: a tool coordinate or jaw opening is within ±{MAX_TOOL_COORDINATE_M} m (MAX_TOOL_COORDINATE_M); give the trajectory in metres"
    )]
    CoordinateOutOfRange {
        /// `x`, `y`, `z` or `jaw_m`.
        column: &'static str,
        /// The value read, m.
        value: f64,
    },
    /// A negative jaw opening.
    #[error("jaw_m = {0} m is negative: a jaw opening is >= 0")]
    NegativeJaw(f64),
    /// A tool index at or above the scene's tool point count.
    #[error("tool point {tool} does not exist: the scene has {count} (indices 0 to {})", .count.saturating_sub(1))]
    UnknownTool {
        /// The index read.
        tool: usize,
        /// The scene's tool point count.
        count: usize,
    },
    /// A time before the previous line's.
    #[error("time {} s goes backwards: line {previous_line} is at {} s", time_s(*.t_s), time_s(*.previous_s))]
    TimeBackwards {
        /// This line's time, s.
        t_s: f64,
        /// The previous sample's line.
        previous_line: usize,
        /// The previous sample's time, s.
        previous_s: f64,
    },
    /// The CSV reader could not read the line (e.g. invalid UTF-8).
    #[error("unreadable: {0}")]
    Unreadable(String),
    /// A finite time beyond ±[`MAX_TRAJECTORY_TIME_S`].
    #[error(
        "time {t_s:e} s is out of range: a trajectory time is within ±{MAX_TRAJECTORY_TIME_S} s (MAX_TRAJECTORY_TIME_S)"
    )]
    TimeOutOfRange {
        /// This line's time, s.
        t_s: f64,
    },
    /// A time further than [`MAX_TRAJECTORY_SPAN_S`] from the earliest or latest so far.
    #[error(
        "time {} s is {} s from line {other_line} at {} s: a trajectory spans at most {MAX_TRAJECTORY_SPAN_S} s (MAX_TRAJECTORY_SPAN_S); split a longer one",
        time_s(*.t_s), time_s(*.span_s), time_s(*.other_s)
    )]
    SpanTooLong {
        /// This line's time, s.
        t_s: f64,
        /// The span this line would give, s.
        span_s: f64,
        /// The line of the earliest (or latest) sample it is too far from.
        other_line: usize,
        /// That sample's time, s.
        other_s: f64,
    },
}

/// What is wrong with the file as a whole.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FileProblem {
    /// No line at all (not even the header).
    #[error("empty: expected the header line `t,tool,x,y,z` or `t,tool,x,y,z,jaw_m,cut`")]
    Empty,
    /// A header but no sample.
    #[error("no samples after the header")]
    NoSamples,
    /// A tool point with no sample: its position would be unknown.
    #[error("tool point {0} has no sample")]
    ToolWithoutSamples(usize),
    /// The tool point count asked for is out of range.
    #[error("tool point count {0} out of range 1..={MAX_TOOL_POINTS}")]
    BadToolCount(usize),
}

/// Why a trajectory could not be read or built. Every message starts with the file (or source
/// name) and, for a line, its 1-based number.
#[derive(Debug, thiserror::Error)]
pub enum TrajectoryError {
    /// The file could not be read or written.
    #[error("{file}: cannot {action} trajectory: {err}")]
    Io {
        /// The file as given.
        file: String,
        /// `read` or `write`.
        action: &'static str,
        /// Underlying I/O error.
        err: io::Error,
    },
    /// A bad line.
    #[error("{file}: line {line}: {problem}")]
    Line {
        /// The file.
        file: String,
        /// 1-based line number (the header is line 1 when nothing precedes it).
        line: usize,
        /// What is wrong.
        problem: LineProblem,
    },
    /// A problem of the whole file.
    #[error("{file}: {problem}")]
    File {
        /// The file.
        file: String,
        /// What is wrong.
        problem: FileProblem,
    },
}
