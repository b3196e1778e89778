//! Offline tables: the byte format ([`format`]), load errors ([`LoadError`]) and
//! the validated, zero-copy views the step path uses ([`PrecomputedTable`],
//! [`TensorMassTable`], and the collision index of a surface,
//! [`SurfaceIndex`], over a [`Grid`]). Depends only on [`crate::math`].
//!
//! A table is bytes until [`PrecomputedTable::load`] has checked it once
//! (magic, version, sizes, alignment, CRC-32, finite values, positive definite
//! diagonal blocks, a compressed compliance's scales, codes and kept blocks:
//! [`ComplianceBlocks`]); afterwards the step path trusts it, and indexes it with
//! the checked indices the views hand out ([`VertexIndex`],
//! [`TriangleIndex`], [`TetIndex`], [`EdgeIndex`], [`FreeIndex`]) instead of
//! raw `u32`s: the format's sentinels stay inside this module.

mod candidates;
mod collision;
mod compressed;
mod container;
mod error;
pub mod format;
mod grid;
mod hierarchical;
mod index;
mod interface;
mod plane;
mod precomputed;
mod tensor_mass;

pub use candidates::{
    CANDIDATE_MARGIN_CELLS, CANDIDATE_MARGIN_RADII, candidate_cells, candidate_margin_m,
    candidate_radius_m, list_subdivision,
};
pub(crate) use candidates::{corners_of, for_each_candidate_filing};
pub(crate) use collision::BuiltLists;
pub use collision::{CandidateList, DEAD_TRIANGLE, SurfaceIndex};
pub use compressed::{CodedBlocks, ComplianceBlocks};
pub use error::LoadError;
pub use grid::{CellBox, Grid, box_of, neighbours, within};
pub use hierarchical::HierarchicalBlocks;
pub(crate) use index::span;
pub use index::{EdgeIndex, FreeIndex, TetIndex, TriangleIndex, VertexIndex, VertexSlot, max_row};
pub use interface::{CondensedStiffness, InterfaceTable};
pub use plane::Plane;
pub(crate) use plane::plane_record;
pub use precomputed::PrecomputedTable;
pub use tensor_mass::{TensorMassTable, TetLanes};

/// A byte buffer aligned to 16 bytes ([`format::SECTION_ALIGN`]), so that table
/// sections can be viewed in place. Use [`crate::include_table!`] for tables
/// linked into flash.
#[repr(C, align(16))]
pub struct Aligned<B: ?Sized>(pub B);

/// Includes a table file as a 16-byte-aligned `&'static [u8]`
/// (`include_bytes!` alone gives no alignment guarantee).
///
/// ```ignore
/// static TABLE: &[u8] = palpate_kernel::include_table!("table.bin");
/// ```
#[macro_export]
macro_rules! include_table {
    ($path:expr) => {{
        static ALIGNED: &$crate::table::Aligned<[u8]> =
            &$crate::table::Aligned(*include_bytes!($path));
        &ALIGNED.0
    }};
}
