//! Why a table was refused at load.

use core::fmt;

use super::format::SectionKind;

/// A table failed validation in [`super::PrecomputedTable::load`]. The host
/// wraps it with the file name; every variant says what is wrong and where.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LoadError {
    /// Fewer bytes than a header and a checksum.
    TooShort {
        /// Bytes given.
        len: usize,
    },
    /// The first 8 bytes are not [`super::format::MAGIC`].
    BadMagic,
    /// A format version this kernel does not read.
    UnsupportedVersion {
        /// Version in the header.
        found: u32,
    },
    /// The header's file length differs from the bytes given (truncated or padded).
    LengthMismatch {
        /// Length the header declares.
        declared: u64,
        /// Bytes given.
        actual: usize,
    },
    /// The CRC-32 trailer does not match the contents (corruption).
    ChecksumMismatch {
        /// CRC stored in the trailer.
        stored: u32,
        /// CRC computed over the contents.
        computed: u32,
    },
    /// The table stores floats of another width than the caller asked for.
    ScalarMismatch {
        /// Bytes per float in the table.
        table: u32,
        /// Bytes per float of the requested scalar.
        requested: u32,
    },
    /// The table is of another kind than the caller asked for.
    WrongTableKind {
        /// The kind value in the header.
        found: u32,
    },
    /// Header counts contradict each other (free > vertices, touchable > free,
    /// directory length, a connection count in a table that is not an
    /// interface table or none in one, mesh triangle count above
    /// `u32::MAX` or not the number of distinct tet faces).
    InconsistentHeader,
    /// Material out of range (E ≤ 0, ν outside [0, 0.5), density < 0,
    /// non-finite).
    BadMaterial,
    /// A section kind this version does not know.
    UnknownSection {
        /// The kind value found.
        kind: u32,
    },
    /// A section kind occurs twice.
    DuplicateSection {
        /// The repeated kind.
        kind: SectionKind,
    },
    /// A required section is absent.
    MissingSection {
        /// The missing kind.
        kind: SectionKind,
    },
    /// A section's element size or count differs from what the header implies.
    SectionSize {
        /// The section.
        kind: SectionKind,
    },
    /// A section lies (partly) outside the payload.
    SectionBounds {
        /// The section.
        kind: SectionKind,
    },
    /// A section is not aligned for its element type in memory (the buffer
    /// must be aligned to 16 bytes, e.g. with `palpate_kernel::include_table!`).
    Misaligned {
        /// The section.
        kind: SectionKind,
    },
    /// `vertex-slot` and `free-vertex` are not inverse maps, or the touchable
    /// ordering is broken, at this vertex.
    BadVertexMap {
        /// Vertex index.
        vertex: u32,
    },
    /// A surface triangle references a vertex out of range.
    BadTriangle {
        /// Triangle index.
        triangle: u32,
    },
    /// A non-finite float.
    NonFinite {
        /// The section.
        kind: SectionKind,
        /// Element index within it.
        index: u64,
    },
    /// The CSR edge list is broken at this vertex's row (row starts not
    /// ascending from 0 to E, a column not in `i+1..N`, columns not ascending).
    BadEdges {
        /// Vertex (row) index.
        vertex: u32,
    },
    /// A tet references a vertex, edge or neighbour that does not exist or does
    /// not match, or has a non-positive rest volume.
    BadTet {
        /// Tet index.
        tet: u32,
    },
    /// A mesh triangle (tensor-mass `mesh-triangle` section) references a
    /// vertex out of range, its ids are not strictly ascending, or it is not
    /// after the previous triangle in lexicographic order (a duplicate).
    BadMeshTriangle {
        /// Mesh-triangle index.
        triangle: u32,
    },
    /// A tet's `tet-triangle` entry is out of range or names a triangle that
    /// is not the tet's face opposite that local vertex.
    BadTetTriangle {
        /// Tet index.
        tet: u32,
    },
    /// The surface-vertex grid is malformed (non-finite or non-positive
    /// geometry, a candidate-list tool radius negative, not finite or
    /// widening by more than a cell, dimensions not matching the cell
    /// count, cell starts not ascending, or a vertex filed more than one
    /// cell away from its position).
    BadSurfaceGrid {
        /// Grid cell (or vertex, for a misfiled vertex) where it was found.
        index: u32,
    },
    /// A surface triangle's stored plane is not finite, not a unit normal,
    /// or not the plane of its corners, or its barycentric frame does not
    /// weigh its corners.
    BadSurfacePlane {
        /// Surface triangle index.
        triangle: u32,
    },
    /// A vertex's list of surface triangles is malformed (starts not
    /// ascending, a triangle out of range, not containing the vertex, or not
    /// ascending).
    BadVertexTriangles {
        /// Vertex index.
        vertex: u32,
    },
    /// A lumped mass or vertex tensor is invalid (negative mass, asymmetric
    /// `K_ii`).
    BadVertexData {
        /// Vertex index.
        vertex: u32,
    },
    /// A connection node of an interface table is malformed: its mesh vertex
    /// is out of range or not after the previous one, its tensor-mass vertex
    /// is not the `dynamic-vertex` entry of its mesh vertex, or a diagonal
    /// entry of its condensed stiffness block is not positive.
    BadConnection {
        /// Connection index `j`.
        connection: u32,
    },
    /// A tet's Lamé coefficients ([`SectionKind::TetMaterial`]) are out of
    /// range: `μ ≤ 0` or `λ ≤ −2μ/3` (a bulk modulus that is not positive).
    BadTetMaterial {
        /// Tet index.
        tet: u32,
    },
    /// A grid cell's candidate triangle list is not the triangles the grid
    /// files there for the declared tool radius (out of range, not
    /// ascending, one missing or one too many).
    BadCellTriangles {
        /// Grid cell, linear index.
        cell: u32,
    },
    /// A tet's lane of the `tet-lanes` section differs from its
    /// `tet-shape` and `tet-material` entries, or a lane past the last tet
    /// is not zero.
    BadTetLanes {
        /// Tet index (of the lane; `≥ tet_count` for a padding lane).
        tet: u32,
    },
    /// A diagonal compliance block `C_kk` is not symmetric positive definite.
    NotPositiveDefinite {
        /// Touchable index `k` (free index; the vertex is `free-vertex[k]`).
        touchable: u32,
    },
    /// The [`SectionKind::ComplianceEncoding`] record is malformed: a drop
    /// threshold outside `[0, 1)`, a measured error that is negative or not
    /// finite, or a reserved field that is not zero.
    BadCompressionRecord,
    /// The compliance-encoding record names an encoding this kernel does
    /// not know for a compliance part.
    UnknownEncoding {
        /// The part: [`SectionKind::ComplianceSurface`] or
        /// [`SectionKind::ComplianceInterior`].
        part: SectionKind,
        /// The value found.
        found: u32,
    },
    /// A section the table's compliance encoding does not use is present
    /// (a part stored both dense and coded, coded sections without the
    /// encoding record, a kept-block bitmap of a dense part).
    UnexpectedSection {
        /// The section.
        kind: SectionKind,
    },
    /// A per-column scale of a coded compliance part is not finite and > 0,
    /// or so large that a valid code times it is not finite.
    BadScale {
        /// The scale section.
        kind: SectionKind,
        /// Column (touchable index `k`).
        column: u32,
    },
    /// A 16-bit fixed-point code is −32768, outside the format's symmetric
    /// range `−32767..=32767`.
    BadCode {
        /// The codes section.
        kind: SectionKind,
        /// Stored block index within it.
        index: u64,
    },
    /// A hierarchical compliance section is inconsistent
    /// ([`crate::table::format::hierarchy`]): which section, which element
    /// (record 0, leaf, block or leaf column), what is wrong.
    BadHierarchy {
        /// The section.
        kind: SectionKind,
        /// The element.
        index: u64,
        /// What is wrong.
        what: &'static str,
    },
    /// A kept-block bitmap is inconsistent: a word's rank is not the number
    /// of bits set before it, or a bit is set past the block count.
    BadKeptBlocks {
        /// The bitmap section.
        kind: SectionKind,
        /// Word index.
        word: u64,
    },
    /// A diagonal compliance block `C_kk` was dropped from a coded surface
    /// part (the contact solve needs every one).
    DroppedDiagonal {
        /// Touchable index `k`.
        touchable: u32,
    },
}

