//! Validated indices: what the views hand out after load, so the step path
//! indexes with checked types and never sees the byte format's sentinels
//! ([`super::format::FIXED_SLOT`], [`super::format::NO_NEIGHBOUR`]).
//!
//! Each index is a `u32` (the format's width) known to be below a count of
//! the table it came from. The kernel makes them only on the loader's
//! checked paths (a section validated at load, or a lookup that compared
//! against the count); anyone else makes one with the fallible `new(value,
//! bound)`. An index of one table used on another is not a panic either:
//! the step path still reads with `.get()`, so it finds nothing.

use core::ops::Range;

// `get` widens `u32` to `usize`: lossless on every target the kernel builds
// for (thumbv7em and 64-bit hosts).
const _: () = assert!(usize::BITS >= u32::BITS);

/// Defines a validated index type (docs given by the caller).
macro_rules! index_type {
    ($(#[$doc:meta])* $name:ident) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
        pub struct $name(u32);

        impl $name {
            /// `value` if it is below `bound` (a count of the table it
            /// indexes), `None` otherwise.
            pub fn new(value: u32, bound: usize) -> Option<Self> {
                // A bound beyond `u32::MAX` admits every `u32`.
                u32::try_from(bound)
                    .map_or(true, |b| value < b)
                    .then_some(Self(value))
            }

            /// An index the loader has checked (or built) to be in range.
            #[inline(always)]
            pub(crate) fn checked(value: u32) -> Self {
                Self(value)
            }

            /// The index, for slicing.
            #[inline(always)]
            pub fn get(self) -> usize {
                self.0 as usize
            }

            /// The index as stored (`u32`).
            #[inline(always)]
            pub fn as_u32(self) -> u32 {
                self.0
            }
        }

        impl From<$name> for u32 {
            fn from(index: $name) -> u32 {
                index.0
            }
        }
    };
}

index_type! {
    /// Index of a free (not fixed) vertex of a pre-computed table: the row of
    /// its compliance blocks. `0..S` are the touchable vertices (free, on the
    /// boundary surface), then the interior ones. Only a validated table makes
    /// one, so it is always `< F`.
    FreeIndex
}

index_type! {
    /// Index of a mesh vertex of a validated table: `< N`, a row of the rest
    /// positions (and of every per-vertex state buffer).
    VertexIndex
}

index_type! {
    /// Index of a boundary-surface triangle of a validated table (or of the
    /// triangles a collision index was built over): a row of the surface
    /// triangles and of the collision planes.
    TriangleIndex
}

index_type! {
    /// Index of a tetrahedron of a validated tensor-mass table: `< M`.
    TetIndex
}

index_type! {
    /// Index of an edge `(i, j)`, `i < j`, of a validated tensor-mass table:
    /// `< E`, a row of the edge tensors and edge terms.
    EdgeIndex
}

/// Where a vertex stands in a pre-computed table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VertexSlot {
    /// A free vertex, with its free index.
    Free(FreeIndex),
    /// Held at zero displacement (a Dirichlet vertex).
    Fixed,
}

impl VertexSlot {
    /// The slot a section entry encodes ([`super::format::FIXED_SLOT`] or a
    /// free index the loader has checked).
    pub(crate) fn of_entry(entry: u32) -> Self {
        if entry == super::format::FIXED_SLOT {
            Self::Fixed
        } else {
            Self::Free(FreeIndex::checked(entry))
        }
    }

    /// `true` for a fixed vertex.
    pub fn is_fixed(self) -> bool {
        self == Self::Fixed
    }
}

/// The slice bounds `start..end` of a CSR row whose starts (`u32`, as
/// stored) are `start` and `end`.
#[inline(always)]
pub(crate) fn span(start: u32, end: u32) -> Range<usize> {
    start as usize..end as usize
}

/// Row `row` of a CSR list with row starts `starts`: `None` past the last
/// row.
#[inline(always)]
pub(crate) fn csr_row(starts: &[u32], row: usize) -> Option<Range<usize>> {
    Some(span(*starts.get(row)?, *starts.get(row.checked_add(1)?)?))
}

/// `true` if `starts` begins at 0, never decreases and ends at `total`: the
/// row starts of a CSR list of `total` entries.
pub(crate) fn csr_ok(starts: &[u32], total: usize) -> bool {
    starts.first() == Some(&0)
        && starts.windows(2).all(|w| w.first() <= w.get(1))
        && starts.last().map(|&x| x as usize) == Some(total)
}

/// The largest row of a CSR list.
pub fn max_row(starts: &[u32]) -> u32 {
    starts
        .windows(2)
        .map(|w| match w {
            [a, b] => b.saturating_sub(*a),
            _ => 0,
        })
        .max()
        .unwrap_or(0)
}
