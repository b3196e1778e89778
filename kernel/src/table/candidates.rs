//! The candidate lists' filing rule (MODELS.md §6): which cells of the
//! lists' grid file each surface triangle for a tool of a given radius
//! ([`candidate_cells`]), how wide the lists reach, and the radius and
//! subdivision a builder chooses. The one rule of the lists' builder
//! (`contact::grid::cell_triangles`) and of the loader's check
//! ([`super::SurfaceIndex`]).

use nalgebra::Vector3;

use super::format::MAX_LIST_SUBDIVISION;
use super::grid::{CellBox, Grid};
use crate::Real;

/// The corners (m) of triangle `tri` over `positions`, `None` for a corner
/// beyond them.
pub(crate) fn corners_of<T: Real>(positions: &[[T; 3]], tri: &[u32; 3]) -> Option<[Vector3<T>; 3]> {
    let at = |v: u32| {
        positions
            .get(v as usize)
            .map(|p| Vector3::new(p[0], p[1], p[2]))
    };
    let [a, b, c] = tri.map(at);
    Some([a?, b?, c?])
}

/// How far from a triangle's plane, on either side, in tool radii, the
/// per-cell candidate lists reach ([`candidate_cells`]): the contact test's
/// depth (`contact::PENETRATION_DEPTH_RADII`, 2: the penetration test takes
/// a plane up to that far behind the centre, the check of the planes it
/// does not reach up to that far in front, each with the centre over its
/// triangle; the contact layer asserts it fits) plus a quarter radius of
/// slack; the sweep's hit lies one radius in front.
pub const CANDIDATE_MARGIN_RADII: f64 = 2.25;

/// The part of a list cell's edge the candidate lists add on every axis
/// ([`candidate_cells`]): the weight tolerance's reach past a triangle's
/// edges (`WEIGHT_TOLERANCE` of an edge, a grid cell at most, on both
/// weights of an edge: 2e-5 of a grid cell in f32), the loader's tolerance
/// on a stored frame (1e-4 in units of the weights: 1e-4 of a grid cell)
/// and the normal's rounding, with a margin: at least 2.5e-4 of a grid
/// cell, whose list cells are at most
/// [`MAX_LIST_SUBDIVISION`] times finer.
pub const CANDIDATE_MARGIN_CELLS: f64 = 1e-3;

/// The widest margin (m) by which candidate lists over `grid` (or a finer
/// lists' grid of its box) widen a triangle's bounding box on an axis, for
/// a tool of radius up to `radius_m`: [`CANDIDATE_MARGIN_RADII`] radii (on
/// an axis along the triangle's normal) and [`CANDIDATE_MARGIN_CELLS`] of a
/// cell of `grid`.
pub fn candidate_margin_m<T: Real>(grid: &Grid<T>, radius_m: T) -> T {
    radius_m * T::of_f64(CANDIDATE_MARGIN_RADII) + grid.cell_m * T::of_f64(CANDIDATE_MARGIN_CELLS)
}

/// The tool radius (m) a table's candidate lists serve when asked for
/// `tool_radius_m`: at most the cell edge over [`CANDIDATE_MARGIN_RADII`],
/// so that a triangle's widened box spans at most `k + 3` cells of the
/// lists' grid per axis (its box is at most an edge, at most a grid cell,
/// wide; [`candidate_margin_m`] at most a grid cell): at most `(k + 3)³`
/// lists per triangle. Negative or non-finite asks give 0.
pub fn candidate_radius_m<T: Real>(grid: &Grid<T>, tool_radius_m: T) -> T {
    let most = grid.cell_m * T::of_f64((1.0 - CANDIDATE_MARGIN_CELLS) / CANDIDATE_MARGIN_RADII);
    if tool_radius_m > T::zero() {
        if tool_radius_m < most {
            tool_radius_m
        } else {
            most
        }
    } else {
        T::zero()
    }
}

/// The subdivision `k` of the candidate lists' grid a builder chooses for
/// `grid` and tools of radius up to `radius_m` (m): list cells no finer than
/// the lists' depth, [`CANDIDATE_MARGIN_RADII`] radii (a face's prism spans
/// at most three of them across), in `1..=`[`MAX_LIST_SUBDIVISION`]. Finer
/// cells hold fewer triangles each, in more lists.
pub fn list_subdivision<T: Real>(grid: &Grid<T>, radius_m: T) -> u32 {
    let depth_m = radius_m * T::of_f64(CANDIDATE_MARGIN_RADII);
    (1..MAX_LIST_SUBDIVISION)
        .rev()
        .map(|k| k + 1)
        .find(|&k| T::of_u32(k) * depth_m <= grid.cell_m)
        .unwrap_or(1)
}

/// The cells (lowest and highest, per axis, clamped to the grid as a query
/// point is) whose candidate lists hold the triangle of `corners_m` (m)
/// for a tool of radius up to `radius_m` (m): the one rule of the lists'
/// builder (`contact::grid::cell_triangles`) and of the loader's check.
///
/// The contact tests accept a triangle only from a sphere centre whose
/// projection on its plane falls in it (within the weight tolerance) and
/// that lies at most [`CANDIDATE_MARGIN_RADII`] radii from the plane (the
/// sweep's hit, one radius in front; the penetration test, two behind; the
/// check of the planes it does not reach, two in front): the triangle's
/// prism along its unit normal `n`, on both sides. Its box is the
/// triangle's, widened on axis `i` by `2.25 r |n_i|`, and by
/// [`CANDIDATE_MARGIN_CELLS`] of a cell of `grid` (the lists' grid) on
/// every axis. A face along the
/// grid's axes is widened in its plane by that slack alone, so a cell's
/// list holds the triangles over or under the cell, not all within reach
/// around it. A collapsed triangle (no normal), which no test accepts, is
/// widened by the whole margin on every axis. Clamping is monotone, so
/// the cell of any centre in the prism is in the range.
pub fn candidate_cells<T: Real>(
    grid: &Grid<T>,
    corners_m: &[Vector3<T>; 3],
    radius_m: T,
) -> CellBox {
    let [a, b, c] = corners_m;
    let normal = (b - a).cross(&(c - a));
    let length = normal.norm();
    let depth_m = radius_m * T::of_f64(CANDIDATE_MARGIN_RADII);
    let slack_m = grid.cell_m * T::of_f64(CANDIDATE_MARGIN_CELLS);
    let reach = normal.map(|x| {
        let along = if length > T::zero() {
            (x / length).abs()
        } else {
            T::one()
        };
        along * depth_m + slack_m
    });
    let lo = a.inf(b).inf(c) - reach;
    let hi = a.sup(b).sup(c) + reach;
    grid.cells_of_box(&lo, &hi)
}

/// `f(cell, t)` for every cell of every triangle `t`'s
/// [`candidate_cells`], triangles in order, cells `x` fastest (a triangle
/// with a corner beyond `positions_m`, a dead slot, is not filed).
pub(crate) fn for_each_candidate_filing<T: Real>(
    grid: &Grid<T>,
    positions_m: &[[T; 3]],
    triangles: &[[u32; 3]],
    radius_m: T,
    mut f: impl FnMut(usize, u32),
) {
    for (t, tri) in triangles.iter().enumerate() {
        let Some(corners) = corners_of(positions_m, tri) else {
            continue;
        };
        candidate_cells(grid, &corners, radius_m).for_each(|c| f(grid.linear(c), t as u32));
    }
}
