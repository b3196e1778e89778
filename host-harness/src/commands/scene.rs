//! `palpate scene`: what a scene asks of the models. `plan` prints the hybrid partition the
//! harness chooses from the scene's zones (MODELS.md §5): per region its model and law, tets,
//! vertices and connection nodes, table size, predicted step cost, stable step and why.

use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::Subcommand;
use palpate::output::atomic;
use palpate::output::vtk::write_regions;
use palpate::partition::{Partition, PlanReport};
use palpate::session::{MeshSource, Scene, ZoneShape};

use super::mesh_files;
use super::stdout;

#[derive(Subcommand)]
pub enum SceneCommand {
    /// Print the partition chosen from the scene's [[zone]]s: regions, sizes, costs, why.
    Plan {
        /// Scene file (TOML), or a built-in scene name as `session run` takes.
        scene: String,
        /// Print one JSON object: {"regions": [...], "connection_nodes": N, ...}.
        #[arg(long)]
        json: bool,
        /// Write the mesh with the integer cell field `region` (0 = pre-computed, 1.. = the
        /// dynamic regions) as legacy VTK, for ParaView.
        #[arg(long)]
        vtk: Option<PathBuf>,
    },
}

/// Runs a `scene` command.
pub fn run(command: SceneCommand) -> anyhow::Result<()> {
    match command {
        SceneCommand::Plan { scene, json, vtk } => plan(&scene, json, vtk.as_deref()),
    }
}

/// `scene plan`.
fn plan(name: &str, json: bool, vtk: Option<&Path>) -> anyhow::Result<()> {
    let mut inputs: Vec<(&str, PathBuf)> = Vec::new();
    if !Scene::BUILT_IN.contains(&name) {
        inputs.push(("the scene", PathBuf::from(name)));
    }
    let scene = Scene::named(name)?;
    if let MeshSource::File(mesh) = &scene.mesh {
        inputs.extend(
            mesh_files(mesh)
                .into_iter()
                .map(|f| ("the scene's mesh", f)),
        );
    }
    for zone in &scene.zones {
        if let ZoneShape::Path { trajectory, .. } = &zone.shape {
            inputs.push(("a [[zone]] trajectory", trajectory.clone()));
        }
    }
    if let Some(out) = vtk {
        let inputs: Vec<(&str, &Path)> = inputs.iter().map(|(l, p)| (*l, p.as_path())).collect();
        atomic::refuse_input(("--vtk", out), &inputs)?;
    }
    let (mesh, report) = scene.load_mesh()?;
    let partition = Partition::of_scene(&scene, &mesh, &report)?;
    let plan = PlanReport::new(&scene, &mesh, &report, &partition)
        .with_context(|| format!("{}: costing the partition", scene.source))?;
    if let Some(out) = vtk {
        write_regions(
            out,
            &mesh.positions,
            &mesh.tets,
            &partition.region_of_tets(),
        )?;
    }
    if json {
        stdout::println(&serde_json::to_string_pretty(&plan)?)?;
    } else {
        stdout::print(&plan.text())?;
    }
    Ok(())
}
