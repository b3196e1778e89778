//! `palpate forces`: the internal elastic forces (`−∂W/∂x`, free body) and
//! energy of one deformed configuration under a per-tet law (St
//! Venant-Kirchhoff, neo-Hookean, co-rotational; MODELS.md §4 and §8),
//! through the kernel's force pass (f64). `palpate stvk forces` prints the
//! same through [`print_forces`].

use std::path::{Path, PathBuf};

use clap::Args;
use palpate::fem::material::Material;
use palpate::mesh::read_mesh;
use palpate::tensor_mass::evaluate::{NonFiniteResult, forces_and_energy, read_positions_csv};
use palpate_kernel::tensor_mass::{ElasticLaw, StvkForm};

use super::args::{JsonArgs, MaterialArgs};
use super::stdout;

/// `palpate forces` arguments.
#[derive(Args)]
pub struct ForcesArgs {
    /// Input mesh (.msh, .node/.ele, .vtk), rest positions, metres.
    mesh: PathBuf,
    /// The elastic law.
    #[arg(long, value_enum)]
    model: LawArg,
    #[command(flatten)]
    material: MaterialArgs,
    /// Deformed positions: one line x,y,z (m) per mesh vertex, input order, no header.
    #[arg(long)]
    deformed: PathBuf,
    #[command(flatten)]
    json: JsonArgs,
}

/// `--model` of `forces`.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum LawArg {
    /// St Venant-Kirchhoff, per tet (as `stvk forces`).
    Stvk,
    /// Compressible neo-Hookean (Bonet & Wood), per tet.
    NeoHookean,
    /// Co-rotational linear (stiffness warping), per tet.
    Corotational,
}

/// Runs `palpate forces`: prints `{"forces": [...], "energy": J}`, the
/// energy `null` for the co-rotational law.
pub fn run(args: &ForcesArgs) -> anyhow::Result<()> {
    args.json.require("forces")?;
    let law = match args.model {
        LawArg::Stvk => ElasticLaw::StVenantKirchhoff(StvkForm::PerTet),
        LawArg::NeoHookean => ElasticLaw::NeoHookean,
        LawArg::Corotational => ElasticLaw::Corotational,
    };
    print_forces(&args.mesh, args.material.material()?, &args.deformed, law)
}

/// Reads `mesh_path` and the positions file `deformed`, and prints the
/// internal forces (N, one `[fx, fy, fz]` per vertex, input order) and the
/// energy (J) of `law` as `{"forces": [...], "energy": x}` (`energy` null
/// for [`ElasticLaw::Corotational`]). Errors name the file at fault.
pub fn print_forces(
    mesh_path: &Path,
    material: Material,
    deformed: &Path,
    law: ElasticLaw,
) -> anyhow::Result<()> {
    let (mesh, report) = read_mesh(mesh_path)?;
    let deformed_m = read_positions_csv(deformed, mesh.positions.len())?;
    anyhow::ensure!(
        deformed_m.len() == mesh.positions.len(),
        "{}: {} lines of deformed positions, expected one x,y,z line per vertex of {} ({} vertices)",
        deformed.display(),
        deformed_m.len(),
        mesh_path.display(),
        mesh.positions.len()
    );
    // A non-finite result comes from the deformed positions: name them.
    let (forces, energy) = forces_and_energy(&mesh, &report, material, law, None, &deformed_m)
        .map_err(|e| {
            let source = if e.downcast_ref::<NonFiniteResult>().is_some() {
                deformed
            } else {
                mesh_path
            };
            e.context(source.display().to_string())
        })?;
    let energy = (law != ElasticLaw::Corotational).then_some(energy);
    let output = serde_json::json!({ "forces": forces, "energy": energy });
    stdout::println(&output.to_string())?;
    Ok(())
}
