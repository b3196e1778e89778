//! The study's tables of a body: the tensor-mass tables' density, the
//! hybrid's tables, and the nodal loads set on their models.

use anyhow::Context;
use nalgebra::Vector3;
use palpate_kernel::hybrid::HybridModel;
use palpate_kernel::tensor_mass::TensorMassModel;

use super::body::Body;
use crate::fem::material::Material;
use crate::hybrid::{HybridOptions, HybridTables, build_hybrid};
use crate::table::file::Precision;

/// Density of the tensor-mass tables, kg/m³ (the static studies').
pub(super) const DENSITY_KG_M3: f64 = 1000.0;

/// The hybrid's tables of `body` with `material` in `precision`: its
/// tensor-mass region [`Body::hybrid_dynamic_tets`], the rest pre-computed.
pub(crate) fn hybrid_tables(
    body: &Body,
    material: Material,
    precision: Precision,
) -> anyhow::Result<HybridTables> {
    let options = HybridOptions::new(material, DENSITY_KG_M3, body.fix.clone(), precision);
    build_hybrid(
        &body.mesh,
        &body.report,
        &body.hybrid_dynamic_tets(),
        &options,
    )
}

/// The nodal `loads` of the whole mesh on the hybrid's tensor-mass region
/// (its vertex numbering); every loaded vertex must lie in it.
pub(crate) fn region_loads(
    tables: &HybridTables,
    loads: &[[f64; 3]],
) -> anyhow::Result<Vec<[f64; 3]>> {
    let split = &tables.split;
    let mut local = vec![[0.0; 3]; split.dynamic_vertex.len()];
    for (v, f) in loads.iter().enumerate() {
        if f.iter().any(|&x| x != 0.0) {
            let l =
                split.dynamic_index[v].context("a loaded vertex outside the tensor-mass region")?;
            local[l as usize] = *f;
        }
    }
    Ok(local)
}

/// Sets the nonzero nodal `loads` (N, f64, converted to `T`) on `model`.
pub(crate) fn set_loads<T: palpate_kernel::Real>(
    model: &mut TensorMassModel<'_, '_, T>,
    loads: &[[f64; 3]],
) -> anyhow::Result<()> {
    for (v, f) in loads.iter().enumerate() {
        if f.iter().any(|&x| x != 0.0) {
            model.set_external_force(v as u32, Vector3::from(f.map(T::of_f64)))?;
        }
    }
    Ok(())
}

/// The hybrid's displacement field over the whole mesh of `n` vertices, m:
/// the pre-computed region's background brought up to date first.
pub(crate) fn hybrid_field(
    h: &mut HybridModel<'_, '_, f64>,
    n: usize,
) -> anyhow::Result<Vec<[f64; 3]>> {
    let mut u = vec![[0.0; 3]; n];
    h.update_background(usize::MAX)?;
    h.displacements::<1>(None, &mut u)?;
    Ok(u)
}
