//! Which tets a zone takes: a tet is in a zone when its interior meets the zone's interior.
//!
//! The tests, exact up to a tolerance `ε = 1e-9 ×` the mesh's bounding-box diagonal (so that a
//! zone drawn on the mesh's own grid planes does not take the tets that only touch it):
//! - box: the separating-axis test of two convex polyhedra, on the box's 3 face normals, the
//!   tet's 4 face normals and the 18 cross products of their edge directions; separated when
//!   the projections overlap by at most `ε` on some axis;
//! - sphere, capsule and path (a union of capsules, one per segment of each tool's polyline):
//!   the distance from the segment to the tet is below `radius − ε`. The distance from a point
//!   to the tet is 0 inside it and otherwise the least distance to its 4 faces (closest point on
//!   a triangle, Ericson, Real-Time Collision Detection §5.1.5); along the segment it is a
//!   convex function of the parameter (the distance to a convex set is convex), minimized by a
//!   golden-section search of [`GOLDEN_ITERATIONS`] steps (the parameter to 2·10⁻¹³).
//!
//! Candidates come from [`TetGrid`], a uniform grid of the tets' bounding boxes, so a zone
//! costs the tets near it, not the mesh. A segment is clipped to the mesh's bounding box grown
//! by the radius first ([`clip_segment`]), and most candidates are decided from their vertices
//! ([`capsule_meets_tet`]) without the search.

use nalgebra::Vector3;

use crate::mesh::TetMesh;
use crate::scene::ZoneShape;

/// Golden-section steps of the segment-to-tet distance (interval `0.618⁶⁰ ≈ 3·10⁻¹³` of the
/// segment).
pub const GOLDEN_ITERATIONS: usize = 60;

type V3 = Vector3<f64>;

/// A tet's 4 vertices, m.
type TetPoints = [V3; 4];

/// A uniform grid over the mesh's bounding box; each cell lists the tets whose bounding box
/// overlaps it (CSR). About one cell per tet.
pub struct TetGrid<'a> {
    mesh: &'a TetMesh,
    origin: V3,
    /// The mesh's bounding box's upper corner (`origin` is the lower), m.
    upper: V3,
    cell_m: f64,
    dims: [usize; 3],
    start: Vec<u32>,
    tets: Vec<u32>,
    /// `ε` of the module doc, m.
    tolerance_m: f64,
}

impl<'a> TetGrid<'a> {
    /// The grid of `mesh` (at least one tet, finite coordinates: the [`TetMesh`] invariants).
    pub fn new(mesh: &'a TetMesh) -> Self {
        let (lo, hi) = bounds(mesh.tets.iter().flatten().map(|&v| point(mesh, v)));
        let extent = hi - lo;
        let diagonal = extent.norm();
        // Cells of about one tet's volume, at least the mean tet's size on the flat axes.
        let volume = extent
            .iter()
            .map(|e| e.max(diagonal * 1e-3))
            .product::<f64>();
        let cell_m = (volume / mesh.tets.len().max(1) as f64)
            .cbrt()
            .max(f64::MIN_POSITIVE);
        let dims = [0, 1, 2].map(|i| ((extent[i] / cell_m).ceil() as usize).clamp(1, 1 << 10));
        let cell_of = |p: &V3| -> [usize; 3] {
            [0, 1, 2]
                .map(|i| (((p[i] - lo[i]) / cell_m).floor().max(0.0) as usize).min(dims[i] - 1))
        };
        let ranges: Vec<([usize; 3], [usize; 3])> = mesh
            .tets
            .iter()
            .map(|t| {
                let (a, b) = bounds(t.iter().map(|&v| point(mesh, v)));
                (cell_of(&a), cell_of(&b))
            })
            .collect();
        let index = |c: [usize; 3]| c[0] + dims[0] * (c[1] + dims[1] * c[2]);
        let mut count = vec![0u32; dims[0] * dims[1] * dims[2] + 1];
        for (a, b) in &ranges {
            for_cells(*a, *b, |c| count[index(c) + 1] += 1);
        }
        for i in 1..count.len() {
            count[i] += count[i - 1];
        }
        let mut fill = count.clone();
        let mut tets = vec![0u32; count.last().copied().unwrap_or(0) as usize];
        for (t, (a, b)) in ranges.iter().enumerate() {
            for_cells(*a, *b, |c| {
                let slot = &mut fill[index(c)];
                tets[*slot as usize] = t as u32;
                *slot += 1;
            });
        }
        Self {
            mesh,
            origin: lo,
            upper: hi,
            cell_m,
            dims,
            start: count,
            tets,
            tolerance_m: 1e-9 * diagonal,
        }
    }

