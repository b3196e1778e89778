//! Contact detection and tracking on a tissue surface (Cotin 1999 §4;
//! MODELS.md §6): the rest surface of a pre-computed model, or the deformed
//! surface of a dynamic model at its last physics update
//! ([`crate::tensor_mass::DeformingSurface`]). A tool point is a sphere of radius
//! `r`; its contact is a point of a surface triangle (barycentric weights),
//! created when the sphere's motion segment crosses the triangle from
//! outside, or when the sphere is found penetrating the surface where it
//! stands (the surface moved onto it: a rebound, tissue another tool
//! pushes, a falling flap), moved with the tool (frictionless sliding: the
//! contact point is the projection of the sphere's lowest point onto the
//! surface, walking across triangle edges; a grasped point stays where it
//! is held), and released when the sphere no longer penetrates.
//!
//! Relative motion: the tool moves every tick, the deforming surface at
//! each physics update. The sweep catches the tool's own motion across the
//! surface as it stands; the penetration test catches the surface's motion
//! onto a tool, for a surface that moves less than a grid cell (the
//! longest surface edge) per update, which bounds it: the nearest triangle
//! under the sphere's centre among those around the 27 cells of its
//! centre decides, so a tool under a thin flap, nearer the flap's lower
//! face, is outside it.

use nalgebra::Vector3;

use super::Contact;
use crate::Real;
use crate::table::{
    InterfaceTable, PrecomputedTable, SurfaceIndex, TensorMassTable, TriangleIndex, VertexIndex,
    within,
};

/// Triangle edges crossed at most per tick while sliding (a bound on the
/// walk; a contact that would slide further stops at the last triangle).
pub const MAX_WALK_STEPS: u32 = 8;

/// How far, in radii, a plane may lie from a tool sphere's centre for the
/// penetration test to look at its triangle ([`SurfaceGeometry::detect`]):
/// a sphere whose centre is up to two radii behind the surface (three radii
/// into it) is found, and a tool hovering clear of the surface costs one
/// dot product per candidate triangle.
pub const PENETRATION_DEPTH_RADII: f64 = 2.0;

// A table's candidate lists file each triangle wide enough for the
// penetration test's depth.
const _: () = assert!(crate::table::CANDIDATE_MARGIN_RADII > PENETRATION_DEPTH_RADII);

/// Work done by detection and tracking (per-stage counters for the timing
/// budget).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ContactWork {
    /// Candidate triangles tested for a crossing.
    pub triangles_tested: u32,
    /// Triangle edges crossed while sliding.
    pub walk_steps: u32,
}

/// The vertices a table holds fixed: a triangle with all three fixed is a
/// rigid support (no compliance) and is not touchable.
#[derive(Clone, Copy, Debug)]
pub enum Supports<'a, T: Real> {
    /// The fixed vertices of a pre-computed table.
    Precomputed(&'a PrecomputedTable<'a, T>),
    /// The fixed vertices of a tensor-mass table.
    TensorMass(&'a TensorMassTable<'a, T>),
    /// The fixed vertices of a hybrid mesh (RR-3510 §6.2): a vertex of the
    /// tensor-mass region as its table says, any other as the pre-computed
    /// table says.
    Hybrid {
        /// The pre-computed region's table (mesh numbering).
        precomputed: &'a PrecomputedTable<'a, T>,
        /// The tensor-mass region's table.
        dynamic: &'a TensorMassTable<'a, T>,
        /// Their interface (the vertex map).
        interface: &'a InterfaceTable<'a, T>,
    },
}

impl<T: Real> Supports<'_, T> {
    fn is_fixed(&self, vertex: VertexIndex) -> bool {
        match self {
            Self::Precomputed(t) => t.is_fixed_vertex(vertex),
            Self::TensorMass(t) => t.is_fixed_vertex(vertex),
            Self::Hybrid {
                precomputed,
                dynamic,
                interface,
            } => match interface.dynamic_vertex(vertex.as_u32()) {
                Some(d) => dynamic.is_fixed(d),
                None => precomputed.is_fixed_vertex(vertex),
            },
        }
    }
}

/// A surface to touch: vertex positions (m), the collision index over its
/// triangles (whose planes match the positions) and the supports.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceGeometry<'a, T: Real> {
    positions: &'a [[T; 3]],
    index: SurfaceIndex<'a, T>,
    supports: Supports<'a, T>,
}

