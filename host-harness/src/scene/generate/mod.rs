//! Trajectory generators: poke, press-and-hold, slide, two-point pinch, fast strike (probes),
//! grasp-and-pull (a grasper), cut line (a cutter).
//!
//! Every generator describes a piecewise-linear path per tool point by its [`Keyframe`]s (start,
//! contact, deepest, ... each labelled), and [`sample_keyframes`] samples it at `rate_hz` on the
//! grid `t = k / rate_hz` (k = 0, 1, ...) plus every keyframe time, so that
//! [`Trajectory::positions_at`] reproduces the path exactly: the requested depth is reached
//! exactly at the deepest keyframe's time. Paths start at `t = 0` and end at the last keyframe.
//! A keyframe also carries the tool columns of the trajectory file (module
//! [`super::trajectory`]): the jaw opening `jaw_m`, linear between keyframes as the position, and
//! the blade's `cut`, held from a keyframe to the next. The probe generators leave them at 0 and
//! off and write the 5-column format; [`GraspPull`] and [`CutLine`] write the 7-column one.
//!
//! The geometry of a press is a [`Press`]: a surface point, its outward normal, a standoff above
//! the surface and a depth below it, and the approach and withdraw speeds. Defaults are on the
//! built-in scene's block (top face `z = 0.06` m, centre `(0.06, 0.06)`), at 1 kHz.
//!
//! One file per family: `press` (the probes' presses: poke, press-and-hold, slide, pinch,
//! strike), `tools` (a grasper's grasp-and-pull, a cutter's cut line), `built_in` (the
//! built-in scenes' tools at work).

mod built_in;
mod press;
mod tools;

pub use built_in::{hepatectomy, surgery};
pub use press::{Pinch, Poke, Press, PressHold, Slide, Strike};
pub use tools::{CutLine, GraspPull};

use super::tool::MAX_TOOL_POINTS;
use super::trajectory::{Sample, ToolState, Trajectory, state_on};

/// Largest number of samples a generator produces, so a typo (a speed of 1e-9 m/s) is an error
/// rather than an exhausted memory.
pub const MAX_GENERATED_SAMPLES: usize = 10_000_000;

/// A bad generator parameter.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{param}: {msg}")]
pub struct GenerateError {
    /// The parameter, as `struct.field`.
    pub param: &'static str,
    /// What is wrong and what is expected.
    pub msg: String,
}

fn err(param: &'static str, msg: impl Into<String>) -> GenerateError {
    GenerateError {
        param,
        msg: msg.into(),
    }
}

/// A point of a tool point's path: at `t_s` the tool point `tool` is at `position_m` with the jaw
/// opening `jaw_m` and the blade enabled if `cut`; between two keyframes of a tool point it moves
/// in a straight line at constant speed, its jaw opening changes linearly, and its `cut` stays
/// the earlier keyframe's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Keyframe {
    /// Tool point index, 0-based.
    pub tool: usize,
    /// Time, s.
    pub t_s: f64,
    /// Position, m.
    pub position_m: [f64; 3],
    /// A grasper's jaw opening, m, finite and ≥ 0 (0 for other tool kinds).
    pub jaw_m: f64,
    /// Whether a cutter's blade is enabled from this keyframe to the next (false for other tool
    /// kinds).
    pub cut: bool,
    /// Which point of the path: `start`, `contact` (crossing the rest surface on the way in; for
    /// a grasper, its jaw spheres touching it; for a cutter, its blade tip reaching it, the blade
    /// enabled from there), `deepest`, `held` (end of a hold), `slid` (end of a slide), `closed`
    /// (pinch or grasper closed), `gripped` (end of the hold closed, before the pull), `pulled`
    /// (end of a pull), `opened` (grasper opened), `cut` (end of a cut line, the blade disabled
    /// from there), `release` (crossing the rest surface on the way out), `end`.
    pub label: &'static str,
}

impl Keyframe {
    /// A keyframe with the jaws at 0 and the blade off (a probe's).
    fn at(tool: usize, t_s: f64, position_m: [f64; 3], label: &'static str) -> Self {
        Self {
            tool,
            t_s,
            position_m,
            jaw_m: 0.0,
            cut: false,
            label,
        }
    }

    fn state(&self) -> ToolState {
        ToolState {
            position_m: self.position_m,
            jaw_m: self.jaw_m,
            cut: self.cut,
        }
    }
}

