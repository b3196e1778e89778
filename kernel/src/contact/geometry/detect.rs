//! Detection ([`SurfaceGeometry::detect`]): the swept sphere against the
//! triangles near its motion, then the penetration test where the tool
//! stands; and the deep check of a centre inside the body
//! ([`SurfaceGeometry::centre_inside`]).

use nalgebra::Vector3;

use super::scan::{Nearest, Pass, Scan, Sphere, Unreached, UnreachedPlanes, Visited};
use super::{ContactWork, SurfaceGeometry};
use crate::Real;
use crate::contact::Contact;
use crate::table::{CandidateList, TriangleIndex, neighbours, within};

/// How far, in radii, a plane may lie from a tool sphere's centre for the
/// penetration test to look at its triangle ([`SurfaceGeometry::detect`]):
/// a sphere whose centre is up to two radii behind the surface (three radii
/// into it) is found, and a tool hovering clear of the surface costs one
/// dot product per candidate triangle.
pub const PENETRATION_DEPTH_RADII: f64 = 2.0;

// A table's candidate lists file each triangle wide enough for the
// penetration test's depth.
const _: () = assert!(crate::table::CANDIDATE_MARGIN_RADII > PENETRATION_DEPTH_RADII);

/// The point where the segment from `inside` (within the box `reach`,
/// lowest and highest corners) to `outside` leaves the box, computed from
/// `inside`: `inside + (outside − inside)·s` with `s ∈ [0, 1]` the smallest
/// exit parameter over the axes, so its error is relative to the box, not to
/// `outside` (which may be 1e10 m away). Constant time; a non-finite
/// `outside` compares false on every axis and is returned as it is.
fn clip_towards<T: Real>(
    inside: &Vector3<T>,
    outside: &Vector3<T>,
    reach: &[Vector3<T>; 2],
) -> Vector3<T> {
    let [lo, hi] = reach;
    let mut s = T::one();
    for (((&a, &b), &l), &h) in inside
        .iter()
        .zip(outside.iter())
        .zip(lo.iter())
        .zip(hi.iter())
    {
        // `a` lies in [l, h], so `b − a` is not zero where `b` is outside.
        let exit = if b > h {
            (h - a) / (b - a)
        } else if b < l {
            (l - a) / (b - a)
        } else {
            continue;
        };
        if exit < s {
            s = exit;
        }
    }
    inside + (outside - inside) * s
}

impl<'a, T: Real> SurfaceGeometry<'a, T> {
    /// The contact of a sphere of radius `radius_m` whose centre moved from
    /// `from_m` (`None`: no earlier position) to `to_m` (m): the first
    /// surface triangle the motion hits from outside, else the triangle it
    /// penetrates where it stands; triangles with all three vertices fixed
    /// (a rigid support, no compliance) are not touchable.
    ///
    /// Candidates, when the table's per-cell lists serve `radius_m`
    /// ([`SurfaceIndex::candidates`](crate::table::SurfaceIndex::candidates)): the list of `to_m`'s cell of the
    /// lists' grid (every triangle the tests below can find from a centre
    /// there) and, for the sweep, the lists of the cells from `from_m`'s
    /// towards `to_m`'s (`SurfaceIndex::for_each_candidate_list_between`;
    /// a triangle in two of them is tested twice, which changes nothing:
    /// each test keeps the first of equals). Otherwise (a deforming
    /// surface, or a tool larger than the lists serve): the triangles
    /// around the surface vertices in the 27 grid cells around `to_m` and,
    /// for the sweep, around `from_m`, each tested once however many of its
    /// corners the cells hold. In both, none around `from_m` when both
    /// points are in the same cell, and none for a point more than a cell
    /// plus the radius outside the grid. Bounded by
    /// [`SurfaceIndex::max_detection_tests`](crate::table::SurfaceIndex::max_detection_tests) triangle tests (with the
    /// penetration test's second pass), most rejected by two dot products
    /// with the stored plane; the sweep and the penetration test share the
    /// visit at `to_m`. A candidate's barycentric weights are two more dot
    /// products, with its stored frame ([`SurfaceIndex::weights`](crate::table::SurfaceIndex::weights)).
    ///
    /// Sweep: an end outside that reach is first moved along the segment to
    /// where the segment leaves it (`clip_towards`, computed from the end
    /// inside): no triangle can be hit beyond it, and a far end (a tool
    /// sample at 1e10 m) would otherwise swamp the intersection's
    /// arithmetic, in f32 every digit of the part near the surface.
    ///
    /// Penetration (the surface moved onto the tool): among the triangles
    /// around `to_m` whose plane lies within [`PENETRATION_DEPTH_RADII`]
    /// radii of the centre and has the centre's projection inside the
    /// triangle, the one with the nearest plane (the first tested of
    /// equals) decides; if the sphere reaches behind it (signed gap < 0)
    /// that is the contact, pushed out along its outward normal, with
    /// [`Contact::entry_gap_m`] its penetration; else there is none (also
    /// when the nearest is a rigid support). A barycentric test is spent
    /// only on planes the sphere reaches, and on the others only when one
    /// of them is nearer than the nearest reached (`Unreached`, or a
    /// second pass, `Pass::Covered`, when more than it keeps came): a
    /// tool hovering within the depth reach costs two dot products per
    /// candidate.
    pub fn detect(
        &self,
        tool: usize,
        from_m: Option<&Vector3<T>>,
        to_m: &Vector3<T>,
        radius_m: T,
        work: &mut ContactWork,
    ) -> Option<Contact<T>> {
        let mut contact = None;
        self.detect_into(tool, from_m, to_m, radius_m, work, &mut contact);
        contact
    }

