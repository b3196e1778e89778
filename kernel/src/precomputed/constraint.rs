//! What the pre-computed solve takes (MODELS.md §2): a point of the surface
//! and the displacement imposed on it ([`AsConstraint`], implemented by a
//! scripted [`Constraint`] and by the haptic path's
//! [`crate::contact::Contact`]), its validation against a table, and the
//! errors of a contact set.

use core::fmt;

use nalgebra::Vector3;

use crate::Real;
use crate::contact::Contact;
use crate::table::{FreeIndex, PrecomputedTable, VertexIndex, VertexSlot};

/// Where a contact acts on the surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ContactPoint<T> {
    /// A touchable (free, boundary-surface) vertex, by mesh vertex index.
    Vertex(u32),
    /// A point on a surface triangle: its three mesh vertices and barycentric
    /// weights (each in `[0, 1]`, summing to 1, within
    /// [`Real::WEIGHT_TOLERANCE`]). A fixed vertex of the triangle contributes
    /// zero compliance (its displacement is zero), which is the exact
    /// constraint `Σ_a β_a u_a = d`. The three vertices must be distinct and
    /// form a triangle of the table's boundary surface, in any order
    /// ([`ContactError::RepeatedVertex`], [`ContactError::NotSurfaceTriangle`]):
    /// a point elsewhere is not on the surface a tool can touch.
    Triangle {
        /// Mesh vertex indices.
        vertices: [u32; 3],
        /// Barycentric weights `β_a`.
        weights: [T; 3],
    },
}

/// A contact as the pre-computed solve sees it: a point of the surface and
/// the displacement `d_p` the tool imposes on it.
pub trait AsConstraint<T: Real> {
    /// Where the tool touches.
    fn point(&self) -> ContactPoint<T>;
    /// Imposed displacement `d_p` of the point from rest, m.
    fn displacement_m(&self) -> Vector3<T>;
    /// The contact as detection or tracking made it on this table's
    /// surface (the haptic path): its triangle's corners are checked
    /// indices of a surface triangle and its weights the clamped ones of
    /// detection, so the solve resolves it from them without
    /// the raw-index checks and the surface look-up of
    /// [`ContactError::NotSurfaceTriangle`]. Scripted input keeps the
    /// default, `None`, and is checked in full.
    fn detected(&self) -> Option<&Contact<T>> {
        None
    }
}

/// A scripted constraint: a point and the displacement imposed on it (the
/// `precomputed solve`/`replay` commands and the firmware's sequences).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Constraint<T: Real> {
    /// Where the tool touches.
    pub point: ContactPoint<T>,
    /// Imposed displacement `d_p` of the point from rest, m.
    pub displacement_m: Vector3<T>,
}

impl<T: Real> AsConstraint<T> for Constraint<T> {
    fn point(&self) -> ContactPoint<T> {
        self.point
    }

    fn displacement_m(&self) -> Vector3<T> {
        self.displacement_m
    }
}

/// A haptic contact imposes `gap · normal` on its triangle point.
impl<T: Real> AsConstraint<T> for Contact<T> {
    fn point(&self) -> ContactPoint<T> {
        ContactPoint::Triangle {
            vertices: self.vertices.map(VertexIndex::as_u32),
            weights: self.weights,
        }
    }

    fn displacement_m(&self) -> Vector3<T> {
        Contact::displacement_m(self)
    }

    /// A contact is made by detection or tracking on the tissue's surface:
    /// its triangle is one of the surface's.
    fn detected(&self) -> Option<&Contact<T>> {
        Some(self)
    }
}

/// A constraint held elsewhere (the haptic loop's contacts, lent to the
/// solve: [`crate::contact::ContactRefs`]).
impl<T: Real, C: AsConstraint<T>> AsConstraint<T> for &mut C {
    fn point(&self) -> ContactPoint<T> {
        (**self).point()
    }

    fn displacement_m(&self) -> Vector3<T> {
        (**self).displacement_m()
    }

    fn detected(&self) -> Option<&Contact<T>> {
        (**self).detected()
    }
}

