//! A scene's tools at one tick as the kernel's tool points
//! ([`palpate_kernel::haptic::ToolInput`]): the one place that expands a
//! trajectory tool point of each [`ToolKind`] into contact spheres and
//! actions.
//!
//! - `probe`: one sphere at the tool point, [`ToolAction::Touch`].
//! - `grasper`: two jaws at `position ∓ jaw_m/2 · jaw_axis` (jaw 0 first),
//!   each [`ToolAction::Grip`] while `jaw_m ≤ grip_opening_m` (the jaws
//!   hold what they touch when they close to it) and `Touch` otherwise.
//! - `cutter`: one sphere at the blade's tip `position + blade_m`, with
//!   [`ToolAction::Cut`] along the blade back to the tool point while the
//!   trajectory's `cut` is 1, `Touch` otherwise (the sphere is what the
//!   hand feels: the tissue ahead of the blade).
//!
//! Kernel tool points are numbered in trajectory order, a grasper taking
//! two.

use nalgebra::Vector3;
use palpate_kernel::haptic::{ToolAction, ToolInput};

use super::scene::{ToolKind, ToolSpec};
use super::trajectory::ToolState;

/// The `P` kernel tool points of `spec`'s tools in `states` (one per
/// trajectory tool point), f32 as the loop runs; a point with no state (a
/// trajectory with fewer tool points) is NaN, which the loop faults on.
pub fn kernel_tools<const P: usize>(spec: &ToolSpec, states: &[ToolState]) -> [ToolInput<f32>; P] {
    let nan = ToolInput::touch(Vector3::repeat(f32::NAN));
    let mut out = [nan; P];
    let mut slots = out.iter_mut();
    let f32_of = |v: [f64; 3]| Vector3::new(v[0] as f32, v[1] as f32, v[2] as f32);
    for (kind, state) in spec.kinds.iter().zip(states) {
        let at = Vector3::from(state.position_m);
        match kind {
            ToolKind::Probe => {
                if let Some(slot) = slots.next() {
                    *slot = ToolInput::touch(f32_of(state.position_m));
                }
            }
            ToolKind::Grasper => {
                let half = Vector3::from(spec.jaw_axis) * (0.5 * state.jaw_m);
                let action = if state.jaw_m <= spec.grip_opening_m {
                    ToolAction::Grip
                } else {
                    ToolAction::Touch
                };
                for jaw in [at - half, at + half] {
                    if let Some(slot) = slots.next() {
                        *slot = ToolInput {
                            position_m: f32_of(jaw.into()),
                            action,
                        };
                    }
                }
            }
            ToolKind::Cutter => {
                let blade = Vector3::from(spec.blade_m);
                if let Some(slot) = slots.next() {
                    *slot = ToolInput {
                        position_m: f32_of((at + blade).into()),
                        action: if state.cut {
                            ToolAction::Cut {
                                blade_m: f32_of((-blade).into()),
                            }
                        } else {
                            ToolAction::Touch
                        },
                    };
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state(position_m: [f64; 3], jaw_m: f64, cut: bool) -> ToolState {
        ToolState {
            position_m,
            jaw_m,
            cut,
        }
    }

    /// A grasper then a cutter: the jaws either side along the axis,
    /// gripping at and below the opening; the cutter's sphere at the blade
    /// tip, its blade back up to the tool point, cutting only when enabled.
    #[test]
    fn grasper_and_cutter_expand_in_trajectory_order() {
        let mut spec = ToolSpec::probes(2, 0.002);
        spec.kinds = vec![ToolKind::Grasper, ToolKind::Cutter];
        spec.grip_opening_m = 0.005;
        let tools: [ToolInput<f32>; 3] = kernel_tools(
            &spec,
            &[
                state([0.1, 0.2, 0.3], 0.005, false),
                state([0.0, 0.0, 0.05], 0.0, true),
            ],
        );
        assert_eq!(tools[0].position_m, Vector3::new(0.0975, 0.2, 0.3));
        assert_eq!(tools[1].position_m, Vector3::new(0.1025, 0.2, 0.3));
        assert_eq!([tools[0].action, tools[1].action], [ToolAction::Grip; 2]);
        assert_eq!(tools[2].position_m, Vector3::new(0.0, 0.0, 0.04));
        assert_eq!(
            tools[2].action,
            ToolAction::Cut {
                blade_m: Vector3::new(0.0, 0.0, 0.01)
            }
        );
        let open: [ToolInput<f32>; 3] = kernel_tools(
            &spec,
            &[
                state([0.1, 0.2, 0.3], 0.0051, false),
                state([0.0; 3], 0.0, false),
            ],
        );
        assert_eq!([open[0].action, open[2].action], [ToolAction::Touch; 2]);
        // A missing trajectory tool point: NaN, which the loop faults on.
        let short: [ToolInput<f32>; 3] = kernel_tools(&spec, &[state([0.0; 3], 0.01, false)]);
        assert!(short[2].position_m.x.is_nan());
    }
}
