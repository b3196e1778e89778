//! `palpate demo`: the built-in scene (two probes pressed and released),
//! run by [`palpate::demo`].

use std::path::PathBuf;

/// `palpate demo`'s arguments.
#[derive(clap::Args)]
pub struct DemoArgs {
    /// Folder for the VTK series (created if absent).
    #[arg(long, default_value = "demo-out")]
    out: PathBuf,
}

/// Runs the demo: forces and timings on stdout, the VTK series in `--out`.
pub fn run(args: &DemoArgs) -> anyhow::Result<()> {
    palpate::demo::run(&args.out)
}
