//! `palpate stvk`: the St Venant-Kirchhoff force (Picinbono 2001,
//! MODELS.md §4) of one deformed configuration (`forces`).

use std::path::PathBuf;

use clap::Subcommand;
use palpate::mesh::read_mesh;
use palpate::tensor_mass::evaluate::{NonFiniteResult, forces_and_energy, read_positions_csv};
use palpate_kernel::tensor_mass::ElasticLaw;

use super::args::{FormArg, JsonArgs, MaterialArgs};
use super::stdout;

#[derive(Subcommand)]
pub enum StvkCommand {
    /// Internal elastic forces (−∂W/∂x, free body) and energy of a deformed mesh.
    Forces {
        /// Input mesh (.msh, .node/.ele, .vtk), rest positions, metres.
        mesh: PathBuf,
        #[command(flatten)]
        material: MaterialArgs,
        /// Deformed positions: one line x,y,z (m) per mesh vertex, input order, no header.
        #[arg(long)]
        deformed: PathBuf,
        /// Which implementation evaluates the force.
        #[arg(long, value_enum, default_value = "per-tet")]
        form: FormArg,
        #[command(flatten)]
        json: JsonArgs,
    },
}

/// Runs a `stvk` command: prints `{"forces": [...], "energy": J}`.
pub fn run(command: StvkCommand) -> anyhow::Result<()> {
    match command {
        StvkCommand::Forces {
            mesh: path,
            material,
            deformed,
            form,
            json,
        } => {
            json.require("stvk forces")?;
            let (mesh, report) = read_mesh(&path)?;
            let deformed_m = read_positions_csv(&deformed, mesh.positions.len())?;
            anyhow::ensure!(
                deformed_m.len() == mesh.positions.len(),
                "{}: {} lines of deformed positions, expected one x,y,z line per vertex of {} ({} vertices)",
                deformed.display(),
                deformed_m.len(),
                path.display(),
                mesh.positions.len()
            );
            // A non-finite result comes from the deformed positions: name them.
            let (forces, energy) = forces_and_energy(
                &mesh,
                &report,
                material.material()?,
                ElasticLaw::StVenantKirchhoff(form.into()),
                None,
                &deformed_m,
            )
            .map_err(|e| {
                let source = if e.downcast_ref::<NonFiniteResult>().is_some() {
                    &deformed
                } else {
                    &path
                };
                e.context(source.display().to_string())
            })?;
            let output = serde_json::json!({ "forces": forces, "energy": energy });
            stdout::println(&output.to_string())?;
            Ok(())
        }
    }
}