/// A generator of a trajectory.
///
/// A single-point generator whose `tool` is not 0 gives a trajectory only together with the
/// other tool points: concatenate the keyframes of one generator per tool point and call
/// [`sample_keyframes`] (e.g. two probes: a [`PressHold`] with `tool: 0` and one with `tool: 1`).
pub trait Generator {
    /// The path's keyframes, per tool point in time order (tool points interleaved).
    fn keyframes(&self) -> Result<Vec<Keyframe>, GenerateError>;

    /// Sampling rate, Hz.
    fn rate_hz(&self) -> f64;

    /// Whether the trajectory has the tool columns `jaw_m,cut` even if no keyframe needs them
    /// (a grasper's or a cutter's path): false by default.
    fn tool_columns(&self) -> bool {
        false
    }

    /// The sampled trajectory: [`sample_keyframes_with_tool_columns`] of
    /// [`Generator::keyframes`].
    fn trajectory(&self) -> Result<Trajectory, GenerateError> {
        sample_keyframes_with_tool_columns(&self.keyframes()?, self.rate_hz(), self.tool_columns())
    }
}

/// Sample piecewise-linear paths at `rate_hz`: for every tool point, a sample at every keyframe
/// time and at every `k / rate_hz` from 0 to the last keyframe time of all tool points (grid times
/// within a millionth of a period of a keyframe are dropped: the keyframe stands for them).
/// Positions and jaw openings between keyframes are linear in time, a `cut` is the one of the
/// latest keyframe at or before the sample's time; a tool point holds its last keyframe.
///
/// Requirements: at least one keyframe; finite values, jaw openings `≥ 0`; keyframe times `≥ 0`
/// and non-decreasing per tool point (equal times with different states are a jump); tool
/// indices below `MAX_TOOL_POINTS`, every index below the largest used; `rate_hz` finite and
/// `> 0`; at most [`MAX_GENERATED_SAMPLES`] samples. Samples are ordered by time, then tool
/// point. The trajectory's tool point count is the largest index + 1; it has the tool columns
/// `jaw_m,cut` if a keyframe has a jaw opening other than 0 or a `cut`.
pub fn sample_keyframes(keyframes: &[Keyframe], rate_hz: f64) -> Result<Trajectory, GenerateError> {
    sample_keyframes_with_tool_columns(keyframes, rate_hz, false)
}

