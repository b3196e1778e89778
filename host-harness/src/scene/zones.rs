//! A scene's intent for the hybrid model (MODELS.md §5, RR-3510 §6): the zones where the tissue
//! must be dynamic (`[[zone]]`) and the margin around them (`[partition]`). The scene states
//! where cutting or large deformation may happen; [`crate::partition`] chooses the tets.
//!
//! ```toml
//! [[zone]]                      # any number; the partition contains every zone plus the margin
//! kind = "cut"                  # "cut" (tensor-mass, cuttable) or "large-deformation"
//!                               # (St Venant-Kirchhoff: rotations or strains past the linear
//!                               # model's validity, about 10 % of the object's size, MODELS.md §2)
//! shape = "box"                 # "box" (min_m, max_m), "sphere" (center_m, radius_m),
//! min_m = [0.0, 0.0, 0.0]       # "capsule" (a_m, b_m, radius_m), "path" (trajectory, radius_m)
//! max_m = [0.04, 0.12, 0.06]
//! # trajectory = "cut.csv"      # path: a trajectory CSV of the session format, relative to the
//! #                             # scene file; the zone is within radius_m of the polyline
//! #                             # through each tool point's samples, in file order
//!
//! [partition]
//! margin_rings = 2              # element rings added around the zones (DEFAULT_MARGIN_RINGS)
//! ```
//!
//! Zones are numbered from 1 in file order in messages (`[[zone]] 2 radius_m = -1: must be
//! finite and > 0 m`). Every shape key is checked; a key of another shape is refused. The
//! trajectory of a `path` zone is read when the scene is (bounded by the trajectory reader's
//! limits, [`crate::limits::MAX_TRAJECTORY_FILE_BYTES`]) with the scene's tool point count.

use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::exact;
use super::trajectory::Trajectory;
use crate::limits::MAX_ZONE_PATH_SEGMENTS;

/// Default [`PartitionSpec::margin_rings`]: element rings around the zones, so that the
/// pre-computed region sees only deformation within the linear model's range (about 10 % of the
/// object's size, MODELS.md §2). Measured (test `host::partition::margin_default_is_where_a_
/// pulled_cut_is_back_in_the_linear_range`): on the demo block (12 × 12 × 6 cells of 1 cm, base
/// fixed, E = 3 kPa, ν = 0.45) with a 4 cm slit cut at the top and its lip pulled 8 mm sideways
/// (the built-in grasp-pull), the largest displacement gradient `|∇u|` outside the slit plus `k`
/// rings is 0.73, 0.36, 0.20, 0.127, 0.097 for `k` = 0..=4: below 0.1 from 4 rings on.
pub const DEFAULT_MARGIN_RINGS: u32 = 4;

/// Largest [`PartitionSpec::margin_rings`]: past a few rings the margin is the whole of any
/// organ mesh Palpate runs in real time (ring growth is a breadth-first pass, linear in the mesh
/// per ring).
pub const MAX_MARGIN_RINGS: u32 = 64;

/// Largest number of `[[zone]]` tables of a scene.
pub const MAX_ZONES: usize = 256;

/// What a zone asks of the tissue in it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ZoneKind {
    /// Cutting may happen: tensor-mass (RR-3510 §5), the only cuttable model.
    Cut,
    /// Rotations or strains past the linear model's validity (MODELS.md §2): tensor-mass with
    /// St Venant-Kirchhoff (MODELS.md §4).
    LargeDeformation,
}

impl ZoneKind {
    /// The scene file's name: `cut` or `large-deformation`.
    pub fn name(self) -> &'static str {
        match self {
            ZoneKind::Cut => "cut",
            ZoneKind::LargeDeformation => "large-deformation",
        }
    }
}

