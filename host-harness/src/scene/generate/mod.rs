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

use super::spec::MAX_TOOL_POINTS;
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

/// Where and how a tool point presses: it starts `standoff_m` above `surface_m` along the outward
/// `normal`, moves against the normal at `approach_speed_m_s` to `depth_m` below the surface, and
/// goes back out at `withdraw_speed_m_s`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Press {
    /// The point of the rest surface where the tool point enters, m.
    pub surface_m: [f64; 3],
    /// Outward surface normal at `surface_m`; any finite non-zero length (normalized).
    pub normal: [f64; 3],
    /// Start distance above the surface along the normal, m, finite and ≥ 0.
    pub standoff_m: f64,
    /// Depth below the rest surface at the deepest point, m, finite and ≥ 0.
    pub depth_m: f64,
    /// Speed on the way in, m/s, finite and > 0.
    pub approach_speed_m_s: f64,
    /// Speed on the way out, m/s, finite and > 0.
    pub withdraw_speed_m_s: f64,
}

impl Default for Press {
    /// The top-face centre of the built-in block, `(0.06, 0.06, 0.06)` m, normal +z, from 5 mm
    /// above to 5 mm deep (below 10 % of the 6 cm thickness, the linear model's range) at
    /// 2 cm/s in and out: 0.5 s each way.
    fn default() -> Self {
        Self {
            surface_m: [0.06, 0.06, 0.06],
            normal: [0.0, 0.0, 1.0],
            standoff_m: 0.005,
            depth_m: 0.005,
            approach_speed_m_s: 0.02,
            withdraw_speed_m_s: 0.02,
        }
    }
}

/// A press resolved into points and times.
struct PressPath {
    /// Unit outward normal.
    n: [f64; 3],
    /// Start point (standoff above the surface).
    start: [f64; 3],
    /// Deepest point.
    deepest: [f64; 3],
    /// Time to cross the surface on the way in, s.
    contact_s: f64,
    /// Time from start to the deepest point, s.
    in_s: f64,
}

impl Press {
    fn path(&self) -> Result<PressPath, GenerateError> {
        if !self.surface_m.iter().all(|x| x.is_finite()) {
            return Err(err(
                "press.surface_m",
                format!("must be finite, got {:?}", self.surface_m),
            ));
        }
        let n = unit(self.normal, "press.normal")?;
        check_finite_at_least(self.standoff_m, 0.0, "press.standoff_m", "m")?;
        check_finite_at_least(self.depth_m, 0.0, "press.depth_m", "m")?;
        check_positive(self.approach_speed_m_s, "press.approach_speed_m_s", "m/s")?;
        check_positive(self.withdraw_speed_m_s, "press.withdraw_speed_m_s", "m/s")?;
        let contact_s = self.standoff_m / self.approach_speed_m_s;
        Ok(PressPath {
            n,
            start: along(self.surface_m, n, self.standoff_m),
            deepest: along(self.surface_m, n, -self.depth_m),
            contact_s,
            in_s: contact_s + self.depth_m / self.approach_speed_m_s,
        })
    }

    /// The keyframes of the way in, for tool point `tool` with the press moved by `offset_m`
    /// along the surface: `start` (t = 0), `contact`, `deepest`. Returns them and the resolved
    /// press (its points not moved by `offset_m`).
    fn way_in(
        &self,
        tool: usize,
        offset_m: [f64; 3],
    ) -> Result<(Vec<Keyframe>, PressPath), GenerateError> {
        let p = self.path()?;
        let at = |t_s, x: [f64; 3], label| Keyframe::at(tool, t_s, along(x, offset_m, 1.0), label);
        let keys = vec![
            at(0.0, p.start, "start"),
            at(p.contact_s, self.surface_m, "contact"),
            at(p.in_s, p.deepest, "deepest"),
        ];
        Ok((keys, p))
    }

    /// The keyframes of the way out from `from` (the deepest point, possibly moved along the
    /// surface) starting at `t_s`: `release` at the rest surface, `end` at the standoff.
    fn way_out(&self, tool: usize, n: [f64; 3], from: [f64; 3], t_s: f64) -> [Keyframe; 2] {
        let release_s = t_s + self.depth_m / self.withdraw_speed_m_s;
        [
            Keyframe::at(tool, release_s, along(from, n, self.depth_m), "release"),
            Keyframe::at(
                tool,
                release_s + self.standoff_m / self.withdraw_speed_m_s,
                along(from, n, self.depth_m + self.standoff_m),
                "end",
            ),
        ]
    }
}

