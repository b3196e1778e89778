//! `palpate stvk forces`: the internal forces and elastic energy of one
//! deformed configuration, through the kernel's force pass (f64).

use anyhow::Context;
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::tensor_mass::{ElasticLaw, TensorMassModel};

use super::OwnedState;
use super::run::{f64_table, host_params};
use crate::fem::material::Material;
use crate::mesh::{MeshReport, TetMesh};
use crate::table::build::BuildOptions;
use crate::table::file::Precision;

/// The force pass gave a non-finite force or energy: the deformed
/// configuration is too far from rest for f64 (coordinates of 1e200 m). The
/// caller names the positions' source ([`forces_and_energy`] returns it
/// inside its `anyhow::Error`; find it with `downcast_ref`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error(
    "the deformed positions give a non-finite {what} (f64 overflow): they must be in metres, \
     within a few times the mesh's size of its rest positions"
)]
pub struct NonFiniteResult {
    /// `"force"` or `"energy"`.
    pub what: &'static str,
}

/// Internal forces (N, one per vertex: the elastic force on each vertex,
/// `−∂W/∂x`, plus the incompressibility penalty when `incompressibility_n` is
/// given) and elastic energy `W` (J) of `mesh` deformed to `deformed_m`
/// (positions, m, one per vertex), free body (no fixed vertices). A
/// non-finite force or energy is an error ([`NonFiniteResult`]), never a
/// result.
pub fn forces_and_energy(
    mesh: &TetMesh,
    report: &MeshReport,
    material: Material,
    law: ElasticLaw,
    incompressibility_n: Option<f64>,
    deformed_m: &[[f64; 3]],
) -> anyhow::Result<(Vec<[f64; 3]>, f64)> {
    anyhow::ensure!(
        deformed_m.len() == mesh.positions.len(),
        "{} deformed positions for {} mesh vertices",
        deformed_m.len(),
        mesh.positions.len()
    );
    // Mass plays no part in the forces; any positive density builds.
    let options = BuildOptions::tensor_mass(material, 1000.0, Vec::new(), Precision::F64);
    let file = f64_table(mesh, report, &options)?;
    let table = TensorMassTable::<f64>::load(file.bytes()).context("tensor-mass table")?;
    let mut state = OwnedState::for_table(&table);
    let params = host_params(&mesh.positions, 0.0)
        .with_law(law)
        .with_incompressibility(incompressibility_n);
    let model = TensorMassModel::new(table, state.buffers(), params)?;
    let u: Vec<[f64; 3]> = deformed_m
        .iter()
        .zip(&mesh.positions)
        .map(|(x, p)| [x[0] - p[0], x[1] - p[1], x[2] - p[2]])
        .collect();
    let mut forces = vec![[0.0; 3]; u.len()];
    model.elastic_forces_of(&u, &mut forces);
    let mut scratch = vec![[0.0; 3]; u.len()];
    let energy = model.elastic_energy_of(&u, &mut scratch);
    if !forces.iter().flatten().all(|f| f.is_finite()) {
        return Err(NonFiniteResult { what: "force" }.into());
    }
    if !energy.is_finite() {
        return Err(NonFiniteResult { what: "energy" }.into());
    }
    Ok((forces, energy))
}

/// Reads deformed positions: one line `x,y,z` (m) per mesh vertex, input
/// order, no header, for a mesh of `vertices` vertices. The read is bounded
/// by [`positions_file_bytes`] of them before anything is parsed (a device
/// such as `/dev/zero` is read no further). Errors name the file and the
/// line.
pub fn read_positions_csv(
    path: &std::path::Path,
    vertices: usize,
) -> anyhow::Result<Vec<[f64; 3]>> {
    let bytes = crate::limits::read_bounded(
        path,
        positions_file_bytes(vertices),
        "a positions file of this mesh (MAX_POSITION_LINE_BYTES per vertex)",
    )
    .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .trim(csv::Trim::All)
        .from_reader(bytes.as_slice());
    let mut positions = Vec::new();
    for (index, record) in reader.deserialize::<[f64; 3]>().enumerate() {
        let line = index + 1;
        let p =
            record.with_context(|| format!("{} line {line}: expected x,y,z", path.display()))?;
        anyhow::ensure!(
            p.iter().all(|c| c.is_finite()),
            "{} line {line}: non-finite coordinate",
            path.display()
        );
        positions.push(p);
    }
    Ok(positions)
}

/// The largest positions file of a mesh of `vertices` vertices, bytes:
/// [`MAX_POSITION_LINE_BYTES`](crate::limits::MAX_POSITION_LINE_BYTES) per
/// vertex, within [`MAX_MESH_FILE_BYTES`](crate::limits::MAX_MESH_FILE_BYTES).
pub fn positions_file_bytes(vertices: usize) -> u64 {
    (vertices as u64)
        .saturating_add(1)
        .saturating_mul(crate::limits::MAX_POSITION_LINE_BYTES)
        .min(crate::limits::MAX_MESH_FILE_BYTES)
}
