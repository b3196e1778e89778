//! A surface triangle's stored plane and barycentric frame (layout:
//! [`super::format::SectionKind::SurfacePlane`]): the one record the
//! collision index reads ([`parts_of`]) and the builder writes
//! ([`plane_record`]).

use nalgebra::Vector3;

use super::format::PLANE_LEN;
use crate::Real;

/// A surface triangle's stored plane and barycentric frame (layout:
/// [`super::format::SectionKind::SurfacePlane`]).
pub type Plane<T> = [T; PLANE_LEN];

/// The unit normal, offset (m) and barycentric gradients `g₁`, `g₂` (1/m)
/// of a stored plane (layout: [`super::format::SectionKind::SurfacePlane`]).
#[inline(always)]
pub(crate) fn parts_of<T: Real>(plane: &Plane<T>) -> (Vector3<T>, T, [Vector3<T>; 2]) {
    let [nx, ny, nz, d, g1x, g1y, g1z, g2x, g2y, g2z] = *plane;
    (
        Vector3::new(nx, ny, nz),
        d,
        [Vector3::new(g1x, g1y, g1z), Vector3::new(g2x, g2y, g2z)],
    )
}

/// A stored plane of unit normal `normal`, offset `offset_m` (m) and
/// barycentric gradients `g` (1/m): the inverse of [`parts_of`].
pub(crate) fn plane_record<T: Real>(
    normal: &Vector3<T>,
    offset_m: T,
    g: &[Vector3<T>; 2],
) -> Plane<T> {
    let [g1, g2] = g;
    [
        normal.x, normal.y, normal.z, offset_m, g1.x, g1.y, g1.z, g2.x, g2.y, g2.z,
    ]
}