/// A poke: in to the depth and straight back out, no hold. The deepest point
/// `surface − depth·n̂` is reached at `(standoff + depth) / approach_speed`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Poke {
    /// Tool point index, `< MAX_TOOL_POINTS`.
    pub tool: usize,
    /// Where and how.
    pub press: Press,
    /// Sampling rate, Hz.
    pub rate_hz: f64,
}

impl Default for Poke {
    /// Tool point 0, the default [`Press`] (1 s in all), 1 kHz.
    fn default() -> Self {
        Self {
            tool: 0,
            press: Press::default(),
            rate_hz: 1000.0,
        }
    }
}

impl Generator for Poke {
    fn keyframes(&self) -> Result<Vec<Keyframe>, GenerateError> {
        check_tool(self.tool, "poke.tool")?;
        let keys = PressHold {
            tool: self.tool,
            press: self.press,
            hold_s: 0.0,
            rate_hz: self.rate_hz,
        }
        .keyframes()?;
        Ok(keys.into_iter().filter(|k| k.label != "held").collect())
    }

    fn rate_hz(&self) -> f64 {
        self.rate_hz
    }
}

/// Press and hold: in to the depth, hold still for `hold_s`, back out.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PressHold {
    /// Tool point index, `< MAX_TOOL_POINTS`.
    pub tool: usize,
    /// Where and how.
    pub press: Press,
    /// Time at the deepest point, s, finite and ≥ 0.
    pub hold_s: f64,
    /// Sampling rate, Hz.
    pub rate_hz: f64,
}

impl Default for PressHold {
    /// Tool point 0, the default [`Press`], held 1 s (2 s in all), 1 kHz.
    fn default() -> Self {
        Self {
            tool: 0,
            press: Press::default(),
            hold_s: 1.0,
            rate_hz: 1000.0,
        }
    }
}

impl Generator for PressHold {
    fn keyframes(&self) -> Result<Vec<Keyframe>, GenerateError> {
        check_tool(self.tool, "press_hold.tool")?;
        check_finite_at_least(self.hold_s, 0.0, "press_hold.hold_s", "s")?;
        let (mut keys, p) = self.press.way_in(self.tool, [0.0; 3])?;
        let held_s = p.in_s + self.hold_s;
        keys.push(Keyframe::at(self.tool, held_s, p.deepest, "held"));
        keys.extend(self.press.way_out(self.tool, p.n, p.deepest, held_s));
        Ok(keys)
    }

    fn rate_hz(&self) -> f64 {
        self.rate_hz
    }
}

/// Slide along the surface: in to the depth, then `distance_m` along the surface (parallel to
/// the rest surface, at the depth) at `slide_speed_m_s`, then out.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slide {
    /// Tool point index, `< MAX_TOOL_POINTS`.
    pub tool: usize,
    /// Where the slide starts and how deep it goes.
    pub press: Press,
    /// Direction of the slide; its part along the normal is removed (it must not be along the
    /// normal).
    pub direction: [f64; 3],
    /// Length of the slide, m, finite and ≥ 0.
    pub distance_m: f64,
    /// Speed of the slide, m/s, finite and > 0.
    pub slide_speed_m_s: f64,
    /// Sampling rate, Hz.
    pub rate_hz: f64,
}

impl Default for Slide {
    /// Tool point 0, the default [`Press`], 3 cm along +x at 2 cm/s (1.5 s), 1 kHz.
    fn default() -> Self {
        Self {
            tool: 0,
            press: Press::default(),
            direction: [1.0, 0.0, 0.0],
            distance_m: 0.03,
            slide_speed_m_s: 0.02,
            rate_hz: 1000.0,
        }
    }
}

impl Generator for Slide {
    fn keyframes(&self) -> Result<Vec<Keyframe>, GenerateError> {
        check_tool(self.tool, "slide.tool")?;
        check_finite_at_least(self.distance_m, 0.0, "slide.distance_m", "m")?;
        check_positive(self.slide_speed_m_s, "slide.slide_speed_m_s", "m/s")?;
        let (mut keys, p) = self.press.way_in(self.tool, [0.0; 3])?;
        let t = tangent(self.direction, p.n, "slide.direction")?;
        let slid = along(p.deepest, t, self.distance_m);
        let slid_s = p.in_s + self.distance_m / self.slide_speed_m_s;
        keys.push(Keyframe::at(self.tool, slid_s, slid, "slid"));
        keys.extend(self.press.way_out(self.tool, p.n, slid, slid_s));
        Ok(keys)
    }

