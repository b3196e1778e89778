//! The incompressibility penalty γ of the tensor-mass models with a volume
//! penalty (Picinbono 2001 §3.3), scaled to the mesh and the material.

use super::material::Material;
use crate::mesh::TetMesh;

/// `γ = PENALTY_SCALE · μ · V̄^(2/3)` (N), with `V̄` the mean rest tet volume:
/// the penalty on a corner, `γ (ΔV/V₀)²`, then equals the elastic force
/// scale `μ V̄^(2/3) |ΔV/V₀|` of the tet at a `1/PENALTY_SCALE` volume
/// change and dominates beyond it. Picinbono gives no value for γ. A larger
/// γ keeps the volume better but also stiffens bending, which moves the
/// stage forces (measured on the default cylinder at 30° tilt: scale 10,
/// 0.10 N, ΔV/V₀ = −0.49 %; scale 30, 0.12 N, −0.30 %; scale 100, 0.20 N,
/// −0.21 %; plain St Venant-Kirchhoff needs 0.09 N). 10 keeps the stage
/// forces closest to plain St Venant-Kirchhoff's.
pub const PENALTY_SCALE: f64 = 10.0;

/// The penalty γ (N) of [`PENALTY_SCALE`] for `mesh` and `material`.
pub fn penalty_n(mesh: &TetMesh, material: &Material) -> f64 {
    let total: f64 = (0..mesh.tets.len()).map(|t| mesh.tet_volume(t)).sum();
    let mean = total / mesh.tets.len() as f64;
    PENALTY_SCALE * material.lame().1 * mean.powf(2.0 / 3.0)
}