    /// Marks in `selected` (one flag per tet) every tet whose interior meets `shape`'s; returns
    /// how many tets the shape meets (those already marked included).
    pub fn select(&self, shape: &ZoneShape, selected: &mut [bool]) -> usize {
        let mut met = vec![false; self.mesh.tets.len()];
        match shape {
            ZoneShape::Box { min_m, max_m } => {
                let (lo, hi) = (V3::from(*min_m), V3::from(*max_m));
                self.visit(lo, hi, &mut met, |p| {
                    box_meets_tet(lo, hi, p, self.tolerance_m)
                });
            }
            ZoneShape::Sphere { center_m, radius_m } => {
                self.capsule(
                    V3::from(*center_m),
                    V3::from(*center_m),
                    *radius_m,
                    &mut met,
                );
            }
            ZoneShape::Capsule { a_m, b_m, radius_m } => {
                self.capsule(V3::from(*a_m), V3::from(*b_m), *radius_m, &mut met);
            }
            ZoneShape::Path {
                polylines,
                radius_m,
                ..
            } => {
                for line in polylines {
                    match line.as_slice() {
                        [p] => self.capsule(V3::from(*p), V3::from(*p), *radius_m, &mut met),
                        _ => {
                            for w in line.windows(2) {
                                self.capsule(V3::from(w[0]), V3::from(w[1]), *radius_m, &mut met);
                            }
                        }
                    }
                }
            }
        }
        let mut n = 0;
        for (s, m) in selected.iter_mut().zip(&met) {
            if *m {
                *s = true;
                n += 1;
            }
        }
        n
    }

    /// Marks in `met` the tets within `radius_m − ε` of the segment `a`–`b`.
    ///
    /// The segment is first clipped to the mesh's bounding box grown by the radius (only that
    /// part can come within the radius of a tet): a segment with far endpoints (`±1e12` m) is
    /// then searched over its part near the mesh, not over a parameter whose resolution is
    /// metres. Each candidate tet is decided from its vertices when they suffice
    /// ([`capsule_meets_tet`]).
    fn capsule(&self, a: V3, b: V3, radius_m: f64, met: &mut [bool]) {
        let r = V3::repeat(radius_m);
        let Some((a, b)) = clip_segment(a, b, self.origin - r, self.upper + r) else {
            return;
        };
        let reach = radius_m - self.tolerance_m;
        self.visit(a.inf(&b) - r, a.sup(&b) + r, met, |p| {
            capsule_meets_tet(a, b, reach, p)
        });
    }

    /// Calls `meets` on every unmarked tet whose grid cells overlap `[lo, hi]` and marks those
    /// it accepts.
    fn visit(&self, lo: V3, hi: V3, met: &mut [bool], meets: impl Fn(&TetPoints) -> bool) {
        let cell = |p: &V3, i: usize| ((p[i] - self.origin[i]) / self.cell_m).floor();
        // Per axis, the cells `[lo, hi]` overlaps; `None` outside the grid.
        let span = [0, 1, 2].map(|i| {
            let (a, b) = (cell(&lo, i), cell(&hi, i));
            let last = (self.dims[i] - 1) as f64;
            (b >= 0.0 && a <= last).then(|| (a.max(0.0) as usize, b.min(last) as usize))
        });
        let [Some(x), Some(y), Some(z)] = span else {
            return;
        };
        let range = [[x.0, y.0, z.0], [x.1, y.1, z.1]];
        let index = |c: [usize; 3]| c[0] + self.dims[0] * (c[1] + self.dims[1] * c[2]);
        for_cells(range[0], range[1], |c| {
            let i = index(c);
            for &t in &self.tets[self.start[i] as usize..self.start[i + 1] as usize] {
                if !met[t as usize]
                    && meets(&self.mesh.tets[t as usize].map(|v| point(self.mesh, v)))
                {
                    met[t as usize] = true;
                }
            }
        });
    }
}

