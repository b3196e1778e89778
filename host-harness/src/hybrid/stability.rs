//! The stable step of the hybrid model next to its tensor-mass region
//! alone (`dynamic critical-dt` on a hybrid scene; MODELS.md §3 for the
//! measurement, RR-3510 §6.2 for the coupling).

use palpate_kernel::tensor_mass::Integrator;
use serde::Serialize;

use super::build::{HybridOptions, build_hybrid};
use super::owned::with_hybrid;
use crate::mesh::{MeshReport, TetMesh};
use crate::table::build::BuildOptions;
use crate::table::file::Precision;
use crate::tensor_mass::run::{diagonal, host_params};
use crate::tensor_mass::stability::{
    CriticalDt, check_critical_dt_work, critical_dt, critical_dt_of_mesh,
};

/// The critical step of the hybrid and of its tensor-mass region alone.
#[derive(Serialize, Debug)]
pub struct HybridCriticalDt {
    /// The tensor-mass region coupled to the condensed pre-computed region.
    pub hybrid: CriticalDt,
    /// The tensor-mass region's mesh on its own (its connection nodes free,
    /// their mass its own tets'), the same fixed vertices.
    pub region_alone: CriticalDt,
}

/// Measures `integrator`'s critical step ([`critical_dt`]: bisection on the
/// energy of a perturbed, released state, with `2/ω_max` beside it) for the
/// hybrid of `mesh` with the tets of `dynamic_tet` dynamic (tables built in
/// f64 with `options`), and for its tensor-mass region alone; damping
/// `damping_per_s` (1/s) in both, perturbation 1e-3 of the mesh's
/// bounding-box diagonal.
pub fn critical_dt_of_hybrid(
    mesh: &TetMesh,
    report: &MeshReport,
    dynamic_tet: &[bool],
    options: &HybridOptions,
    damping_per_s: f64,
    integrator: Integrator,
) -> anyhow::Result<HybridCriticalDt> {
    // The coupled model's measurement and its region's alone.
    check_critical_dt_work(mesh.tets.len(), 2)?;
    let mut options = options.clone();
    options.build.precision = Precision::F64;
    let tables = build_hybrid(mesh, report, dynamic_tet, &options)?;
    let amplitude = 1e-3 * diagonal(&mesh.positions);
    let params = host_params(&mesh.positions, damping_per_s);
    let hybrid = with_hybrid(&tables, params, |hybrid| {
        critical_dt(hybrid.dynamic_mut(), integrator, amplitude)
    })?;
    let region = tables.split.dynamic_mesh(mesh);
    let build = &options.build;
    let alone = BuildOptions::tensor_mass(
        build.material,
        options.density_kg_m3,
        build.fix.clone(),
        Precision::F64,
    );
    let flags = &tables.split.dynamic_tet;
    let alone = alone.with_tet_materials(
        build
            .materials_for(mesh.tets.len())?
            .subset((0..flags.len()).filter(|&t| flags[t])),
    );
    let region_alone = critical_dt_of_mesh(&region, report, &alone, damping_per_s, integrator)?;
    Ok(HybridCriticalDt {
        hybrid,
        region_alone,
    })
}