impl fmt::Display for LoadError {
    /// The message of the stage of the load that found the error: the
    /// container (length, identity, checksum, header, directory), a
    /// section's contents (the element named), or the compliance and its
    /// encoding.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LoadError::TooShort { .. }
            | LoadError::BadMagic
            | LoadError::UnsupportedVersion { .. }
            | LoadError::LengthMismatch { .. }
            | LoadError::ChecksumMismatch { .. }
            | LoadError::ScalarMismatch { .. }
            | LoadError::WrongTableKind { .. }
            | LoadError::BadConnection { .. }
            | LoadError::InconsistentHeader
            | LoadError::BadMaterial
            | LoadError::UnknownSection { .. }
            | LoadError::DuplicateSection { .. }
            | LoadError::MissingSection { .. }
            | LoadError::SectionSize { .. }
            | LoadError::SectionBounds { .. }
            | LoadError::Misaligned { .. } => self.fmt_container(f),
            LoadError::BadVertexMap { .. }
            | LoadError::BadTriangle { .. }
            | LoadError::NonFinite { .. }
            | LoadError::BadEdges { .. }
            | LoadError::BadTet { .. }
            | LoadError::BadMeshTriangle { .. }
            | LoadError::BadSurfaceGrid { .. }
            | LoadError::BadSurfacePlane { .. }
            | LoadError::BadVertexTriangles { .. }
            | LoadError::BadTetTriangle { .. }
            | LoadError::BadVertexData { .. }
            | LoadError::BadTetMaterial { .. }
            | LoadError::BadCellTriangles { .. }
            | LoadError::BadTetLanes { .. } => self.fmt_contents(f),
            LoadError::NotPositiveDefinite { .. }
            | LoadError::BadCompressionRecord
            | LoadError::UnknownEncoding { .. }
            | LoadError::UnexpectedSection { .. }
            | LoadError::BadScale { .. }
            | LoadError::BadCode { .. }
            | LoadError::BadKeptBlocks { .. }
            | LoadError::BadHierarchy { .. }
            | LoadError::DroppedDiagonal { .. } => self.fmt_compliance(f),
        }
    }
}

