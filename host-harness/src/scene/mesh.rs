//! Where a scene's tissue mesh comes from ([`MeshSource`]: a file, a generated box or the
//! built-in organ), the ranges of a generated box, and the mesh loaded.

use std::path::PathBuf;

use crate::mesh::generate::box_mesh;
use crate::mesh::organ::organ;
use crate::mesh::{MeshError, MeshReport, TetMesh, read_mesh};

/// Largest vertex count of a `[generated]` box, so a typo cannot ask for a mesh that does not
/// fit in memory (the table build is quadratic in the surface size long before this).
pub const MAX_GENERATED_VERTICES: usize = 10_000_000;

/// Where the tissue mesh comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum MeshSource {
    /// A mesh file (any format [`read_mesh`] reads), already resolved against the scene file's
    /// folder.
    File(PathBuf),
    /// A generated box ([`box_mesh`]): `[0, size_m[0]] × [0, size_m[1]] × [0, size_m[2]]` in m,
    /// `cells[i] ≥ 1` cells per axis.
    GeneratedBox {
        /// Box size, m, each finite and > 0.
        size_m: [f64; 3],
        /// Cells per axis, each ≥ 1 (6 tets per cell).
        cells: [usize; 3],
    },
    /// The built-in liver-like organ ([`organ`]: the smooth gmsh mesh embedded in the binary,
    /// 1118 vertices, 3947 tets, its flat underside the lowest vertices); the built-in hybrid
    /// scene's.
    BuiltInOrgan,
}

impl MeshSource {
    /// Load (or generate) the mesh. A generated box is built by [`box_mesh`] and satisfies the
    /// [`TetMesh`] invariants by construction; its report names it (`generated box ...`) and is
    /// otherwise empty. A file's errors name the file (see [`read_mesh`]); the built-in organ is
    /// read from the binary as a file is.
    pub fn load(&self) -> Result<(TetMesh, MeshReport), MeshError> {
        match self {
            MeshSource::File(path) => read_mesh(path),
            MeshSource::GeneratedBox { size_m, cells } => {
                let mesh = box_mesh(*cells, *size_m);
                let report = MeshReport {
                    source: format!(
                        "generated box {} x {} x {} m, {} x {} x {} cells",
                        size_m[0], size_m[1], size_m[2], cells[0], cells[1], cells[2]
                    ),
                    ..MeshReport::default()
                };
                Ok((mesh, report))
            }
            MeshSource::BuiltInOrgan => organ(),
        }
    }

    /// The ranges of a `[generated]` box: every size finite and > 0 m, every cell count ≥ 1, at
    /// most [`MAX_GENERATED_VERTICES`] vertices; errors are `(key, message)`.
    pub(crate) fn check(&self) -> Result<(), (String, String)> {
        let MeshSource::GeneratedBox { size_m, cells } = *self else {
            return Ok(());
        };
        if !size_m.iter().all(|&s| s.is_finite() && s > 0.0) {
            return Err((
                format!("[generated] box_m = {size_m:?}"),
                "every size must be finite and > 0 m".into(),
            ));
        }
        let vertices = cells.iter().try_fold(1usize, |n, &c| {
            if c == 0 {
                None
            } else {
                n.checked_mul(c.checked_add(1)?)
            }
        });
        match vertices {
            None if cells.contains(&0) => Err((
                format!("[generated] cells = {cells:?}"),
                "every cell count must be >= 1".into(),
            )),
            Some(n) if n <= MAX_GENERATED_VERTICES => Ok(()),
            _ => Err((
                format!("[generated] cells = {cells:?}"),
                format!("too many vertices: at most {MAX_GENERATED_VERTICES}"),
            )),
        }
    }
}