    /// [`Self::detect`] into `contact` (the haptic loop's slot: the record
    /// is written in place, not copied from a returned one).
    pub(crate) fn detect_into(
        &self,
        tool: usize,
        from_m: Option<&Vector3<T>>,
        to_m: &Vector3<T>,
        radius_m: T,
        work: &mut ContactWork,
        contact: &mut Option<Contact<T>>,
    ) {
        *contact = None;
        let Some((triangle, weights, found_inside)) = self.search(from_m, to_m, radius_m, work)
        else {
            return;
        };
        let Some(face) = self.face(triangle) else {
            return;
        };
        // Found inside on a rigid support: no contact.
        if found_inside && face.vertices.iter().all(|&v| self.supports.is_fixed(v)) {
            return;
        }
        let made = contact.insert(self.contact(tool, triangle, &face, weights, to_m, radius_m));
        if found_inside {
            made.entry_gap_m = made.gap_m;
        }
    }

    /// The search of [`Self::detect`]: the triangle and weights of the
    /// contact, and whether it was found inside (by the penetration test).
    /// Its stages, each inlined here (one function in the compiled code):
    /// the sweep's segment and start ([`Self::sweep_start`]), the first
    /// pass over the table's lists ([`Self::list_passes`]) or the 27-cell
    /// walk ([`Self::walk_passes`]), then the sweep's hit, or the nearest
    /// reached plane unless a plane the sphere does not reach covers the
    /// centre ([`Self::covered`]).
    fn search(
        &self,
        from_m: Option<&Vector3<T>>,
        to_m: &Vector3<T>,
        radius_m: T,
        work: &mut ContactWork,
    ) -> Option<(TriangleIndex, [T; 3], bool)> {
        let reach = self.index.reach(radius_m);
        let to_in = within(to_m, &reach);
        // The table's per-cell lists when they serve this radius (and the
        // motion is short, below), else the walk over the 27 cells around
        // each point; cells of the lists' grid or of the grid.
        let served = self.index.serves(radius_m);
        let to_cell = self.index.detection_cell_of(to_m, served);
        let mut planes = UnreachedPlanes::new();
        let sphere = Sphere {
            to_m: *to_m,
            radius_m,
            depth_m: radius_m * T::of_f64(PENETRATION_DEPTH_RADII),
        };
        let mut scan = Scan::new(sphere, &mut planes);
        // The sweep's start and its cell, when it lies within the reach
        // and not in the tool's cell; whether the motion is short.
        let mut start = None;
        let mut short = true;
        if let Some(from_m) = from_m {
            let from_cell = self.index.detection_cell_of(from_m, served);
            let ends = [(from_m, from_cell), (to_m, to_cell)];
            (start, short) = Self::sweep_start(ends, to_in, &reach, &mut scan.segment);
        }
        let lists = (served && short).then(|| self.index.candidates_at(to_cell));
        match lists {
            Some(list) => {
                let start_cell = start.map(|(_, from_cell)| from_cell);
                self.list_passes(list, to_in, to_cell, start_cell, work, &mut scan);
            }
            None => {
                let start_m = start.as_ref().map(|(from_m, _)| from_m);
                self.walk_passes(to_m, to_in, start_m, work, &mut scan);
            }
        }
        if let Some((_, triangle, weights)) = scan.hit {
            return Some((triangle, weights, false));
        }
        let Nearest {
            distance_m,
            triangle,
            weights,
            order,
        } = scan.reached.take()?;
        let bound_m = distance_m.abs();
        if self.covered(&mut scan, (bound_m, order), lists, to_m, work) {
            return None;
        }
        Some((triangle, weights, true))
    }

