//! `palpate stvk`: the St Venant-Kirchhoff force (Picinbono 2001,
//! MODELS.md §4) of one deformed configuration (`forces`).

use std::path::PathBuf;

use clap::Subcommand;
use palpate_kernel::tensor_mass::ElasticLaw;

use super::args::{FormArg, JsonArgs, MaterialArgs};
use super::forces::print_forces;

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
            let law = ElasticLaw::StVenantKirchhoff(form.into());
            print_forces(&path, material.material()?, &deformed, law)
        }
    }
}
