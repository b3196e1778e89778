//! Where the budget's probes press, on the scene's own surface, and the
//! generated trajectories it runs there ([`trajectories`]).
//!
//! Site rule: tool point `k` presses straight down (normal +z) at the
//! anchor moved along y by [`PROBE_SITE_SPACING_M`] times `[0, 1, −1, 2][k]`,
//! onto the top of the rest surface there. The anchor is
//! - on a generated box, its top-face centre (the built-in block's
//!   `(0.06, 0.06, 0.06)` m, the sites y = 6, 8, 4 and 10 cm: the recorded
//!   ticks of `tools/cycles-check.sh` and their figures depend on them);
//! - on any other mesh (a file, the built-in organ), the centre of its
//!   boundary surface's bounding box in x and y, each site at the height of
//!   the highest surface triangle over it (`crate::mesh::top_height`): a
//!   site over no triangle is an error naming it.
//!
//! The slide and the pinch run from the anchor.

use anyhow::anyhow;

use crate::mesh::{boundary_surface, top_height};
use crate::scene::generate::{
    GenerateError, Generator, Keyframe, Pinch, Poke, Press, PressHold, Slide, Strike, hepatectomy,
    sample_keyframes, surgery,
};
use crate::scene::{DEFAULT_HAPTIC_HZ, MAX_TOOL_POINTS, MeshSource, Scene, ToolKind, Trajectory};

/// Spacing of the probe sites of a scene with several probes, m (see the
/// module docs: every site 2 cm or more from the others, and on the
/// built-in block from its edges).
pub const PROBE_SITE_SPACING_M: f64 = 0.02;

/// Site steps along y of tool points 0..4, in [`PROBE_SITE_SPACING_M`].
const STEPS: [f64; MAX_TOOL_POINTS] = [0.0, 1.0, -1.0, 2.0];

/// The budget's probe sites of a scene: the anchor's press and each tool
/// point's (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeSites {
    /// The press at the anchor (the slide's and the pinch's).
    pub anchor: Press,
    /// Tool point `k`'s press.
    pub points: [Press; MAX_TOOL_POINTS],
}

impl ProbeSites {
    /// The sites on `scene`'s mesh (a mesh other than a generated box is
    /// loaded for it).
    pub fn of(scene: &Scene) -> anyhow::Result<Self> {
        let step = |k: usize| STEPS[k] * PROBE_SITE_SPACING_M;
        if let MeshSource::GeneratedBox { size_m, .. } = scene.mesh {
            let anchor = Press {
                surface_m: [size_m[0] / 2.0, size_m[1] / 2.0, size_m[2]],
                ..Press::default()
            };
            let points = core::array::from_fn(|k| {
                let mut surface_m = anchor.surface_m;
                surface_m[1] += step(k);
                Press {
                    surface_m,
                    ..anchor
                }
            });
            return Ok(Self { anchor, points });
        }
        let (mesh, _) = scene.load_mesh()?;
        let surface = boundary_surface(&mesh);
        let (mut low, mut high) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for v in surface.triangles.iter().flatten() {
            let p = mesh.positions[*v as usize];
            for i in 0..2 {
                low[i] = low[i].min(p[i]);
                high[i] = high[i].max(p[i]);
            }
        }
        let centre = [(low[0] + high[0]) / 2.0, (low[1] + high[1]) / 2.0];
        let press_at = |x: f64, y: f64| -> anyhow::Result<Press> {
            let z = top_height(&mesh.positions, &surface.triangles, x, y).ok_or_else(|| {
                anyhow!(
                    "{}: the budget's probe site ({x:.4}, {y:.4}) m is over no surface \
                     triangle of the mesh",
                    scene.source
                )
            })?;
            Ok(Press {
                surface_m: [x, y, z],
                ..Press::default()
            })
        };
        let anchor = press_at(centre[0], centre[1])?;
        let mut points = [anchor; MAX_TOOL_POINTS];
        for (k, point) in points.iter_mut().enumerate() {
            *point = press_at(centre[0], centre[1] + step(k))?;
        }
        Ok(Self { anchor, points })
    }
}

/// The generated trajectories a budget runs for `scene`'s tool: for probes
/// the poke, press-hold, slide and strike, each tool point on its own site
/// ([`ProbeSites`]) moving together, so that `P` probes make up to `P`
/// simultaneous contacts, and with two or more points the pinch (tool
/// points 0 and 1 at the anchor; the others press and hold on their
/// sites); for a scene with a grasper or a cutter, [`surgery`] (on the
/// built-in block's top), or [`hepatectomy`] on the built-in organ.
pub fn trajectories(scene: &Scene) -> anyhow::Result<Vec<(&'static str, Trajectory)>> {
    let err = |e: GenerateError| anyhow!("{e}");
    let tool = &scene.tool;
    if tool.kinds.iter().any(|k| *k != ToolKind::Probe) {
        return Ok(match scene.mesh {
            MeshSource::BuiltInOrgan => {
                vec![("hepatectomy", hepatectomy(tool).map_err(err)?)]
            }
            _ => vec![("surgery", surgery(tool).map_err(err)?)],
        });
    }
    let sites = ProbeSites::of(scene)?;
    let points = tool.points.clamp(1, MAX_TOOL_POINTS);
    // Every tool point's keyframes of one generator, sampled together.
    let every_point = |keys: &dyn Fn(usize) -> Result<Vec<Keyframe>, GenerateError>| {
        let mut all = Vec::new();
        for k in 0..points {
            all.extend(keys(k)?);
        }
        sample_keyframes(&all, DEFAULT_HAPTIC_HZ).map_err(err)
    };
    // Tool point `k`'s site, with the standoff and speeds of `press`.
    let site = |k: usize, press: Press| Press {
        surface_m: sites.points[k].surface_m,
        ..press
    };
    let poke = |k| {
        Poke {
            tool: k,
            press: site(k, Poke::default().press),
            ..Poke::default()
        }
        .keyframes()
    };
    let press_hold = |k| {
        PressHold {
            tool: k,
            press: site(k, PressHold::default().press),
            ..PressHold::default()
        }
        .keyframes()
    };
    let slide = |k| {
        Slide {
            tool: k,
            press: site(k, Slide::default().press),
            ..Slide::default()
        }
        .keyframes()
    };
    let strike = |k| {
        Strike {
            tool: k,
            press: site(k, Strike::default().press),
            ..Strike::default()
        }
        .keyframes()
    };
    let mut out = vec![
        ("poke", every_point(&poke)?),
        ("press-hold", every_point(&press_hold)?),
        ("slide", every_point(&slide)?),
        ("strike", every_point(&strike)?),
    ];
    if points >= 2 {
        let pinch = |k| match k {
            0 => Pinch {
                press: Press {
                    surface_m: sites.anchor.surface_m,
                    ..Pinch::default().press
                },
                ..Pinch::default()
            }
            .keyframes(),
            1 => Ok(Vec::new()),
            _ => press_hold(k),
        };
        out.push(("pinch", every_point(&pinch)?));
    }
    Ok(out)
}