    fn rate_hz(&self) -> f64 {
        self.rate_hz
    }
}

/// A two-point pinch (tool points 0 and 1, a grasper's jaws): both start `start_gap_m` apart
/// along `axis`, centred on `press.surface_m` (tool point 0 on the −axis side), press in to the
/// depth together, close to `end_gap_m` while pressed (each moving toward the other at
/// `close_speed_m_s`, the gap shrinking at twice that), hold `hold_s`, and come out together.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pinch {
    /// The centre of the pinch and how deep both points press.
    pub press: Press,
    /// Direction joining the points; its part along the normal is removed.
    pub axis: [f64; 3],
    /// Distance between the points at the start, m, finite, `> end_gap_m`.
    pub start_gap_m: f64,
    /// Distance between the points when closed, m, finite and ≥ 0.
    pub end_gap_m: f64,
    /// Speed of each point toward the other, m/s, finite and > 0.
    pub close_speed_m_s: f64,
    /// Time closed before coming out, s, finite and ≥ 0.
    pub hold_s: f64,
    /// Sampling rate, Hz.
    pub rate_hz: f64,
}

impl Default for Pinch {
    /// The default [`Press`], jaws along x closing from 4 cm to 2 cm apart at 1 cm/s each
    /// (1 s), held 0.5 s, 1 kHz.
    fn default() -> Self {
        Self {
            press: Press::default(),
            axis: [1.0, 0.0, 0.0],
            start_gap_m: 0.04,
            end_gap_m: 0.02,
            close_speed_m_s: 0.01,
            hold_s: 0.5,
            rate_hz: 1000.0,
        }
    }
}

impl Generator for Pinch {
    fn keyframes(&self) -> Result<Vec<Keyframe>, GenerateError> {
        check_finite_at_least(self.end_gap_m, 0.0, "pinch.end_gap_m", "m")?;
        if !(self.start_gap_m.is_finite() && self.start_gap_m > self.end_gap_m) {
            return Err(err(
                "pinch.start_gap_m",
                format!(
                    "must be finite and > end_gap_m = {} m, got {}",
                    self.end_gap_m, self.start_gap_m
                ),
            ));
        }
        check_positive(self.close_speed_m_s, "pinch.close_speed_m_s", "m/s")?;
        check_finite_at_least(self.hold_s, 0.0, "pinch.hold_s", "s")?;
        let n = self.press.path()?.n;
        let a = tangent(self.axis, n, "pinch.axis")?;
        let close_m = (self.start_gap_m - self.end_gap_m) / 2.0;
        let mut keys = Vec::new();
        for (tool, side) in [(0, -1.0), (1, 1.0)] {
            let offset = a.map(|x| side * self.start_gap_m / 2.0 * x);
            let (way_in, p) = self.press.way_in(tool, offset)?;
            let deepest = along(p.deepest, offset, 1.0);
            let closed = along(deepest, a, -side * close_m);
            let closed_s = p.in_s + close_m / self.close_speed_m_s;
            let held_s = closed_s + self.hold_s;
            keys.extend(way_in);
            keys.push(Keyframe::at(tool, closed_s, closed, "closed"));
            keys.push(Keyframe::at(tool, held_s, closed, "held"));
            keys.extend(self.press.way_out(tool, n, closed, held_s));
        }
        Ok(keys)
    }

    fn rate_hz(&self) -> f64 {
        self.rate_hz
    }
}

/// A fast strike: the tool point hits the surface at `press.approach_speed_m_s` (fast) without
/// slowing down, stops at the depth, holds `hold_s`, and withdraws at
/// `press.withdraw_speed_m_s`. The path of [`PressHold`]; the separate type carries the defaults
/// of a strike (and the force jump the slew limit must absorb).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Strike {
    /// Tool point index, `< MAX_TOOL_POINTS`.
    pub tool: usize,
    /// Where and how: a high `approach_speed_m_s`.
    pub press: Press,
    /// Time at the deepest point, s, finite and ≥ 0.
    pub hold_s: f64,
    /// Sampling rate, Hz.
    pub rate_hz: f64,
}

