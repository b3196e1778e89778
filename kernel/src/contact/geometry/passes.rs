//! The candidate tests of a detection's passes: the walk over the 27
//! cells around a point, and per triangle the sweep's crossing test, the
//! penetration test's nearest plane, and the check of a plane over the
//! centre (each with the triangle's stored plane and frame).

use nalgebra::Vector3;

use super::scan::{Nearest, Pass, Scan, Sphere, Unreached, Visited, WALK_CHUNK};
use super::{ContactWork, SurfaceGeometry, clamp_weights};
use crate::Real;
use crate::table::TriangleIndex;

impl<'a, T: Real> SurfaceGeometry<'a, T> {
    /// Runs `pass` of `scan` once for each surface triangle around the
    /// surface vertices in the 27 grid cells around `around` (m) that
    /// `visited` has not met; a triangle is around up to three of the
    /// vertices, and is tested at the first. The walk hands them to the
    /// tests [`WALK_CHUNK`] at a time, in its order.
    pub(super) fn visit(
        &self,
        around: &Vector3<T>,
        visited: &mut Visited,
        work: &mut ContactWork,
        pass: Pass<T>,
        scan: &mut Scan<'_, T>,
    ) {
        let mut chunk = heapless::Vec::<u32, WALK_CHUNK>::new();
        self.index.for_each_vertex_near(around, |v| {
            for t in self.index.triangles_of(v) {
                if !visited.first_visit(t) {
                    continue;
                }
                if chunk.push(t.as_u32()).is_err() {
                    self.visit_triangles(&chunk, work, pass, scan);
                    chunk.clear();
                    // Room: just cleared.
                    let _ = chunk.push(t.as_u32());
                }
            }
        });
        self.visit_triangles(&chunk, work, pass, scan);
    }

    /// Runs `pass` of `scan` once for each of `triangles` (surface
    /// triangle indices: a cell's list or a chunk of the walk), in order,
    /// with its stored plane, and counts the tests in `work`. The one copy
    /// of the tests in the firmware's flash (not inlined into its two
    /// callers).
    #[inline(never)]
    pub(super) fn visit_triangles(
        &self,
        triangles: &[u32],
        work: &mut ContactWork,
        pass: Pass<T>,
        scan: &mut Scan<'_, T>,
    ) {
        // Read once (kept in registers across the loop, where the tests'
        // writes into `scan` would have it read again per candidate).
        let sphere = scan.sphere;
        for &t in triangles {
            let t = TriangleIndex::checked(t);
            let Some((normal, offset)) = self.index.plane(t) else {
                continue;
            };
            // At most `max_detection_tests` per detection, P per tick: no
            // wrap.
            work.triangles_tested = work.triangles_tested.wrapping_add(1);
            self.test(pass, &sphere, scan, t, normal, offset);
        }
    }

    /// One candidate `t` (plane `normal`, `offset`) of `pass`.
    #[inline(always)]
    fn test(
        &self,
        pass: Pass<T>,
        sphere: &Sphere<T>,
        scan: &mut Scan<'_, T>,
        t: TriangleIndex,
        normal: Vector3<T>,
        offset: T,
    ) {
        let Sphere {
            to_m,
            radius_m,
            depth_m,
        } = *sphere;
        match pass {
            Pass::Start => {
                if let Some(segment) = &scan.segment {
                    let [_, end_m] = segment;
                    let end_distance_m = normal.dot(end_m) - offset;
                    let plane = (normal, offset, end_distance_m);
                    self.sweep_test(t, plane, segment, radius_m, &mut scan.hit);
                }
            }
            Pass::Tool => {
                let distance = normal.dot(&to_m) - offset;
                // A pass at the tool runs with the tool inside the grid's
                // reach, so the segment ends at the tool (only a start
                // outside it is clipped): its end's distance is this one.
                if let Some(segment) = &scan.segment {
                    let plane = (normal, offset, distance);
                    self.sweep_test(t, plane, segment, radius_m, &mut scan.hit);
                }
                if distance.abs() <= depth_m && normal != Vector3::zeros() {
                    if distance < radius_m {
                        // A sweep hit decides the detection (`search`):
                        // from the first, the nearest reached plane is not
                        // read. (Tested here, where the sphere reaches the
                        // plane, not per candidate: a walk over hundreds of
                        // candidates without a hit would pay it on each.)
                        if scan.hit.is_none() {
                            self.nearest_test(t, distance, &to_m, scan.order, &mut scan.reached);
                        }
                    } else {
                        scan.unreached.note(t, distance, scan.order);
                    }
                }
                scan.order = scan.order.wrapping_add(1);
            }
            Pass::Deep => {
                if normal != Vector3::zeros() {
                    let distance = normal.dot(&to_m) - offset;
                    self.nearest_test(t, distance, &to_m, scan.order, &mut scan.reached);
                }
            }
            Pass::Covered { bound_m, order } => {
                let distance = normal.dot(&to_m) - offset;
                let nearer = Unreached::nearer(distance, scan.order, bound_m, order);
                scan.order = scan.order.wrapping_add(1);
                if !scan.covered && distance >= radius_m && distance <= depth_m && nearer {
                    scan.covered = self.over(t, &to_m);
                }
            }
        }
    }

