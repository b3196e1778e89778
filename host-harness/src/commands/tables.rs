//! `palpate tables`: build a table of either kind (`build`), print a table's
//! report (`info`).

use std::path::PathBuf;

use anyhow::{Context, bail};
use clap::parser::ValueSource;
use clap::{ArgMatches, Subcommand};
use palpate::mesh::read_mesh;
use palpate::table::build::{BuildOptions, TableKindOptions, build};
use palpate::table::compliance::Solver;
use palpate::table::file::Precision;
use palpate::table::load::TableFile;

use super::args::{FixArgs, MaterialArgs};

#[derive(Subcommand)]
pub enum TablesCommand {
    /// Build the compliance table of a tetrahedral mesh (.msh, .node/.ele, .vtk),
    /// or with `--kind tensor-mass` its tensor-mass table (RR-3510 §5).
    Build {
        /// Input mesh.
        mesh: PathBuf,
        #[command(flatten)]
        material: MaterialArgs,
        #[command(flatten)]
        fix: FixArgs,
        /// Sparse Cholesky (default) or the paper's conjugate-gradient baseline.
        #[arg(long, value_enum, default_value = "cholesky")]
        solver: SolverArg,
        /// Stored float width: f32 (firmware) or f64 (verification).
        #[arg(long, value_enum, default_value = "f32")]
        precision: Precision,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
        /// Output table file.
        #[arg(short = 'o', long = "output")]
        output: PathBuf,
        /// Table kind: the pre-computed compliance table (RR-3510 §4) or the
        /// dynamic tensor-mass table (§5).
        #[arg(long, value_enum, default_value = "precomputed")]
        kind: TableKindArg,
        /// Mass density, kg/m3 (required with, and only with, --kind tensor-mass).
        #[arg(long)]
        density: Option<f64>,
    },
    /// Print a table's counts, sizes, material and checksum status.
    Info {
        /// Table file.
        table: PathBuf,
    },
}

/// `tables build --kind`: which model's table.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum TableKindArg {
    Precomputed,
    TensorMass,
}

/// `tables build --solver`.
#[derive(Clone, Copy, clap::ValueEnum)]
pub enum SolverArg {
    Cholesky,
    Cg,
}

impl From<SolverArg> for Solver {
    fn from(solver: SolverArg) -> Self {
        match solver {
            SolverArg::Cholesky => Solver::Cholesky,
            SolverArg::Cg => Solver::Cg,
        }
    }
}

/// Runs a `tables` command; `matches` are those of `tables` (whether
/// `--solver` was given is read from them).
pub fn run(command: TablesCommand, matches: &ArgMatches) -> anyhow::Result<()> {
    match command {
        TablesCommand::Build {
            mesh,
            material,
            fix,
            solver,
            precision,
            quiet,
            output,
            kind,
            density,
        } => {
            let solver_given = matches
                .subcommand_matches("build")
                .and_then(|m| m.value_source("solver"))
                == Some(ValueSource::CommandLine);
            let kind = match (kind, density) {
                (TableKindArg::TensorMass, None) => {
                    bail!("--kind tensor-mass needs --density <kg/m3>")
                }
                (TableKindArg::Precomputed, Some(_)) => {
                    bail!(
                        "--density applies to --kind tensor-mass only (the pre-computed model is quasi-static)"
                    )
                }
                (TableKindArg::TensorMass, Some(_)) if solver_given => {
                    bail!("--solver applies to --kind precomputed only")
                }
                (TableKindArg::TensorMass, Some(density_kg_m3)) => {
                    TableKindOptions::TensorMass { density_kg_m3 }
                }
                (TableKindArg::Precomputed, None) => TableKindOptions::Precomputed {
                    solver: solver.into(),
                },
            };
            let (mesh_data, report) = read_mesh(&mesh)?;
            for w in &report.warnings {
                eprintln!("warning: {w}");
            }
            let options = BuildOptions {
                kind,
                material: material.material()?,
                fix: fix.fix,
                precision,
                progress: !quiet,
            };
            let built = build(&mesh_data, &report, &options)?;
            std::fs::write(&output, &built.bytes)
                .with_context(|| format!("{}: cannot write", output.display()))?;
            // The summary line on stderr: the mesh, then the kind's counts.
            let vertices = format!(
                "{} vertices ({} fixed by --fix, {} unreferenced kept fixed), {} tets",
                mesh_data.positions.len(),
                built.fixed_by_predicate,
                built.fixed_unreferenced,
                mesh_data.tets.len()
            );
            let mesh_notes = format!(
                "{} non-tet elements skipped, {} tets reoriented",
                report.skipped_elements, report.reoriented_tets
            );
            let (source, bytes, output) = (&report.source, built.bytes.len(), output.display());
            match kind {
                TableKindOptions::Precomputed { .. } => eprintln!(
                    "{source}: {vertices}, {} free, {} touchable; {mesh_notes}; \
                     compliance in {:.3} s; wrote {bytes} bytes to {output}",
                    built.free_count,
                    built.touchable_count,
                    built.arrays_time.as_secs_f64()
                ),
                TableKindOptions::TensorMass { density_kg_m3 } => eprintln!(
                    "{source}: tensor-mass table: {vertices}, {} edges, {density_kg_m3} kg/m3; \
                     {mesh_notes}; wrote {bytes} bytes to {output}",
                    built.edge_count
                ),
            }
            Ok(())
        }
        TablesCommand::Info { table } => {
            let file = TableFile::read(&table)?;
            match file.info(&table.display().to_string()) {
                Ok(report) => {
                    print!("{report}");
                    Ok(())
                }
                Err(report) => {
                    print!("{report}");
                    bail!("{}: table failed validation", table.display())
                }
            }
        }
    }
}
