//! `palpate experiment`: reproductions of the papers' figures
//! (`volume-bend`: Picinbono 2001 table 2).

use clap::Subcommand;
use palpate::experiment::{scenes, volume_bend};

use super::stdout;

#[derive(Subcommand)]
pub enum ExperimentCommand {
    /// Picinbono 2001 table 2: volume change of a bent cylinder (three stages)
    /// and a lifted organ lobe, linear vs St Venant-Kirchhoff vs St
    /// Venant-Kirchhoff + incompressibility, at static equilibrium.
    VolumeBend {
        /// Print one JSON object instead of the table.
        #[arg(long)]
        json: bool,
    },
}

/// Runs an `experiment` command: progress on stderr, the table (or JSON
/// with the paper's figures beside it) on stdout.
pub fn run(command: ExperimentCommand) -> anyhow::Result<()> {
    match command {
        ExperimentCommand::VolumeBend { json } => {
            let controls = volume_bend::Controls::default();
            let mut results = Vec::new();
            for scene in [scenes::default_cylinder(), scenes::organ()] {
                results.push(volume_bend::run_scene(&scene, &controls, |line| {
                    eprintln!("{line}")
                })?);
            }
            if json {
                let paper: serde_json::Map<String, serde_json::Value> = volume_bend::PAPER_TABLE_2
                    .iter()
                    .map(|(name, [linear, stvk, incompressible])| {
                        let value = serde_json::json!({
                            "linear": linear,
                            "stvk": stvk,
                            "stvk_incompressible": incompressible,
                        });
                        (name.to_string(), value)
                    })
                    .collect();
                let output = serde_json::json!({ "scenes": results, "paper_percent": paper });
                stdout::println(&output.to_string())?;
            } else {
                stdout::print(&volume_bend::table(&results))?;
            }
            Ok(())
        }
    }
}