/// Corners and unit outward normal of a triangle.
struct Face<T: Real> {
    vertices: [VertexIndex; 3],
    corners: [Vector3<T>; 3],
    normal: Vector3<T>,
}

/// The nearest plane the penetration test found under a sphere's centre.
struct Nearest<T> {
    /// Signed distance of the centre from the plane, m.
    distance_m: T,
    triangle: TriangleIndex,
    weights: [T; 3],
    /// Its place in the order the candidates were tested.
    order: u32,
}

/// What one pass of [`SurfaceGeometry::detect`] over the candidates does.
#[derive(Clone, Copy)]
enum Pass<T> {
    /// Around the tool: the sweep and the penetration test.
    Tool,
    /// Around the motion's start: the sweep only.
    Start,
    /// Around the tool, for [`SurfaceGeometry::centre_inside`]: the nearest
    /// plane over the centre at any distance (no sweep, no depth bound).
    Deep,
    /// Around the tool again, when more unreached planes came than
    /// [`Unreached`] keeps: is one over the centre nearer than `bound_m`,
    /// or as near and tested before the `order`-th? Then it, not the
    /// nearest plane the sphere reaches, is the nearest, and the tool is
    /// outside (beyond a thin flap, nearer its other face).
    Covered {
        /// Distance of the nearest reached plane, m.
        bound_m: T,
        /// Its place in the test order.
        order: u32,
    },
}

/// The tool sphere of a detection, as its passes read it.
#[derive(Clone, Copy)]
struct Sphere<T> {
    /// The centre and radius, m.
    to_m: Vector3<T>,
    radius_m: T,
    /// How far behind a plane the centre may lie and be found, m
    /// ([`PENETRATION_DEPTH_RADII`] radii).
    depth_m: T,
}

/// The state of one detection's passes (see [`SurfaceGeometry::detect`]).
struct Scan<'p, T> {
    /// The tool sphere (read once per list of candidates).
    sphere: Sphere<T>,
    /// The swept segment, `None` without an earlier position.
    segment: Option<[Vector3<T>; 2]>,
    /// The sweep's earliest hit: `(along, triangle, weights)`.
    hit: Option<(T, TriangleIndex, [T; 3])>,
    /// The nearest plane the sphere reaches, under the centre (not kept
    /// once `hit` is `Some`: unused then).
    reached: Option<Nearest<T>>,
    /// The planes within the depth it does not reach.
    unreached: Unreached<'p, T>,
    /// Candidates tested so far in a [`Pass::Tool`] or [`Pass::Covered`].
    order: u32,
    /// The answer of a [`Pass::Covered`].
    covered: bool,
}

/// Planes the penetration test keeps that the sphere does not reach: 16,
/// more than the longest candidate list of the built-in block, and enough
/// that the 27-cell walk of a deforming surface rarely takes the second
/// pass (with 8 the hybrid's worst 4-contact tick tested 1314 triangles,
/// 192 512 cycles instead of about 150 000: `tools/cycles-check.sh --all`).
const UNREACHED_CAPACITY: usize = 16;

/// The penetration test's planes within the depth reach that the sphere
/// does not reach (signed distance at least the radius): their nearest
/// distance, and the first [`UNREACHED_CAPACITY`] of them with their place
/// in the test order, so that the check of [`SurfaceGeometry::detect`]
/// (is one of them over the centre, nearer than the nearest reached?)
/// needs no second pass ([`Pass::Covered`]) unless more came.
struct Unreached<'p, T> {
    /// The nearest noted plane's distance, m; +∞ before the first (a
    /// noted plane lies within the depth reach: finite).
    nearest_m: T,
    /// Each kept plane's triangle and place in the test order (its
    /// distance is computed again from the stored plane, bit for bit).
    planes: &'p mut UnreachedPlanes,
    overflowed: bool,
}

/// The planes [`Unreached`] keeps: a local of its own, so that the
/// detection's state is not stored as one constant that the compiler
/// zeroes whole, this buffer with it (a `memclr` of 133 bytes a probe
/// on the Cortex-M4F).
type UnreachedPlanes = heapless::Vec<(TriangleIndex, u32), UNREACHED_CAPACITY>;

