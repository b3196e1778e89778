//! The scene's tool (`[tool]`): a few trajectory tool points, each a probe, a grasper or a
//! cutter ([`ToolKind`]), their radius and the grasper's and cutter's settings ([`ToolSpec`]),
//! with the ranges [`crate::scene::Scene::validate`] checks (`check_tool`).

use palpate_kernel::MAX_CONTACTS;

/// Largest number of tool points of a scene, both the trajectory's tool points (`[tool] points`)
/// and the kernel tool points their kinds need ([`ToolSpec::kernel_points`]: a grasper's two jaws
/// count two): the kernel's contact capacity ([`palpate_kernel::MAX_CONTACTS`]), one contact per
/// kernel tool point.
pub const MAX_TOOL_POINTS: usize = MAX_CONTACTS;

/// Default tool point count.
pub const DEFAULT_TOOL_POINTS: usize = 1;
/// Default tool point radius, m (a 4 mm probe tip).
pub const DEFAULT_TOOL_RADIUS_M: f64 = 0.002;
/// Default grasper jaw axis (from jaw 0 to jaw 1): +x.
pub const DEFAULT_JAW_AXIS: [f64; 3] = [1.0, 0.0, 0.0];
/// Default grasper grip opening, in tool radii: `grip_opening_m = 2.5 × radius_m`.
pub const DEFAULT_GRIP_OPENING_RADII: f64 = 2.5;
/// Largest tool radius, as a fraction of the mesh's largest bounding-box extent: 0.5, a tool
/// sphere as wide as the body. A larger one (`radius_m = 1.0` on a 12 cm block) covers the
/// whole body from any side: the contact search faulted every tick. Checked once the mesh is
/// loaded (`Scene::check_on_mesh`).
pub const MAX_TOOL_RADIUS_FRACTION: f64 = 0.5;

/// Default cutter blade, m: 1 cm straight down from the tool point.
pub const DEFAULT_BLADE_M: [f64; 3] = [0.0, 0.0, -0.01];
/// Longest cutter blade, m.
pub const MAX_BLADE_M: f64 = 0.1;

/// What a trajectory tool point is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ToolKind {
    /// A probe tip: one sphere that pushes (one kernel tool point).
    Probe,
    /// A grasper: two jaws along [`ToolSpec::jaw_axis`] (two kernel tool points) that hold what
    /// they touch once closed to [`ToolSpec::grip_opening_m`].
    Grasper,
    /// A cutter: a blade [`ToolSpec::blade_m`] from the tool point that removes the tets it
    /// touches (one kernel tool point).
    Cutter,
}

impl ToolKind {
    /// Every kind, in documentation order.
    pub const ALL: [ToolKind; 3] = [ToolKind::Probe, ToolKind::Grasper, ToolKind::Cutter];

    /// The scene file's name: `probe`, `grasper` or `cutter`.
    pub fn name(self) -> &'static str {
        match self {
            ToolKind::Probe => "probe",
            ToolKind::Grasper => "grasper",
            ToolKind::Cutter => "cutter",
        }
    }

    /// Kernel tool points (contact spheres) of one such trajectory tool point: a grasper's two
    /// jaws, one otherwise.
    pub fn kernel_points(self) -> usize {
        match self {
            ToolKind::Grasper => 2,
            ToolKind::Probe | ToolKind::Cutter => 1,
        }
    }

    /// The kind a scene file names, if any.
    pub(crate) fn from_name(name: &str) -> Option<ToolKind> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }
}

/// The tool: a few trajectory tool points, each of a [`ToolKind`], with a radius.
#[derive(Clone, Debug, PartialEq)]
pub struct ToolSpec {
    /// Number of trajectory tool points (the trajectory's tool columns), in
    /// `1..=MAX_TOOL_POINTS`.
    pub points: usize,
    /// Radius of every kernel tool point (probe tip, jaw, blade), m, finite and > 0.
    pub radius_m: f64,
    /// The kind of each trajectory tool point: `points` of them, needing at most
    /// [`MAX_TOOL_POINTS`] kernel tool points in all ([`Self::kernel_points`]).
    pub kinds: Vec<ToolKind>,
    /// Grasper: unit direction from jaw 0 to jaw 1 (finite; the file's value is normalized).
    pub jaw_axis: [f64; 3],
    /// Grasper: jaw opening, m, at or below which the jaws hold what they touch; finite and > 0.
    pub grip_opening_m: f64,
    /// Cutter: the blade, m, from the tool point (its upper end) to its tip; finite, length in
    /// `(0, MAX_BLADE_M]`.
    pub blade_m: [f64; 3],
}

