//! The one contact type of the haptic path and its bounded set (MODELS.md
//! §6): detection and tracking create a [`Contact`] on the tissue's surface,
//! the loop hands the active ones to the tissue's solve as a
//! [`ContactRefs`] (its own records, not copies), the solve writes each
//! one's force, and the loop sums them for the supervisor. A physics
//! update takes them as a [`ContactSet`] of copies.

use nalgebra::Vector3;

use crate::Real;
use crate::table::{TriangleIndex, VertexIndex};

/// A tool point touching a surface triangle, from detection to force.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact<T> {
    /// The tool point (index into the loop's tool points).
    pub tool: usize,
    /// The surface triangle (checked index into the surface's triangles).
    pub triangle: TriangleIndex,
    /// Its mesh vertices (checked indices of the surface's vertices).
    pub vertices: [VertexIndex; 3],
    /// Barycentric weights of the contact point, each in `[0, 1]`, summing
    /// to 1.
    pub weights: [T; 3],
    /// Unit outward normal of the triangle.
    pub normal: Vector3<T>,
    /// The contact point on the surface, m.
    pub point_m: Vector3<T>,
    /// The tool sphere's centre, m.
    pub tip_m: Vector3<T>,
    /// Signed gap between the tool sphere and the contact point along the
    /// normal, `(tip − point)·n − r`, m (negative while the sphere
    /// penetrates): the contact point's imposed displacement is
    /// `gap · normal`.
    pub gap_m: T,
    /// Force the tool applies to the tissue here, N, written by the
    /// tissue's solve into the loop's record (zero from detection or
    /// tracking until the tick's solve; `force · normal > 0` is adhesive:
    /// the tool would pull, which only a grip may).
    pub force_n: Vector3<T>,
    /// `Some` while a grasper's jaw holds the contact point (MODELS.md §6):
    /// the offset `tip − target` from the point's held position to the
    /// tool sphere's centre, m, fixed when the grip closed. A held point
    /// stays at its barycentric place on its triangle and follows the tool
    /// in all three directions: pulling transmits force.
    pub grip_offset_m: Option<Vector3<T>>,
    /// The signed gap when the contact was made, m: zero when the sphere's
    /// motion crossed the surface, the penetration when the sphere was
    /// found already inside (the surface moved onto it). A model that
    /// extrapolates from the tool's motion counts it from here, so a
    /// contact found inside starts from zero force instead of a jump.
    pub entry_gap_m: T,
}

impl<T: Real> Contact<T> {
    /// The displacement to impose on the contact point from where the
    /// surface has it (`point_m`), m: `gap · normal` onto the tool sphere,
    /// or for a held point the way to its held position
    /// `tip − grip_offset − point`.
    pub fn displacement_m(&self) -> Vector3<T> {
        match self.grip_offset_m {
            Some(offset) => self.tip_m - offset - self.point_m,
            None => self.normal * self.gap_m,
        }
    }

    /// Holds this contact where it is now: from here on the contact point
    /// keeps its place on the triangle and its offset from the tool
    /// sphere's centre (the grip continues the imposed displacement
    /// `gap · normal` of the surface's triangle as it stands; a model that
    /// imposes along another normal, such as the dynamic tissue's rest
    /// normal, sees a step of about `|gap|` times the tilt between them).
    pub fn grip(&mut self) {
        self.grip_offset_m = Some(self.tip_m - self.point_m - self.normal * self.gap_m);
    }
}

/// At most `M` contacts, in tool-point order, copied: what a physics update
/// takes (the solve takes the loop's records themselves, [`ContactRefs`];
/// `heapless::Vec`: capacity a const generic, pushes beyond it refused,
/// never a panic).
pub type ContactSet<T, const M: usize> = heapless::Vec<Contact<T>, M>;

/// At most `M` contacts held where they are, in tool-point order: the set a
/// tissue's solve writes the forces of ([`super::Tissue::solve`]). The
/// haptic loop lends its own records: a copied set is 104 bytes a contact
/// copied every tick, 150 cycles each on the Cortex-M4F.
pub type ContactRefs<'c, T, const M: usize> = heapless::Vec<&'c mut Contact<T>, M>;

/// The first `M` of `contacts`, lent as a [`ContactRefs`] (the rest are
/// left out: the callers hold at most `M`).
pub fn lend<'c, T: Real, const M: usize>(
    contacts: impl IntoIterator<Item = &'c mut Contact<T>>,
) -> ContactRefs<'c, T, M> {
    let mut set = ContactRefs::new();
    for c in contacts.into_iter().take(M) {
        // At most `M`: room.
        let _ = set.push(c);
    }
    set
}
