//! Tetrahedral mesh input, validation and boundary surface.
//!
//! Readers: Gmsh MSH 2.2 and 4.1 (ASCII and binary), TetGen `.node`/`.ele`, VTK legacy
//! `UNSTRUCTURED_GRID` (ASCII and binary). Every reader ends in the same validation
//! ([`TetMesh::new_validated`]), so a mesh read from any format satisfies the [`TetMesh`]
//! invariants. No input bytes make a reader panic; bad files give a [`MeshError`] naming the file,
//! the vertex or tet (0-based; for MSH also the file's id) and what is wrong.

use std::path::Path;

use crate::limits::{MAX_MESH_FILE_BYTES, read_bounded};

mod cursor;
mod error;
pub mod generate;
mod gmsh;
pub mod organ;
mod surface;
mod tetgen;
mod validate;
mod vtk;

pub use error::MeshError;
pub use surface::{Surface, boundary_face_slots, boundary_surface, top_height};
pub use tetgen::read_tetgen;

/// A validated tetrahedral mesh (linear 4-node tets).
///
/// Invariants: every tet has 4 distinct vertex indices `< positions.len()`, positive signed volume
/// `det[p1-p0, p2-p0, p3-p0] / 6 > 0`, no two tets share the same vertex set, all coordinates are
/// finite, and there is at least one tet. Vertex numbering is the input file's vertex order,
/// 0-based. Coordinates are in mesh units (SI metres for Palpate's own meshes). Vertices not used
/// by any tet may exist (see [`MeshReport::unreferenced_vertices`]).
#[derive(Debug, Clone, PartialEq)]
pub struct TetMesh {
    /// Vertex positions `[x, y, z]`, mesh units (m).
    pub positions: Vec<[f64; 3]>,
    /// Tets as 0-based vertex indices, positively oriented.
    pub tets: Vec<[u32; 4]>,
}

/// What validation found and fixed while building a [`TetMesh`] (these are not errors).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MeshReport {
    /// The file or source name the mesh came from.
    pub source: String,
    /// Number of non-tet elements (points, lines, triangles, hexes...) skipped by the reader.
    pub skipped_elements: usize,
    /// Number of tets with negative volume that were fixed by swapping their last two vertices.
    pub reoriented_tets: usize,
    /// Vertices used by no tet, ascending. They are kept so the numbering stays the file's;
    /// callers decide what to do with them.
    pub unreferenced_vertices: Vec<u32>,
    /// Non-fatal findings, e.g. an open or non-manifold boundary surface.
    pub warnings: Vec<String>,
    /// The region id of each tet (same order as [`TetMesh::tets`]), where the file has them:
    /// MSH 2.2 the first tag of a tet element (its physical tag; 0 without tags), MSH 4.1 the
    /// first physical tag of the tet's volume entity in `$Entities` (0 for an entity without
    /// one; `None` without an `$Entities` section or with one that does not parse), VTK the integer `CELL_DATA` field named
    /// `region` (a `SCALARS` or `FIELD` array; `None` without it), TetGen the first region
    /// attribute of the `.ele` file (`None` without attributes). The scene's `[[region]]`
    /// materials are looked up here (heterogeneous tissue).
    pub tet_regions: Option<Vec<u32>>,
}

/// Input formats understood by [`read_mesh_bytes`]. TetGen needs two buffers: see [`read_tetgen`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshFormat {
    /// Gmsh MSH: version 2.x or 4.1, ASCII or binary (sniffed from `$MeshFormat`).
    Msh,
    /// VTK legacy `UNSTRUCTURED_GRID`, ASCII or binary (big-endian), file versions up to 5.1.
    Vtk,
}

impl TetMesh {
    /// Validate raw arrays into a mesh.
    ///
    /// `source` names the data in messages. Inverted tets are fixed (last two vertices swapped) and
    /// counted in the report; unreferenced vertices are kept and listed; an open or non-manifold
    /// boundary gives a warning. Non-finite coordinates, out-of-range or repeated indices,
    /// degenerate tets (`|V| < 1e-9 × mean |V|`), duplicate tets and an empty tet list are errors.
    pub fn new_validated(
        positions: Vec<[f64; 3]>,
        tets: Vec<[u32; 4]>,
        source: &str,
    ) -> Result<(TetMesh, MeshReport), MeshError> {
        let raw = validate::RawMesh {
            positions,
            node_ids: None,
            tets: tets.iter().map(|t| t.map(i64::from)).collect(),
            elem_ids: None,
            numbering: validate::Numbering::Base(0),
            skipped: 0,
            tet_regions: None,
        };
        validate::validate(raw, source, source, source)
    }

