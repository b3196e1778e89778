//! `palpate dynamic`: the tensor-mass model (RR-3510 §5) stepped through the
//! kernel: a scripted run (`run`) and the critical time step of an
//! integrator (`critical-dt`).

use std::path::PathBuf;

use anyhow::{Context, anyhow, bail};
use clap::Subcommand;
use palpate::dispatch::HostDispatch;
use palpate::hybrid::HybridOptions;
use palpate::hybrid::hmatrix::InterfaceCompression;
use palpate::hybrid::stability::critical_dt_of_hybrid;
use palpate::mesh::{MeshReport, TetMesh, read_mesh};
use palpate::partition::Partition;
use palpate::scene::Scene;
use palpate::session::options::tensor_mass_options;
use palpate::table::build::BuildOptions;
use palpate::table::file::Precision;
use palpate::tensor_mass::run::RunOptions;
use palpate::threads::Threaded;
use palpate_kernel::tensor_mass::{ElasticLaw, Integrator};

use super::args::{
    FixArgs, FormArg, JsonArgs, MassMaterialArgs, ThreadsArgs, finite_vector, non_negative,
    optional_fix, positive,
};
use super::stdout;

#[derive(Subcommand)]
pub enum DynamicCommand {
    /// Step the model under constant loads and print the final state as JSON.
    Run {
        #[command(flatten)]
        model: DynamicModelArgs,
        /// Constant external force <V>:<fx>,<fy>,<fz> (N, repeatable).
        #[arg(long = "load", value_parser = parse_load, allow_hyphen_values = true)]
        load: Vec<(u32, [f64; 3])>,
        /// Gravity <gx>,<gy>,<gz> (m/s2).
        #[arg(long, value_parser = finite_vector, allow_hyphen_values = true, default_value = "0,0,0")]
        gravity: [f64; 3],
        /// Time step, s.
        #[arg(long, value_parser = positive, allow_negative_numbers = true)]
        dt: f64,
        /// Number of steps.
        #[arg(long)]
        steps: usize,
        /// Tets to remove before the first step: <i>,<j>,...
        #[arg(long = "cut-tets", value_delimiter = ',')]
        cut_tets: Vec<u32>,
        /// Elastic law: linear tensor-mass, St Venant-Kirchhoff, St
        /// Venant-Kirchhoff with the incompressibility penalty,
        /// co-rotational linear, or neo-Hookean (the last two per tet).
        #[arg(long = "model", value_enum, default_value = "linear")]
        law: ModelArg,
        /// How the St Venant-Kirchhoff force is evaluated.
        #[arg(long, value_enum, default_value = "per-tet")]
        form: FormArg,
        /// Incompressibility penalty γ, N (required by, and only for,
        /// --model stvk-incompressible).
        #[arg(long)]
        incompressibility: Option<f64>,
        /// What the table stores and the step computes in: f64
        /// (verification) or f32 (the firmware's); the output is the same
        /// JSON either way. A hybrid scene runs in f64 only.
        #[arg(long, value_enum, default_value = "f64")]
        precision: Precision,
        #[command(flatten)]
        threads: ThreadsArgs,
    },
    /// Largest stable time step of an integrator (bisection) next to 2/ω_max.
    CriticalDt {
        #[command(flatten)]
        model: DynamicModelArgs,
    },
}

/// What both `dynamic` commands take: the mesh, its material and supports
/// (or a scene in their place), the damping and the integrator.
#[derive(clap::Args)]
#[command(mut_arg("fix", optional_fix))]
pub struct DynamicModelArgs {
    /// Input mesh (.msh, .node/.ele, .vtk), metres.
    #[arg(required_unless_present = "scene")]
    mesh: Option<PathBuf>,
    /// A scene (file, or a built-in name) in place of the mesh, --young,
    /// --poisson, --density and --fix: its mesh, per-region materials and
    /// supports; its [[zone]]s, when they make part of the mesh dynamic,
    /// run the hybrid model (displacements of every mesh vertex).
    #[arg(long, conflicts_with_all = ["mesh", "young", "poisson", "density", "fix"])]
    scene: Option<String>,
    #[command(flatten)]
    material: MassMaterialArgs,
    /// Mass-proportional damping c (1/s): damping force −c·m_i·v_i.
    #[arg(long, value_parser = non_negative, allow_negative_numbers = true)]
    damping: f64,
    #[command(flatten)]
    fix: FixArgs,
    /// Time integrator.
    #[arg(long, value_enum)]
    integrator: IntegratorArg,
    #[command(flatten)]
    json: JsonArgs,
}

/// What a `dynamic` command runs on.
struct Setup {
    mesh: TetMesh,
    report: MeshReport,
    /// The (f64) tensor-mass table options: materials, density, supports.
    table: BuildOptions,
    /// The tets a scene's zones make dynamic, when they make some but not
    /// all: the hybrid model.
    hybrid: Option<Vec<bool>>,
    /// The hybrid's interface compressed as the scene's `[tables]` says.
    interface_compression: Option<InterfaceCompression>,
    /// The mesh file or the scene, for messages.
    name: String,
}

