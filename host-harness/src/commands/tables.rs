//! `palpate tables`: build a table of either kind (`build`), print a table's
//! report (`info`).

use std::io::Write as _;
use std::path::{Path, PathBuf};

use anyhow::bail;
use clap::parser::ValueSource;
use clap::{ArgMatches, Subcommand};
use palpate::mesh::{MeshReport, TetMesh, read_mesh};
use palpate::output::atomic::{self, AtomicFile};
use palpate::output::stderr;
use palpate::table::build::{
    BuildOptions, BuiltTable, DEFAULT_LIST_TOOL_RADIUS_M, TableKindOptions, build_with_limits,
};
use palpate::table::compliance::Solver;
use palpate::table::compress::{BlockCode, Compression, ContactBlocks};
use palpate::table::estimate::SizeLimits;
use palpate::table::file::Precision;
use palpate::table::hmatrix::DEFAULT_TOLERANCE;
use palpate::table::load::TableFile;

use super::args::{FixArgs, MaterialArgs, fraction};
use super::{mesh_files, stdout};

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
        /// Store the compliance in 16 bits per value with a per-column scale
        /// (f16: binary16; q16: fixed point), about half the f32 table; or
        /// (hmatrix) the touchable compliance as a hierarchical matrix,
        /// far blocks low-rank within --tolerance, no interior
        /// displacements; hmatrix-q16: the same in 16-bit fixed point
        /// with a scale per block, about half the bytes. The force and displacement errors are measured
        /// and stored in the table (`tables info` prints them).
        #[arg(long, value_enum, value_name = "CODE")]
        compress: Option<BlockCode>,
        /// With --compress hmatrix|hmatrix-q16: the far blocks' relative truncation
        /// tolerance (Frobenius norm per block), in (0, 1); default 1e-5.
        #[arg(long, value_name = "REL")]
        tolerance: Option<f64>,
        /// With --compress: leave out each interior compliance block whose
        /// largest entry is below REL times the largest of its column
        /// (far-field blocks; they count as zero), REL in [0, 1).
        #[arg(long, value_name = "REL", value_parser = fraction, allow_negative_numbers = true)]
        drop_below: Option<f64>,
        /// With --compress: how the touchable-touchable blocks (the contact
        /// solve's) are stored: coded (default), f32, or coded with
        /// --drop-below applied to them too (costs contact force accuracy).
        #[arg(long, value_enum)]
        contact_blocks: Option<ContactBlocks>,
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
        /// The largest tool-sphere radius, m, the pre-computed table's
        /// per-cell contact candidate lists serve (a larger tool still
        /// works, by the slower walk over 27 grid cells); at most the grid
        /// cell over 2.25 (the longest surface edge over 2.25, or more).
        #[arg(long, value_name = "M", default_value_t = DEFAULT_LIST_TOOL_RADIUS_M)]
        tool_radius: f64,
        /// Refuse, before building, a table estimated above this many bytes
        /// (the estimate is printed; 4294967296, MAX_TABLE_FILE_BYTES, and the
        /// memory available apply in any case).
        #[arg(long, value_name = "BYTES")]
        max_table_bytes: Option<u64>,
    },
    /// Print a table's counts, sizes, material and checksum status.
    Info {
        /// Table file.
        table: PathBuf,
        /// Print one JSON object instead: at least `{"bytes": N, "encoding":
        /// "...", "measured": {"force_error": x, "touchable_displacement_error":
        /// x}}` (a pre-computed table; an uncompressed one measures 0 against
        /// itself; other kinds have a null encoding).
        #[arg(long)]
        json: bool,
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

/// `; compressed …, …` for a compressed table's summary line: its encoding
/// and the errors measured at build time; empty otherwise.
fn compression_note(bytes: &[u8]) -> String {
    let file = TableFile::from_bytes(bytes);
    match palpate_kernel::PrecomputedTable::<f32>::load(file.bytes()) {
        Ok(table) => match table.compression() {
            Some(record) => format!("; {}", palpate::table::load::describe_compression(record)),
            None => String::new(),
        },
        Err(_) => String::new(),
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
            compress,
            tolerance,
            drop_below,
            contact_blocks,
            quiet,
            output,
            kind,
            density,
            tool_radius,
            max_table_bytes,
        } => {
            let solver_given = matches
                .subcommand_matches("build")
                .and_then(|m| m.value_source("solver"))
                == Some(ValueSource::CommandLine);
            let compression = compression(compress, tolerance, drop_below, contact_blocks)?;
            let kind = kind_options(
                kind,
                density,
                solver,
                solver_given,
                compression,
                tool_radius,
            )?;
            // The output: never one of the inputs, and written whole or not at
            // all (opened before the build, so an unwritable path fails fast).
            let inputs = mesh_files(&mesh);
            let inputs: Vec<(&str, &Path)> =
                inputs.iter().map(|p| ("the mesh", p.as_path())).collect();
            atomic::refuse_input(("-o", output.as_path()), &inputs)?;
            let mut file = AtomicFile::create(&output)?;
            let (mesh_data, report) = read_mesh(&mesh)?;
            for w in &report.warnings {
                stderr::line(&format!("warning: {w}"));
            }
            let options = BuildOptions {
                kind,
                material: material.material()?,
                tet_materials: None,
                fix: fix.fix,
                precision,
                progress: !quiet,
            };
            // The size estimate is checked (and printed) before the build.
            let limits = SizeLimits {
                max_table_bytes,
                print_estimate: true,
                ..SizeLimits::system()
            };
            let built = build_with_limits(&mesh_data, &report, &options, &limits)?;
            file.write_all(&built.bytes)?;
            file.commit()?;
            summary_line(&mesh_data, &report, &built, &kind, &output);
            Ok(())
        }
        TablesCommand::Info { table, json } => {
            // Read whole when small enough, so a damaged table is reported.
            let file = TableFile::read_for_report(&table)?;
            if json {
                return match palpate::table::info_json::info_json(&file) {
                    Ok(value) => Ok(stdout::print(&format!("{value}\n"))?),
                    Err(e) => bail!("{}: table failed validation: {e}", table.display()),
                };
            }
            match file.info(&table.display().to_string()) {
                Ok(report) => {
                    stdout::print(&report)?;
                    Ok(())
                }
                Err(report) => {
                    stdout::print(&report)?;
                    bail!("{}: table failed validation", table.display())
                }
            }
        }
    }
}

