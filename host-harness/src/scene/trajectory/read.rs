//! The trajectory readers: the CSV parsed line by line into a [`Trajectory`], checked (or, for
//! the lenient reader, with each problem reported), and the constructors from samples.

use std::path::Path;

use super::{
    FileProblem, HEADER, LineProblem, Sample, TOOL_HEADER, ToolState, Trajectory, TrajectoryError,
};
use crate::limits::{
    MAX_TOOL_COORDINATE_M, MAX_TRAJECTORY_FILE_BYTES, MAX_TRAJECTORY_SPAN_S, MAX_TRAJECTORY_TIME_S,
    read_bounded,
};
use crate::scene::tool::MAX_TOOL_POINTS;

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
}