impl<T: Real> Constraint<T> {
    /// A contact at a touchable vertex.
    pub fn at_vertex(vertex: u32, displacement_m: Vector3<T>) -> Self {
        Self {
            point: ContactPoint::Vertex(vertex),
            displacement_m,
        }
    }

    /// A contact at a point of a surface triangle.
    pub fn on_triangle(vertices: [u32; 3], weights: [T; 3], displacement_m: Vector3<T>) -> Self {
        Self {
            point: ContactPoint::Triangle { vertices, weights },
            displacement_m,
        }
    }
}

/// Why a contact set was refused. `contact` is the index in the caller's slice.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContactError {
    /// More contacts than the compile-time capacity `M`.
    TooManyContacts {
        /// Contacts given.
        given: usize,
        /// Capacity `M`.
        capacity: usize,
    },
    /// A vertex index beyond the mesh.
    VertexOutOfRange {
        /// Contact index.
        contact: usize,
        /// The vertex.
        vertex: u32,
    },
    /// A vertex contact on a fixed vertex: it cannot move, no force can be
    /// defined.
    FixedVertex {
        /// Contact index.
        contact: usize,
        /// The vertex.
        vertex: u32,
    },
    /// A free vertex that is not on the boundary surface (not touchable).
    NotOnSurface {
        /// Contact index.
        contact: usize,
        /// The vertex.
        vertex: u32,
    },
    /// A triangle contact names the same vertex twice (no triangle has a
    /// repeated corner).
    RepeatedVertex {
        /// Contact index.
        contact: usize,
        /// The repeated vertex.
        vertex: u32,
    },
    /// A triangle contact's three vertices are not a triangle of the
    /// table's boundary surface (checked through the collision index: at
    /// most the valence of the first vertex in triangle look-ups).
    NotSurfaceTriangle {
        /// Contact index.
        contact: usize,
        /// The three vertices, as given.
        vertices: [u32; 3],
    },
    /// Barycentric weights outside `[0, 1]` or not summing to one.
    BadWeights {
        /// Contact index.
        contact: usize,
    },
    /// A NaN or infinite displacement or weight.
    NonFiniteInput {
        /// Contact index.
        contact: usize,
    },
    /// Two vertex contacts on the same vertex: the system would be singular.
    DuplicateContact {
        /// First contact index.
        first: usize,
        /// Second contact index.
        second: usize,
    },
    /// The contact system is singular or too ill-conditioned for the scalar
    /// (a Cholesky pivot below [`Real::MIN_PIVOT_RATIO`] of the largest
    /// diagonal compliance), e.g. two contacts at the same point, or a point
    /// whose weight is all on fixed vertices.
    IllConditioned {
        /// Contact index at which factorization failed.
        contact: usize,
    },
    /// The solve produced a non-finite force (not reachable with a valid table
    /// and finite input; kept so no wrong force can leave).
    NonFiniteResult,
}

impl ContactError {
    /// The index of the contact this error names (the one to drop), if
    /// any.
    pub fn contact(&self) -> Option<usize> {
        match *self {
            ContactError::VertexOutOfRange { contact, .. }
            | ContactError::FixedVertex { contact, .. }
            | ContactError::NotOnSurface { contact, .. }
            | ContactError::RepeatedVertex { contact, .. }
            | ContactError::NotSurfaceTriangle { contact, .. }
            | ContactError::BadWeights { contact }
            | ContactError::NonFiniteInput { contact }
            | ContactError::IllConditioned { contact } => Some(contact),
            ContactError::DuplicateContact { second, .. } => Some(second),
            ContactError::TooManyContacts { .. } | ContactError::NonFiniteResult => None,
        }
    }
}

