//! `palpate experiment`: reproductions of the papers' figures
//! (`volume-bend`: Picinbono 2001 table 2).

use clap::{Subcommand, ValueEnum};
use palpate::experiment::volume_bend::Protocol;
use palpate::experiment::{scenes, volume_bend};
use palpate::output::stderr;

use super::stdout;

#[derive(Subcommand)]
pub enum ExperimentCommand {
    /// Picinbono 2001 table 2: volume change of a bent cylinder (three stages)
    /// and a lifted organ lobe, linear vs St Venant-Kirchhoff vs St
    /// Venant-Kirchhoff + incompressibility, at static equilibrium.
    VolumeBend {
        /// Print one JSON object instead of the tables.
        #[arg(long)]
        json: bool,
        /// Which stages: the paper's loads F, 2F, 3F (F gives the linear
        /// model the paper's first volume change), the penalized model's
        /// tilts, or both (the paper's first).
        #[arg(long, value_enum, default_value_t = Protocols::Both)]
        protocol: Protocols,
    },
}

/// `--protocol` of `experiment volume-bend`.
#[derive(Clone, Copy, ValueEnum)]
pub enum Protocols {
    /// Loads F, 2F, 3F.
    PaperLoads,
    /// The penalized model's tilts 30°, 60°, 75°.
    Tilt,
    /// The paper's loads, then the tilts.
    Both,
}

impl Protocols {
    fn list(self) -> &'static [Protocol] {
        match self {
            Self::PaperLoads => &[Protocol::PaperLoads],
            Self::Tilt => &[Protocol::Tilt],
            Self::Both => &[Protocol::PaperLoads, Protocol::Tilt],
        }
    }
}

/// Runs an `experiment` command: progress on stderr, the table (or JSON
/// with the paper's figures beside it) on stdout.
pub fn run(command: ExperimentCommand) -> anyhow::Result<()> {
    match command {
        ExperimentCommand::VolumeBend { json, protocol } => {
            let controls = volume_bend::Controls::default();
            let mut tables = Vec::new();
            for &protocol in protocol.list() {
                let mut results = Vec::new();
                for scene in [scenes::default_cylinder(), scenes::organ()] {
                    results.push(volume_bend::run_scene(
                        &scene,
                        protocol,
                        &controls,
                        stderr::line,
                    )?);
                }
                tables.push(results);
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
                // Tilt results first: `scenes` held only those before the
                // paper's loads were added; each result names its protocol.
                let mut results: Vec<_> = tables.into_iter().flatten().collect();
                results.sort_by_key(|r| r.protocol != Protocol::Tilt);
                let output = serde_json::json!({ "scenes": results, "paper_percent": paper });
                stdout::println(&output.to_string())?;
            } else {
                let text: Vec<String> = tables.iter().map(|r| volume_bend::table(r)).collect();
                stdout::print(&text.join("\n"))?;
            }
            Ok(())
        }
    }
}
