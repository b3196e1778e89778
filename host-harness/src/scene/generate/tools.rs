//! The generators of the tools that need the trajectory's tool columns: a grasper's
//! [`GraspPull`] and a cutter's [`CutLine`].

use super::press::Press;
use super::{
    GenerateError, Generator, Keyframe, along, check_finite_at_least, check_positive, check_tool,
    err, tangent, unit,
};

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