impl DynamicModelArgs {
    /// Checks `--json`, reads the mesh (or the scene and its mesh) and
    /// gathers the (f64) table options.
    fn read(&self, command: &str) -> anyhow::Result<Setup> {
        self.json.require(&format!("dynamic {command}"))?;
        if let Some(name) = &self.scene {
            let scene = Scene::named(name)?;
            let (mesh, report) = scene.load_mesh()?;
            let mut table = tensor_mass_options(&scene, &mesh, &report)?;
            table.precision = Precision::F64;
            let hybrid = if scene.zones.is_empty() {
                None
            } else {
                let partition =
                    Partition::of_scene(&scene, &mesh, &report).map_err(|e| anyhow!("{e}"))?;
                let dynamic = partition.dynamic.iter().filter(|&&d| d).count();
                (dynamic > 0 && dynamic < mesh.tets.len()).then_some(partition.dynamic)
            };
            return Ok(Setup {
                mesh,
                report,
                table,
                hybrid,
                interface_compression: scene.tables.interface_compression(),
                name: scene.source,
            });
        }
        let (Some(path), Some(material)) = (&self.mesh, self.material.given()) else {
            bail!("give a mesh with --young, --poisson and --density, or --scene");
        };
        let (material, density) = material?;
        let (mesh, report) = read_mesh(path)?;
        let table =
            BuildOptions::tensor_mass(material, density, self.fix.fix.clone(), Precision::F64);
        Ok(Setup {
            mesh,
            report,
            table,
            hybrid: None,
            interface_compression: None,
            name: path.display().to_string(),
        })
    }
}

/// `--model` of `dynamic run`.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ModelArg {
    Linear,
    Stvk,
    StvkIncompressible,
    Corotational,
    NeoHookean,
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
            (ModelArg::Corotational, None) => Ok((ElasticLaw::Corotational, None)),
            (ModelArg::NeoHookean, None) => Ok((ElasticLaw::NeoHookean, None)),
            (ModelArg::StvkIncompressible, Some(gamma)) if gamma.is_finite() && gamma >= 0.0 => {
                Ok((stvk, Some(gamma)))
            }
            (ModelArg::StvkIncompressible, Some(gamma)) => {
                bail!(
                    "--incompressibility must be finite and >= 0 N, got {}",
                    palpate::output::number::shown(gamma)
                )
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

/// `--integrator`.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum IntegratorArg {
    Euler,
    Symplectic,
    Rk4,
    Central,
}

impl IntegratorArg {
    /// Every integrator, in the kernel's order (`Integrator::ALL`).
    pub const ALL: [IntegratorArg; 4] = [
        IntegratorArg::Euler,
        IntegratorArg::Symplectic,
        IntegratorArg::Rk4,
        IntegratorArg::Central,
    ];
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

fn parse_load(s: &str) -> Result<(u32, [f64; 3]), String> {
    palpate_script::parse_vertex_vector(s).map_err(|e| e.to_string())
}

/// Runs a `dynamic` command: prints its JSON object.
pub fn run(command: DynamicCommand) -> anyhow::Result<()> {
    match command {
        DynamicCommand::Run {
            model,
            load,
            gravity,
            dt,
            steps,
            cut_tets,
            law,
            form,
            incompressibility,
            precision,
            threads,
        } => {
            let setup = model.read("run")?;
            let (law, incompressibility_n) = law.law(form, incompressibility)?;
            if setup.hybrid.is_some() && precision != Precision::F64 {
                bail!("--precision f32: a hybrid scene runs in f64 only");
            }
            let options = RunOptions {
                table: setup.table,
                precision,
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
            let (mesh, report) = (&setup.mesh, &setup.report);
            let output = match &setup.hybrid {
                Some(dynamic) => palpate::hybrid::run::run(
                    mesh,
                    report,
                    dynamic,
                    setup.interface_compression,
                    &options,
                ),
                None => {
                    let dispatch = Threaded::new(HostDispatch::detect(), threads.count());
                    palpate::tensor_mass::run::run_with(mesh, report, &options, dispatch)
                }
            }
            .with_context(|| setup.name.clone())?;
            stdout::println(&serde_json::to_string(&output)?)?;
            Ok(())
        }
        DynamicCommand::CriticalDt { model } => {
            let setup = model.read("critical-dt")?;
            let (mesh, report, table) = (&setup.mesh, &setup.report, &setup.table);
            let integrator = model.integrator.into();
            let json = match &setup.hybrid {
                Some(dynamic) => {
                    let options = HybridOptions {
                        interface_compression: setup.interface_compression,
                        ..HybridOptions::of_tensor_mass(table)?
                    };
                    let result = critical_dt_of_hybrid(
                        mesh,
                        report,
                        dynamic,
                        &options,
                        model.damping,
                        integrator,
                    )
                    .with_context(|| setup.name.clone())?;
                    serde_json::to_string(&result)?
                }
                None => {
                    let result = palpate::tensor_mass::stability::critical_dt_of_mesh(
                        mesh,
                        report,
                        table,
                        model.damping,
                        integrator,
                    )
                    .with_context(|| setup.name.clone())?;
                    serde_json::to_string(&result)?
                }
            };
            stdout::println(&json)?;
            Ok(())
        }
    }
}
