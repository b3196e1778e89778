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
//! - every time is within ±[`MAX_TRAJECTORY_TIME_S`] (2³² s) and the samples span at most
//!   [`MAX_TRAJECTORY_SPAN_S`] (one hour) from the earliest to the latest, so that a session's
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
//! A file is read whole, at most [`MAX_TRAJECTORY_FILE_BYTES`] (`crate::limits::read_bounded`).

use std::io;
use std::path::Path;

use super::spec::MAX_TOOL_POINTS;
use crate::limits::{
    MAX_TOOL_COORDINATE_M, MAX_TRAJECTORY_FILE_BYTES, MAX_TRAJECTORY_SPAN_S, MAX_TRAJECTORY_TIME_S,
    read_bounded,
};
use crate::output::number::time_s;

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

/// Whether the readers refuse non-finite values and backward times or only report them.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Mode {
    Checked,
    Lenient,
}

/// Builds a trajectory sample by sample, applying the rules of the module doc.
struct Builder<'a> {
    file: &'a str,
    mode: Mode,
    samples: Vec<Sample>,
    tracks: Vec<Vec<(f64, ToolState)>>,
    /// The tool columns are wanted even if no sample needs them (the 7-field header, or asked
    /// for by [`Trajectory::from_samples_with_tool_columns`]).
    tool_columns: bool,
    /// Line and time of the last sample with a non-NaN time.
    previous: Option<(usize, f64)>,
    /// Line and time of the earliest and of the latest finite time so far.
    earliest: Option<(usize, f64)>,
    latest: Option<(usize, f64)>,
    findings: Vec<TrajectoryError>,
}

impl<'a> Builder<'a> {
    fn new(file: &'a str, tool_count: usize, mode: Mode) -> Result<Self, TrajectoryError> {
        if !(1..=MAX_TOOL_POINTS).contains(&tool_count) {
            return Err(TrajectoryError::File {
                file: file.to_owned(),
                problem: FileProblem::BadToolCount(tool_count),
            });
        }
        Ok(Self {
            file,
            mode,
            samples: Vec::new(),
            tracks: vec![Vec::new(); tool_count],
            tool_columns: false,
            previous: None,
            earliest: None,
            latest: None,
            findings: Vec::new(),
        })
    }

    fn line_error(&self, line: usize, problem: LineProblem) -> TrajectoryError {
        TrajectoryError::Line {
            file: self.file.to_owned(),
            line,
            problem,
        }
    }

    /// Refused in checked mode, a finding in lenient mode.
    fn soft(&mut self, line: usize, problem: LineProblem) -> Result<(), TrajectoryError> {
        let err = self.line_error(line, problem);
        match self.mode {
            Mode::Checked => Err(err),
            Mode::Lenient => {
                self.findings.push(err);
                Ok(())
            }
        }
    }

    fn push(&mut self, line: usize, sample: Sample) -> Result<(), TrajectoryError> {
        let count = self.tracks.len();
        let values = [
            ("t", sample.t_s),
            ("x", sample.position_m[0]),
            ("y", sample.position_m[1]),
            ("z", sample.position_m[2]),
            ("jaw_m", sample.jaw_m),
        ];
        if let Some(&(column, value)) = values.iter().find(|(_, v)| !v.is_finite()) {
            self.soft(line, LineProblem::NonFinite { column, value })?;
        }
        if sample.jaw_m.is_finite() && sample.jaw_m < 0.0 {
            self.soft(line, LineProblem::NegativeJaw(sample.jaw_m))?;
        }
        if let Some(&(column, value)) = values[1..]
            .iter()
            .find(|(_, v)| v.is_finite() && v.abs() > MAX_TOOL_COORDINATE_M)
        {
            self.soft(line, LineProblem::CoordinateOutOfRange { column, value })?;
        }
        if let Some((previous_line, previous_s)) = self.previous
            && sample.t_s < previous_s
        {
            self.soft(
                line,
                LineProblem::TimeBackwards {
                    t_s: sample.t_s,
                    previous_line,
                    previous_s,
                },
            )?;
        }
        if !sample.t_s.is_nan() {
            self.previous = Some((line, sample.t_s));
        }
        if sample.t_s.is_finite() {
            self.check_span(line, sample.t_s)?;
        }
        let Some(track) = self.tracks.get_mut(sample.tool) else {
            return Err(self.line_error(
                line,
                LineProblem::UnknownTool {
                    tool: sample.tool,
                    count,
                },
            ));
        };
        track.push((sample.t_s, sample.tool_state()));
        self.samples.push(sample);
        Ok(())
    }