/// Vertex `v`'s position.
fn point(mesh: &TetMesh, v: u32) -> V3 {
    V3::from(mesh.positions[v as usize])
}

/// The bounding box of `points`.
fn bounds(points: impl Iterator<Item = V3>) -> (V3, V3) {
    points.fold(
        (V3::repeat(f64::INFINITY), V3::repeat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.inf(&p), hi.sup(&p)),
    )
}

/// Calls `f` on every cell of the inclusive range `a..=b`.
fn for_cells(a: [usize; 3], b: [usize; 3], mut f: impl FnMut([usize; 3])) {
    for k in a[2]..=b[2] {
        for j in a[1]..=b[1] {
            for i in a[0]..=b[0] {
                f([i, j, k]);
            }
        }
    }
}

/// Whether the box `[lo, hi]` and the tet `p` overlap by more than `eps` on every separating
/// axis (module doc).
pub fn box_meets_tet(lo: V3, hi: V3, p: &TetPoints, eps: f64) -> bool {
    let center = (lo + hi) / 2.0;
    let half = (hi - lo) / 2.0;
    let edges = [
        p[1] - p[0],
        p[2] - p[0],
        p[3] - p[0],
        p[2] - p[1],
        p[3] - p[1],
        p[3] - p[2],
    ];
    let faces = [
        edges[3].cross(&edges[4]),
        edges[1].cross(&edges[2]),
        edges[0].cross(&edges[2]),
        edges[0].cross(&edges[1]),
    ];
    let separated = |axis: V3| {
        let norm = axis.norm();
        if norm <= f64::EPSILON * edges.iter().map(|e| e.norm()).fold(0.0, f64::max) {
            return false; // a degenerate axis separates nothing
        }
        let axis = axis / norm;
        let (mut a, mut b) = (f64::INFINITY, f64::NEG_INFINITY);
        for q in p {
            let x = q.dot(&axis);
            a = a.min(x);
            b = b.max(x);
        }
        let c = center.dot(&axis);
        let r = half[0] * axis[0].abs() + half[1] * axis[1].abs() + half[2] * axis[2].abs();
        b.min(c + r) - a.max(c - r) <= eps
    };
    let units = [V3::x(), V3::y(), V3::z()];
    !(units.iter().any(|&u| separated(u))
        || faces.iter().any(|&n| separated(n))
        || units
            .iter()
            .any(|u| edges.iter().any(|e| separated(u.cross(e)))))
}

/// The part of the segment `a`–`b` inside the box `[lo, hi]` (Liang-Barsky), `None` if it
/// misses the box. The parameters are computed from the endpoints and the clipped points from
/// the nearer endpoint, so a point near the box keeps the precision of the input.
pub fn clip_segment(a: V3, b: V3, lo: V3, hi: V3) -> Option<(V3, V3)> {
    let d = b - a;
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for i in 0..3 {
        if d[i] == 0.0 {
            if a[i] < lo[i] || a[i] > hi[i] {
                return None;
            }
            continue;
        }
        let (mut u, mut v) = ((lo[i] - a[i]) / d[i], (hi[i] - a[i]) / d[i]);
        if u > v {
            core::mem::swap(&mut u, &mut v);
        }
        t0 = t0.max(u);
        t1 = t1.min(v);
        if t0 > t1 {
            return None;
        }
    }
    let at = |t: f64| {
        if t <= 0.5 {
            a + d * t
        } else {
            b - d * (1.0 - t)
        }
    };
    Some((
        if t0 == 0.0 { a } else { at(t0) },
        if t1 == 1.0 { b } else { at(t1) },
    ))
}

