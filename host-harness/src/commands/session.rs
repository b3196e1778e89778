//! `palpate session`: haptic sessions, the kernel's fixed-timestep loop
//! driven by a trajectory (`run`), and generated trajectories (`generate`).

use std::path::PathBuf;

use anyhow::Context;
use clap::Subcommand;
use palpate::session::run::run_session;
use palpate::session::{Generator, Pinch, Poke, PressHold, Scene, Slide, Strike, Trajectory};

#[derive(Subcommand)]
pub enum SessionCommand {
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
pub enum TrajectoryKind {
    Poke,
    PressHold,
    Slide,
    Pinch,
    Strike,
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
        } => {
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
            let summary = run_session(&scene, &trajectory, &mut writer, vtk.as_deref())?;
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
        SessionCommand::Generate { kind, output } => {
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
    }
}
