//! The state of one detection's passes over the candidate triangles
//! ([`SurfaceGeometry::detect`]): the tool sphere, the sweep's earliest hit,
//! the nearest plane the sphere reaches, the planes it does not reach, and
//! the triangles a 27-cell walk has tested.

use nalgebra::Vector3;

use crate::Real;
use crate::table::TriangleIndex;

/// The nearest plane the penetration test found under a sphere's centre.
pub(super) struct Nearest<T> {
    /// Signed distance of the centre from the plane, m.
    pub(super) distance_m: T,
    pub(super) triangle: TriangleIndex,
    pub(super) weights: [T; 3],
    /// Its place in the order the candidates were tested.
    pub(super) order: u32,
}

/// What one pass of [`SurfaceGeometry::detect`] over the candidates does.
#[derive(Clone, Copy)]
pub(super) enum Pass<T> {
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
pub(super) struct Sphere<T> {
    /// The centre and radius, m.
    pub(super) to_m: Vector3<T>,
    pub(super) radius_m: T,
    /// How far behind a plane the centre may lie and be found, m
    /// ([`PENETRATION_DEPTH_RADII`] radii).
    pub(super) depth_m: T,
}

/// The state of one detection's passes (see [`SurfaceGeometry::detect`]).
pub(super) struct Scan<'p, T> {
    /// The tool sphere (read once per list of candidates).
    pub(super) sphere: Sphere<T>,
    /// The swept segment, `None` without an earlier position.
    pub(super) segment: Option<[Vector3<T>; 2]>,
    /// The sweep's earliest hit: `(along, triangle, weights)`.
    pub(super) hit: Option<(T, TriangleIndex, [T; 3])>,
    /// The nearest plane the sphere reaches, under the centre (not kept
    /// once `hit` is `Some`: unused then).
    pub(super) reached: Option<Nearest<T>>,
    /// The planes within the depth it does not reach.
    pub(super) unreached: Unreached<'p, T>,
    /// Candidates tested so far in a [`Pass::Tool`] or [`Pass::Covered`].
    pub(super) order: u32,
    /// The answer of a [`Pass::Covered`].
    pub(super) covered: bool,
}

impl<'p, T: Real> Scan<'p, T> {
    /// A detection's state before its first pass: the tool `sphere`, no
    /// segment, hit nor reached plane, and none noted into the empty
    /// `planes`.
    #[inline(always)]
    pub(super) fn new(sphere: Sphere<T>, planes: &'p mut UnreachedPlanes) -> Self {
        Self {
            sphere,
            segment: None,
            hit: None,
            reached: None,
            unreached: Unreached::new(planes),
            order: 0,
            covered: false,
        }
    }
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
pub(super) struct Unreached<'p, T> {
    /// The nearest noted plane's distance, m; +∞ before the first (a
    /// noted plane lies within the depth reach: finite).
    pub(super) nearest_m: T,
    /// Each kept plane's triangle and place in the test order (its
    /// distance is computed again from the stored plane, bit for bit).
    pub(super) planes: &'p mut UnreachedPlanes,
    pub(super) overflowed: bool,
}

/// The planes [`Unreached`] keeps: a local of its own, so that the
/// detection's state is not stored as one constant that the compiler
/// zeroes whole, this buffer with it (a `memclr` of 133 bytes a probe
/// on the Cortex-M4F).
pub(super) type UnreachedPlanes = heapless::Vec<(TriangleIndex, u32), UNREACHED_CAPACITY>;

impl<'p, T: Real> Unreached<'p, T> {
    /// None noted yet, into the empty `planes`.
    pub(super) fn new(planes: &'p mut UnreachedPlanes) -> Self {
        Self {
            nearest_m: T::of_f64(f64::INFINITY),
            planes,
            overflowed: false,
        }
    }

    /// Notes triangle `t`, its plane `distance_m` from the centre, the
    /// `order`-th tested.
    pub(super) fn note(&mut self, t: TriangleIndex, distance_m: T, order: u32) {
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
    pub(super) fn nearer(distance_m: T, k: u32, bound_m: T, order: u32) -> bool {
        distance_m < bound_m || (distance_m == bound_m && k < order)
    }
}

/// Candidate triangles the 27-cell walk hands to the tests at once
/// ([`SurfaceGeometry::visit`]).
pub(super) const WALK_CHUNK: usize = 32;

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
pub(super) struct Visited {
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

    pub(super) fn new() -> Self {
        Self {
            slots: [Self::EMPTY; VISITED_CAPACITY],
            len: 0,
        }
    }

    /// `true` the first time `t` is offered (or when the set is full),
    /// `false` after. At most `VISITED_CAPACITY` probes, a few at the
    /// set's load.
    pub(super) fn first_visit(&mut self, t: TriangleIndex) -> bool {
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