    /// Signed volume of tet `t` in mesh units^3 (m^3): `det[p1-p0, p2-p0, p3-p0] / 6`, positive for
    /// a validated mesh. Panics if `t >= self.tets.len()`.
    pub fn tet_volume(&self, t: usize) -> f64 {
        let [a, b, c, d] = self.tets[t];
        let p = |i: u32| self.positions[i as usize];
        validate::signed_volume(p(a), p(b), p(c), p(d))
    }

    /// Centroid of tet `t`, mesh units (m): the mean of its 4 vertices.
    /// Panics if `t >= self.tets.len()`.
    pub fn tet_centroid(&self, t: usize) -> [f64; 3] {
        let tet = self.tets[t];
        core::array::from_fn(|i| {
            tet.iter()
                .map(|&v| self.positions[v as usize][i])
                .sum::<f64>()
                / 4.0
        })
    }

    /// Per vertex: whether some tet uses it. Length `positions.len()`.
    pub fn referenced(&self) -> Vec<bool> {
        let mut used = vec![false; self.positions.len()];
        for t in &self.tets {
            for &v in t {
                if let Some(u) = used.get_mut(v as usize) {
                    *u = true;
                }
            }
        }
        used
    }

    /// CRC-64 (`CRC_64_XZ`) over all positions as `f64` little-endian (x, y, z per vertex) followed
    /// by all tets as `u32` little-endian. Independent of the file format the mesh came from.
    pub fn content_hash(&self) -> u64 {
        const CRC: crc::Crc<u64> = crc::Crc::<u64>::new(&crc::CRC_64_XZ);
        let mut d = CRC.digest();
        let mut buf = Vec::with_capacity(self.positions.len() * 24 + self.tets.len() * 16);
        for p in &self.positions {
            for x in p {
                buf.extend_from_slice(&x.to_le_bytes());
            }
        }
        for t in &self.tets {
            for v in t {
                buf.extend_from_slice(&v.to_le_bytes());
            }
        }
        d.update(&buf);
        d.finalize()
    }
}

/// Read a mesh file, choosing the reader by extension: `.msh` (Gmsh 2.x / 4.1, ASCII or binary,
/// sniffed), `.node` (reads the sibling `.ele`) or `.ele` (reads the sibling `.node`), `.vtk`.
/// Messages name the file as `path` displays. Each file is read whole, at most
/// [`MAX_MESH_FILE_BYTES`] (checked from a regular file's size before reading; anything else,
/// a pipe or a device, is read through a bounded reader: [`read_bounded`]).
pub fn read_mesh(path: &Path) -> Result<(TetMesh, MeshReport), MeshError> {
    let name = path.display().to_string();
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    // Bounded: a mesh larger than the limit, or `/dev/zero` named `.msh`, is refused with a
    // message instead of filling the memory.
    let read = |p: &Path| {
        read_bounded(p, MAX_MESH_FILE_BYTES, "a mesh file (MAX_MESH_FILE_BYTES)").map_err(|err| {
            MeshError::Io {
                file: p.display().to_string(),
                err,
            }
        })
    };
    match ext.as_str() {
        "msh" => read_mesh_bytes(&read(path)?, MeshFormat::Msh, &name),
        "vtk" => read_mesh_bytes(&read(path)?, MeshFormat::Vtk, &name),
        "node" | "ele" => {
            let node = read(&path.with_extension("node"))?;
            let ele = read(&path.with_extension("ele"))?;
            read_tetgen(&node, &ele, &path.with_extension("").display().to_string())
        }
        _ => Err(MeshError::Unsupported {
            file: name,
            msg: format!("unknown extension {ext:?} (expected .msh, .node, .ele or .vtk)"),
        }),
    }
}

/// Read a mesh from memory. `source` names the data in messages and in the report.
pub fn read_mesh_bytes(
    bytes: &[u8],
    format: MeshFormat,
    source: &str,
) -> Result<(TetMesh, MeshReport), MeshError> {
    let raw = match format {
        MeshFormat::Msh => gmsh::parse(bytes, source)?,
        MeshFormat::Vtk => vtk::parse(bytes, source)?,
    };
    validate::validate(raw, source, source, source)
}
