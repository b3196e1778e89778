//! A scene's tool-point count, known at run time, as the const generic `P`
//! of the kernel's haptic loop (its tool points and contact capacity): the
//! one place that turns the one into the other.

use crate::scene::MAX_TOOL_POINTS;

/// Work generic over the tool-point count, run by [`with_tool_points`]
/// with the count of a scene.
pub trait ForToolPoints {
    /// What the work returns.
    type Output;

    /// Runs the work with `P` tool points.
    fn call<const P: usize>(self) -> Self::Output;
}

// The arms of `with_tool_points` cover every count a scene admits.
const _: () = assert!(MAX_TOOL_POINTS == 4);

/// Runs `work` with `P = points`, for `points` in `1..=MAX_TOOL_POINTS` (a
/// validated scene's range); any other count runs with `MAX_TOOL_POINTS`.
pub fn with_tool_points<W: ForToolPoints>(points: usize, work: W) -> W::Output {
    match points {
        1 => work.call::<1>(),
        2 => work.call::<2>(),
        3 => work.call::<3>(),
        _ => work.call::<MAX_TOOL_POINTS>(),
    }
}