/// A zone's region of space, m (mesh units).
#[derive(Clone, Debug, PartialEq)]
pub enum ZoneShape {
    /// The axis-aligned box `[min_m, max_m]`; `min_m[i] < max_m[i]`, finite.
    Box {
        /// Lowest corner, m.
        min_m: [f64; 3],
        /// Highest corner, m.
        max_m: [f64; 3],
    },
    /// The points within `radius_m` of `center_m`.
    Sphere {
        /// Centre, m, finite.
        center_m: [f64; 3],
        /// Radius, m, finite and > 0.
        radius_m: f64,
    },
    /// The points within `radius_m` of the segment `a_m`–`b_m` (a sphere if they coincide).
    Capsule {
        /// One end, m, finite.
        a_m: [f64; 3],
        /// The other end, m, finite.
        b_m: [f64; 3],
        /// Radius, m, finite and > 0.
        radius_m: f64,
    },
    /// The points within `radius_m` of the polylines through each tool point's samples.
    Path {
        /// The trajectory file, resolved against the scene file's folder.
        trajectory: PathBuf,
        /// One polyline per tool point (its samples' positions in file order, consecutive
        /// repeats dropped; a single point for a tool that never moves), m.
        polylines: Vec<Vec<[f64; 3]>>,
        /// Radius, m, finite and > 0.
        radius_m: f64,
    },
}

impl ZoneShape {
    /// The scene file's name: `box`, `sphere`, `capsule` or `path`.
    pub fn name(&self) -> &'static str {
        match self {
            ZoneShape::Box { .. } => "box",
            ZoneShape::Sphere { .. } => "sphere",
            ZoneShape::Capsule { .. } => "capsule",
            ZoneShape::Path { .. } => "path",
        }
    }
}

/// One `[[zone]]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Zone {
    /// What the zone asks for.
    pub kind: ZoneKind,
    /// Where it is.
    pub shape: ZoneShape,
}

impl Zone {
    /// How messages name zone `index` (0-based): `[[zone]] 1 (cut, box)`.
    pub fn label(&self, index: usize) -> String {
        format!(
            "[[zone]] {} ({}, {})",
            index + 1,
            self.kind.name(),
            self.shape.name()
        )
    }
}

/// `[partition]`: how the zones become tets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PartitionSpec {
    /// Element rings added around the zones' tets (each ring: every tet sharing a vertex with
    /// the set), in `0..=MAX_MARGIN_RINGS`.
    pub margin_rings: u32,
}

impl Default for PartitionSpec {
    fn default() -> Self {
        Self {
            margin_rings: DEFAULT_MARGIN_RINGS,
        }
    }
}

// ---- The file as written (serde), before validation. ----

/// A `[[zone]]` table as written.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ZoneFile {
    kind: String,
    shape: String,
    #[serde(default, deserialize_with = "exact::three_opt")]
    min_m: Option<[f64; 3]>,
    #[serde(default, deserialize_with = "exact::three_opt")]
    max_m: Option<[f64; 3]>,
    #[serde(default, deserialize_with = "exact::three_opt")]
    center_m: Option<[f64; 3]>,
    #[serde(default, deserialize_with = "exact::three_opt")]
    a_m: Option<[f64; 3]>,
    #[serde(default, deserialize_with = "exact::three_opt")]
    b_m: Option<[f64; 3]>,
    radius_m: Option<f64>,
    trajectory: Option<PathBuf>,
}

/// The `[partition]` table as written.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct PartitionFile {
    margin_rings: Option<i64>,
}

/// The zones and partition of a scene file: every key checked, `path` trajectories read
/// (relative to `base_dir`, with `tool_points` tool points). Errors are `(key, message)`.
pub(crate) fn zones_spec(
    zones: &[ZoneFile],
    partition: Option<&PartitionFile>,
    base_dir: &Path,
    tool_points: usize,
) -> Result<(Vec<Zone>, PartitionSpec), (String, String)> {
    if zones.len() > MAX_ZONES {
        return Err((
            "[[zone]]".into(),
            format!("{} zones: at most {MAX_ZONES} (MAX_ZONES)", zones.len()),
        ));
    }
    let zones = zones
        .iter()
        .enumerate()
        .map(|(i, z)| zone(i + 1, z, base_dir, tool_points))
        .collect::<Result<Vec<_>, _>>()?;
    let margin_rings = match partition.and_then(|p| p.margin_rings) {
        None => DEFAULT_MARGIN_RINGS,
        Some(k) => u32::try_from(k)
            .ok()
            .filter(|&k| k <= MAX_MARGIN_RINGS)
            .ok_or_else(|| {
                (
                    format!("[partition] margin_rings = {k}"),
                    format!("must be in 0..={MAX_MARGIN_RINGS} (MAX_MARGIN_RINGS)"),
                )
            })?,
    };
    Ok((zones, PartitionSpec { margin_rings }))
}

