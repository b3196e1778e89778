//! `palpate demo`: the mission in one command, needing no input file.
//!
//! Part one ([`block`]): the built-in block on the pre-computed model,
//! pressed by two probes, held and released. Part two ([`organ`]): the
//! built-in hybrid organ in a generated surgery, a grasper holding its
//! pre-computed region while a cutter cuts its tensor-mass region. Then the
//! report: each model's tick and physics-update cost side by side, and
//! where the VTK series are.

pub mod block;
pub mod organ;
pub mod timing;

use std::io::Write;
use std::path::Path;

use crate::output::atomic::SeriesDir;
use timing::{Costs, median_max};

/// What a demo run measured.
#[derive(Clone, Debug)]
pub struct DemoRun {
    /// Part one: the block's steps.
    pub block: Costs,
    /// Part two: the organ's ticks, updates, counts and removed tets.
    pub organ: organ::OrganRun,
}

/// Runs the whole demo ([`run_with`] with all of the surgery).
pub fn run(out_dir: &Path, printed: &mut dyn Write) -> anyhow::Result<DemoRun> {
    run_with(out_dir, None, printed)
}

/// Runs the demo with the organ's surgery cut to its first `organ_s`
/// seconds (`None`: all of it), writing both VTK series into the folder
/// `out_dir`, whole or not at all ([`SeriesDir`]: a fresh folder, or one a
/// previous run wrote, replaced when both series are complete; anything
/// else is refused before the run), then printing the forces per phase
/// and the timings to `printed`. The report is printed once the series are
/// in place, so a reader that closes `printed` early (`palpate demo |
/// head`) cannot stop them.
pub fn run_with(
    out_dir: &Path,
    organ_s: Option<f64>,
    printed: &mut dyn Write,
) -> anyhow::Result<DemoRun> {
    let mut report = Vec::new();
    let series = SeriesDir::create(out_dir)?;
    writeln!(
        report,
        "part one: the pre-computed block, two probes pressed, held and released"
    )?;
    let block = block::run(series.dir(), &mut report)?;
    writeln!(
        report,
        "part two: the hybrid organ, a grasper holding it and a cutter cutting it"
    )?;
    let organ = organ::run(series.dir(), organ_s, &mut report)?;
    series.commit()?;
    costs(&mut report, &block, &organ.costs)?;
    writeln!(
        report,
        "wrote {} VTK frames and {} (the block), {} VTK frames and {} (the organ; open in ParaView)",
        block.frames,
        out_dir.join(block::COLLECTION).display(),
        organ.costs.frames,
        out_dir.join(organ::COLLECTION).display()
    )?;
    printed.write_all(&report)?;
    Ok(DemoRun { block, organ })
}

/// The cost table: per model, its haptic-rate step and its physics update,
/// median and worst, µs.
fn costs(out: &mut dyn Write, block: &Costs, organ: &Costs) -> anyhow::Result<()> {
    writeln!(
        out,
        "cost per model (us)                      ticks  median   worst  physics updates  median    worst"
    )?;
    for (name, c) in [
        ("pre-computed block (2 vertex contacts)", block),
        ("hybrid organ (grasper and cutter)", organ),
    ] {
        let (tick_median, tick_worst) = median_max(&c.ticks);
        let (update_median, update_worst) = median_max(&c.physics);
        writeln!(
            out,
            "{name:<40} {:>5} {tick_median:>7.2} {tick_worst:>7.1}  {:>15} {update_median:>7.1} {update_worst:>8.1}",
            c.ticks.len(),
            c.physics.len()
        )?;
    }
    Ok(())
}
