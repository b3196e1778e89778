//! The `palpate` command line (contract in README.md): tables, solves, demo.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, bail};
use clap::{ArgMatches, CommandFactory, FromArgMatches, Parser, Subcommand};
use palpate::dynamic::run::RunOptions;
use palpate::fem::material::Material;
use palpate::fix::FixPredicate;
use palpate::mesh::{MeshReport, TetMesh, read_mesh};
use palpate::tables::build::{BuildOptions, build_table};
use palpate::tables::compliance::Solver;
use palpate::tables::file::Precision;
use palpate::tables::load::{AnyModel, TableFile};
use palpate::tables::tensor_mass::TensorMassOptions;
use palpate_kernel::tensor_mass::{ElasticLaw, Integrator, StvkForm};
use palpate_kernel::{Constraint, Real};

#[derive(Parser)]
#[command(
    name = "palpate",
    version,
    about = "Real-time soft-tissue kernel: host harness"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Offline tables of the pre-computed model.
    #[command(subcommand)]
    Tables(TablesCommand),
    /// Queries of the pre-computed model, through the kernel code path.
    #[command(subcommand)]
    Precomputed(PrecomputedCommand),
    /// The dynamic tensor-mass model (RR-3510 §5), stepped through the kernel.
    #[command(subcommand)]
    Dynamic(DynamicCommand),
    /// The St Venant-Kirchhoff force (Picinbono 2001, MODELS.md §4).
    #[command(subcommand)]
    Stvk(StvkCommand),
    /// Experiments that reproduce the papers' figures.
    #[command(subcommand)]
    Experiment(ExperimentCommand),
    /// Haptic sessions: the kernel's fixed-timestep loop driven by a trajectory.
    #[command(subcommand)]
    Session(SessionCommand),
    /// Per-tick instruction counts (callgrind) of every generated trajectory
    /// against the static bound from the table sizes and capacities.
    Budget {
        /// Scene file (TOML), `built-in` or `built-in-dynamic`.
        scene: String,
        /// Working folder for tables, trajectories and callgrind dumps.
        #[arg(long, default_value = "budget-out")]
        work_dir: PathBuf,
        /// Print one JSON array instead of the table.
        #[arg(long)]
        json: bool,
        /// Internal: run the ticks of this trajectory on this table (the
        /// process callgrind measures).
        #[arg(long, hide = true, num_args = 2, value_names = ["TABLE", "TRAJECTORY"])]
        probe: Option<Vec<PathBuf>>,
    },
    /// Built-in scene: two-probe press and release, forces, timings, VTK series.
    Demo {
        /// Folder for the VTK series (created if absent).
        #[arg(long, default_value = "demo-out")]
        out: PathBuf,
    },
}

