//! The built-in organ: a smooth liver-like tet mesh, made once with gmsh by
//! `tools/meshes/organ.py` (which documents the shape, the sizes and the gmsh version) and
//! embedded here (`host-harness/assets/organ.msh`, Gmsh MSH 2.2 ASCII), so the binary needs
//! neither the file nor Python.
//!
//! Shape (m; x from the left lobe's tip to the right lobe, y front to back, z up): a thick right
//! lobe (up to 6.1 cm high) blending into a thin left lobe (1.3 cm thick 4.5 cm from its
//! tip), its underside cut flat at `z = ORGAN_FLOOR_Z_M` below the right lobe; 0.169 m ×
//! 0.120 m × 0.061 m, 0.47 L. Tets of about 5 mm edge over the left lobe (x < −0.02 m),
//! growing to about 13 mm over the right lobe (x > 0.03 m).

use super::{MeshError, MeshFormat, MeshReport, TetMesh, read_mesh_bytes};

/// The organ's mesh file as `tools/meshes/organ.py` wrote it.
const ORGAN_MSH: &[u8] = include_bytes!("../../assets/organ.msh");

/// How messages and the mesh report name the embedded organ.
pub const ORGAN_SOURCE: &str = "built-in organ (host-harness/assets/organ.msh)";

/// Height of the organ's flat underside, m: its lowest vertices, exactly at this `z`.
pub const ORGAN_FLOOR_Z_M: f64 = -0.02;

/// The built-in organ, read from the embedded file like any MSH file ([`read_mesh_bytes`]):
/// 1118 vertices, 3947 tets, every [`TetMesh`] invariant, no tet reoriented, no vertex
/// unreferenced, a closed manifold boundary. An error only if the embedded file were damaged.
pub fn organ() -> Result<(TetMesh, MeshReport), MeshError> {
    read_mesh_bytes(ORGAN_MSH, MeshFormat::Msh, ORGAN_SOURCE)
}
