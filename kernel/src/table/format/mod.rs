//! The table file format, version 6: one definition shared by the host writer
//! and the kernel reader.
//!
//! ```text
//! offset 0            RawHeader (112 bytes)
//! offset 112          SectionEntry × section_count (24 bytes each)
//! …                   sections, each starting at a multiple of SECTION_ALIGN
//! file_len - 4        CRC-32/ISO-HDLC of bytes [0, file_len - 4), little-endian
//! ```
//!
//! All integers and floats are little-endian. Floats in the sections are the
//! table scalar (`scalar_bytes` = 4 for `f32`, 8 for `f64`).
//!
//! Vertex numbering is the source mesh's input order. The free vertices (not
//! fixed) are renumbered by a *free index*: first the `touchable_count` free
//! surface vertices (the ones a tool can touch) in ascending vertex order
//! (in a hierarchical table, the order of its cluster tree's leaves:
//! [`hierarchy`]), then the interior free vertices in ascending order.
//!
//! Compliance blocks `C_nk` (RR-3510 §4, MODELS.md §2; `C = A⁻¹`, `A` the
//! stiffness restricted to free DOFs; unit m/N) are stored for every free `n`
//! and every touchable `k`, row-major 3×3: element `3a + b` is
//! `C[(n, a), (k, b)]`. Blocks that occur twice by symmetry (`C_kn = C_nkᵀ`,
//! both touchable) are stored once:
//! - [`SectionKind::ComplianceSurface`]: `S(S+1)/2` blocks, packed upper by
//!   columns: column `k` holds rows `n = 0..=k` at index `k(k+1)/2 + n`;
//! - [`SectionKind::ComplianceInterior`]: `I·S` blocks (`I = F − S`): column `k`
//!   holds interior rows `i = 0..I` (free index `S + i`) at index `k·I + i`.
//!
//! Version history: 1 had a 96-byte header; 2 appends
//! [`RawHeader::mesh_triangle_count`] and the St Venant-Kirchhoff term
//! sections of tensor-mass tables ([`SectionKind::VertexTerms`] to
//! [`SectionKind::TetTerms`], Picinbono 2001 §3.1, table 1; the monomial
//! layouts are documented in the tensor-mass model's `stvk_terms` module),
//! a 104-byte header at first, then [`RawHeader::grid_cell_count`] and
//! [`RawHeader::surface_vertex_count`] with the collision-index sections of
//! pre-computed tables: the 112-byte header of today ([`HEADER_LEN`]). 3 adds
//! [`SectionKind::TetMaterial`], each tet's own Lamé coefficients, required
//! in both table kinds (heterogeneous tissue); the header's `young_pa` and
//! `poisson` stay as the scene's default `[material]` (informative: every
//! model reads the per-tet section). 4 adds [`SectionKind::TetLanes`] to
//! tensor-mass tables: the rest shapes and Lamé coefficients again, by
//! blocks of [`TET_LANES`] tets in structure-of-arrays form, which the
//! St Venant-Kirchhoff pass reads with vector loads instead of gathering
//! them tet by tet. 5 widens [`SectionKind::SurfacePlane`] from 4 to
//! [`PLANE_LEN`] scalars: after the plane, the in-plane gradients of the
//! triangle's second and third barycentric weights, so that a contact test
//! weighs a point with two dot products instead of two cross products and
//! two divisions over the corners; it also adds to pre-computed tables
//! the collision index's per-cell candidate lists
//! ([`SectionKind::CellTriangleStart`], [`SectionKind::CellTriangle`]: the
//! triangles a detection in a cell tests, filed against the tool radius the
//! table declares in [`SectionKind::SurfaceGrid`], read as one list instead
//! of a walk over 27 cells). 6 files the lists by each triangle's prism (its
//! box widened along its normal, not on every axis: a contact test takes a
//! triangle only from a centre over it) on a finer lists' grid, the second
//! row of [`SectionKind::GridDims`] ([`MAX_LIST_SUBDIVISION`]). A table of
//! an earlier version is refused ([`super::LoadError::UnsupportedVersion`]),
//! never misread.
//!
//! ## Compressed compliance (version 3, additive)
//!
//! A pre-computed table may store its compliance blocks compressed, to fit a
//! microcontroller's flash. It is the same table kind and version: the
//! [`SectionKind::ComplianceEncoding`] section (one [`CompressionRecord`])
//! says, for each of the two compliance parts, which [`BlockEncoding`]
//! stores it. Without that section (every table written before it existed)
//! both parts are [`BlockEncoding::Scalar`]. A kernel that predates it
//! refuses a compressed table (`unknown section kind 50`), never misreads it.
//!
//! A part stored as [`BlockEncoding::Scalar`] is the section above
//! ([`SectionKind::ComplianceSurface`], [`SectionKind::ComplianceInterior`]).
//! A part stored as [`BlockEncoding::F16`] or [`BlockEncoding::Q16`] replaces
//! it by three sections (`X` = surface or interior):
//! - `X-scale`: one scale per column `k` (touchable vertex), m/N, finite and
//!   `> 0`, in the table scalar;
//! - `X-codes`: `[u16; 9]` per *stored* block, in the dense layout's block
//!   order (column by column as above) with the dropped blocks left out.
//!   Block entry `e` of column `k` is `decode(code) · scale[k]`: for F16,
//!   `decode` is the IEEE 754 binary16 value of the code ([`f16_to_f32`];
//!   infinities and NaNs are refused at load); for Q16 it is the code as a
//!   two's complement `i16` in `−32767..=32767` (`−32768` is refused);
//! - `X-kept` (only when some blocks were dropped, not all: without it
//!   `X-codes` holds every block, or none when all were dropped): which
//!   blocks of the dense layout are stored, one bit per block (bit `j % 32` of word `j / 32`,
//!   least significant first), each word followed by the number of bits set
//!   in the words before it (a rank directory, so a block is found in
//!   constant time: [`kept_position`]). A dropped block is zero. Bits past
//!   the block count are zero, the ranks are exact, the bits set are the
//!   `X-codes` count, and every diagonal block `C_kk` is kept.
//!
//! ## Hierarchical compliance (additive)
//!
//! The surface part may instead be a hierarchical matrix
//! ([`BlockEncoding::Hierarchical`], sections
//! [`SectionKind::HierarchyRecord`] to [`SectionKind::HierarchyData`]): dense
//! near-field blocks and low-rank far-field blocks over a cluster tree of
//! the touchable vertices, whose free indices then follow the tree's
//! leaves. Layout and invariants in [`hierarchy`]. A kernel that predates it
//! refuses such a table (`unknown block encoding 3`), never misreads it.
//! [`BlockEncoding::HierarchicalQ16`] stores the same hierarchy with its
//! numbers as 16-bit codes ([`SectionKind::HierarchyCodes`],
//! [`SectionKind::HierarchyScales`] in place of
//! [`SectionKind::HierarchyData`]; [`hierarchy`], "q16 data"): a kernel that
//! predates it refuses it as `unknown block encoding 4`.