impl ToolSpec {
    /// `points` probes of radius `radius_m`, the grasper and cutter settings at their defaults
    /// ([`DEFAULT_JAW_AXIS`], [`DEFAULT_GRIP_OPENING_RADII`] × `radius_m`, [`DEFAULT_BLADE_M`]).
    pub fn probes(points: usize, radius_m: f64) -> ToolSpec {
        ToolSpec {
            points,
            radius_m,
            kinds: vec![ToolKind::Probe; points.min(MAX_TOOL_POINTS)],
            jaw_axis: DEFAULT_JAW_AXIS,
            grip_opening_m: DEFAULT_GRIP_OPENING_RADII * radius_m,
            blade_m: DEFAULT_BLADE_M,
        }
    }

    /// Kernel tool points the kinds need: the sum of [`ToolKind::kernel_points`] (a grasper is
    /// two jaws).
    pub fn kernel_points(&self) -> usize {
        self.kinds.iter().map(|k| k.kernel_points()).sum()
    }
}

/// `a / |a|` computed without overflow or underflow (scaled by the largest component first), to
/// within a few ulps of unit length; `a` itself if it is not finite or is zero.
pub(crate) fn normalized(a: [f64; 3]) -> [f64; 3] {
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if !(a.iter().all(|x| x.is_finite()) && scale > 0.0) {
        return a;
    }
    let b = a.map(|x| x / scale);
    let length = b.iter().map(|x| x * x).sum::<f64>().sqrt();
    b.map(|x| x / length)
}

/// Euclidean length of `a` (overflows to infinity only past `f64::MAX`; NaN if a component is).
pub(crate) fn length(a: [f64; 3]) -> f64 {
    if a.iter().any(|x| x.is_nan()) {
        return f64::NAN;
    }
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if !(scale.is_finite() && scale > 0.0) {
        return scale;
    }
    scale
        * a.map(|x| x / scale)
            .iter()
            .map(|x| x * x)
            .sum::<f64>()
            .sqrt()
}

/// The ranges of a [`ToolSpec`] (after `points` and `radius_m`); errors are `(key, message)`.
pub(crate) fn check_tool(tool: &ToolSpec) -> Result<(), (String, String)> {
    let names = || {
        let names: Vec<&str> = tool.kinds.iter().map(|k| k.name()).collect();
        format!("[tool] kind = {names:?}")
    };
    if tool.kinds.len() != tool.points {
        return Err((
            names(),
            format!(
                "{} given for points = {}: give one kind per trajectory tool point, or a single kind for all",
                tool.kinds.len(),
                tool.points
            ),
        ));
    }
    let needed = tool.kernel_points();
    if needed > MAX_TOOL_POINTS {
        return Err((
            names(),
            format!(
                "needs {needed} kernel tool points (a grasper is 2 jaws, a probe or cutter 1): at most {MAX_TOOL_POINTS} (MAX_TOOL_POINTS, the kernel's contact capacity)"
            ),
        ));
    }
    let axis = tool.jaw_axis;
    if !axis.iter().all(|x| x.is_finite()) || axis.iter().all(|&x| x == 0.0) {
        return Err((
            format!("[tool] jaw_axis = {axis:?}"),
            "must be finite and non-zero (the direction from jaw 0 to jaw 1)".into(),
        ));
    }
    if (length(axis) - 1.0).abs() > 1e-12 {
        return Err((
            format!("[tool] jaw_axis = {axis:?}"),
            "must have unit length (a scene file's jaw_axis is normalized when read)".into(),
        ));
    }
    let grip = tool.grip_opening_m;
    if !(grip.is_finite() && grip > 0.0) {
        return Err((
            format!("[tool] grip_opening_m = {grip}"),
            "must be finite and > 0 m".into(),
        ));
    }
    let blade = tool.blade_m;
    let blade_length = length(blade);
    if !(blade.iter().all(|x| x.is_finite()) && blade_length > 0.0 && blade_length <= MAX_BLADE_M) {
        return Err((
            format!("[tool] blade_m = {blade:?}"),
            format!(
                "must be finite, with a length > 0 and at most {MAX_BLADE_M} m (MAX_BLADE_M), from the tool point to the blade's tip"
            ),
        ));
    }
    Ok(())
}
