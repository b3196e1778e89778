//! Errors raised while reading or validating a tetrahedral mesh.

/// Why a mesh could not be read or validated.
///
/// Every message starts with the file (or source name) and, where it applies, names the 0-based
/// vertex or tet index and, for MSH files, the file's own node or element id.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// The file could not be read from disk.
    #[error("{file}: cannot read file: {err}")]
    Io {
        /// File name as given by the caller.
        file: String,
        /// Underlying I/O error.
        err: std::io::Error,
    },
    /// The file extension or the format version is not supported.
    #[error("{file}: unsupported mesh format: {msg}")]
    Unsupported {
        /// File name.
        file: String,
        /// What is not supported.
        msg: String,
    },
    /// The file is truncated or garbled.
    #[error("{file}: {msg}")]
    Parse {
        /// File name.
        file: String,
        /// Where (section, line or element) and what went wrong.
        msg: String,
    },
    /// A vertex coordinate is NaN or infinite.
    #[error("{file}: vertex {vertex}{}: non-finite coordinate {value} (component {component})", id_suffix("node id", .node_id))]
    NonFiniteCoordinate {
        /// File name.
        file: String,
        /// 0-based vertex index.
        vertex: usize,
        /// The file's node id, where the format has one.
        node_id: Option<i64>,
        /// 0 = x, 1 = y, 2 = z.
        component: usize,
        /// The offending value.
        value: f64,
    },
    /// More vertices than fit a `u32` index.
    #[error(
        "{file}: too many vertices ({count}); at most {} are supported",
        u32::MAX
    )]
    TooManyVertices {
        /// File name.
        file: String,
        /// Number of vertices found.
        count: usize,
    },
    /// A tet references a vertex index outside `0..n_vertices`.
    #[error("{file}: tet {tet}{}: vertex index {index} out of range ({n_vertices} vertices)", id_suffix("element id", .elem_id))]
    IndexOutOfRange {
        /// File name.
        file: String,
        /// 0-based tet index (counting tets only).
        tet: usize,
        /// The file's element id, where the format has one.
        elem_id: Option<i64>,
        /// The 0-based vertex index found.
        index: i64,
        /// Number of vertices in the mesh.
        n_vertices: usize,
    },
    /// A tet references a node id that no node defines (MSH).
    #[error("{file}: tet {tet}{}: node id {node_id} is not defined ({n_vertices} vertices)", id_suffix("element id", .elem_id))]
    UnknownNode {
        /// File name.
        file: String,
        /// 0-based tet index.
        tet: usize,
        /// The file's element id.
        elem_id: Option<i64>,
        /// The undefined node id.
        node_id: i64,
        /// Number of vertices in the mesh.
        n_vertices: usize,
    },
    /// A tet uses the same vertex twice.
    #[error("{file}: tet {tet}{}: vertex {vertex} repeated in {vertices:?}", id_suffix("element id", .elem_id))]
    RepeatedVertex {
        /// File name.
        file: String,
        /// 0-based tet index.
        tet: usize,
        /// The file's element id.
        elem_id: Option<i64>,
        /// The repeated 0-based vertex index.
        vertex: u32,
        /// The tet's 0-based vertex indices.
        vertices: [u32; 4],
    },
    /// A tet has (near) zero or non-finite volume.
    #[error("{file}: tet {tet}{}: degenerate, volume {volume:e} (mean |volume| {mean:e})", id_suffix("element id", .elem_id))]
    DegenerateTet {
        /// File name.
        file: String,
        /// 0-based tet index.
        tet: usize,
        /// The file's element id.
        elem_id: Option<i64>,
        /// Signed volume in mesh units^3.
        volume: f64,
        /// Mean absolute volume over all tets, mesh units^3.
        mean: f64,
    },
    /// Two tets have the same vertex set.
    #[error("{file}: tets {first}{} and {second}{} have the same vertices {vertices:?}", id_suffix("element id", .first_id), id_suffix("element id", .second_id))]
    DuplicateTet {
        /// File name.
        file: String,
        /// 0-based index of the first tet.
        first: usize,
        /// File element id of the first tet.
        first_id: Option<i64>,
        /// 0-based index of the second tet.
        second: usize,
        /// File element id of the second tet.
        second_id: Option<i64>,
        /// The shared vertex set, sorted.
        vertices: [u32; 4],
    },
    /// The file holds no tetrahedra.
    #[error("{file}: mesh has no tetrahedra ({skipped} other elements skipped)")]
    NoTets {
        /// File name.
        file: String,
        /// Number of non-tet elements skipped.
        skipped: usize,
    },
}

/// ` (node id 7)` or empty.
fn id_suffix(what: &str, id: &Option<i64>) -> String {
    match id {
        Some(id) => format!(" ({what} {id})"),
        None => String::new(),
    }
}