mod encoding;
mod header;
pub mod hierarchy;
mod section;
mod tet;

pub use encoding::{
    BlockEncoding, COMPRESSION_RECORD_LEN, CompressionRecord, F16_LARGEST_CODE, KEPT_BITS,
    PROBE_SAMPLE_COUNT, PROBE_SET_EVERY_TOUCHABLE, PROBE_SET_SAMPLED, Q16_LARGEST_CODE, f16_to_f32,
    is_kept, kept_position, kept_rank, kept_words, q16_value,
};
pub use header::{
    CRC_LEN, CRC32, FORMAT_VERSION, HEADER_LEN, MAGIC, RawHeader, SECTION_ALIGN, SECTION_ENTRY_LEN,
    SectionEntry,
};
pub use hierarchy::{
    HIERARCHY_BLOCK_LEN, HIERARCHY_MAX_RANK, HIERARCHY_MIRRORED, HIERARCHY_RECORD_LEN,
    HierarchyBlock, HierarchyRecord,
};
pub use section::{
    EDGE_TERMS_LEN, FIXED_SLOT, GRID_LEN, MAX_LIST_SUBDIVISION, MAX_LISTS_PER_TRIANGLE,
    NO_NEIGHBOUR, PLANE_LEN, SectionKind, TET_LANE_ROWS, TET_LANES, TET_MATERIAL_LEN,
    TET_SHAPE_LEN, TET_TERMS_LEN, TRIANGLE_TERMS_LEN, TableKind, VERTEX_TERMS_LEN,
    surface_block_index, tet_lane_row,
};
pub use tet::{TET_EDGE_PAIRS, tet_edge_vertices, tet_face_vertices};
