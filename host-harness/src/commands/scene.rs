//! `palpate scene`: what a scene asks of the models. `plan` prints the hybrid partition the
//! harness chooses from the scene's zones (MODELS.md §5): per region its model and law, tets,
//! vertices and connection nodes, table size, predicted step cost, stable step and why.
//! `tables` writes a hybrid scene's three tables (RR-3510 §6.2) for firmware; `replay-hybrid`
//! runs the firmware's scripted hybrid sequence on them through the same code
//! ([`palpate_script::hybrid`]), for `tools/firmware-check.sh --hybrid` to compare byte for byte.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use clap::Subcommand;
use palpate::hybrid::owned::with_hybrid_files;
use palpate::limits::{MAX_SEQUENCE_FILE_BYTES, read_bounded};
use palpate::output::atomic::{self, FolderKind, SeriesDir};
use palpate::output::vtk::write_regions;
use palpate::partition::{Partition, PlanReport};
use palpate::scene::{MeshSource, Scene, ZoneShape};
use palpate::session::model::{SceneModel, hybrid_tables};
use palpate::table::file::Precision;
use palpate::table::load::TableFile;

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
    /// Write a hybrid scene's three tables: DIR/precomputed.bin, DIR/dynamic.bin,
    /// DIR/interface.bin (the scene's zones must make some, not all, tets dynamic).
    Tables {
        /// Scene file (TOML), or a built-in scene name as `session run` takes.
        scene: String,
        /// Output folder: created, or replaced as a whole (the three tables
        /// together) if a previous run wrote it; anything else is refused.
        #[arg(long)]
        out_dir: PathBuf,
        /// Stored float width: f32 (firmware) or f64 (verification).
        #[arg(long, value_enum, default_value = "f32")]
        precision: Precision,
    },
    /// Replay the firmware's hybrid sequence on f32 tables written by `scene tables` and print
    /// one line per step (format: the palpate-script crate's `hybrid` module).
    ReplayHybrid {
        /// Folder holding precomputed.bin, dynamic.bin and interface.bin.
        tables: PathBuf,
        /// Sequence file (palpate-script contact syntax, one line per step).
        sequence: PathBuf,
        /// The tensor-mass region's law: linear (the firmware scene's), stvk (tet by tet),
        /// corotational or neo-hookean; the firmware takes the same name in
        /// PALPATE_HYBRID_LAW.
        #[arg(long, default_value = "linear")]
        law: String,
    },
}

/// The files `scene tables` writes in its `--out-dir`: the pre-computed region's table, the
/// tensor-mass region's, the interface (RR-3510 §6.2).
const TABLE_FILES: [&str; 3] = ["precomputed.bin", "dynamic.bin", "interface.bin"];

/// Runs a `scene` command.
pub fn run(command: SceneCommand) -> anyhow::Result<()> {
    match command {
        SceneCommand::Plan { scene, json, vtk } => plan(&scene, json, vtk.as_deref()),
        SceneCommand::Tables {
            scene,
            out_dir,
            precision,
        } => tables(&scene, &out_dir, precision),
        SceneCommand::ReplayHybrid {
            tables,
            sequence,
            law,
        } => replay_hybrid(&tables, &sequence, &law),
    }
}

/// The scene named `name` and the files it reads (the scene file, its mesh, its zones'
/// trajectories), labelled for [`atomic::refuse_input`].
fn scene_and_inputs(name: &str) -> anyhow::Result<(Scene, Vec<(&'static str, PathBuf)>)> {
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
    Ok((scene, inputs))
}

/// Refuses `output` (labelled `label`) if it is one of `inputs`.
fn refuse_input(label: &str, output: &Path, inputs: &[(&str, PathBuf)]) -> anyhow::Result<()> {
    let inputs: Vec<(&str, &Path)> = inputs.iter().map(|(l, p)| (*l, p.as_path())).collect();
    Ok(atomic::refuse_input((label, output), &inputs)?)
}

/// `scene plan`.
fn plan(name: &str, json: bool, vtk: Option<&Path>) -> anyhow::Result<()> {
    let (scene, inputs) = scene_and_inputs(name)?;
    if let Some(out) = vtk {
        refuse_input("--vtk", out, &inputs)?;
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

/// `scene tables`: the three tables of a hybrid scene, built in memory, written into a fresh
/// hidden folder and renamed into place as `out_dir` ([`SeriesDir`]): `out_dir` holds the old
/// set or the new one, never a mix; nothing changes if the build fails. Refused before any
/// work: an `out_dir` palpate did not write, or one holding an input.
fn tables(name: &str, out_dir: &Path, precision: Precision) -> anyhow::Result<()> {
    let (scene, inputs) = scene_and_inputs(name)?;
    let labelled: Vec<(&str, &Path)> = inputs.iter().map(|(l, p)| (*l, p.as_path())).collect();
    atomic::refuse_inside(("--out-dir", out_dir), &labelled)?;
    let folder = SeriesDir::of_kind(out_dir, FolderKind::HybridTables)?;
    let (mesh, report) = scene.load_mesh()?;
    let SceneModel::Hybrid { partition, .. } = SceneModel::of(&scene, &mesh, &report)? else {
        bail!(
            "scene {name}: not a hybrid: its [[zone]]s must make some tets dynamic, not none or all (see `palpate scene plan`)"
        );
    };
    let built = hybrid_tables(&scene, &mesh, &report, &partition, precision)?;
    for (file, table) in
        TABLE_FILES
            .iter()
            .zip([&built.precomputed, &built.dynamic, &built.interface])
    {
        atomic::write_file(&folder.dir().join(file), table.bytes())?;
    }
    Ok(folder.commit()?)
}

/// `scene replay-hybrid`: the three f32 tables of `dir` and the sequence, through
/// [`palpate_script::hybrid::replay`] on heap buffers (the firmware's are static arrays), the
/// tensor-mass region under the law named `law` ([`palpate_script::hybrid::LAWS`]).
fn replay_hybrid(dir: &Path, sequence: &Path, law: &str) -> anyhow::Result<()> {
    let Some(law) = palpate_script::hybrid::law_named(law) else {
        let names: Vec<&str> = palpate_script::hybrid::LAWS
            .iter()
            .map(|(n, _)| *n)
            .collect();
        bail!(
            "--law {law}: not a law of the hybrid replay; one of {}",
            names.join(", ")
        );
    };
    let [precomputed, dynamic, interface] = TABLE_FILES.map(|f| TableFile::read(&dir.join(f)));
    let text = read_bounded(
        sequence,
        MAX_SEQUENCE_FILE_BYTES,
        "a sequence file (MAX_SEQUENCE_FILE_BYTES)",
    )
    .and_then(|bytes| {
        String::from_utf8(bytes)
            .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, e))
    })
    .with_context(|| format!("{}: cannot read", sequence.display()))?;
    let mut out = String::new();
    with_hybrid_files(
        [&precomputed?, &dynamic?, &interface?],
        palpate_script::hybrid::params(law),
        |model| {
            let mut displacements = vec![[0.0f32; 3]; model.interface().vertex_count()];
            palpate_script::hybrid::replay(model, &text, &mut displacements, &mut out)
        },
    )
    .with_context(|| format!("{}: the hybrid tables", dir.display()))?
    .with_context(|| sequence.display().to_string())?;
    stdout::print(&out)?;
    Ok(())
}
