//! The built-in scenes' tools at work: [`surgery`] (`built-in-tools`) and [`hepatectomy`]
//! (`built-in-hybrid`).

use super::press::PressHold;
use super::tools::{CutLine, GraspPull};
use super::{GenerateError, Generator, sample_keyframes_with_tool_columns};
use crate::scene::Trajectory;
use crate::scene::built_in::HepatectomySites;
use crate::scene::tool::{ToolKind, ToolSpec};

/// The tools of `tool` at work on the built-in block's top, one generator
/// per trajectory tool point `i` by its kind, at `y = 0.03 + 0.025 i` m:
/// a grasper's [`GraspPull`], a cutter's [`CutLine`] (with the scene's
/// blade), a probe's [`PressHold`]; all sampled at 1 kHz with the tool
/// columns (`session generate surgery` writes it for `built-in-tools`).
pub fn surgery(tool: &ToolSpec) -> Result<Trajectory, GenerateError> {
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
/// ([`crate::scene::Scene::built_in_hybrid`], sites [`HepatectomySites`]): the
/// grasper (tool 0) grasps the right lobe's dome and pulls it up ([`GraspPull`]'s defaults);
/// at the same time the cutter (tool 1, the scene's blade) goes in at the cut line's start,
/// its tip `HEPATECTOMY_CUT_DEPTH_M` below the lobe's top (the blade's upper end 2 mm above
/// it), cuts along the line at 20 mm/s (through the lobe, whose tip comes off), and comes out
/// 25 mm ([`CutLine`]'s other defaults); 1 kHz with the tool columns (`session generate
/// hepatectomy`).
pub fn hepatectomy(tool: &ToolSpec) -> Result<Trajectory, GenerateError> {
    let sites = HepatectomySites::on_the_organ();
    let mut keyframes = GraspPull {
        tool: 0,
        surface_m: sites.grasp_m,
        ..GraspPull::default()
    }
    .keyframes()?;
    let (a, b) = (sites.cut_from_m, sites.cut_to_m);
    let mut cut = CutLine {
        tool: 1,
        blade_m: tool.blade_m,
        direction: [b[0] - a[0], b[1] - a[1], 0.0],
        distance_m: (b[0] - a[0]).hypot(b[1] - a[1]),
        cut_speed_m_s: 0.02,
        withdraw_m: 0.025,
        ..CutLine::default()
    };
    cut.press.surface_m = a;
    cut.press.depth_m = HEPATECTOMY_CUT_DEPTH_M;
    keyframes.extend(cut.keyframes()?);
    sample_keyframes_with_tool_columns(&keyframes, 1000.0, true)
}

/// How deep the hepatectomy's blade tip goes below the lobe's top, m: 18 mm, through the
/// 1.3 cm thick left lobe with the scene's 2 cm blade.
const HEPATECTOMY_CUT_DEPTH_M: f64 = 0.018;