impl Default for Strike {
    /// Tool point 0 from 1 cm above the default surface point to 5 mm deep at 0.5 m/s (30 ms:
    /// 0.5 mm per 1 kHz tick), held 0.2 s, out at 2 cm/s, 1 kHz.
    fn default() -> Self {
        Self {
            tool: 0,
            press: Press {
                standoff_m: 0.01,
                approach_speed_m_s: 0.5,
                ..Press::default()
            },
            hold_s: 0.2,
            rate_hz: 1000.0,
        }
    }
}

impl Generator for Strike {
    fn keyframes(&self) -> Result<Vec<Keyframe>, GenerateError> {
        check_tool(self.tool, "strike.tool")?;
        check_finite_at_least(self.hold_s, 0.0, "strike.hold_s", "s")?;
        PressHold {
            tool: self.tool,
            press: self.press,
            hold_s: self.hold_s,
            rate_hz: self.rate_hz,
        }
        .keyframes()
    }

    fn rate_hz(&self) -> f64 {
        self.rate_hz
    }
}

/// Grasp and pull with a grasper: tool point `tool` is the grasper's centre, and the scene puts
/// its two jaw spheres (radius `radius_m`) at the centre ± `jaw_m`/2 along its jaw axis. The
/// centre starts `standoff_m` above `surface_m` along the outward `normal` with the jaws open at
/// `open_m`, goes down at `approach_speed_m_s` until the jaw spheres are `depth_m` into the rest
/// surface (the centre `radius_m − depth_m` above it), closes the jaws to `closed_m` in
/// `close_s` (the grasper grips once the opening is at or below the scene's grip opening), holds
/// `hold_closed_s`, pulls `pull_m` outward at `pull_speed_m_s`, holds `hold_pulled_s`, opens the
/// jaws back to `open_m` in `open_s` (releasing the hold), and withdraws `withdraw_m` outward at
/// `withdraw_speed_m_s`.
///
/// Keyframes: `start`, `contact` (the jaw spheres touch the rest surface), `deepest`, `closed`,
/// `gripped` (end of the hold closed), `pulled`, `held` (end of the hold pulled), `opened`, `end`.
/// The trajectory has the tool columns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GraspPull {
    /// Tool point index, `< MAX_TOOL_POINTS`.
    pub tool: usize,
    /// The point of the rest surface under the grasper's centre, m.
    pub surface_m: [f64; 3],
    /// Outward surface normal at `surface_m`; any finite non-zero length (normalized).
    pub normal: [f64; 3],
    /// Radius of the jaw spheres (the scene's `[tool] radius_m`), m, finite and > 0.
    pub radius_m: f64,
    /// Start height of the centre above the surface along the normal, m, finite and
    /// `≥ radius_m` (the jaws start clear of the surface).
    pub standoff_m: f64,
    /// How far the jaw spheres go into the surface, m, finite and ≥ 0.
    pub depth_m: f64,
    /// Speed on the way down, m/s, finite and > 0.
    pub approach_speed_m_s: f64,
    /// Jaw opening at the start and after the release, m, finite and `> closed_m`.
    pub open_m: f64,
    /// Jaw opening when closed, m, finite and ≥ 0.
    pub closed_m: f64,
    /// Time to close the jaws, s, finite and ≥ 0.
    pub close_s: f64,
    /// Time closed before the pull, s, finite and ≥ 0.
    pub hold_closed_s: f64,
    /// Length of the pull along the normal, m, finite and ≥ 0.
    pub pull_m: f64,
    /// Speed of the pull, m/s, finite and > 0.
    pub pull_speed_m_s: f64,
    /// Time held after the pull, closed, s, finite and ≥ 0.
    pub hold_pulled_s: f64,
    /// Time to open the jaws, s, finite and ≥ 0.
    pub open_s: f64,
    /// Distance along the normal from the pulled position to the end, m, finite and ≥ 0.
    pub withdraw_m: f64,
    /// Speed on the way out, m/s, finite and > 0.
    pub withdraw_speed_m_s: f64,
    /// Sampling rate, Hz.
    pub rate_hz: f64,
}

