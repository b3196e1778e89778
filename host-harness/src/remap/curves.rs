//! Compression curves: the CSV a tissue test gives (`force,axial,radial`).
//!
//! Format: a header line `force,axial,radial`, then one row per sample of a
//! compression at a fixed loading speed: the axial force on the sample, N;
//! the axial compression (the top's displacement towards the base, ≥ 0), m;
//! the radial displacement of the sample's mid-height surface outwards, m.
//! Rows are in increasing compression; the first may be the rest state
//! `0,0,0`. At most [`MAX_CURVE_ROWS`] rows.

use std::path::Path;

use anyhow::{Context, bail, ensure};

use crate::limits::read_bounded;

/// Most rows of a curve file: a test sampled at 1 kHz for 100 s, far more
/// than a degree-5 least-squares fit needs.
pub const MAX_CURVE_ROWS: usize = 100_000;

/// Largest curve file, bytes (100 000 rows of three numbers of at most 32
/// characters each).
pub const MAX_CURVE_FILE_BYTES: u64 = 10 << 20;

/// One sample of a compression test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurvePoint {
    /// Axial force, N.
    pub force_n: f64,
    /// Axial compression, m (≥ 0).
    pub axial_m: f64,
    /// Radial displacement of the mid-height surface, m.
    pub radial_m: f64,
}

/// The CSV text of `points` (header and rows; full `f64` precision).
pub fn to_csv(points: &[CurvePoint]) -> String {
    let mut out = String::from("force,axial,radial\n");
    for p in points {
        out.push_str(&format!("{},{},{}\n", p.force_n, p.axial_m, p.radial_m));
    }
    out
}

/// Parses curve CSV `text` (format in the module documentation); errors
/// name the line.
pub fn parse(text: &str) -> anyhow::Result<Vec<CurvePoint>> {
    let mut lines = text.lines().enumerate();
    let header = lines.next().map(|(_, l)| l.trim()).unwrap_or("");
    ensure!(
        header == "force,axial,radial",
        "line 1: header must be `force,axial,radial`, found `{header}`"
    );
    let mut points: Vec<CurvePoint> = Vec::new();
    for (i, line) in lines {
        let line_no = i + 1;
        if line.trim().is_empty() {
            continue;
        }
        ensure!(
            points.len() < MAX_CURVE_ROWS,
            "line {line_no}: more than {MAX_CURVE_ROWS} rows"
        );
        let values: Vec<f64> = line
            .split(',')
            .map(|v| v.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .with_context(|| format!("line {line_no}: not three numbers: `{line}`"))?;
        let [force_n, axial_m, radial_m] = values[..] else {
            bail!("line {line_no}: {} columns, expected 3", values.len());
        };
        ensure!(
            [force_n, axial_m, radial_m].iter().all(|x| x.is_finite()),
            "line {line_no}: a value is not finite"
        );
        ensure!(
            axial_m >= 0.0,
            "line {line_no}: axial compression {axial_m} m is negative"
        );
        if let Some(last) = points.last() {
            ensure!(
                axial_m > last.axial_m,
                "line {line_no}: axial compression {axial_m} m does not increase"
            );
        }
        points.push(CurvePoint {
            force_n,
            axial_m,
            radial_m,
        });
    }
    ensure!(
        points.iter().filter(|p| p.axial_m > 0.0).count() >= 2,
        "fewer than two rows with a positive compression"
    );
    Ok(points)
}

/// Reads and parses the curve file at `path` (bounded by
/// [`MAX_CURVE_FILE_BYTES`]).
pub fn read(path: &Path) -> anyhow::Result<Vec<CurvePoint>> {
    let bytes = read_bounded(path, MAX_CURVE_FILE_BYTES, "a curve file")
        .with_context(|| format!("{}", path.display()))?;
    let text =
        String::from_utf8(bytes).with_context(|| format!("{}: not UTF-8", path.display()))?;
    parse(&text).with_context(|| format!("{}", path.display()))
}
