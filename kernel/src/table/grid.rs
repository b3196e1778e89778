//! The regular grid of the collision index (Cotin 1999 §4, collision
//! buckets; MODELS.md §6): its geometry, in the one place the view
//! ([`super::SurfaceIndex`], validated at load or assembled) and the
//! builder (`contact::grid`, at table build and per physics update) both
//! read it from. A grid is a box of cubic cells (origin, cell edge, cells
//! per axis); a point has a cell (clamped to the grid), a cell a linear
//! index and a centre, and the cells a query, a sweep or a filing visits
//! are a [`CellBox`].

use nalgebra::Vector3;

use super::format::MAX_LIST_SUBDIVISION;
use crate::Real;

/// A regular grid over a box: origin (its lowest corner), cell edge and
/// cells per axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid<T> {
    /// The lowest corner, m.
    pub origin_m: Vector3<T>,
    /// The cell edge, m.
    pub cell_m: T,
    /// Cells per axis.
    pub dims: [u32; 3],
}

/// A box of grid cells: the lowest and the highest cell on each axis, both
/// included (cell coordinates `[i, j, k]`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CellBox {
    /// The lowest cell on each axis.
    pub lo: [u32; 3],
    /// The highest cell on each axis.
    pub hi: [u32; 3],
}

/// `true` if `p` lies in the box `[lo, hi]` (a non-finite coordinate does
/// not).
pub fn within<T: Real>(p: &Vector3<T>, [lo, hi]: &[Vector3<T>; 2]) -> bool {
    p.iter()
        .zip(lo.iter().zip(hi.iter()))
        .all(|(&x, (&l, &h))| x >= l && x <= h)
}

/// The box of `points` (m): its lowest and highest corners; for no point,
/// the empty box (lowest `+MAX`, highest `−MAX`), which [`within`] holds
/// nothing of. The surface's box ([`super::SurfaceIndex::surface_box`]) is
/// this over its triangles' corners: the body lies in it.
pub fn box_of<T: Real>(points: impl IntoIterator<Item = Vector3<T>>) -> [Vector3<T>; 2] {
    let max = Vector3::repeat(T::of_f64(f64::MAX));
    points
        .into_iter()
        .fold([max, -max], |[lo, hi], p| [lo.inf(&p), hi.sup(&p)])
}

/// `true` if cells `a` and `b` are at most one apart on every axis (the
/// same cell, or one of its 26 neighbours).
#[inline]
pub fn neighbours(a: [u32; 3], b: [u32; 3]) -> bool {
    a.iter().zip(b).all(|(&x, y)| x.abs_diff(y) <= 1)
}

/// Cell coordinates or counts per axis, widened for indexing.
#[inline(always)]
fn widen(c: [u32; 3]) -> [usize; 3] {
    c.map(|x| x as usize)
}

impl<T> Grid<T> {
    /// Cells of the grid (`nx · ny · nz`), `None` if that overflows.
    pub(crate) fn cell_count(&self) -> Option<usize> {
        widen(self.dims)
            .iter()
            .try_fold(1usize, |n, &d| n.checked_mul(d))
    }

    /// The linear index `i + nx (j + ny k)` of cell `c = [i, j, k]`.
    #[inline(always)]
    pub(crate) fn linear(&self, c: [u32; 3]) -> usize {
        let ([i, j, k], [nx, ny, _]) = (widen(c), widen(self.dims));
        i + nx * (j + ny * k)
    }

    /// The cell `[i, j, k]` of linear index `cell` (its inverse).
    pub(crate) fn coordinates(&self, cell: usize) -> [u32; 3] {
        let [nx, ny, _] = widen(self.dims);
        let (x, rest) = (cell.checked_rem(nx), cell.checked_div(nx));
        let (y, z) = (
            rest.and_then(|r| r.checked_rem(ny)),
            rest.and_then(|r| r.checked_div(ny)),
        );
        [x, y, z].map(|c| c.unwrap_or(0) as u32)
    }

    /// Every cell of the grid (of at least one cell per axis).
    pub(crate) fn all(&self) -> CellBox {
        CellBox {
            lo: [0; 3],
            hi: self.dims.map(|d| d.saturating_sub(1)),
        }
    }

    /// The 27 cells around cell `c` (the cell and its neighbours), fewer at
    /// the grid's border.
    #[inline(always)]
    pub(crate) fn around(&self, c: [u32; 3]) -> CellBox {
        let [cx, cy, cz] = c;
        let [nx, ny, nz] = self.dims;
        let range = |c: u32, n: u32| (c.saturating_sub(1), (c + 1).min(n.saturating_sub(1)));
        let ((x0, x1), (y0, y1), (z0, z1)) = (range(cx, nx), range(cy, ny), range(cz, nz));
        CellBox {
            lo: [x0, y0, z0],
            hi: [x1, y1, z1],
        }
    }
}

impl<T: Real> Grid<T> {
    /// The grid of cells of edge `cell_m` (m) from `origin_m` (m) with as
    /// many cells per axis as cover `extent_m` (m) from there:
    /// `⌊e / cell⌋ + 1`, so that a point at the far end is in the last
    /// cell.
    pub fn covering(origin_m: Vector3<T>, extent_m: &Vector3<T>, cell_m: T) -> Self {
        let dims = extent_m.map(|e| ((e / cell_m).floor().as_f64() as u32).saturating_add(1));
        Self {
            origin_m,
            cell_m,
            dims: [dims.x, dims.y, dims.z],
        }
    }