impl Default for GraspPull {
    /// Tool point 0 over the top-face centre of the built-in block, `(0.06, 0.06, 0.06)` m,
    /// normal +z, jaw spheres of radius 2 mm (the built-in tool's): from 10 mm above with the
    /// jaws open at 12 mm (the spheres at x = 0.054 and 0.066 m), down at 20 mm/s until the
    /// spheres are 1 mm into the surface (0.45 s), closed to 4.5 mm in 0.3 s (below the default
    /// grip opening, 2.5 radii = 5 mm), held 0.2 s, pulled 8 mm up at 10 mm/s (0.8 s), held
    /// 0.5 s, opened to 12 mm in 0.2 s, out 10 mm at 20 mm/s (0.5 s): 2.95 s in all, 1 kHz.
    fn default() -> Self {
        Self {
            tool: 0,
            surface_m: [0.06, 0.06, 0.06],
            normal: [0.0, 0.0, 1.0],
            radius_m: 0.002,
            standoff_m: 0.01,
            depth_m: 0.001,
            approach_speed_m_s: 0.02,
            open_m: 0.012,
            closed_m: 0.0045,
            close_s: 0.3,
            hold_closed_s: 0.2,
            pull_m: 0.008,
            pull_speed_m_s: 0.01,
            hold_pulled_s: 0.5,
            open_s: 0.2,
            withdraw_m: 0.01,
            withdraw_speed_m_s: 0.02,
            rate_hz: 1000.0,
        }
    }
}

impl Generator for GraspPull {
    fn keyframes(&self) -> Result<Vec<Keyframe>, GenerateError> {
        check_tool(self.tool, "grasp_pull.tool")?;
        if !self.surface_m.iter().all(|x| x.is_finite()) {
            return Err(err(
                "grasp_pull.surface_m",
                format!("must be finite, got {:?}", self.surface_m),
            ));
        }
        let n = unit(self.normal, "grasp_pull.normal")?;
        check_positive(self.radius_m, "grasp_pull.radius_m", "m")?;
        check_finite_at_least(
            self.standoff_m,
            self.radius_m,
            "grasp_pull.standoff_m",
            "m (grasp_pull.radius_m)",
        )?;
        check_finite_at_least(self.depth_m, 0.0, "grasp_pull.depth_m", "m")?;
        check_positive(
            self.approach_speed_m_s,
            "grasp_pull.approach_speed_m_s",
            "m/s",
        )?;
        check_finite_at_least(self.closed_m, 0.0, "grasp_pull.closed_m", "m")?;
        if !(self.open_m.is_finite() && self.open_m > self.closed_m) {
            return Err(err(
                "grasp_pull.open_m",
                format!(
                    "must be finite and > closed_m = {} m, got {}",
                    self.closed_m, self.open_m
                ),
            ));
        }
        check_finite_at_least(self.close_s, 0.0, "grasp_pull.close_s", "s")?;
        check_finite_at_least(self.hold_closed_s, 0.0, "grasp_pull.hold_closed_s", "s")?;
        check_finite_at_least(self.pull_m, 0.0, "grasp_pull.pull_m", "m")?;
        check_positive(self.pull_speed_m_s, "grasp_pull.pull_speed_m_s", "m/s")?;
        check_finite_at_least(self.hold_pulled_s, 0.0, "grasp_pull.hold_pulled_s", "s")?;
        check_finite_at_least(self.open_s, 0.0, "grasp_pull.open_s", "s")?;
        check_finite_at_least(self.withdraw_m, 0.0, "grasp_pull.withdraw_m", "m")?;
        check_positive(
            self.withdraw_speed_m_s,
            "grasp_pull.withdraw_speed_m_s",
            "m/s",
        )?;

        let contact_s = (self.standoff_m - self.radius_m) / self.approach_speed_m_s;
        let deepest_s = contact_s + self.depth_m / self.approach_speed_m_s;
        let closed_s = deepest_s + self.close_s;
        let gripped_s = closed_s + self.hold_closed_s;
        let pulled_s = gripped_s + self.pull_m / self.pull_speed_m_s;
        let held_s = pulled_s + self.hold_pulled_s;
        let opened_s = held_s + self.open_s;
        let end_s = opened_s + self.withdraw_m / self.withdraw_speed_m_s;

        let start = along(self.surface_m, n, self.standoff_m);
        let contact = along(self.surface_m, n, self.radius_m);
        let deepest = along(self.surface_m, n, self.radius_m - self.depth_m);
        let pulled = along(deepest, n, self.pull_m);
        let key = |t_s, position_m, jaw_m, label| Keyframe {
            jaw_m,
            ..Keyframe::at(self.tool, t_s, position_m, label)
        };
        let (open, closed) = (self.open_m, self.closed_m);
        Ok(vec![
            key(0.0, start, open, "start"),
            key(contact_s, contact, open, "contact"),
            key(deepest_s, deepest, open, "deepest"),
            key(closed_s, deepest, closed, "closed"),
            key(gripped_s, deepest, closed, "gripped"),
            key(pulled_s, pulled, closed, "pulled"),
            key(held_s, pulled, closed, "held"),
            key(opened_s, pulled, open, "opened"),
            key(end_s, along(pulled, n, self.withdraw_m), open, "end"),
        ])
    }