impl fmt::Display for ContactError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            ContactError::TooManyContacts { given, capacity } => {
                write!(f, "{given} contacts exceed the capacity of {capacity}")
            }
            ContactError::VertexOutOfRange { contact, vertex } => {
                write!(f, "contact {contact}: vertex {vertex} out of range")
            }
            ContactError::FixedVertex { contact, vertex } => {
                write!(f, "contact {contact}: vertex {vertex} is fixed")
            }
            ContactError::NotOnSurface { contact, vertex } => write!(
                f,
                "contact {contact}: vertex {vertex} is not on the boundary surface"
            ),
            ContactError::RepeatedVertex { contact, vertex } => write!(
                f,
                "contact {contact}: vertex {vertex} appears twice; a triangle contact needs three distinct vertices"
            ),
            ContactError::NotSurfaceTriangle {
                contact,
                vertices: [a, b, c],
            } => write!(
                f,
                "contact {contact}: vertices {a},{b},{c} are not a triangle of the table's boundary surface"
            ),
            ContactError::BadWeights { contact } => write!(
                f,
                "contact {contact}: barycentric weights must lie in [0, 1] and sum to 1"
            ),
            ContactError::NonFiniteInput { contact } => {
                write!(f, "contact {contact}: non-finite displacement or weight")
            }
            ContactError::DuplicateContact { first, second } => {
                write!(f, "contacts {first} and {second} are on the same vertex")
            }
            ContactError::IllConditioned { contact } => write!(
                f,
                "contact system singular or ill-conditioned at contact {contact}"
            ),
            ContactError::NonFiniteResult => {
                f.write_str("contact solve produced a non-finite force")
            }
        }
    }
}

impl core::error::Error for ContactError {}

/// A contact point resolved against a table: up to three touchable free
/// indices with weights. Fixed vertices (zero compliance) are dropped.
/// Invariant: the entries past `len` are [`Self::empty`]'s (touchable
/// index 0, weight zero).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ResolvedPoint<T> {
    pub(crate) touchable: [FreeIndex; 3],
    pub(crate) weights: [T; 3],
    pub(crate) len: usize,
}

impl<T: Real> ResolvedPoint<T> {
    /// A point with no term.
    pub(crate) fn empty() -> Self {
        Self {
            // Placeholders past `len`: `terms` stops there; the point
            // compliance reads them, with their zero weight.
            touchable: [FreeIndex::checked(0); 3],
            weights: [T::zero(); 3],
            len: 0,
        }
    }

    /// Appends the term `(touchable, weight)` (none past three).
    fn push(&mut self, touchable: FreeIndex, weight: T) {
        if let (Some(t), Some(b)) = (
            self.touchable.get_mut(self.len),
            self.weights.get_mut(self.len),
        ) {
            *t = touchable;
            *b = weight;
            self.len += 1;
        }
    }

    /// The `(touchable index, weight)` pairs, at most three.
    pub(crate) fn terms(&self) -> impl Iterator<Item = (FreeIndex, T)> + '_ {
        self.touchable
            .iter()
            .copied()
            .zip(self.weights.iter().copied())
            .take(self.len)
    }
}

/// Validates contact `index` against `table` (see [`ContactError`]): its
/// displacement, then a detected contact's point from its checked indices
/// ([`AsConstraint::detected`]), any other's in full.
pub(crate) fn resolve<T: Real>(
    table: &PrecomputedTable<'_, T>,
    index: usize,
    contact: &impl AsConstraint<T>,
) -> Result<ResolvedPoint<T>, ContactError> {
    if !contact.displacement_m().iter().all(|x| x.finite()) {
        return Err(ContactError::NonFiniteInput { contact: index });
    }
    match contact.detected() {
        Some(detected) => resolve_detected(table, index, detected),
        None => resolve_point(table, index, contact.point()),
    }
}

/// A detected contact's point ([`AsConstraint::detected`]): each corner's
/// slot read with its checked index (no range check of a raw index, no
/// repeated-corner or surface look-up: the corners are those of a surface
/// triangle). Its weights are detection's, clamped to `[0, 1]` and
/// normalized, finite when its displacement is (which [`resolve`]
/// checked); of the full weight checks, only the sum can fail for them
/// (all zero, when the clamp's sum overflowed), and only it is made. The
/// same point, or the same error, as [`resolve_point`] gives such a
/// contact.
fn resolve_detected<T: Real>(
    table: &PrecomputedTable<'_, T>,
    index: usize,
    contact: &Contact<T>,
) -> Result<ResolvedPoint<T>, ContactError> {
    if !sums_to_one(&contact.weights) {
        return Err(ContactError::BadWeights { contact: index });
    }
    let mut point = ResolvedPoint::empty();
    for (&vertex, &w) in contact.vertices.iter().zip(contact.weights.iter()) {
        let slot = table.vertex_slot_of(vertex);
        if let Some(free) = touchable(table, index, vertex.as_u32(), slot)? {
            point.push(free, w);
        }
    }
    Ok(point)
}

