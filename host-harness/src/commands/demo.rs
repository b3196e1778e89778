//! `palpate demo`: the pre-computed block pressed by two probes, then the
//! hybrid organ grasped and cut, run by [`palpate::demo`].

use std::io::Write as _;
use std::path::PathBuf;

use super::stdout::Stdout;

/// `palpate demo`'s arguments.
#[derive(clap::Args)]
pub struct DemoArgs {
    /// Folder for the VTK series (the block's `demo.pvd`, the organ's
    /// `organ.pvd`): created, or replaced if a previous run wrote it
    /// (anything else is refused).
    #[arg(long, default_value = "demo-out")]
    out: PathBuf,
}

/// Runs the demo: forces and timings on stdout, the VTK series in `--out`.
pub fn run(args: &DemoArgs) -> anyhow::Result<()> {
    let mut out = Stdout;
    palpate::demo::run(&args.out, &mut out)?;
    out.flush()?;
    Ok(())
}