    fn rate_hz(&self) -> f64 {
        self.rate_hz
    }

    fn tool_columns(&self) -> bool {
        true
    }
}

/// A cut along a line with a cutter: tool point `tool` is the blade's upper end, and the blade
/// runs from it to its tip at the tool point + `blade_m` (the scene's blade vector). The blade
/// tip follows `press`: from `press.standoff_m` above `press.surface_m`, down at
/// `press.approach_speed_m_s` to `press.depth_m` below the rest surface, the blade enabled
/// (`cut = 1`) from the moment the tip reaches the surface; then along the surface
/// (`direction`, its normal part removed) for `distance_m` at `cut_speed_m_s`, still enabled;
/// then disabled, and out `withdraw_m` along the normal at `press.withdraw_speed_m_s`.
///
/// Keyframes: `start` (blade off), `contact` (the tip at the rest surface, blade on),
/// `deepest`, `cut` (end of the line, blade off from there), `release` (the tip back at the rest
/// surface), `end`. The trajectory has the tool columns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CutLine {
    /// Tool point index, `< MAX_TOOL_POINTS`.
    pub tool: usize,
    /// Where and how the blade tip goes in (`press.standoff_m` and `press.depth_m` are the
    /// tip's); `press.withdraw_speed_m_s` is the speed on the way out.
    pub press: Press,
    /// From the tool point (the blade's upper end) to the blade tip, m, finite: the scene's blade
    /// vector.
    pub blade_m: [f64; 3],
    /// Direction of the cut; its part along the normal is removed (it must not be along the
    /// normal).
    pub direction: [f64; 3],
    /// Length of the cut, m, finite and ≥ 0.
    pub distance_m: f64,
    /// Speed of the cut, m/s, finite and > 0.
    pub cut_speed_m_s: f64,
    /// Distance along the normal from the end of the cut to the end, m, finite and
    /// `≥ press.depth_m` (the blade leaves the tissue).
    pub withdraw_m: f64,
    /// Sampling rate, Hz.
    pub rate_hz: f64,
}

impl Default for CutLine {
    /// Tool point 0, the default blade `[0, 0, −0.01]` m (straight down): the tip from 5 mm above
    /// the built-in block's top face at `(0.03, 0.06)` down at 20 mm/s to 4 mm below it (the
    /// blade enabled from the surface on, at 0.25 s; 0.45 s in all), along +x at 10 mm/s for
    /// 60 mm to x = 0.09 m (6 s), then disabled and out 15 mm up at 20 mm/s (0.75 s): 7.2 s in
    /// all, 1 kHz.
    fn default() -> Self {
        Self {
            tool: 0,
            press: Press {
                surface_m: [0.03, 0.06, 0.06],
                normal: [0.0, 0.0, 1.0],
                standoff_m: 0.005,
                depth_m: 0.004,
                approach_speed_m_s: 0.02,
                withdraw_speed_m_s: 0.02,
            },
            blade_m: [0.0, 0.0, -0.01],
            direction: [1.0, 0.0, 0.0],
            distance_m: 0.06,
            cut_speed_m_s: 0.01,
            withdraw_m: 0.015,
            rate_hz: 1000.0,
        }
    }
}