    /// The time range and span rules, in both modes: an error for `t_s` (finite) on `line`.
    fn check_span(&mut self, line: usize, t_s: f64) -> Result<(), TrajectoryError> {
        if t_s.abs() > MAX_TRAJECTORY_TIME_S {
            return Err(self.line_error(line, LineProblem::TimeOutOfRange { t_s }));
        }
        let earliest = *self.earliest.get_or_insert((line, t_s));
        let latest = *self.latest.get_or_insert((line, t_s));
        // The span with this time is its distance to the farther of the two extremes (both
        // within ±2³² s: the differences are exact enough and finite).
        let (other_line, other_s) = if t_s - earliest.1 >= latest.1 - t_s {
            earliest
        } else {
            latest
        };
        let span_s = (t_s - other_s).abs();
        if span_s > MAX_TRAJECTORY_SPAN_S {
            return Err(self.line_error(
                line,
                LineProblem::SpanTooLong {
                    t_s,
                    span_s,
                    other_line,
                    other_s,
                },
            ));
        }
        if t_s < earliest.1 {
            self.earliest = Some((line, t_s));
        }
        if t_s > latest.1 {
            self.latest = Some((line, t_s));
        }
        Ok(())
    }

    fn finish(self) -> Result<(Trajectory, Vec<TrajectoryError>), TrajectoryError> {
        let whole = |problem| TrajectoryError::File {
            file: self.file.to_owned(),
            problem,
        };
        if self.samples.is_empty() {
            return Err(whole(FileProblem::NoSamples));
        }
        if let Some(tool) = self.tracks.iter().position(Vec::is_empty) {
            return Err(whole(FileProblem::ToolWithoutSamples(tool)));
        }
        let tool_columns = self.tool_columns || self.samples.iter().any(Sample::needs_tool_columns);
        Ok((
            Trajectory {
                samples: self.samples,
                tracks: self.tracks,
                tool_columns,
            },
            self.findings,
        ))
    }
}

/// Parse one data record (5 fields, or 7 with `tool_columns`, checked by the caller) into a
/// sample.
fn parse_record(record: &csv::StringRecord, tool_columns: bool) -> Result<Sample, LineProblem> {
    let field = |i: usize| record.get(i).unwrap_or("");
    let number = |i: usize, column: &'static str| {
        field(i)
            .parse::<f64>()
            .map_err(|_| LineProblem::NotANumber {
                column,
                text: field(i).to_owned(),
            })
    };
    let t_s = number(0, "t")?;
    let tool = field(1)
        .parse::<usize>()
        .map_err(|_| LineProblem::BadToolIndex(field(1).to_owned()))?;
    let position_m = [number(2, "x")?, number(3, "y")?, number(4, "z")?];
    let (jaw_m, cut) = if tool_columns {
        let jaw_m = number(5, "jaw_m")?;
        let cut = match field(6) {
            "0" => false,
            "1" => true,
            other => return Err(LineProblem::BadCut(other.to_owned())),
        };
        (jaw_m, cut)
    } else {
        (0.0, false)
    };
    Ok(Sample {
        t_s,
        tool,
        position_m,
        jaw_m,
        cut,
    })
}

