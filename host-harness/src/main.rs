//! The `palpate` command line (contract in README.md): tables, solves,
//! sessions, experiments, demo. This file parses, dispatches to the command
//! groups of [`commands`] and applies the error policy: any error is one
//! line `error: …` on stderr and exit status 2, except a closed standard
//! output (a broken pipe), which ends the run normally (exit 0). Standard
//! error is written through `palpate::output::stderr` only: a full or
//! closed one loses the lines, never the run (its outputs, its status).

use std::process::ExitCode;

use anyhow::Context;
use clap::{ArgMatches, CommandFactory, FromArgMatches, Parser, Subcommand};
use palpate::output::stderr;

mod commands;

use commands::{
    bench, budget, chart, demo, dynamic, experiment, forces, precomputed, remap, scene, session,
    stvk, tables,
};

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
    Tables(tables::TablesCommand),
    /// Queries of the pre-computed model, through the kernel code path.
    #[command(subcommand)]
    Precomputed(precomputed::PrecomputedCommand),
    /// The dynamic tensor-mass model (RR-3510 §5), stepped through the kernel.
    #[command(subcommand)]
    Dynamic(dynamic::DynamicCommand),
    /// The St Venant-Kirchhoff force (Picinbono 2001, MODELS.md §4).
    #[command(subcommand)]
    Stvk(stvk::StvkCommand),
    /// Internal elastic forces (−∂W/∂x, free body) and energy of a deformed
    /// mesh under a per-tet law: St Venant-Kirchhoff, neo-Hookean,
    /// co-rotational (MODELS.md §4, §8).
    Forces(forces::ForcesArgs),
    /// Experiments that reproduce the papers' figures.
    #[command(subcommand)]
    Experiment(experiment::ExperimentCommand),
    /// The quasi-non-linear pre-computed model's remaps (Cotin 1999 TVCG §3).
    #[command(subcommand)]
    Remap(remap::RemapCommand),
    /// Haptic sessions: the kernel's fixed-timestep loop driven by a trajectory.
    #[command(subcommand)]
    Session(session::SessionCommand),
    /// What a scene asks of the models: the hybrid partition of its zones (`scene plan`).
    #[command(subcommand)]
    Scene(scene::SceneCommand),
    /// Timings of the models on a mesh of one's own (the criterion benches
    /// are the reference figures).
    Bench(bench::BenchArgs),
    /// Per-tick instruction counts (callgrind) of every generated trajectory
    /// against the static bound from the table sizes and capacities.
    Budget(budget::BudgetArgs),
    /// The speed/accuracy study: every model against the Newton St
    /// Venant-Kirchhoff reference, timed; charts and a report.
    Chart(chart::ChartArgs),
    /// Built-in scenes: the block pressed by two probes, the hybrid organ
    /// grasped and cut; forces, tick costs, VTK series.
    Demo(demo::DemoArgs),
}

fn main() -> ExitCode {
    let matches = Cli::command().get_matches();
    let result = Cli::from_arg_matches(&matches)
        .map_err(anyhow::Error::from)
        .and_then(|cli| run(cli, &matches));
    match result {
        Ok(()) => ExitCode::SUCCESS,
        // The reader of standard output went away (`… | head -1`): a normal end.
        Err(e) if commands::stdout::is_broken_pipe(&e) => ExitCode::SUCCESS,
        Err(e) => {
            stderr::line(&format!("error: {e:#}"));
            ExitCode::from(2)
        }
    }
}

/// Runs the parsed command; `matches` are the whole command line's (two
/// commands read argument order or sources below their group's).
fn run(cli: Cli, matches: &ArgMatches) -> anyhow::Result<()> {
    let group = matches
        .subcommand()
        .map(|(_, group)| group)
        .context("internal: no command")?;
    match cli.command {
        Command::Tables(command) => tables::run(command, group),
        Command::Precomputed(command) => precomputed::run(command, group),
        Command::Dynamic(command) => dynamic::run(command),
        Command::Stvk(command) => stvk::run(command),
        Command::Forces(args) => forces::run(&args),
        Command::Experiment(command) => experiment::run(command),
        Command::Remap(command) => remap::run(command),
        Command::Session(command) => session::run(command),
        Command::Scene(command) => scene::run(command),
        Command::Bench(args) => bench::run_bench(&args),
        Command::Budget(args) => budget::run(&args),
        Command::Chart(args) => chart::run(&args),
        Command::Demo(args) => demo::run(&args),
    }
}