    /// The same box in cells `k` times finer on every axis (edge
    /// `cell_m / k`), `None` for `k = 0` or cell counts past `u32`.
    pub fn subdivided(&self, k: u32) -> Option<Self> {
        let [x, y, z] = self.dims;
        let dims = [x.checked_mul(k)?, y.checked_mul(k)?, z.checked_mul(k)?];
        (k > 0).then(|| Self {
            origin_m: self.origin_m,
            cell_m: self.cell_m / T::of_u32(k),
            dims,
        })
    }

    /// The candidate lists' grid of `list_dims` cells per axis over this
    /// grid's box ([`super::format::SectionKind::GridDims`]): this grid
    /// [`Self::subdivided`] `k` times, `None` unless `list_dims` is `k`
    /// times its cells on every axis with `k` in
    /// `1..=`[`MAX_LIST_SUBDIVISION`]. The one rule of the loader and the
    /// host's writer.
    pub fn lists(&self, list_dims: [u32; 3]) -> Option<Self> {
        let k = list_dims[0].checked_div(self.dims[0])?;
        self.subdivided(k)
            .filter(|l| l.dims == list_dims && k <= MAX_LIST_SUBDIVISION)
    }

    /// The cell containing `p` (m), clamped to the grid (a point outside
    /// maps to the nearest border cell; non-finite coordinates map to 0).
    pub fn cell_of(&self, p: &Vector3<T>) -> [u32; 3] {
        let mut cell = [0u32; 3];
        for ((c, (&x, &o)), &d) in cell
            .iter_mut()
            .zip(p.iter().zip(self.origin_m.iter()))
            .zip(&self.dims)
        {
            // Truncation is the floor for the positive values it sees.
            let f = (x - o) / self.cell_m;
            let top = T::of_u32(d.saturating_sub(1));
            // NaN fails both comparisons and stays at 0.
            *c = if f > T::zero() {
                let clamped = if f < top { f } else { top };
                clamped.trunc_u32()
            } else {
                0
            };
        }
        cell
    }

    /// The cells of the points of the box `[lo_m, hi_m]` (m), each corner
    /// clamped as [`Self::cell_of`] (clamping is monotone: the cell of any
    /// point of the box is in it).
    pub fn cells_of_box(&self, lo_m: &Vector3<T>, hi_m: &Vector3<T>) -> CellBox {
        CellBox {
            lo: self.cell_of(lo_m),
            hi: self.cell_of(hi_m),
        }
    }

    /// Centre of cell `c`, m.
    pub(crate) fn centre(&self, c: [u32; 3]) -> Vector3<T> {
        let half = T::of_f64(0.5);
        let at = |axis: usize| {
            let o = self.origin_m.get(axis).copied().unwrap_or(T::zero());
            let i = c.get(axis).copied().unwrap_or(0);
            o + (T::of_f64(f64::from(i)) + half) * self.cell_m
        };
        Vector3::new(at(0), at(1), at(2))
    }

    /// The box within one cell edge plus `margin_m` (m) of the grid: its
    /// lowest and highest corners, m.
    pub fn reach(&self, margin_m: T) -> [Vector3<T>; 2] {
        let margin = Vector3::repeat(self.cell_m + margin_m);
        let [lo, hi] = self.bounds();
        [lo - margin, hi + margin]
    }

    /// The box of the grid's cells: its lowest corner (the origin) and its
    /// highest, m. A grid built over points ([`Self::covering`] from their
    /// lowest corner and extent) holds every one of them.
    pub fn bounds(&self) -> [Vector3<T>; 2] {
        let extent = Vector3::from(self.dims.map(|d| self.cell_m * T::of_f64(f64::from(d))));
        [self.origin_m, self.origin_m + extent]
    }
}

impl CellBox {
    /// The box of cells between cells `a` and `b` (lowest and highest of
    /// the two on each axis).
    #[inline(always)]
    pub fn between([ax, ay, az]: [u32; 3], [bx, by, bz]: [u32; 3]) -> Self {
        Self {
            lo: [ax.min(bx), ay.min(by), az.min(bz)],
            hi: [ax.max(bx), ay.max(by), az.max(bz)],
        }
    }

    /// `true` if cell `c` is in the box.
    pub fn contains(&self, c: [u32; 3]) -> bool {
        c.iter()
            .zip(self.lo.iter().zip(&self.hi))
            .all(|(x, (l, h))| l <= x && x <= h)
    }

    /// The cells in the box: the product of its spans (a box whose `hi`
    /// lies below its `lo` on an axis counts one cell there).
    pub fn count(&self) -> u64 {
        let [l0, l1, l2] = self.lo;
        let [h0, h1, h2] = self.hi;
        let span = |l: u32, h: u32| u64::from(h.saturating_sub(l)) + 1;
        span(l0, h0) * span(l1, h1) * span(l2, h2)
    }

    /// Calls `f` with every cell of the box, `x` fastest, then `y`, then
    /// `z`. Bounded by [`Self::count`].
    #[inline(always)]
    pub fn for_each(&self, mut f: impl FnMut([u32; 3])) {
        let [x0, y0, z0] = self.lo;
        let [x1, y1, z1] = self.hi;
        for k in z0..=z1 {
            for j in y0..=y1 {
                for i in x0..=x1 {
                    f([i, j, k]);
                }
            }
        }
    }
}
