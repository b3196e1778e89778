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

use crate::scene::trajectory::ToolState;
use crate::scene::{ToolKind, ToolSpec};

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