/// A point given from outside (a scripted constraint), checked in full:
/// weights finite, each in `[0, 1]` and summing to one, vertices in range,
/// distinct, touchable or fixed, and a triangle of the table's surface.
fn resolve_point<T: Real>(
    table: &PrecomputedTable<'_, T>,
    index: usize,
    given: ContactPoint<T>,
) -> Result<ResolvedPoint<T>, ContactError> {
    let contact_index = index;
    let lookup = |vertex: u32| touchable(table, contact_index, vertex, table.slot(vertex));
    let mut point = ResolvedPoint::empty();
    match given {
        ContactPoint::Vertex(vertex) => {
            let slot = lookup(vertex)?.ok_or(ContactError::FixedVertex {
                contact: contact_index,
                vertex,
            })?;
            point.touchable[0] = slot;
            point.weights[0] = T::one();
            point.len = 1;
        }
        ContactPoint::Triangle { vertices, weights } => {
            if !weights.iter().all(|w| w.finite()) {
                return Err(ContactError::NonFiniteInput {
                    contact: contact_index,
                });
            }
            let tol = T::WEIGHT_TOLERANCE;
            let in_range = weights.iter().all(|&w| w >= -tol && w <= T::one() + tol);
            if !in_range || !sums_to_one(&weights) {
                return Err(ContactError::BadWeights {
                    contact: contact_index,
                });
            }
            if let Some(vertex) = repeated(vertices) {
                return Err(ContactError::RepeatedVertex {
                    contact: contact_index,
                    vertex,
                });
            }
            for (&vertex, &w) in vertices.iter().zip(weights.iter()) {
                if let Some(slot) = lookup(vertex)? {
                    point.push(slot, w);
                }
            }
            // Every vertex is in range here (`lookup` refused the others).
            let on_surface = match vertices.map(|v| table.vertex(v)) {
                [Some(a), Some(b), Some(c)] => {
                    table.surface_index().find_triangle([a, b, c]).is_some()
                }
                _ => false,
            };
            if !on_surface {
                return Err(ContactError::NotSurfaceTriangle {
                    contact: contact_index,
                    vertices,
                });
            }
        }
    }
    Ok(point)
}

/// The touchable free index of `vertex` of contact `contact`, given its
/// `slot` in `table` (`None`: out of range); `None` for a fixed vertex
/// (zero compliance).
fn touchable<T: Real>(
    table: &PrecomputedTable<'_, T>,
    contact: usize,
    vertex: u32,
    slot: Option<VertexSlot>,
) -> Result<Option<FreeIndex>, ContactError> {
    match slot {
        None => Err(ContactError::VertexOutOfRange { contact, vertex }),
        Some(VertexSlot::Fixed) => Ok(None),
        Some(VertexSlot::Free(i)) if i.get() < table.touchable_count() => Ok(Some(i)),
        Some(VertexSlot::Free(_)) => Err(ContactError::NotOnSurface { contact, vertex }),
    }
}

/// `Σ_a β_a` within [`Real::WEIGHT_TOLERANCE`] of one (`false` for a NaN).
fn sums_to_one<T: Real>(weights: &[T; 3]) -> bool {
    let sum = weights.iter().fold(T::zero(), |a, &w| a + w);
    (sum - T::one()).abs() <= T::WEIGHT_TOLERANCE
}

/// The first vertex that occurs twice in `vertices`, if any.
fn repeated(vertices: [u32; 3]) -> Option<u32> {
    let [a, b, c] = vertices;
    if a == b || a == c {
        Some(a)
    } else if b == c {
        Some(b)
    } else {
        None
    }
}