/// [`sample_keyframes`], with the tool columns `jaw_m,cut` also when no keyframe needs them if
/// `tool_columns`.
pub fn sample_keyframes_with_tool_columns(
    keyframes: &[Keyframe],
    rate_hz: f64,
    tool_columns: bool,
) -> Result<Trajectory, GenerateError> {
    if !(rate_hz.is_finite() && rate_hz > 0.0) {
        return Err(err(
            "rate_hz",
            format!("must be finite and > 0 Hz, got {rate_hz}"),
        ));
    }
    let Some(tool_count) = keyframes.iter().map(|k| k.tool + 1).max() else {
        return Err(err("keyframes", "no keyframe"));
    };
    if tool_count > MAX_TOOL_POINTS {
        return Err(err(
            "keyframes",
            format!(
                "tool point {} out of range 0..{MAX_TOOL_POINTS}",
                tool_count - 1
            ),
        ));
    }
    let mut paths: Vec<Vec<(f64, ToolState)>> = vec![Vec::new(); tool_count];
    for k in keyframes {
        if !(k.t_s.is_finite()
            && k.t_s >= 0.0
            && k.position_m.iter().all(|x| x.is_finite())
            && k.jaw_m.is_finite()
            && k.jaw_m >= 0.0)
        {
            return Err(err(
                "keyframes",
                format!(
                    "{} of tool point {}: non-finite value, negative time or negative jaw_m",
                    k.label, k.tool
                ),
            ));
        }
        let Some(path) = paths.get_mut(k.tool) else {
            continue; // Unreachable: tool < tool_count.
        };
        match path.last() {
            Some(&(t, _)) if k.t_s < t => {
                return Err(err(
                    "keyframes",
                    format!(
                        "{} of tool point {}: time {} s before {t} s",
                        k.label, k.tool, k.t_s
                    ),
                ));
            }
            // A zero-length phase (no hold, no standoff): the same keyframe again.
            Some(&(t, p)) if k.t_s == t && k.state() == p => {}
            _ => path.push((k.t_s, k.state())),
        }
    }
    if let Some(tool) = paths.iter().position(Vec::is_empty) {
        return Err(err(
            "keyframes",
            format!("tool point {tool} has no keyframe"),
        ));
    }
    let end_s = paths
        .iter()
        .filter_map(|p| p.last().map(|&(t, _)| t))
        .fold(0.0, f64::max);
    let grid_count = (end_s * rate_hz).floor() + 1.0;
    let estimate = grid_count * tool_count as f64 + keyframes.len() as f64;
    if estimate > MAX_GENERATED_SAMPLES as f64 {
        return Err(err(
            "rate_hz",
            format!(
                "{estimate} samples ({end_s} s at {rate_hz} Hz): at most {MAX_GENERATED_SAMPLES}"
            ),
        ));
    }
    // Below MAX_GENERATED_SAMPLES, so the conversion is exact.
    let grid_count = grid_count as usize;
    let tolerance_s = 1e-6 / rate_hz;
    let mut samples = Vec::new();
    for (tool, path) in paths.iter().enumerate() {
        let grid = (0..grid_count).map(|k| k as f64 / rate_hz).filter(|&t| {
            // The keyframes nearest `t` (the path is time-ordered): none within tolerance.
            let i = path.partition_point(|&(tk, _)| tk < t);
            let near = |j: Option<usize>| {
                j.and_then(|j| path.get(j))
                    .is_some_and(|&(tk, _)| (t - tk).abs() <= tolerance_s)
            };
            !near(i.checked_sub(1)) && !near(Some(i))
        });
        let mut times: Vec<f64> = grid.chain(path.iter().map(|&(t, _)| t)).collect();
        times.sort_by(f64::total_cmp);
        let mut keys = path.iter().peekable();
        for t in times {
            // A keyframe time gives that keyframe's own state (each of a jump's two).
            let state = match keys.peek() {
                Some(&&(tk, p)) if tk == t => {
                    keys.next();
                    p
                }
                _ => state_on(path, t),
            };
            samples.push(Sample {
                t_s: t,
                tool,
                position_m: state.position_m,
                jaw_m: state.jaw_m,
                cut: state.cut,
            });
        }
    }
    samples.sort_by(|a, b| a.t_s.total_cmp(&b.t_s));
    Trajectory::from_samples_with_tool_columns(samples, tool_count, tool_columns)
        .map_err(|e| err("keyframes", e.to_string()))
}

/// `a + s·d`, componentwise.
fn along(a: [f64; 3], d: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] + s * d[0], a[1] + s * d[1], a[2] + s * d[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `v / |v|`, or an error if `v` is not finite or (near) zero.
fn unit(v: [f64; 3], param: &'static str) -> Result<[f64; 3], GenerateError> {
    let n = dot(v, v).sqrt();
    if v.iter().all(|x| x.is_finite()) && n > 1e-12 {
        Ok(v.map(|x| x / n))
    } else {
        Err(err(
            param,
            format!("must be a finite non-zero vector, got {v:?}"),
        ))
    }
}

/// The unit tangent of `direction` at a surface of unit normal `n`: `direction` minus its normal
/// part, normalized; an error if it is (nearly) along the normal.
fn tangent(
    direction: [f64; 3],
    n: [f64; 3],
    param: &'static str,
) -> Result<[f64; 3], GenerateError> {
    let d = unit(direction, param)?;
    let t = along(d, n, -dot(d, n));
    if dot(t, t).sqrt() < 1e-6 {
        return Err(err(
            param,
            format!("{direction:?} is along the surface normal"),
        ));
    }
    unit(t, param)
}

fn check_finite_at_least(
    x: f64,
    min: f64,
    param: &'static str,
    unit: &str,
) -> Result<(), GenerateError> {
    if x.is_finite() && x >= min {
        Ok(())
    } else {
        Err(err(
            param,
            format!("must be finite and >= {min} {unit}, got {x}"),
        ))
    }
}

fn check_positive(x: f64, param: &'static str, unit: &str) -> Result<(), GenerateError> {
    if x.is_finite() && x > 0.0 {
        Ok(())
    } else {
        Err(err(
            param,
            format!("must be finite and > 0 {unit}, got {x}"),
        ))
    }
}

fn check_tool(tool: usize, param: &'static str) -> Result<(), GenerateError> {
    if tool < MAX_TOOL_POINTS {
        Ok(())
    } else {
        Err(err(
            param,
            format!("tool point {tool} out of range 0..{MAX_TOOL_POINTS}"),
        ))
    }
}