    /// The sweep of a motion between `ends` (the earlier position and the
    /// tool, m, each with its cell of [`SurfaceIndex::detection_cell_of`](crate::table::SurfaceIndex::detection_cell_of);
    /// the tool within `reach` when `to_in`): writes the swept segment
    /// into `segment`, clipped to the grid's `reach` when exactly one end
    /// lies outside it (written where it is found: each copy of the segment
    /// is a dozen stores on the firmware target), and returns the sweep's
    /// start with its cell (when it lies within the reach and not in the
    /// tool's cell) and whether the motion is short (between neighbouring
    /// cells within the reach: the lists of the cells between its ends hold
    /// every triangle the walk would meet; a longer one walks).
    #[inline(always)]
    #[allow(clippy::type_complexity)]
    fn sweep_start(
        ends: [(&Vector3<T>, [u32; 3]); 2],
        to_in: bool,
        reach: &[Vector3<T>; 2],
        segment: &mut Option<[Vector3<T>; 2]>,
    ) -> (Option<(Vector3<T>, [u32; 3])>, bool) {
        let [(from_m, from_cell), (to_m, to_cell)] = ends;
        let from_in = within(from_m, reach);
        let ([a, b, c], [x, y, z]) = (from_cell, to_cell);
        // Corner by corner: an array comparison is a `memcmp` call on
        // the firmware target.
        let same_cell = a == x && b == y && c == z;
        *segment = Some(match (from_in, to_in) {
            (false, true) => [clip_towards(to_m, from_m, reach), *to_m],
            (true, false) => [*from_m, clip_towards(from_m, to_m, reach)],
            _ => [*from_m, *to_m],
        });
        let short = from_in && to_in && neighbours(from_cell, to_cell);
        let start = (!same_cell && from_in).then_some((*from_m, from_cell));
        (start, short)
    }

    /// The first passes over the table's candidate lists (they serve the
    /// tool and the motion is short): the tool's pass over `list`, the
    /// list of the tool's cell `to_cell` (when the tool lies within the
    /// reach, `to_in`), then the sweep's over the lists of the cells from
    /// `start_cell` (the sweep's start, if any) towards the tool's.
    #[inline(always)]
    fn list_passes(
        &self,
        list: CandidateList<'a>,
        to_in: bool,
        to_cell: [u32; 3],
        start_cell: Option<[u32; 3]>,
        work: &mut ContactWork,
        scan: &mut Scan<'_, T>,
    ) {
        if to_in {
            self.visit_triangles(list.as_slice(), work, Pass::Tool, scan);
        }
        if let Some(from_cell) = start_cell {
            // The lists serve this radius and the motion is short: its
            // ends lie within the reach, unclipped.
            self.index
                .for_each_candidate_list_between(from_cell, to_cell, |list| {
                    self.visit_triangles(list.as_slice(), work, Pass::Start, scan)
                });
        }
    }

