//! The probes' presses: a [`Press`] (where and how a tool point presses) and the generators
//! built on it: [`Poke`], [`PressHold`], [`Slide`], [`Pinch`], [`Strike`].

use super::{
    GenerateError, Generator, Keyframe, along, check_finite_at_least, check_positive, check_tool,
    err, tangent, unit,
};

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
pub(super) struct PressPath {
    /// Unit outward normal.
    pub(super) n: [f64; 3],
    /// Start point (standoff above the surface).
    pub(super) start: [f64; 3],
    /// Deepest point.
    pub(super) deepest: [f64; 3],
    /// Time to cross the surface on the way in, s.
    pub(super) contact_s: f64,
    /// Time from start to the deepest point, s.
    pub(super) in_s: f64,
}

impl Press {
    pub(super) fn path(&self) -> Result<PressPath, GenerateError> {
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
    pub(super) fn way_in(
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
    pub(super) fn way_out(
        &self,
        tool: usize,
        n: [f64; 3],
        from: [f64; 3],
        t_s: f64,
    ) -> [Keyframe; 2] {
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
