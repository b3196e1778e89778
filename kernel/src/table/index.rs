//! Validated indices: what the views hand out after load, so the step path
//! never sees the byte format's sentinel ([`super::format::FIXED_SLOT`]).

/// Index of a free (not fixed) vertex of a pre-computed table: the row of
/// its compliance blocks. `0..S` are the touchable vertices (free, on the
/// boundary surface), then the interior ones. Only a validated table makes
/// one, so it is always `< F`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct FreeIndex(u32);

impl FreeIndex {
    /// A free index the table has checked to be `< F`.
    pub(crate) fn checked(index: u32) -> Self {
        Self(index)
    }

    /// The index, for slicing.
    pub fn get(self) -> usize {
        self.0 as usize
    }

    /// The index as stored (`u32`).
    pub fn as_u32(self) -> u32 {
        self.0
    }
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