/// Zone `n` (1-based) of the file.
fn zone(
    n: usize,
    z: &ZoneFile,
    base_dir: &Path,
    tool_points: usize,
) -> Result<Zone, (String, String)> {
    let key = |k: &str| format!("[[zone]] {n} {k}");
    let kind = match z.kind.as_str() {
        "cut" => ZoneKind::Cut,
        "large-deformation" => ZoneKind::LargeDeformation,
        other => {
            return Err((
                key(&format!("kind = {other:?}")),
                "expected \"cut\" or \"large-deformation\"".into(),
            ));
        }
    };
    check_shape_keys(z, &key)?;
    let shape = shape(z, &key, base_dir, tool_points)?;
    Ok(Zone { kind, shape })
}

/// The keys `z`'s shape takes are given, and no other: errors are `(key, message)`, the key
/// named by `key`.
fn check_shape_keys(z: &ZoneFile, key: &dyn Fn(&str) -> String) -> Result<(), (String, String)> {
    // The keys each shape takes; any other given key is refused.
    let wanted: &[&str] = match z.shape.as_str() {
        "box" => &["min_m", "max_m"],
        "sphere" => &["center_m", "radius_m"],
        "capsule" => &["a_m", "b_m", "radius_m"],
        "path" => &["trajectory", "radius_m"],
        other => {
            return Err((
                key(&format!("shape = {other:?}")),
                "expected \"box\", \"sphere\", \"capsule\" or \"path\"".into(),
            ));
        }
    };
    let given = [
        ("min_m", z.min_m.is_some()),
        ("max_m", z.max_m.is_some()),
        ("center_m", z.center_m.is_some()),
        ("a_m", z.a_m.is_some()),
        ("b_m", z.b_m.is_some()),
        ("radius_m", z.radius_m.is_some()),
        ("trajectory", z.trajectory.is_some()),
    ];
    for (name, is_given) in given {
        if is_given && !wanted.contains(&name) {
            return Err((
                key(name),
                format!(
                    "does not apply to shape = {:?} (it takes {})",
                    z.shape,
                    wanted.join(", ")
                ),
            ));
        }
        if !is_given && wanted.contains(&name) {
            return Err((
                key(name),
                format!("missing: shape = {:?} needs {}", z.shape, wanted.join(", ")),
            ));
        }
    }
    Ok(())
}

/// The shape of `z` (its keys checked by [`check_shape_keys`]), a `path`'s trajectory read
/// relative to `base_dir` with `tool_points` tool points; errors are `(key, message)`.
fn shape(
    z: &ZoneFile,
    key: &dyn Fn(&str) -> String,
    base_dir: &Path,
    tool_points: usize,
) -> Result<ZoneShape, (String, String)> {
    let point = |name: &str, p: Option<[f64; 3]>| {
        let p = p.unwrap_or_default();
        if p.iter().all(|x| x.is_finite()) {
            Ok(p)
        } else {
            Err((key(&format!("{name} = {p:?}")), "must be finite m".into()))
        }
    };
    let radius = || {
        let r = z.radius_m.unwrap_or_default();
        if r.is_finite() && r > 0.0 {
            Ok(r)
        } else {
            Err((
                key(&format!("radius_m = {r}")),
                "must be finite and > 0 m".into(),
            ))
        }
    };
    let shape = match z.shape.as_str() {
        "box" => {
            let (min_m, max_m) = (point("min_m", z.min_m)?, point("max_m", z.max_m)?);
            if (0..3).any(|i| min_m[i] >= max_m[i]) {
                return Err((
                    key(&format!("min_m = {min_m:?}")),
                    format!("must be below max_m = {max_m:?} on every axis"),
                ));
            }
            ZoneShape::Box { min_m, max_m }
        }
        "sphere" => ZoneShape::Sphere {
            center_m: point("center_m", z.center_m)?,
            radius_m: radius()?,
        },
        "capsule" => ZoneShape::Capsule {
            a_m: point("a_m", z.a_m)?,
            b_m: point("b_m", z.b_m)?,
            radius_m: radius()?,
        },
        _ => {
            let radius_m = radius()?;
            let trajectory = base_dir.join(z.trajectory.clone().unwrap_or_default());
            let read = Trajectory::read(&trajectory, tool_points).map_err(|e| {
                (
                    key(&format!(
                        "trajectory = {:?}",
                        trajectory.display().to_string()
                    )),
                    e.to_string().replace('\n', "; "),
                )
            })?;
            let polylines = polylines(&read);
            let segments: usize = polylines.iter().map(|l| l.len().saturating_sub(1)).sum();
            if segments > MAX_ZONE_PATH_SEGMENTS {
                return Err((
                    key(&format!(
                        "trajectory = {:?}",
                        trajectory.display().to_string()
                    )),
                    format!(
                        "{segments} segments once its collinear runs are merged, more than \
                         {MAX_ZONE_PATH_SEGMENTS} (MAX_ZONE_PATH_SEGMENTS): resample it more \
                         coarsely (a zone needs a sample every millimetre or so, not every tick)"
                    ),
                ));
            }
            ZoneShape::Path {
                trajectory,
                polylines,
                radius_m,
            }
        }
    };
    Ok(shape)
}