/// The compression of `--compress` with its `--tolerance` (hmatrix only),
/// `--drop-below` and `--contact-blocks` (f16 and q16 only; all refused
/// without `--compress`).
fn compression(
    compress: Option<BlockCode>,
    tolerance: Option<f64>,
    drop_below: Option<f64>,
    contact_blocks: Option<ContactBlocks>,
) -> anyhow::Result<Option<Compression>> {
    if compress.is_some_and(BlockCode::is_hierarchical) {
        if drop_below.is_some() || contact_blocks.is_some() {
            bail!(
                "--drop-below and --contact-blocks apply to --compress f16|q16: --compress \
                 hmatrix|hmatrix-q16 keeps every touchable block (far ones low-rank within \
                 --tolerance) and no interior one"
            );
        }
    } else if tolerance.is_some() {
        bail!("--tolerance applies to --compress hmatrix|hmatrix-q16");
    }
    if compress.is_none() {
        if drop_below.is_some() {
            bail!("--drop-below applies to a compressed table: add --compress f16|q16");
        }
        if contact_blocks.is_some() {
            bail!("--contact-blocks applies to a compressed table: add --compress f16|q16");
        }
    }
    Ok(compress.map(|code| Compression {
        code,
        drop_below: drop_below.unwrap_or(0.0),
        contact: contact_blocks.unwrap_or_default(),
        tolerance: tolerance.unwrap_or(DEFAULT_TOLERANCE),
    }))
}

/// The table kind's options of `--kind` with `--density`, `--solver`
/// (`solver_given`: on the command line), the `compression` and
/// `--tool-radius`: each option refused where its kind does not take it.
fn kind_options(
    kind: TableKindArg,
    density: Option<f64>,
    solver: SolverArg,
    solver_given: bool,
    compression: Option<Compression>,
    tool_radius: f64,
) -> anyhow::Result<TableKindOptions> {
    Ok(match (kind, density) {
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
        (TableKindArg::TensorMass, Some(_)) if compression.is_some() => {
            bail!("--compress applies to --kind precomputed only")
        }
        (TableKindArg::TensorMass, Some(density_kg_m3)) => {
            TableKindOptions::TensorMass { density_kg_m3 }
        }
        (TableKindArg::Precomputed, None) => TableKindOptions::Precomputed {
            solver: solver.into(),
            compression,
            tool_radius_m: tool_radius,
        },
    })
}

/// The build's summary line on stderr: the mesh, then the kind's counts.
fn summary_line(
    mesh_data: &TetMesh,
    report: &MeshReport,
    built: &BuiltTable,
    kind: &TableKindOptions,
    output: &Path,
) {
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
        TableKindOptions::Precomputed { .. } => stderr::line(&format!(
            "{source}: {vertices}, {} free, {} touchable; {mesh_notes}; \
             compliance in {:.3} s; wrote {bytes} bytes to {output}{}",
            built.free_count,
            built.touchable_count,
            built.arrays_time.as_secs_f64(),
            compression_note(&built.bytes)
        )),
        TableKindOptions::TensorMass { density_kg_m3 } => stderr::line(&format!(
            "{source}: tensor-mass table: {vertices}, {} edges, {density_kg_m3} kg/m3; \
             {mesh_notes}; wrote {bytes} bytes to {output}",
            built.edge_count
        )),
    }
}
