//! `palpate precomputed`: queries of the pre-computed model through the
//! kernel's code path: one contact set (`solve`), a contact sequence file
//! (`replay`).

use std::path::PathBuf;

use anyhow::{Context, bail};
use clap::{ArgMatches, Subcommand};
use palpate::limits::{MAX_SEQUENCE_FILE_BYTES, read_bounded};
use palpate::table::load::{AnyModel, TableFile};
use palpate_kernel::{Constraint, Real};

use super::args::JsonArgs;
use super::stdout;

#[derive(Subcommand)]
pub enum PrecomputedCommand {
    /// Contact forces and every vertex displacement for one contact set.
    Solve {
        /// Table file.
        table: PathBuf,
        /// Vertex contact <V>:<dx>,<dy>,<dz> (m).
        #[arg(long = "contact", allow_hyphen_values = true)]
        contact: Vec<String>,
        /// Barycentric contact <A>,<B>,<C>@<ba>,<bb>,<bc>:<dx>,<dy>,<dz> (m).
        #[arg(long = "contact-bary", allow_hyphen_values = true)]
        contact_bary: Vec<String>,
        #[command(flatten)]
        json: JsonArgs,
    },
    /// Run a contact sequence file (one step per line) and print each step's
    /// forces as f32 bit patterns, exactly as the firmware example does.
    Replay {
        /// Table file (f32).
        table: PathBuf,
        /// Sequence file.
        sequence: PathBuf,
    },
}

/// Runs a `precomputed` command; `matches` are those of `precomputed` (the
/// contacts are read from them in command-line order).
pub fn run(command: PrecomputedCommand, matches: &ArgMatches) -> anyhow::Result<()> {
    match command {
        PrecomputedCommand::Solve { table, json, .. } => {
            json.require("precomputed solve")?;
            let solve = matches
                .subcommand_matches("solve")
                .context("internal: solve arguments")?;
            let file = TableFile::read(&table)?;
            let model = file
                .model()
                .with_context(|| format!("{}: invalid table", table.display()))?;
            let text = match model {
                AnyModel::F32(m) => {
                    serde_json::to_string(&palpate::precomputed::solve(&m, &contacts(solve)?)?)?
                }
                AnyModel::F64(m) => {
                    serde_json::to_string(&palpate::precomputed::solve(&m, &contacts(solve)?)?)?
                }
            };
            stdout::println(&text)?;
            Ok(())
        }
        PrecomputedCommand::Replay { table, sequence } => {
            let file = TableFile::read(&table)?;
            let text = read_bounded(
                &sequence,
                MAX_SEQUENCE_FILE_BYTES,
                "a sequence file (MAX_SEQUENCE_FILE_BYTES)",
            )
            .and_then(|bytes| {
                String::from_utf8(bytes)
                    .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, e))
            })
            .with_context(|| format!("{}: cannot read", sequence.display()))?;
            let (table_name, sequence_name) =
                (table.display().to_string(), sequence.display().to_string());
            let lines = palpate::replay::replay(&file, &table_name, &text, &sequence_name)?;
            stdout::print(&lines)?;
            Ok(())
        }
    }
}

/// The `--contact` and `--contact-bary` values in command-line order.
fn contacts<T: Real>(solve: &ArgMatches) -> anyhow::Result<Vec<Constraint<T>>> {
    let mut all: Vec<(usize, bool, &String)> = Vec::new();
    for (id, bary) in [("contact", false), ("contact_bary", true)] {
        if let (Some(indices), Some(values)) = (solve.indices_of(id), solve.get_many::<String>(id))
        {
            all.extend(indices.zip(values).map(|(i, v)| (i, bary, v)));
        }
    }
    all.sort_by_key(|(i, _, _)| *i);
    all.into_iter()
        .map(|(_, bary, text)| {
            let flag = if bary { "--contact-bary" } else { "--contact" };
            let contact = palpate_script::parse_contact::<T>(text)
                .map_err(|e| anyhow::anyhow!("{flag} '{text}': {e}"))?;
            let is_bary = matches!(contact.point, palpate_kernel::ContactPoint::Triangle { .. });
            if is_bary != bary {
                bail!("{flag} '{text}': wrong form for {flag}");
            }
            Ok(contact)
        })
        .collect()
}