/// Per tool point, its samples' positions in file order without consecutive repeats, each run
/// of samples on one straight segment (to [`COLLINEAR_TOLERANCE`] of the path's size) merged
/// into that segment ([`merge_collinear`]): a trajectory sampled at 1 kHz along straight moves
/// is a few segments, not thousands.
fn polylines(trajectory: &Trajectory) -> Vec<Vec<[f64; 3]>> {
    let mut lines = vec![Vec::new(); trajectory.tool_count()];
    for s in trajectory.samples() {
        if let Some(line) = lines.get_mut(s.tool)
            && line.last() != Some(&s.position_m)
        {
            line.push(s.position_m);
        }
    }
    let (lo, hi) = lines.iter().flatten().fold(
        ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
        |(lo, hi), p| {
            (
                [0, 1, 2].map(|i| lo[i].min(p[i])),
                [0, 1, 2].map(|i| hi[i].max(p[i])),
            )
        },
    );
    let diagonal = (0..3).map(|i| (hi[i] - lo[i]).powi(2)).sum::<f64>().sqrt();
    let tolerance_m = COLLINEAR_TOLERANCE * diagonal;
    lines
        .into_iter()
        .map(|line| merge_collinear(&line, tolerance_m))
        .collect()
}

/// Relative distance, to the path's bounding-box diagonal, within which a sample counts as on
/// the segment through its neighbours: 10⁻¹², a thousandth of the partition's own tolerance
/// (10⁻⁹ of the mesh's diagonal) for a path the size of the mesh.
pub const COLLINEAR_TOLERANCE: f64 = 1e-12;

/// Most samples one merged segment spans ([`merge_collinear`]'s work is this many distance
/// tests per sample at most).
const MAX_MERGED_RUN: usize = 1024;

/// `line` with every sample within `tolerance_m` of the segment from the last kept sample to a
/// later one dropped (greedily, at most `MAX_MERGED_RUN` samples a segment): the union of
/// capsules around it differs from the original's by at most `tolerance_m`.
pub fn merge_collinear(line: &[[f64; 3]], tolerance_m: f64) -> Vec<[f64; 3]> {
    let Some(&first) = line.first() else {
        return Vec::new();
    };
    let near = |p: [f64; 3], a: [f64; 3], b: [f64; 3]| {
        let d = [0, 1, 2].map(|i| b[i] - a[i]);
        let q = [0, 1, 2].map(|i| p[i] - a[i]);
        let len_sq: f64 = d.iter().map(|x| x * x).sum();
        let t = if len_sq > 0.0 {
            ((0..3).map(|i| q[i] * d[i]).sum::<f64>() / len_sq).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (0..3).map(|i| (q[i] - t * d[i]).powi(2)).sum::<f64>() <= tolerance_m * tolerance_m
    };
    let mut kept = vec![first];
    let mut start = 0;
    let mut end = 1;
    while end < line.len() {
        // Extend the segment from `start` to `end + 1` while every sample between stays on it.
        let next = end + 1;
        let extends = next < line.len()
            && next - start <= MAX_MERGED_RUN
            && (start + 1..next).all(|k| near(line[k], line[start], line[next]));
        if extends {
            end = next;
        } else {
            kept.push(line[end]);
            start = end;
            end += 1;
        }
    }
    kept
}
