//! `palpate dynamic run --scene` on a hybrid scene: the hybrid's tables
//! built in memory (f64) with the run's gravity and the pre-computed
//! region's point loads built in, `N` steps through the kernel, the JSON
//! report of `dynamic run` over every mesh vertex (RR-3510 §6.2).

use anyhow::{Context, bail};
use nalgebra::Vector3;

use super::build::{HybridOptions, build_hybrid};
use super::hmatrix::InterfaceCompression;
use super::owned::with_hybrid;
use crate::mesh::{MeshReport, TetMesh};
use crate::output::number::shown;
use crate::table::file::Precision;
use crate::tensor_mass::run::{RunOptions, RunOutput, host_params, run_steps, volume_change};

/// Runs `options` on the hybrid of `mesh` with the tets of `dynamic_tet` in
/// the tensor-mass region: a load on a vertex only the pre-computed region
/// has is built into its table, any other load is an external force of the
/// tensor-mass model; `--cut-tets` must name dynamic tets (the pre-computed
/// region cannot be cut); the interface's condensed stiffness compressed as
/// `interface_compression` says (`None`: dense). Divergence bound: the mesh's
/// bounding-box diagonal, as [`crate::tensor_mass::run::run`].
pub fn run(
    mesh: &TetMesh,
    report: &MeshReport,
    dynamic_tet: &[bool],
    interface_compression: Option<InterfaceCompression>,
    options: &RunOptions,
) -> anyhow::Result<RunOutput> {
    crate::tensor_mass::run::check_run_steps(mesh, options)?;
    if !(options.dt_s.is_finite() && options.dt_s > 0.0) {
        bail!("--dt must be finite and > 0 s, got {}", shown(options.dt_s));
    }
    let mut in_dynamic = vec![false; mesh.positions.len()];
    for (tet, _) in mesh.tets.iter().zip(dynamic_tet).filter(|(_, d)| **d) {
        for &v in tet {
            in_dynamic[v as usize] = true;
        }
    }
    let (precomputed_loads, dynamic_loads): (Vec<_>, Vec<_>) = options
        .loads
        .iter()
        .partition(|(v, _)| !in_dynamic.get(*v as usize).copied().unwrap_or(false));
    let mut build = options.table.clone();
    build.precision = Precision::F64;
    let hybrid = HybridOptions {
        gravity_m_s2: options.gravity_m_s2,
        point_loads: precomputed_loads,
        interface_compression,
        ..HybridOptions::of_tensor_mass(&build)?
    };
    let tables = build_hybrid(mesh, report, dynamic_tet, &hybrid)?;
    let split = &tables.split;
    let mesh_tet: Vec<u32> = (0..mesh.tets.len() as u32)
        .filter(|&t| split.dynamic_tet[t as usize])
        .collect();
    let params = host_params(&mesh.positions, options.damping_per_s)
        .with_law(options.law)
        .with_incompressibility(options.incompressibility_n)
        .with_gravity(Vector3::from(options.gravity_m_s2));
    with_hybrid(&tables, params, |hybrid| -> anyhow::Result<RunOutput> {
        for &tet in &options.cut_tets {
            let Some(local) = mesh_tet.iter().position(|&t| t == tet) else {
                bail!(
                    "--cut-tets {tet}: not a tet of the tensor-mass region (the pre-computed region cannot be cut)"
                );
            };
            hybrid
                .dynamic_mut()
                .remove_tet(local as u32)
                .with_context(|| format!("--cut-tets {tet}"))?;
        }
        for &(vertex, force) in &dynamic_loads {
            let local = split.dynamic_index[vertex as usize].unwrap_or(u32::MAX);
            hybrid
                .dynamic_mut()
                .set_external_force(local, Vector3::from(force))
                .with_context(|| format!("--load {vertex}"))?;
        }
        let mut first = vec![[0.0; 3]; mesh.positions.len()];
        hybrid.displacements::<1>(None, &mut first)?;
        let (last, kinetic_energy, fault) = run_steps(options.steps, first, |field| {
            let report = hybrid.step(options.integrator, options.dt_s)?;
            // A good step leaves a readable state of the right length.
            let _ = hybrid.displacements::<1>(None, field);
            Ok(report)
        })?;
        let mut alive = vec![true; mesh.tets.len()];
        for (&t, &a) in mesh_tet.iter().zip(hybrid.dynamic().tet_alive()) {
            alive[t as usize] = a;
        }
        Ok(RunOutput {
            volume_change: volume_change(mesh, &last, &alive),
            displacements: last,
            kinetic_energy,
            fault,
            removed_tets: (0..alive.len() as u32)
                .filter(|&t| !alive[t as usize])
                .collect(),
        })
    })?
}