/// Whether the tet `p` comes within `reach` of the segment `a`–`b` (m), deciding from its
/// vertices when they suffice and by [`segment_tet_distance`] otherwise.
///
/// A vertex within `reach` decides yes. The squared distance to a convex set, `g`, has a
/// 2-Lipschitz gradient, so at any point `x = Σλᵢvᵢ` of the tet
/// `g(x) ≥ Σλᵢ g(vᵢ) − Σλᵢ|vᵢ − x|² ≥ minᵢ g(vᵢ) − L²` (`L` the tet's longest edge): when that
/// bound is at least `reach²`, no point of the tet is within `reach`, and the answer is no
/// without the search.
pub fn capsule_meets_tet(a: V3, b: V3, reach: f64, p: &TetPoints) -> bool {
    let nearest_sq = p
        .iter()
        .map(|&q| point_segment_distance_sq(q, a, b))
        .fold(f64::INFINITY, f64::min);
    if nearest_sq < reach * reach {
        return true;
    }
    let longest_sq = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
        .iter()
        .map(|&(i, j)| (p[i] - p[j]).norm_squared())
        .fold(0.0, f64::max);
    if nearest_sq - longest_sq >= reach * reach {
        return false;
    }
    segment_tet_distance(a, b, p) < reach
}

/// Squared distance from `q` to the segment `a`–`b`, m².
fn point_segment_distance_sq(q: V3, a: V3, b: V3) -> f64 {
    let d = b - a;
    let len_sq = d.norm_squared();
    let t = if len_sq > 0.0 {
        ((q - a).dot(&d) / len_sq).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (q - (a + d * t)).norm_squared()
}

/// Distance from the segment `a`–`b` to the tet `p` (0 where they meet), m: golden-section
/// search of the convex distance along the segment (module doc).
pub fn segment_tet_distance(a: V3, b: V3, p: &TetPoints) -> f64 {
    let f = |t: f64| point_tet_distance(a + (b - a) * t, p);
    if a == b {
        return f(0.0);
    }
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let (mut lo, mut hi) = (0.0, 1.0);
    let (mut x1, mut x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
    let (mut f1, mut f2) = (f(x1), f(x2));
    for _ in 0..GOLDEN_ITERATIONS {
        if f1 <= f2 {
            hi = x2;
            (x2, f2) = (x1, f1);
            x1 = hi - g * (hi - lo);
            f1 = f(x1);
        } else {
            lo = x1;
            (x1, f1) = (x2, f2);
            x2 = lo + g * (hi - lo);
            f2 = f(x2);
        }
    }
    f1.min(f2).min(f(0.0)).min(f(1.0))
}

/// Distance from `q` to the (positively oriented) tet `p`, m: 0 inside, else the least distance
/// to its faces.
pub fn point_tet_distance(q: V3, p: &TetPoints) -> f64 {
    // Face opposite vertex i, and whether q is on the outer side of it.
    const FACES: [[usize; 3]; 4] = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];
    let mut outside = false;
    let mut best = f64::INFINITY;
    for [i, j, k] in FACES {
        let n = (p[j] - p[i]).cross(&(p[k] - p[i]));
        if (q - p[i]).dot(&n) > 0.0 {
            outside = true;
        }
        best = best.min((q - closest_on_triangle(q, p[i], p[j], p[k])).norm());
    }
    if outside { best } else { 0.0 }
}

/// The point of the triangle `a b c` closest to `q` (Ericson §5.1.5, by Voronoi regions).
fn closest_on_triangle(q: V3, a: V3, b: V3, c: V3) -> V3 {
    let (ab, ac, aq) = (b - a, c - a, q - a);
    let (d1, d2) = (ab.dot(&aq), ac.dot(&aq));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bq = q - b;
    let (d3, d4) = (ab.dot(&bq), ac.dot(&bq));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cq = q - c;
    let (d5, d6) = (ab.dot(&cq), ac.dot(&cq));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}