impl Generator for CutLine {
    fn keyframes(&self) -> Result<Vec<Keyframe>, GenerateError> {
        check_tool(self.tool, "cut_line.tool")?;
        if !self.blade_m.iter().all(|x| x.is_finite()) {
            return Err(err(
                "cut_line.blade_m",
                format!("must be finite, got {:?}", self.blade_m),
            ));
        }
        check_finite_at_least(self.distance_m, 0.0, "cut_line.distance_m", "m")?;
        check_positive(self.cut_speed_m_s, "cut_line.cut_speed_m_s", "m/s")?;
        // The tool point is the tip moved back along the blade.
        let upper = self.blade_m.map(|x| -x);
        let (mut keys, p) = self.press.way_in(self.tool, upper)?;
        check_finite_at_least(
            self.withdraw_m,
            self.press.depth_m,
            "cut_line.withdraw_m",
            "m (press.depth_m)",
        )?;
        let t = tangent(self.direction, p.n, "cut_line.direction")?;
        for k in &mut keys {
            k.cut = k.label != "start";
        }
        let cut = along(p.deepest, t, self.distance_m);
        let cut_s = p.in_s + self.distance_m / self.cut_speed_m_s;
        let speed = self.press.withdraw_speed_m_s;
        let key = |t_s, tip, label| Keyframe::at(self.tool, t_s, along(tip, upper, 1.0), label);
        keys.extend([
            key(cut_s, cut, "cut"),
            key(
                cut_s + self.press.depth_m / speed,
                along(cut, p.n, self.press.depth_m),
                "release",
            ),
            key(
                cut_s + self.withdraw_m / speed,
                along(cut, p.n, self.withdraw_m),
                "end",
            ),
        ]);
        Ok(keys)
    }

    fn rate_hz(&self) -> f64 {
        self.rate_hz
    }

    fn tool_columns(&self) -> bool {
        true
    }
}

/// The tools of `tool` at work on the built-in block's top, one generator
/// per trajectory tool point `i` by its kind, at `y = 0.03 + 0.025 i` m:
/// a grasper's [`GraspPull`], a cutter's [`CutLine`] (with the scene's
/// blade), a probe's [`PressHold`]; all sampled at 1 kHz with the tool
/// columns (`session generate surgery` writes it for `built-in-tools`).
pub fn surgery(tool: &super::spec::ToolSpec) -> Result<Trajectory, GenerateError> {
    use super::spec::ToolKind;
    let mut keyframes = Vec::new();
    for (i, kind) in tool.kinds.iter().enumerate() {
        let y = 0.03 + 0.025 * i as f64;
        keyframes.extend(match kind {
            ToolKind::Grasper => GraspPull {
                tool: i,
                surface_m: [0.06, y, 0.06],
                ..GraspPull::default()
            }
            .keyframes()?,
            ToolKind::Cutter => {
                let mut cut = CutLine {
                    tool: i,
                    blade_m: tool.blade_m,
                    ..CutLine::default()
                };
                cut.press.surface_m[1] = y;
                cut.keyframes()?
            }
            ToolKind::Probe => {
                let mut press = PressHold {
                    tool: i,
                    ..PressHold::default()
                };
                press.press.surface_m[1] = y;
                press.keyframes()?
            }
        });
    }
    sample_keyframes_with_tool_columns(&keyframes, 1000.0, true)
}

/// The built-in hybrid scene's tools at work on the organ
/// ([`super::spec::Scene::built_in_hybrid`], sites [`super::spec::HepatectomySites`]): the
/// grasper (tool 0) grasps the right lobe's terrace and pulls it up, the cutter (tool 1, the
/// scene's blade) cuts along the cut line at the same time; 1 kHz with the tool columns
/// (`session generate hepatectomy`).
pub fn hepatectomy(tool: &super::spec::ToolSpec) -> Result<Trajectory, GenerateError> {
    let sites = super::spec::HepatectomySites::on_the_organ();
    let mut keyframes = GraspPull {
        tool: 0,
        surface_m: sites.grasp_m,
        ..GraspPull::default()
    }
    .keyframes()?;
    let mut cut = CutLine {
        tool: 1,
        blade_m: tool.blade_m,
        distance_m: sites.cut_to_m[0] - sites.cut_from_m[0],
        ..CutLine::default()
    };
    cut.press.surface_m = sites.cut_from_m;
    keyframes.extend(cut.keyframes()?);
    sample_keyframes_with_tool_columns(&keyframes, 1000.0, true)
}
