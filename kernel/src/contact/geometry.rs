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

mod detect;
mod passes;
mod scan;
mod track;

use nalgebra::Vector3;

use super::Contact;
use crate::Real;
use crate::table::{
    InterfaceTable, PrecomputedTable, SurfaceIndex, TensorMassTable, TriangleIndex, VertexIndex,
    corners_of,
};

pub use detect::PENETRATION_DEPTH_RADII;
pub use track::MAX_WALK_STEPS;

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
        let corners = corners_of(self.positions, &vertices.map(|v| v.as_u32()))?;
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
}