    /// The sweep's test of triangle `t` (`plane`: unit normal, offset, and
    /// the signed distance of the segment's end from it, m) against the
    /// sphere moving along `segment`: keeps in `best` the earliest hit from
    /// outside, as `(along, triangle, weights)`.
    #[inline(always)]
    fn sweep_test(
        &self,
        t: TriangleIndex,
        plane: (Vector3<T>, T, T),
        segment: &[Vector3<T>; 2],
        radius_m: T,
        best: &mut Option<(T, TriangleIndex, [T; 3])>,
    ) {
        let (normal, offset, end_distance_m) = plane;
        // A start exactly touching the surface may round to just inside it.
        let slack_m = T::WEIGHT_TOLERANCE * self.index.cell_m();
        let [start_m, _] = segment;
        // The stored plane first: two dot products reject almost all.
        let s0 = normal.dot(start_m) - offset - radius_m;
        let s1 = end_distance_m - radius_m;
        if s0 >= -slack_m && s1 < T::zero() {
            // The crossing lies `along = s0 / (s0 − s1)` of the way: no
            // earlier than the earliest hit so far (the first of equals
            // kept), compared without the division (`s0 − s1 > 0`), is no
            // hit. Over a flat face every candidate crosses at the same
            // `along`: after the hit, each costs this comparison.
            let s0 = s0.larger(T::zero());
            if best.as_ref().is_some_and(|(b, ..)| *b * (s0 - s1) <= s0) {
                return;
            }
            self.sweep_hit(t, [s0, s1], segment, best);
        }
    }

    /// The rest of [`Self::sweep_test`] for a segment that crosses the
    /// plane (signed distances `s` of its ends from the plane, less the
    /// radius, the first not below zero), earlier than the earliest hit so
    /// far: the crossing point's barycentric weights.
    fn sweep_hit(
        &self,
        t: TriangleIndex,
        s: [T; 2],
        segment: &[Vector3<T>; 2],
        best: &mut Option<(T, TriangleIndex, [T; 3])>,
    ) {
        let tolerance = T::WEIGHT_TOLERANCE;
        let [start_m, end_m] = segment;
        let [s0, s1] = s;
        let along = s0 / (s0 - s1);
        // The pre-filter's product rounds apart from this quotient: the
        // first of equals is kept by the quotient itself.
        if best.as_ref().is_some_and(|(b, ..)| *b <= along) {
            return;
        }
        // The frame's gradients lie in the plane: the centre's point of the
        // segment weighs as its contact point, a radius below it.
        let x = start_m + (end_m - start_m) * along;
        let Some(w) = self.weights(t, &x) else { return };
        if !w.iter().all(|&wi| wi >= -tolerance) {
            return;
        }
        let Some(vertices) = self.index.triangle(t) else {
            return;
        };
        if vertices.iter().all(|&v| self.supports.is_fixed(v)) {
            return;
        }
        *best = Some((along, t, clamp_weights(w)));
    }

    /// The penetration test of triangle `t`, whose plane lies `distance_m`
    /// from the centre `tip_m`, the `order`-th tested:
    /// keeps in `nearest` the triangle with the nearest plane under the
    /// centre (the first tested of equals).
    fn nearest_test(
        &self,
        t: TriangleIndex,
        distance_m: T,
        tip_m: &Vector3<T>,
        order: u32,
        nearest: &mut Option<Nearest<T>>,
    ) {
        if nearest
            .as_ref()
            .is_some_and(|n| n.distance_m.abs() <= distance_m.abs())
        {
            return;
        }
        let Some(w) = self.weights(t, tip_m) else {
            return;
        };
        if w.iter().all(|&wi| wi >= -T::WEIGHT_TOLERANCE) {
            *nearest = Some(Nearest {
                distance_m,
                triangle: t,
                weights: clamp_weights(w),
                order,
            });
        }
    }

    /// Whether the centre `tip_m` projects into triangle `t` (the rare
    /// check of the planes the sphere does not reach: out of line).
    #[inline(never)]
    pub(super) fn over(&self, t: TriangleIndex, tip_m: &Vector3<T>) -> bool {
        self.weights(t, tip_m)
            .is_some_and(|w| w.iter().all(|&wi| wi >= -T::WEIGHT_TOLERANCE))
    }
}