    /// The first passes of the 27-cell walk: the tool's around `to_m`
    /// (when it lies within the reach, `to_in`), then the sweep's around
    /// `start_m` (the sweep's start, if any), each triangle tested once.
    #[inline(always)]
    fn walk_passes(
        &self,
        to_m: &Vector3<T>,
        to_in: bool,
        start_m: Option<&Vector3<T>>,
        work: &mut ContactWork,
        scan: &mut Scan<'_, T>,
    ) {
        let mut visited = Visited::new();
        if to_in {
            self.visit(to_m, &mut visited, work, Pass::Tool, scan);
        }
        if let Some(from_m) = start_m {
            self.visit(from_m, &mut visited, work, Pass::Start, scan);
        }
    }

    /// Whether a plane the sphere does not reach lies over the centre
    /// `to_m` nearer than the nearest reached plane (`nearest`: its
    /// distance `bound_m`, m, and its place in the test order), or as near
    /// and tested first: then the tool is outside (beyond a thin flap,
    /// nearer its other face). From the planes [`Scan`] kept, or, when more
    /// came than it keeps, a second pass over the same candidates (`lists`,
    /// or the walk) in the same order.
    #[inline(always)]
    fn covered(
        &self,
        scan: &mut Scan<'_, T>,
        nearest: (T, u32),
        lists: Option<CandidateList<'a>>,
        to_m: &Vector3<T>,
        work: &mut ContactWork,
    ) -> bool {
        let (bound_m, order) = nearest;
        let unreached = &scan.unreached;
        // Every note keeps its plane or overflows a full list.
        let noted = !unreached.planes.is_empty();
        if !(noted && unreached.nearest_m <= bound_m) {
            return false;
        }
        if scan.unreached.overflowed {
            // The second pass, over the same candidates in the same order.
            scan.order = 0;
            let pass = Pass::Covered { bound_m, order };
            match lists {
                Some(list) => self.visit_triangles(list.as_slice(), work, pass, scan),
                None => self.visit(to_m, &mut Visited::new(), work, pass, scan),
            }
            scan.covered
        } else {
            scan.unreached.planes.iter().any(|&(t, k)| {
                self.index.plane(t).is_some_and(|(normal, offset)| {
                    let distance = normal.dot(to_m) - offset;
                    Unreached::nearer(distance, k, bound_m, order) && self.over(t, to_m)
                })
            })
        }
    }

    /// Whether the centre `to_m` (m) of a tool sphere of radius `radius_m`
    /// lies inside the body: the deep check a detection that made no
    /// contact is followed by when the tool may have got deeper than the
    /// penetration test looks ([`PENETRATION_DEPTH_RADII`] radii behind a
    /// plane) without the sweep seeing it cross the surface (the haptic
    /// loop's first tick, a motion longer than a grid cell, a contact let
    /// go or refused: `HapticLoop::tick_tools`).
    ///
    /// Among the surface triangles around the surface vertices in the 27
    /// grid cells around `to_m` (the walk of [`Self::detect`], bounded by
    /// [`SurfaceIndex::max_query_triangles`](crate::table::SurfaceIndex::max_query_triangles); the grid's cell is at least
    /// the longest surface edge, so a centre within a cell of the surface
    /// sees the faces over it), the one with the nearest plane over the
    /// centre (its projection inside the triangle) decides:
    /// `Some(true)` when the centre lies behind it (inside the body),
    /// `Some(false)` in front of it, or, without the walk, for a centre
    /// outside the box of the surface's vertices
    /// ([`SurfaceIndex::surface_box`](crate::table::SurfaceIndex::surface_box),
    /// which holds the body: a tool arriving from outside, the usual first
    /// tick, pays six comparisons, not the 27-cell walk); `None` when no
    /// plane there lies over the centre (deeper in a body than a grid cell,
    /// or in a cavity wider than one): the surface near the tool does not
    /// say.
    pub fn centre_inside(
        &self,
        to_m: &Vector3<T>,
        radius_m: T,
        work: &mut ContactWork,
    ) -> Option<bool> {
        if !within(to_m, &self.index.surface_box()) {
            return Some(false);
        }
        let mut planes = UnreachedPlanes::new();
        let sphere = Sphere {
            to_m: *to_m,
            radius_m,
            depth_m: T::zero(),
        };
        let mut scan = Scan::new(sphere, &mut planes);
        self.visit(to_m, &mut Visited::new(), work, Pass::Deep, &mut scan);
        scan.reached.map(|nearest| nearest.distance_m < T::zero())
    }
}