impl LoadError {
    /// The container's errors: length, identity, checksum, header and directory.
    fn fmt_container(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            LoadError::TooShort { len } => write!(f, "table too short ({len} bytes)"),
            LoadError::BadMagic => f.write_str("not a Palpate table (bad magic)"),
            LoadError::UnsupportedVersion { found } => write!(
                f,
                "table format version {found} is not read by this kernel (version {})",
                super::format::FORMAT_VERSION
            ),
            LoadError::LengthMismatch { declared, actual } => write!(
                f,
                "table length {actual} bytes differs from the header's {declared} (truncated?)"
            ),
            LoadError::ChecksumMismatch { stored, computed } => write!(
                f,
                "checksum mismatch: stored CRC-32 {stored:#010x}, computed {computed:#010x} (corrupt table)"
            ),
            LoadError::ScalarMismatch { table, requested } => write!(
                f,
                "table stores {table}-byte floats, caller requested {requested}-byte floats"
            ),
            LoadError::WrongTableKind { found } => {
                write!(f, "table kind {found} is not the kind requested")
            }
            LoadError::BadConnection { connection } => write!(
                f,
                "connection node {connection}: bad vertex numbers or condensed stiffness"
            ),
            LoadError::InconsistentHeader => f.write_str("inconsistent header counts"),
            LoadError::BadMaterial => f.write_str("material out of range in header"),
            LoadError::UnknownSection { kind } => write!(f, "unknown section kind {kind}"),
            LoadError::DuplicateSection { kind } => {
                write!(f, "section {} occurs twice", kind.name())
            }
            LoadError::MissingSection { kind } => write!(f, "section {} missing", kind.name()),
            LoadError::SectionSize { kind } => {
                write!(f, "section {} has the wrong size", kind.name())
            }
            LoadError::SectionBounds { kind } => {
                write!(f, "section {} lies outside the table", kind.name())
            }
            LoadError::Misaligned { kind } => write!(
                f,
                "section {} is misaligned in memory (align the table buffer to 16 bytes)",
                kind.name()
            ),
            // The other stages' (see `fmt`).
            _ => Ok(()),
        }
    }

    /// A section's contents: the element that is wrong.
    fn fmt_contents(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            LoadError::BadVertexMap { vertex } => {
                write!(f, "vertex {vertex}: free-vertex/vertex-slot maps disagree")
            }
            LoadError::BadTriangle { triangle } => {
                write!(
                    f,
                    "surface triangle {triangle} references a vertex out of range"
                )
            }
            LoadError::NonFinite { kind, index } => {
                write!(
                    f,
                    "section {} element {index}: non-finite value",
                    kind.name()
                )
            }
            LoadError::BadEdges { vertex } => {
                write!(f, "edge list broken at the row of vertex {vertex}")
            }
            LoadError::BadTet { tet } => write!(
                f,
                "tet {tet}: bad vertex, edge or neighbour reference, or non-positive rest volume"
            ),
            LoadError::BadMeshTriangle { triangle } => write!(
                f,
                "mesh triangle {triangle}: vertex out of range, ids not strictly ascending, or not in ascending order (duplicate)"
            ),
            LoadError::BadSurfaceGrid { index } => {
                write!(f, "surface grid malformed at cell or vertex {index}")
            }
            LoadError::BadSurfacePlane { triangle } => write!(
                f,
                "surface triangle {triangle}: stored plane or barycentric frame is not that of its corners"
            ),
            LoadError::BadVertexTriangles { vertex } => write!(
                f,
                "vertex {vertex}: surface-triangle list malformed (range, order, or a triangle without the vertex)"
            ),
            LoadError::BadTetTriangle { tet } => write!(
                f,
                "tet {tet}: mesh-triangle reference out of range or not the face opposite its vertex"
            ),
            LoadError::BadVertexData { vertex } => write!(
                f,
                "vertex {vertex}: negative lumped mass or asymmetric vertex tensor"
            ),
            LoadError::BadTetMaterial { tet } => write!(
                f,
                "tet {tet}: Lame coefficients out of range (need mu > 0 and lambda > -2 mu / 3)"
            ),
            LoadError::BadCellTriangles { cell } => write!(
                f,
                "grid cell {cell}: candidate triangle list is not the triangles the grid files there"
            ),
            LoadError::BadTetLanes { tet } => write!(
                f,
                "tet {tet}: its tet-lanes entry differs from its tet-shape and tet-material entries (or a lane past the last tet is not zero)"
            ),
            // The other stages' (see `fmt`).
            _ => Ok(()),
        }
    }

    /// The compliance and its encoding.
    fn fmt_compliance(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            LoadError::NotPositiveDefinite { touchable } => write!(
                f,
                "compliance block C_kk of touchable index {touchable} is not symmetric positive definite"
            ),
            LoadError::BadCompressionRecord => f.write_str(
                "compliance-encoding record malformed (drop threshold outside [0, 1), a measured error negative or not finite, or reserved bits set)",
            ),
            LoadError::UnknownEncoding { part, found } => write!(
                f,
                "compliance-encoding: unknown block encoding {found} for {}",
                part.name()
            ),
            LoadError::UnexpectedSection { kind } => write!(
                f,
                "section {} is not used by the table's compliance encoding",
                kind.name()
            ),
            LoadError::BadScale { kind, column } => write!(
                f,
                "section {} column {column}: scale not finite and > 0, or too large for the codes",
                kind.name()
            ),
            LoadError::BadCode { kind, index } => write!(
                f,
                "section {} block {index}: q16 code -32768 outside -32767..=32767",
                kind.name()
            ),
            LoadError::BadHierarchy { kind, index, what } => {
                write!(f, "section {} element {index}: {what}", kind.name())
            }
            LoadError::BadKeptBlocks { kind, word } => write!(
                f,
                "section {} word {word}: rank not the bits set before it, or a bit past the block count",
                kind.name()
            ),
            LoadError::DroppedDiagonal { touchable } => write!(
                f,
                "compliance block C_kk of touchable index {touchable} was dropped (every diagonal block must be stored)"
            ),
            // The other stages' (see `fmt`).
            _ => Ok(()),
        }
    }
}

impl core::error::Error for LoadError {}