impl<'p, T: Real> Unreached<'p, T> {
    /// None noted yet, into the empty `planes`.
    fn new(planes: &'p mut UnreachedPlanes) -> Self {
        Self {
            nearest_m: T::of_f64(f64::INFINITY),
            planes,
            overflowed: false,
        }
    }

    /// Notes triangle `t`, its plane `distance_m` from the centre, the
    /// `order`-th tested.
    fn note(&mut self, t: TriangleIndex, distance_m: T, order: u32) {
        if distance_m < self.nearest_m {
            self.nearest_m = distance_m;
        }
        if self.planes.push((t, order)).is_err() {
            self.overflowed = true;
        }
    }

    /// Whether a plane `distance_m` away, the `k`-th tested, comes before
    /// the nearest reached plane (`bound_m` away, the `order`-th): nearer,
    /// or as near and tested first.
    fn nearer(distance_m: T, k: u32, bound_m: T, order: u32) -> bool {
        distance_m < bound_m || (distance_m == bound_m && k < order)
    }
}

/// Candidate triangles the 27-cell walk hands to the tests at once
/// ([`SurfaceGeometry::visit`]).
const WALK_CHUNK: usize = 32;

/// Distinct triangles one detection remembers having tested: the 27-cell
/// visit meets a triangle once per corner in those cells, and tests it
/// once. A power of two; a detection on the built-in block tests at most
/// 48 (`tools/cycles-check.sh`, the triangles tested per tick), and a
/// larger candidate set is still correct, with repeated tests beyond the
/// set's three quarters.
const VISITED_CAPACITY: usize = 128;

/// The triangles a detection has tested: an open-addressed set on the
/// stack (linear probing), filled to at most three quarters so that a
/// look-up ends after a few probes. Past that a triangle is let through
/// again, with no probe, which changes nothing: every test keeps the first
/// of equals.
struct Visited {
    slots: [u32; VISITED_CAPACITY],
    len: usize,
}

impl Visited {
    const EMPTY: u32 = u32::MAX;
    /// Most triangles remembered.
    const MAX_LEN: usize = VISITED_CAPACITY / 4 * 3;
    /// Bits of the multiplicative hash's slot index.
    const SHIFT: u32 = {
        assert!(VISITED_CAPACITY.is_power_of_two() && VISITED_CAPACITY >= 4);
        32 - VISITED_CAPACITY.trailing_zeros()
    };

    fn new() -> Self {
        Self {
            slots: [Self::EMPTY; VISITED_CAPACITY],
            len: 0,
        }
    }

    /// `true` the first time `t` is offered (or when the set is full),
    /// `false` after. At most `VISITED_CAPACITY` probes, a few at the
    /// set's load.
    fn first_visit(&mut self, t: TriangleIndex) -> bool {
        if self.len >= Self::MAX_LEN {
            return true;
        }
        let key = t.get() as u32;
        // Fibonacci hashing: the top bits of the product.
        let mut i = (key.wrapping_mul(0x9E37_79B9) >> Self::SHIFT) as usize;
        for _ in 0..VISITED_CAPACITY {
            let Some(slot) = self.slots.get_mut(i) else {
                return true;
            };
            if *slot == key {
                return false;
            }
            if *slot == Self::EMPTY {
                *slot = key;
                self.len += 1;
                return true;
            }
            i = (i + 1) % VISITED_CAPACITY;
        }
        true
    }
}

