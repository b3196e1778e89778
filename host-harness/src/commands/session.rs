//! `palpate session`: haptic sessions, the kernel's fixed-timestep loop
//! driven by a trajectory (`run`), the physics for a controller across a
//! link (`serve`), and generated trajectories (`generate`).

use std::path::{Path, PathBuf};

use clap::Subcommand;
use palpate::output::atomic::{self, AtomicFile};
use palpate::output::stderr;
use palpate::scene::generate::{hepatectomy, surgery};
use palpate::scene::{
    CutLine, Generator, GraspPull, MeshSource, Pinch, Poke, PressHold, Scene, Slide, Strike,
    Trajectory,
};
use palpate::session::run::{removed_path, removes_tets, run_session_to_files_threads};
use palpate::session::serve::{self, serve_scene, update_every};

use super::args::ThreadsArgs;
use super::mesh_files;

#[derive(Subcommand)]
pub enum SessionCommand {
    /// Drive the haptic loop tick by tick; write `t,fx,fy,fz,contacts,status` per tick.
    Run {
        /// Scene file (TOML), `built-in` (the demo block, pre-computed model),
        /// `built-in-dynamic` (the same block on the dynamic model),
        /// `built-in-tools` (the dynamic block with a grasper and a cutter) or
        /// `built-in-hybrid` (the organ on the hybrid model: a grasper on its
        /// pre-computed region, a cutter in its tensor-mass region).
        scene: String,
        /// Trajectory file: CSV `t,tool,x,y,z` (s, tool point, m) with a header,
        /// optionally with the tool columns `jaw_m,cut` (header
        /// `t,tool,x,y,z,jaw_m,cut`: a grasper's jaw opening, m; `1` enables a
        /// cutter's blade, `0` not).
        #[arg(long)]
        trajectory: PathBuf,
        /// Output CSV, one line per tick (replaced only when the run succeeds).
        /// A dynamic scene with a cutter or tearing also writes the removed
        /// tets, `t,tet` per tet in removal order, to OUT with the extension
        /// `removed.csv`.
        #[arg(long)]
        out: PathBuf,
        /// Folder for a VTK frame per physics update and `session.pvd`: created,
        /// or replaced if a previous run wrote it (anything else is refused).
        #[arg(long)]
        vtk: Option<PathBuf>,
        /// Keep non-finite values and backward times (reported on stderr) and
        /// feed them to the kernel, for robustness runs.
        #[arg(long)]
        lenient: bool,
        #[command(flatten)]
        threads: ThreadsArgs,
    },
    /// Run a dynamic scene's physics for a haptic controller on a loopback socket: reads its
    /// tool points (command frames), sends a physics update per period (update frames), and
    /// ends when the controller disconnects.
    Serve {
        /// Scene file (TOML) or a built-in scene on the dynamic model (`built-in-dynamic`,
        /// `built-in-tools`).
        scene: String,
        /// Address to listen on: loopback only (`127.0.0.1:PORT`, `[::1]:PORT`).
        #[arg(long)]
        listen: core::net::SocketAddr,
        /// Physics updates per second (the nearest whole number of haptic ticks per update).
        #[arg(long, default_value_t = 100.0)]
        update_hz: f64,
        #[command(flatten)]
        threads: ThreadsArgs,
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
pub enum TrajectoryKind {
    Poke,
    PressHold,
    Slide,
    Pinch,
    Strike,
    // A grasper (tool point 0: its centre) grasping the block, pulling and releasing.
    GraspPull,
    // A cutter (tool point 0: the blade's upper end) cutting a 6 cm line in the block.
    CutLine,
    // The `built-in-tools` scene's grasper (tool 0) and cutter (tool 1) at work together.
    Surgery,
    // The `built-in-hybrid` scene's grasper (tool 0) holding the organ's right lobe while its
    // cutter (tool 1) cuts the left lobe's tip off.
    Hepatectomy,
}

/// Runs a `session` command.
pub fn run(command: SessionCommand) -> anyhow::Result<()> {
    match command {
        SessionCommand::Run {
            scene,
            trajectory,
            out,
            vtk,
            lenient,
            threads,
        } => {
            // The outputs: never an input, nor inside the VTK folder they
            // replace; checked before anything is read (and again with the
            // scene's mesh once the scene names it).
            let scene_file = Path::new(&scene);
            let mut inputs: Vec<(&str, PathBuf)> = vec![("--trajectory", trajectory.clone())];
            if !Scene::BUILT_IN.contains(&scene.as_str()) {
                inputs.push(("the scene", scene_file.to_path_buf()));
            }
            refuse_inputs(&out, vtk.as_deref(), &inputs)?;
            let scene = Scene::named(&scene)?;
            if let MeshSource::File(mesh) = &scene.mesh {
                for file in mesh_files(mesh) {
                    inputs.push(("the scene's mesh", file));
                }
                refuse_inputs(&out, vtk.as_deref(), &inputs)?;
            }
            if removes_tets(&scene) {
                let inputs: Vec<(&str, &Path)> =
                    inputs.iter().map(|(l, p)| (*l, p.as_path())).collect();
                atomic::refuse_input(("the removed-tets file", &removed_path(&out)), &inputs)?;
            }
            let points = scene.tool.points;
            let trajectory = if lenient {
                let (t, findings) = Trajectory::read_unchecked(&trajectory, points)?;
                for finding in findings {
                    stderr::line(&format!("warning: {finding}"));
                }
                t
            } else {
                Trajectory::read(&trajectory, points)?
            };
            let summary = run_session_to_files_threads(
                &scene,
                &trajectory,
                &out,
                vtk.as_deref(),
                threads.count(),
            )?;
            stderr::line(&format!(
                "{} ticks ({} in contact, {} clamped, {} faulted); max force {:.3} N, max jump {:.4} N per tick; {} VTK frames",
                summary.ticks,
                summary.ticks_in_contact,
                summary.clamped,
                summary.faulted,
                summary.max_force_n,
                summary.max_jump_n,
                summary.frames
            ));
            if removes_tets(&scene) {
                stderr::line(&format!(
                    "{} tets removed (cuts and tears), listed in {}",
                    summary.removed_tets,
                    removed_path(&out).display()
                ));
            }
            if summary.cut_refused > 0 {
                stderr::line(&format!(
                    "{} ticks with an enabled blade on tissue the pre-computed model cannot cut (status cut-refused)",
                    summary.cut_refused
                ));
            }
            if summary.tool_inside > 0 {
                stderr::line(&format!(
                    "{} ticks with a tool point inside the body and no contact: it adds no force (status tool-inside)",
                    summary.tool_inside
                ));
            }
            if let Some(e) = summary.physics_error {
                stderr::line(&format!(
                    "physics update failed at {e}; the force was zero from the next tick on"
                ));
            }
            Ok(())
        }
        SessionCommand::Serve {
            scene,
            listen,
            update_hz,
            threads,
        } => serve_command(&scene, &listen, update_hz, threads.count()),
        SessionCommand::Generate { kind, output } => {
            let trajectory = match kind {
                TrajectoryKind::Poke => Poke::default().trajectory(),
                TrajectoryKind::PressHold => PressHold::default().trajectory(),
                TrajectoryKind::Slide => Slide::default().trajectory(),
                TrajectoryKind::Pinch => Pinch::default().trajectory(),
                TrajectoryKind::Strike => Strike::default().trajectory(),
                TrajectoryKind::GraspPull => GraspPull::default().trajectory(),
                TrajectoryKind::CutLine => CutLine::default().trajectory(),
                TrajectoryKind::Surgery => surgery(&Scene::built_in_tools().tool),
                TrajectoryKind::Hepatectomy => hepatectomy(&Scene::built_in_hybrid().tool),
            }
            .map_err(|e| anyhow::anyhow!("{e}"))?;
            let mut file = AtomicFile::create(&output)?;
            trajectory.write_csv(&mut file)?;
            file.commit()?;
            Ok(())
        }
    }
}

/// `session serve`: the scene's physics for one controller on `listen`.
fn serve_command(
    scene: &str,
    listen: &core::net::SocketAddr,
    update_hz: f64,
    threads: usize,
) -> anyhow::Result<()> {
    let scene = Scene::named(scene)?;
    serve::check_servable(&scene)?;
    let every = update_every(&scene, update_hz)?;
    let listener = serve::listen(listen)?;
    stderr::line(&format!(
        "listening on {}: a physics update every {every} ticks ({:.1} Hz)",
        listener.local_addr()?,
        scene.rates.haptic_hz / f64::from(every)
    ));
    let (counters, physics_error) = serve_scene(&scene, &listener, every, threads)?;
    stderr::line(&format!(
        "controller gone: {} commands, {} ticks ({} filled, {} repeated), {} updates sent, {} frames dropped",
        counters.commands,
        counters.ticks,
        counters.filled,
        counters.repeated,
        counters.updates,
        counters.dropped
    ));
    if let Some(e) = physics_error {
        stderr::line(&format!(
            "physics update failed at {e}; no update was sent after it"
        ));
    }
    Ok(())
}

/// Refuses `session run` outputs that would overwrite an input: `--out` one
/// of `inputs`, or `--out` or an input inside the `--vtk` folder.
fn refuse_inputs(out: &Path, vtk: Option<&Path>, inputs: &[(&str, PathBuf)]) -> anyhow::Result<()> {
    let inputs: Vec<(&str, &Path)> = inputs.iter().map(|(l, p)| (*l, p.as_path())).collect();
    atomic::refuse_input(("--out", out), &inputs)?;
    if let Some(dir) = vtk {
        let mut inside = inputs.clone();
        inside.push(("--out", out));
        atomic::refuse_inside(("--vtk", dir), &inside)?;
    }
    Ok(())
}