/// Read CSV `bytes` under `mode`; `file` names it in messages.
///
/// Lines are split here (on `\n`, a trailing `\r` dropped) and each is read as one CSV record
/// by the `csv` crate: the crate's own line count skips blank lines uncounted, and every message
/// must name the file's physical line.
fn read_csv(
    bytes: &[u8],
    file: &str,
    tool_count: usize,
    mode: Mode,
) -> Result<(Trajectory, Vec<TrajectoryError>), TrajectoryError> {
    let mut builder = Builder::new(file, tool_count, mode)?;
    let mut parser = csv::ReaderBuilder::new();
    parser
        .has_headers(false)
        .flexible(true)
        .trim(csv::Trim::All)
        .buffer_capacity(256);
    // The header's field count, once seen.
    let mut header_columns = None;
    let mut record = csv::StringRecord::new();
    let mut extra = csv::ByteRecord::new();
    for (index, text) in bytes.split(|&b| b == b'\n').enumerate() {
        let line = index + 1;
        let text = text.strip_suffix(b"\r").unwrap_or(text);
        let content = text.trim_ascii();
        if content.is_empty() || content.starts_with(b"#") {
            continue;
        }
        let mut reader = parser.from_reader(text);
        if let Err(err) = reader.read_record(&mut record) {
            return Err(builder.line_error(line, LineProblem::Unreadable(err.to_string())));
        }
        // The CSV reader also ends a record at a bare `\r`: what follows it on the line would be
        // a second record, silently dropped.
        if !matches!(reader.read_byte_record(&mut extra), Ok(false)) {
            return Err(builder.line_error(
                line,
                LineProblem::Unreadable(
                    "a carriage return inside the line (one record per line)".into(),
                ),
            ));
        }
        let Some(columns) = header_columns else {
            if record.iter().eq(HEADER) {
                header_columns = Some(HEADER.len());
            } else if record.iter().eq(TOOL_HEADER) {
                header_columns = Some(TOOL_HEADER.len());
                builder.tool_columns = true;
            } else {
                let found = record.iter().collect::<Vec<_>>().join(",");
                return Err(builder.line_error(line, LineProblem::MissingHeader(found)));
            }
            continue;
        };
        if record.len() != columns {
            let problem = if builder.tool_columns {
                LineProblem::ToolColumnCount(record.len())
            } else {
                LineProblem::ColumnCount(record.len())
            };
            return Err(builder.line_error(line, problem));
        }
        let sample = parse_record(&record, builder.tool_columns)
            .map_err(|problem| builder.line_error(line, problem))?;
        builder.push(line, sample)?;
    }
    if header_columns.is_none() {
        return Err(TrajectoryError::File {
            file: file.to_owned(),
            problem: FileProblem::Empty,
        });
    }
    builder.finish()
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

/// Reads the file at `path` in `mode`; messages name it as `path` displays.
fn read_file(
    path: &Path,
    tool_count: usize,
    mode: Mode,
) -> Result<(Trajectory, Vec<TrajectoryError>), TrajectoryError> {
    let file = path.display().to_string();
    let bytes = read_bounded(
        path,
        MAX_TRAJECTORY_FILE_BYTES,
        "a trajectory file (MAX_TRAJECTORY_FILE_BYTES)",
    )
    .map_err(|err| TrajectoryError::Io {
        file: file.clone(),
        action: "read",
        err,
    })?;
    read_csv(&bytes, &file, tool_count, mode)
}

impl Trajectory {
    /// Read and check a trajectory file for a scene with `tool_count` tool points (see the
    /// module doc for the rules). Messages name the file as `path` displays.
    pub fn read(path: &Path, tool_count: usize) -> Result<Trajectory, TrajectoryError> {
        read_file(path, tool_count, Mode::Checked).map(|(t, _)| t)
    }

    /// [`Trajectory::read`] from text; `source` names it in messages.
    pub fn from_csv_str(
        text: &str,
        source: &str,
        tool_count: usize,
    ) -> Result<Trajectory, TrajectoryError> {
        read_csv(text.as_bytes(), source, tool_count, Mode::Checked).map(|(t, _)| t)
    }

    /// The lenient reader, for robustness tests: non-finite values, negative jaw openings and
    /// times going backwards are kept, and each such problem is returned as a finding, in line
    /// order (the errors [`Trajectory::read`] refuses with; a line can give several: a non-finite
    /// value, a negative jaw opening, a backward time). A missing header, a wrong field count, a
    /// field that is not a number, a `cut` other than `0` or `1`, an unknown tool point or a tool
    /// point without a sample are still errors: there is no value to keep; so are a finite time
    /// out of range and a span beyond the limit (module doc).
    pub fn read_unchecked(
        path: &Path,
        tool_count: usize,
    ) -> Result<(Trajectory, Vec<TrajectoryError>), TrajectoryError> {
        read_file(path, tool_count, Mode::Lenient)
    }

    /// [`Trajectory::read_unchecked`] from text; `source` names it in messages.
    pub fn from_csv_str_unchecked(
        text: &str,
        source: &str,
        tool_count: usize,
    ) -> Result<(Trajectory, Vec<TrajectoryError>), TrajectoryError> {
        read_csv(text.as_bytes(), source, tool_count, Mode::Lenient)
    }

    /// A checked trajectory from samples in order. Errors name the source `samples` and the line
    /// each sample would have in the file [`Trajectory::write_csv`] writes (sample `i` on line
    /// `i + 2`). It has the tool columns if a sample needs them: a `jaw_m` other than `+0` or a
    /// `cut` (so that [`Trajectory::write_csv`] keeps them).
    pub fn from_samples(
        samples: Vec<Sample>,
        tool_count: usize,
    ) -> Result<Trajectory, TrajectoryError> {
        Self::from_samples_with_tool_columns(samples, tool_count, false)
    }

    /// [`Trajectory::from_samples`], with the tool columns also when no sample needs them if
    /// `tool_columns` (a grasper held open at 0 m, a cutter never enabled).
    pub fn from_samples_with_tool_columns(
        samples: Vec<Sample>,
        tool_count: usize,
        tool_columns: bool,
    ) -> Result<Trajectory, TrajectoryError> {
        let mut builder = Builder::new("samples", tool_count, Mode::Checked)?;
        builder.tool_columns = tool_columns;
        for (i, sample) in samples.into_iter().enumerate() {
            builder.push(i + 2, sample)?;
        }
        builder.finish().map(|(t, _)| t)
    }

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