/// Weights clamped to `[0, 1]` and renormalized.
fn clamp_weights<T: Real>(w: [T; 3]) -> [T; 3] {
    let c = w.map(|x| if x > T::zero() { x } else { T::zero() });
    let sum = c[0] + c[1] + c[2];
    if sum > T::zero() {
        // One division (14 cycles on the Cortex-M4F), three products.
        let inverse = T::one() / sum;
        c.map(|x| x * inverse)
    } else {
        [T::one() / T::of_f64(3.0); 3]
    }
}

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
    /// The rest surface of a pre-computed `table`.
    pub fn new(table: &'a PrecomputedTable<'a, T>) -> Self {
        Self::of_parts(
            table.rest_positions(),
            *table.surface_index(),
            Supports::Precomputed(table),
        )
    }

    /// A surface from its parts; `index` must have been built over
    /// `positions` (its vertices index them).
    pub(crate) fn of_parts(
        positions: &'a [[T; 3]],
        index: SurfaceIndex<'a, T>,
        supports: Supports<'a, T>,
    ) -> Self {
        Self {
            positions,
            index,
            supports,
        }
    }

    /// The collision index.
    pub fn index(&self) -> &SurfaceIndex<'a, T> {
        &self.index
    }

    /// The barycentric weights of the point of triangle `t`'s plane under
    /// `x_m` (m), from its stored frame ([`SurfaceIndex::weights`]).
    #[inline(always)]
    fn weights(&self, t: TriangleIndex, x_m: &Vector3<T>) -> Option<[T; 3]> {
        self.index.weights(t, self.positions, x_m)
    }

    /// [`Self::weights`], all zero for a triangle that has left the
    /// surface: tracking's form, one copy in the firmware's flash for its
    /// two calls (the candidate tests keep theirs inline).
    #[inline(never)]
    fn tracked_weights(&self, t: TriangleIndex, x_m: &Vector3<T>) -> [T; 3] {
        self.weights(t, x_m).unwrap_or([T::zero(); 3])
    }

    /// Vertices, corners (m) and unit outward normal of a surface triangle.
    fn face(&self, triangle: TriangleIndex) -> Option<Face<T>> {
        let vertices = self.index.triangle(triangle)?;
        let mut corners = [Vector3::zeros(); 3];
        for (c, &v) in corners.iter_mut().zip(&vertices) {
            let p = self.positions.get(v.get())?;
            *c = Vector3::new(p[0], p[1], p[2]);
        }
        let (normal, _) = self.index.plane(triangle)?;
        Some(Face {
            vertices,
            corners,
            normal,
        })
    }

    /// Tool point `tool`'s contact at `weights` on `triangle`, with the
    /// sphere (radius `radius_m`) centred at `tip_m` (m); no force yet.
    fn contact(
        &self,
        tool: usize,
        triangle: TriangleIndex,
        face: &Face<T>,
        weights: [T; 3],
        tip_m: &Vector3<T>,
        radius_m: T,
    ) -> Contact<T> {
        let mut contact = Contact {
            tool,
            triangle,
            vertices: face.vertices,
            weights,
            normal: face.normal,
            point_m: Vector3::zeros(),
            tip_m: *tip_m,
            gap_m: T::zero(),
            force_n: Vector3::zeros(),
            grip_offset_m: None,
            entry_gap_m: T::zero(),
        };
        self.place(&mut contact, triangle, face, weights, tip_m, radius_m);
        contact
    }

    /// Moves `contact` to `weights` on `triangle` with the sphere (radius
    /// `radius_m`) centred at `tip_m` (m), in place: its point, normal and
    /// signed gap follow, its force is zero again; its tool, grip offset
    /// and entry gap stay.
    #[inline(always)]
    fn place(
        &self,
        contact: &mut Contact<T>,
        triangle: TriangleIndex,
        face: &Face<T>,
        weights: [T; 3],
        tip_m: &Vector3<T>,
        radius_m: T,
    ) {
        let [a, b, c] = face.corners;
        let point_m = a * weights[0] + b * weights[1] + c * weights[2];
        contact.triangle = triangle;
        contact.vertices = face.vertices;
        contact.weights = weights;
        contact.normal = face.normal;
        contact.point_m = point_m;
        contact.tip_m = *tip_m;
        contact.gap_m = (tip_m - point_m).dot(&face.normal) - radius_m;
        contact.force_n = Vector3::zeros();
    }

    /// The contact of a sphere of radius `radius_m` whose centre moved from
    /// `from_m` (`None`: no earlier position) to `to_m` (m): the first
    /// surface triangle the motion hits from outside, else the triangle it
    /// penetrates where it stands; triangles with all three vertices fixed
    /// (a rigid support, no compliance) are not touchable.
    ///
    /// Candidates, when the table's per-cell lists serve `radius_m`
    /// ([`SurfaceIndex::candidates`]): the list of `to_m`'s cell of the
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
    /// [`SurfaceIndex::max_detection_tests`] triangle tests (with the
    /// penetration test's second pass), most rejected by two dot products
    /// with the stored plane; the sweep and the penetration test share the
    /// visit at `to_m`. A candidate's barycentric weights are two more dot
    /// products, with its stored frame ([`SurfaceIndex::weights`]).
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
        let cell_of = |p: &Vector3<T>| {
            if served {
                self.index.list_cell_of(p)
            } else {
                self.index.cell_of(p)
            }
        };
        let to_cell = cell_of(to_m);
        let mut planes = UnreachedPlanes::new();
        let mut scan = Scan {
            sphere: Sphere {
                to_m: *to_m,
                radius_m,
                depth_m: radius_m * T::of_f64(PENETRATION_DEPTH_RADII),
            },
            segment: None,
            hit: None,
            reached: None,
            unreached: Unreached::new(&mut planes),
            order: 0,
            covered: false,
        };
        // The sweep's start and its cell, when it lies within the reach
        // and not in the tool's cell; whether the motion is short. Written
        // into `scan` where they are found (no intermediate record: each
        // copy of the segment is a dozen stores on the firmware target).
        let mut start = None;
        let mut short = true;
        if let Some(from_m) = from_m {
            let from_in = within(from_m, &reach);
            let from_cell = cell_of(from_m);
            let ([a, b, c], [x, y, z]) = (from_cell, to_cell);
            // Corner by corner: an array comparison is a `memcmp` call on
            // the firmware target.
            let same_cell = a == x && b == y && c == z;
            // The swept segment, clipped to the reach of the grid when
            // exactly one end lies outside it (both outside: no candidate).
            scan.segment = Some(match (from_in, to_in) {
                (false, true) => [clip_towards(to_m, from_m, &reach), *to_m],
                (true, false) => [*from_m, clip_towards(from_m, to_m, &reach)],
                _ => [*from_m, *to_m],
            });
            // A motion between neighbouring cells within the reach: the
            // lists of the cells between its ends hold every triangle the
            // walk would meet (a longer one walks).
            let near = a.abs_diff(x) <= 1 && b.abs_diff(y) <= 1 && c.abs_diff(z) <= 1;
            short = from_in && to_in && near;
            if !same_cell && from_in {
                start = Some((*from_m, from_cell));
            }
        }
        let lists = (served && short).then(|| self.index.candidates_at(to_cell));
        match lists {
            Some(list) => {
                if to_in {
                    self.visit_triangles(list.as_slice(), work, Pass::Tool, &mut scan);
                }
                if let Some((_, from_cell)) = &start {
                    // The lists serve this radius and the motion is short:
                    // its ends lie within the reach, unclipped.
                    self.index
                        .for_each_candidate_list_between(*from_cell, to_cell, |list| {
                            self.visit_triangles(list.as_slice(), work, Pass::Start, &mut scan)
                        });
                }
            }
            None => {
                let mut visited = Visited::new();
                if to_in {
                    self.visit(to_m, &mut visited, work, Pass::Tool, &mut scan);
                }
                if let Some((from_m, _)) = &start {
                    self.visit(from_m, &mut visited, work, Pass::Start, &mut scan);
                }
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
        let unreached = &scan.unreached;
        // Every note keeps its plane or overflows a full list.
        let noted = !unreached.planes.is_empty();
        if noted && unreached.nearest_m <= bound_m {
            let covered = if scan.unreached.overflowed {
                // The second pass, over the same candidates in the same order.
                scan.order = 0;
                let pass = Pass::Covered { bound_m, order };
                match lists {
                    Some(list) => self.visit_triangles(list.as_slice(), work, pass, &mut scan),
                    None => self.visit(to_m, &mut Visited::new(), work, pass, &mut scan),
                }
                scan.covered
            } else {
                scan.unreached.planes.iter().any(|&(t, k)| {
                    self.index.plane(t).is_some_and(|(normal, offset)| {
                        let distance = normal.dot(to_m) - offset;
                        Unreached::nearer(distance, k, bound_m, order) && self.over(t, to_m)
                    })
                })
            };
            if covered {
                return None;
            }
        }
        Some((triangle, weights, true))
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
    /// [`SurfaceIndex::max_query_triangles`]; the grid's cell is at least
    /// the longest surface edge, so a centre within a cell of the surface
    /// sees the faces over it), the one with the nearest plane over the
    /// centre (its projection inside the triangle) decides:
    /// `Some(true)` when the centre lies behind it (inside the body),
    /// `Some(false)` in front of it, or for a centre beyond the grid's
    /// reach (outside every face's box by more than a cell); `None` when no
    /// plane there lies over the centre (deeper in a body than a grid cell,
    /// or in a cavity wider than one): the surface near the tool does not
    /// say.
    pub fn centre_inside(
        &self,
        to_m: &Vector3<T>,
        radius_m: T,
        work: &mut ContactWork,
    ) -> Option<bool> {
        if !within(to_m, &self.index.reach(radius_m)) {
            return Some(false);
        }
        let mut planes = UnreachedPlanes::new();
        let mut scan = Scan {
            sphere: Sphere {
                to_m: *to_m,
                radius_m,
                depth_m: T::zero(),
            },
            segment: None,
            hit: None,
            reached: None,
            unreached: Unreached::new(&mut planes),
            order: 0,
            covered: false,
        };
        self.visit(to_m, &mut Visited::new(), work, Pass::Deep, &mut scan);
        scan.reached.map(|nearest| nearest.distance_m < T::zero())
    }

    /// Runs `pass` of `scan` once for each surface triangle around the
    /// surface vertices in the 27 grid cells around `around` (m) that
    /// `visited` has not met; a triangle is around up to three of the
    /// vertices, and is tested at the first. The walk hands them to the
    /// tests [`WALK_CHUNK`] at a time, in its order.
    fn visit(
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
    fn visit_triangles(
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
    fn over(&self, t: TriangleIndex, tip_m: &Vector3<T>) -> bool {
        self.weights(t, tip_m)
            .is_some_and(|w| w.iter().all(|&wi| wi >= -T::WEIGHT_TOLERANCE))
    }

    /// Moves `contact` with a sphere now at `tip_m` (m): the projection of
    /// the sphere's lowest point `tip − r n` onto the surface, walking to
    /// the neighbouring triangle across any edge it falls outside of (at
    /// most [`MAX_WALK_STEPS`]; never straight back, which over a concave
    /// fold would swing between the two triangles). Moves `contact` in
    /// place (no copy of it), with its signed gap (negative while the
    /// sphere penetrates), and returns `true`. A held contact
    /// ([`Contact::grip_offset_m`]) keeps its triangle and weights (its
    /// point is where the surface has them now). `false`, with `contact`
    /// unchanged, when the triangle has left the surface (a cut or a tear
    /// removed its tet).
    pub fn track(
        &self,
        contact: &mut Contact<T>,
        tip_m: &Vector3<T>,
        radius_m: T,
        work: &mut ContactWork,
    ) -> bool {
        let tolerance = T::WEIGHT_TOLERANCE;
        let mut triangle = contact.triangle;
        let Some(mut face) = self.face(triangle) else {
            return false;
        };
        if contact.grip_offset_m.is_some() {
            self.place(contact, triangle, &face, contact.weights, tip_m, radius_m);
            return true;
        }
        let mut came_from = None;
        // The weights on the current triangle (each step moves to the next
        // and weighs again).
        let mut w = self.tracked_weights(triangle, tip_m);
        for _ in 0..MAX_WALK_STEPS {
            let Some(out) = (0..3).find(|&i| w.get(i).is_some_and(|&x| x < -tolerance)) else {
                break;
            };
            // Cross the edge opposite corner `out` to the triangle sharing it.
            let (Some(&j), Some(&k)) = (
                face.vertices.get((out + 1) % 3),
                face.vertices.get((out + 2) % 3),
            ) else {
                break;
            };
            let shared = self.index.across(triangle, j, k);
            // Back where it came from: the point lies over a concave fold
            // between the two (a dimple's valley); stay, clamped to the edge.
            if shared == came_from {
                break;
            }
            let Some(next) = shared.and_then(|t| self.face(t).map(|f| (t, f))) else {
                break;
            };
            work.walk_steps = work.walk_steps.saturating_add(1);
            came_from = Some(triangle);
            (triangle, face) = next;
            w = self.tracked_weights(triangle, tip_m);
        }
        self.place(contact, triangle, &face, clamp_weights(w), tip_m, radius_m);
        true
    }
}