#[derive(Subcommand)]
enum TablesCommand {
    /// Build the compliance table of a tetrahedral mesh (.msh, .node/.ele, .vtk),
    /// or with `--kind tensor-mass` its tensor-mass table (RR-3510 §5).
    Build {
        /// Input mesh.
        mesh: PathBuf,
        /// Young's modulus, Pa.
        #[arg(long)]
        young: f64,
        /// Poisson ratio, in [0, 0.5).
        #[arg(long)]
        poisson: f64,
        /// Fixed vertices: x|y|z then <, <=, > or >= then a number in mesh units (repeatable).
        #[arg(long = "fix", required = true, value_parser = parse_fix, allow_hyphen_values = true)]
        fix: Vec<FixPredicate>,
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
enum TableKindArg {
    Precomputed,
    TensorMass,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum SolverArg {
    Cholesky,
    Cg,
}

#[derive(Subcommand)]
enum PrecomputedCommand {
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
        /// Print one JSON object (the only output format).
        #[arg(long)]
        json: bool,
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

/// What both `dynamic` commands take: the mesh, its material and supports,
/// the damping and the integrator.
#[derive(clap::Args)]
struct DynamicModelArgs {
    /// Input mesh (.msh, .node/.ele, .vtk), metres.
    mesh: PathBuf,
    /// Young's modulus, Pa.
    #[arg(long)]
    young: f64,
    /// Poisson ratio, in [0, 0.5).
    #[arg(long)]
    poisson: f64,
    /// Mass density, kg/m3.
    #[arg(long)]
    density: f64,
    /// Mass-proportional damping c (1/s): damping force −c·m_i·v_i.
    #[arg(long)]
    damping: f64,
    /// Fixed vertices: x|y|z then <, <=, > or >= then a number (repeatable; none = free body).
    #[arg(long = "fix", value_parser = parse_fix, allow_hyphen_values = true)]
    fix: Vec<FixPredicate>,
    /// Time integrator.
    #[arg(long, value_enum)]
    integrator: IntegratorArg,
    /// Print one JSON object (the only output format).
    #[arg(long)]
    json: bool,
}

impl DynamicModelArgs {
    /// Checks `--json`, reads the mesh and gathers the table options.
    fn read(&self, command: &str) -> anyhow::Result<(TetMesh, MeshReport, TensorMassOptions)> {
        if !self.json {
            bail!("dynamic {command} prints JSON only: pass --json");
        }
        let (mesh, report) = read_mesh(&self.mesh)?;
        let options = TensorMassOptions {
            material: Material::new(self.young, self.poisson)?,
            density_kg_m3: self.density,
            fix: self.fix.clone(),
            precision: Precision::F64,
        };
        Ok((mesh, report, options))
    }
}

#[derive(Subcommand)]
enum SessionCommand {
    /// Drive the haptic loop tick by tick; write `t,fx,fy,fz,contacts,status` per tick.
    Run {
        /// Scene file (TOML), `built-in` (the demo block, pre-computed model) or
        /// `built-in-dynamic` (the same block on the dynamic model).
        scene: String,
        /// Trajectory file: CSV `t,tool,x,y,z` (s, tool point, m) with a header.
        #[arg(long)]
        trajectory: PathBuf,
        /// Output CSV, one line per tick.
        #[arg(long)]
        out: PathBuf,
        /// Folder for a VTK frame per physics update and `session.pvd`.
        #[arg(long)]
        vtk: Option<PathBuf>,
        /// Keep non-finite values and backward times (reported on stderr) and
        /// feed them to the kernel, for robustness runs.
        #[arg(long)]
        lenient: bool,
    },
    /// Write a generated trajectory for the built-in scene.
    Generate {
        /// Which path.
        #[arg(value_enum)]
        kind: TrajectoryKind,
        /// Output CSV.
        #[arg(short = 'o', long = "output")]
        output: PathBuf,
    },
}

/// The trajectory generators.
#[derive(Clone, Copy, clap::ValueEnum)]
enum TrajectoryKind {
    Poke,
    PressHold,
    Slide,
    Pinch,
    Strike,
}

#[derive(Subcommand)]
enum ExperimentCommand {
    /// Picinbono 2001 table 2: volume change of a bent cylinder (three stages)
    /// and a lifted organ lobe, linear vs St Venant-Kirchhoff vs St
    /// Venant-Kirchhoff + incompressibility, at static equilibrium.
    VolumeBend {
        /// Print one JSON object instead of the table.
        #[arg(long)]
        json: bool,
    },
}

#[derive(Subcommand)]
enum StvkCommand {
    /// Internal elastic forces (−∂W/∂x, free body) and energy of a deformed mesh.
    Forces {
        /// Input mesh (.msh, .node/.ele, .vtk), rest positions, metres.
        mesh: PathBuf,
        /// Young's modulus, Pa.
        #[arg(long)]
        young: f64,
        /// Poisson ratio, in [0, 0.5).
        #[arg(long)]
        poisson: f64,
        /// Deformed positions: one line x,y,z (m) per mesh vertex, input order, no header.
        #[arg(long)]
        deformed: PathBuf,
        /// Which implementation evaluates the force.
        #[arg(long, value_enum, default_value = "per-tet")]
        form: FormArg,
        /// Print one JSON object (the only output format).
        #[arg(long)]
        json: bool,
    },
}

#[derive(Subcommand)]
enum DynamicCommand {
    /// Step the model under constant loads and print the final state as JSON.
    Run {
        #[command(flatten)]
        model: DynamicModelArgs,
        /// Constant external force <V>:<fx>,<fy>,<fz> (N, repeatable).
        #[arg(long = "load", value_parser = parse_load, allow_hyphen_values = true)]
        load: Vec<(u32, [f64; 3])>,
        /// Gravity <gx>,<gy>,<gz> (m/s2).
        #[arg(long, value_parser = parse_gravity, allow_hyphen_values = true, default_value = "0,0,0")]
        gravity: [f64; 3],
        /// Time step, s.
        #[arg(long)]
        dt: f64,
        /// Number of steps.
        #[arg(long)]
        steps: usize,
        /// Tets to remove before the first step: <i>,<j>,...
        #[arg(long = "cut-tets", value_delimiter = ',')]
        cut_tets: Vec<u32>,
        /// Elastic law: linear tensor-mass, St Venant-Kirchhoff, or St
        /// Venant-Kirchhoff with the incompressibility penalty.
        #[arg(long = "model", value_enum, default_value = "linear")]
        law: ModelArg,
        /// How the St Venant-Kirchhoff force is evaluated.
        #[arg(long, value_enum, default_value = "per-tet")]
        form: FormArg,
        /// Incompressibility penalty γ, N (required by, and only for,
        /// --model stvk-incompressible).
        #[arg(long)]
        incompressibility: Option<f64>,
    },
    /// Largest stable time step of an integrator (bisection) next to 2/ω_max.
    CriticalDt {
        #[command(flatten)]
        model: DynamicModelArgs,
    },
}

/// `--model` of `dynamic run`.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum ModelArg {
    Linear,
    Stvk,
    StvkIncompressible,
}

/// `--form`: the two St Venant-Kirchhoff implementations.
#[derive(Clone, Copy, clap::ValueEnum)]
enum FormArg {
    /// Per tet from the deformation gradient.
    PerTet,
    /// Picinbono's split terms on vertices, edges, triangles and tets.
    Tensors,
}

impl From<FormArg> for StvkForm {
    fn from(form: FormArg) -> Self {
        match form {
            FormArg::PerTet => StvkForm::PerTet,
            FormArg::Tensors => StvkForm::Tensors,
        }
    }
}

impl ModelArg {
    /// The law and penalty of `--model`, `--form` and `--incompressibility`.
    fn law(
        self,
        form: FormArg,
        incompressibility: Option<f64>,
    ) -> anyhow::Result<(ElasticLaw, Option<f64>)> {
        let stvk = ElasticLaw::StVenantKirchhoff(form.into());
        match (self, incompressibility) {
            (ModelArg::Linear, None) => Ok((ElasticLaw::Linear, None)),
            (ModelArg::Stvk, None) => Ok((stvk, None)),
            (ModelArg::StvkIncompressible, Some(gamma)) if gamma.is_finite() && gamma >= 0.0 => {
                Ok((stvk, Some(gamma)))
            }
            (ModelArg::StvkIncompressible, Some(gamma)) => {
                bail!("--incompressibility must be finite and >= 0 N, got {gamma}")
            }
            (ModelArg::StvkIncompressible, None) => {
                bail!("--model stvk-incompressible needs --incompressibility <gamma> (N)")
            }
            (_, Some(_)) => {
                bail!("--incompressibility applies to --model stvk-incompressible only")
            }
        }
    }
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum IntegratorArg {
    Euler,
    Symplectic,
    Rk4,
    Central,
}

impl From<IntegratorArg> for Integrator {
    fn from(arg: IntegratorArg) -> Self {
        match arg {
            IntegratorArg::Euler => Integrator::ExplicitEuler,
            IntegratorArg::Symplectic => Integrator::SymplecticEuler,
            IntegratorArg::Rk4 => Integrator::Rk4,
            IntegratorArg::Central => Integrator::CentralDifference,
        }
    }
}

fn parse_fix(s: &str) -> Result<FixPredicate, String> {
    s.parse()
}

fn parse_load(s: &str) -> Result<(u32, [f64; 3]), String> {
    palpate_script::parse_vertex_vector(s).map_err(|e| e.to_string())
}

fn parse_gravity(s: &str) -> Result<[f64; 3], String> {
    palpate_script::parse_vector(s).map_err(|e| e.to_string())
}

fn main() -> ExitCode {
    let matches = Cli::command().get_matches();
    let result = Cli::from_arg_matches(&matches)
        .map_err(anyhow::Error::from)
        .and_then(|cli| run(cli, &matches));
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}

fn run(cli: Cli, matches: &ArgMatches) -> anyhow::Result<()> {
    match cli.command {
        Command::Tables(TablesCommand::Build {
            mesh,
            young,
            poisson,
            fix,
            solver,
            precision,
            quiet,
            output,
            kind,
            density,
        }) => {
            let tensor_mass = kind == TableKindArg::TensorMass;
            let solver_given = matches
                .subcommand_matches("tables")
                .and_then(|m| m.subcommand_matches("build"))
                .and_then(|m| m.value_source("solver"))
                == Some(clap::parser::ValueSource::CommandLine);
            match (tensor_mass, density) {
                (true, None) => bail!("--kind tensor-mass needs --density <kg/m3>"),
                (false, Some(_)) => {
                    bail!(
                        "--density applies to --kind tensor-mass only (the pre-computed model is quasi-static)"
                    )
                }
                (true, Some(_)) if solver_given => {
                    bail!("--solver applies to --kind precomputed only")
                }
                _ => {}
            }
            let (mesh_data, report) = read_mesh(&mesh)?;
            for w in &report.warnings {
                eprintln!("warning: {w}");
            }
            if let (true, Some(density_kg_m3)) = (tensor_mass, density) {
                let (_, fixed_by_predicate) = palpate::fix::fixed_vertices(
                    &mesh_data.positions,
                    &fix,
                    &report.unreferenced_vertices,
                );
                let options = TensorMassOptions {
                    material: Material::new(young, poisson)?,
                    density_kg_m3,
                    fix,
                    precision,
                };
                let bytes = palpate::tables::tensor_mass::build_tensor_mass_table(
                    &mesh_data, &report, &options,
                )?;
                std::fs::write(&output, &bytes)
                    .with_context(|| format!("{}: cannot write", output.display()))?;
                let edges = TableFile::from_bytes(&bytes)
                    .raw_header()
                    .map_or(0, |h| h.edge_count);
                eprintln!(
                    "{}: tensor-mass table: {} vertices ({} fixed by --fix, {} unreferenced kept \
                     fixed), {} tets, {} edges, {} kg/m3; {} non-tet elements skipped, {} tets \
                     reoriented; wrote {} bytes to {}",
                    report.source,
                    mesh_data.positions.len(),
                    fixed_by_predicate,
                    report.unreferenced_vertices.len(),
                    mesh_data.tets.len(),
                    edges,
                    density_kg_m3,
                    report.skipped_elements,
                    report.reoriented_tets,
                    bytes.len(),
                    output.display()
                );
                return Ok(());
            }
            let options = BuildOptions {
                material: Material::new(young, poisson)?,
                fix,
                solver: match solver {
                    SolverArg::Cholesky => Solver::Cholesky,
                    SolverArg::Cg => Solver::Cg,
                },
                precision,
                progress: !quiet,
            };
            let built = build_table(&mesh_data, &report, &options)?;
            std::fs::write(&output, &built.bytes)
                .with_context(|| format!("{}: cannot write", output.display()))?;
            eprintln!(
                "{}: {} vertices ({} fixed by --fix, {} unreferenced kept fixed), {} tets, \
                 {} free, {} touchable; {} non-tet elements skipped, {} tets reoriented; \
                 compliance in {:.3} s; wrote {} bytes to {}",
                report.source,
                mesh_data.positions.len(),
                built.fixed_by_predicate,
                built.fixed_unreferenced,
                mesh_data.tets.len(),
                built.free_count,
                built.touchable_count,
                report.skipped_elements,
                report.reoriented_tets,
                built.solve_time.as_secs_f64(),
                built.bytes.len(),
                output.display()
            );
            Ok(())
        }
        Command::Tables(TablesCommand::Info { table }) => {
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
        Command::Precomputed(PrecomputedCommand::Solve { table, json, .. }) => {
            if !json {
                bail!("precomputed solve prints JSON only: pass --json");
            }
            let solve = matches
                .subcommand_matches("precomputed")
                .and_then(|m| m.subcommand_matches("solve"))
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
            println!("{text}");
            Ok(())
        }
        Command::Precomputed(PrecomputedCommand::Replay { table, sequence }) => {
            let file = TableFile::read(&table)?;
            let text = std::fs::read_to_string(&sequence)
                .with_context(|| format!("{}: cannot read", sequence.display()))?;
            print!("{}", palpate::replay::replay(&file, &text)?);
            Ok(())
        }
        Command::Dynamic(DynamicCommand::Run {
            model,
            load,
            gravity,
            dt,
            steps,
            cut_tets,
            law,
            form,
            incompressibility,
        }) => {
            let (mesh, report, table) = model.read("run")?;
            let (law, incompressibility_n) = law.law(form, incompressibility)?;
            let options = RunOptions {
                table,
                damping_per_s: model.damping,
                law,
                incompressibility_n,
                loads: load,
                gravity_m_s2: gravity,
                integrator: model.integrator.into(),
                dt_s: dt,
                steps,
                cut_tets,
            };
            let output = palpate::dynamic::run::run(&mesh, &report, &options)
                .with_context(|| model.mesh.display().to_string())?;
            println!("{}", serde_json::to_string(&output)?);
            Ok(())
        }
        Command::Dynamic(DynamicCommand::CriticalDt { model }) => {
            let (mesh, report, table) = model.read("critical-dt")?;
            let result = palpate::dynamic::stability::critical_dt_of_mesh(
                &mesh,
                &report,
                &table,
                model.damping,
                model.integrator.into(),
            )
            .with_context(|| model.mesh.display().to_string())?;
            println!("{}", serde_json::to_string(&result)?);
            Ok(())
        }
        Command::Stvk(StvkCommand::Forces {
            mesh: path,
            young,
            poisson,
            deformed,
            form,
            json,
        }) => {
            if !json {
                bail!("stvk forces prints JSON only: pass --json");
            }
            let (mesh, report) = read_mesh(&path)?;
            let deformed_m = palpate::dynamic::evaluate::read_positions_csv(&deformed)?;
            let (forces, energy) = palpate::dynamic::evaluate::forces_and_energy(
                &mesh,
                &report,
                Material::new(young, poisson)?,
                ElasticLaw::StVenantKirchhoff(form.into()),
                None,
                &deformed_m,
            )
            .with_context(|| path.display().to_string())?;
            let output = serde_json::json!({ "forces": forces, "energy": energy });
            println!("{output}");
            Ok(())
        }
        Command::Experiment(ExperimentCommand::VolumeBend { json }) => {
            use palpate::experiment::{scenes, volume_bend};
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
                println!("{output}");
            } else {
                print!("{}", volume_bend::table(&results));
            }
            Ok(())
        }
        Command::Session(SessionCommand::Run {
            scene,
            trajectory,
            out,
            vtk,
            lenient,
        }) => {
            use palpate::session::{Scene, Trajectory};
            let scene = Scene::named(&scene)?;
            let points = scene.tool.points;
            let trajectory = if lenient {
                let (t, findings) = Trajectory::read_unchecked(&trajectory, points)?;
                for finding in findings {
                    eprintln!("warning: {finding}");
                }
                t
            } else {
                Trajectory::read(&trajectory, points)?
            };
            if let Some(dir) = &vtk {
                std::fs::create_dir_all(dir).with_context(|| dir.display().to_string())?;
            }
            let file = std::fs::File::create(&out).with_context(|| out.display().to_string())?;
            let mut writer = std::io::BufWriter::new(file);
            let summary = palpate::session::run::run_session(
                &scene,
                &trajectory,
                &mut writer,
                vtk.as_deref(),
            )?;
            std::io::Write::flush(&mut writer)?;
            eprintln!(
                "{} ticks ({} in contact, {} clamped, {} faulted); max force {:.3} N, max jump {:.4} N per tick; {} VTK frames",
                summary.ticks,
                summary.ticks_in_contact,
                summary.clamped,
                summary.faulted,
                summary.max_force_n,
                summary.max_jump_n,
                summary.frames
            );
            if let Some(e) = summary.physics_error {
                eprintln!("physics update failed at {e}; the force was zero from the next tick on");
            }
            Ok(())
        }
        Command::Session(SessionCommand::Generate { kind, output }) => {
            use palpate::session::{Generator, Pinch, Poke, PressHold, Slide, Strike};
            let trajectory = match kind {
                TrajectoryKind::Poke => Poke::default().trajectory(),
                TrajectoryKind::PressHold => PressHold::default().trajectory(),
                TrajectoryKind::Slide => Slide::default().trajectory(),
                TrajectoryKind::Pinch => Pinch::default().trajectory(),
                TrajectoryKind::Strike => Strike::default().trajectory(),
            }
            .map_err(|e| anyhow::anyhow!("{e}"))?;
            trajectory.write_csv_file(&output)?;
            Ok(())
        }
        Command::Budget {
            scene,
            work_dir,
            json,
            probe,
        } => budget(&scene, &work_dir, json, probe.as_deref()),
        Command::Demo { out } => palpate::demo::run(&out),
    }
}

/// `palpate budget`: measure every generated trajectory on the scene's mesh
/// (and, for a generated box, at half its resolution) under callgrind.
fn budget(
    scene_arg: &str,
    work_dir: &std::path::Path,
    json: bool,
    probe: Option<&[PathBuf]>,
) -> anyhow::Result<()> {
    use palpate::budget::{BudgetRow, M4F_IPS, budget_table, measure, trajectories};
    use palpate::session::{MeshSource, Scene, Trajectory};
    let mut scene = Scene::named(scene_arg)?;
    if let Some([table_path, trajectory_path]) = probe {
        let bytes = palpate::tables::load::TableFile::read(table_path)?;
        let trajectory = Trajectory::read(trajectory_path, scene.tool.points)?;
        let counters = palpate::budget::probe(bytes.bytes(), &scene, &trajectory)
            .with_context(|| table_path.display().to_string())?
            .counters;
        let lines: Vec<String> = counters
            .iter()
            .map(|c| {
                format!(
                    "{},{},{}",
                    c.contact.triangles_tested, c.contact.walk_steps, c.solves
                )
            })
            .collect();
        std::fs::write(trajectory_path.with_extension("work"), lines.join("\n"))?;
        return Ok(());
    }
    std::fs::create_dir_all(work_dir).with_context(|| work_dir.display().to_string())?;
    let exe = std::env::current_exe()?;
    let mut sizes = vec![scene.mesh.clone()];
    if let MeshSource::GeneratedBox { size_m, cells } = &scene.mesh {
        let coarse = cells.map(|c| (c / 2).max(1));
        sizes.insert(
            0,
            MeshSource::GeneratedBox {
                size_m: *size_m,
                cells: coarse,
            },
        );
    }
    let points = scene.tool.points;
    let mut rows: Vec<BudgetRow> = Vec::new();
    for (s, source) in sizes.into_iter().enumerate() {
        scene.mesh = source;
        let (mesh, report) = scene.load_mesh()?;
        let (bytes, bound) = budget_table(&scene, &mesh, &report)?;
        let table_path = work_dir.join(format!("table-{s}.bin"));
        std::fs::write(&table_path, &bytes)?;
        let file = TableFile::from_bytes(&bytes);
        for (name, trajectory) in trajectories(points)? {
            let csv = work_dir.join(format!("{name}-{s}.csv"));
            trajectory.write_csv_file(&csv)?;
            let args: Vec<String> = vec![
                "budget".into(),
                scene_arg.into(),
                "--probe".into(),
                table_path.display().to_string(),
                csv.display().to_string(),
            ];
            let irs = measure(&exe, &args, &work_dir.join(format!("cg-{name}-{s}")))?;
            let work = std::fs::read_to_string(csv.with_extension("work"))?;
            let mut max_work = [0u32; 3];
            for line in work.lines() {
                for (m, v) in max_work.iter_mut().zip(line.split(',')) {
                    *m = (*m).max(v.parse().unwrap_or(0));
                }
            }
            let max_ir = irs.iter().copied().max().unwrap_or(0);
            let total_ir = irs.iter().sum::<u64>();
            let mean_ir = total_ir as f64 / irs.len().max(1) as f64;
            // The host's time per instruction in the ticks, run natively.
            let native = palpate::budget::probe(file.bytes(), &scene, &trajectory)?;
            let host_ns_per_ir = native.ticks_s * 1e9 / total_ir.max(1) as f64;
            rows.push(BudgetRow {
                mesh: format!(
                    "{} vertices, {} tets",
                    mesh.positions.len(),
                    mesh.tets.len()
                ),
                trajectory: name,
                ticks: irs.len(),
                max_ir,
                mean_ir,
                bound_ir: bound,
                bound_host_us: bound as f64 * host_ns_per_ir / 1e3,
                max_work,
            });
        }
    }
    if json {
        println!("{}", serde_json::to_string(&rows)?);
        return Ok(());
    }
    println!(
        "{:<26} {:<11} {:>6} {:>9} {:>9} {:>9} {:>6} {:>11} {:>11} {:>12}",
        "mesh",
        "trajectory",
        "ticks",
        "mean Ir",
        "max Ir",
        "bound Ir",
        "max/b",
        "bound@168M",
        "bound@host",
        "tests/walk/solves"
    );
    for r in &rows {
        println!(
            "{:<26} {:<11} {:>6} {:>9.0} {:>9} {:>9} {:>6.3} {:>8.1} µs {:>8.2} µs {:>5}/{}/{}",
            r.mesh,
            r.trajectory,
            r.ticks,
            r.mean_ir,
            r.max_ir,
            r.bound_ir,
            r.max_ir as f64 / r.bound_ir as f64,
            r.bound_ir as f64 / M4F_IPS * 1e6,
            r.bound_host_us,
            r.max_work[0],
            r.max_work[1],
            r.max_work[2]
        );
    }
    if let Some(r) = rows.iter().find(|r| r.max_ir > r.bound_ir) {
        anyhow::bail!(
            "{} on {}: {} instructions exceed the bound {}",
            r.trajectory,
            r.mesh,
            r.max_ir,
            r.bound_ir
        );
    }
    Ok(())
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
