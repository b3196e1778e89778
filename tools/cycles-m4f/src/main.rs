//! The Cortex-M4F program whose haptic ticks `tools/cycles` counts: the
//! release build of the kernel as firmware links it (LTO, `opt-level = 3`),
//! the tables of a scene linked into flash, and the ticks `palpate budget
//! --record` recorded from every generated trajectory of that scene (one
//! folder per contact count, `build.rs`) run through the kernel's haptic
//! loop exactly as the host's budget probe runs them: a fresh loop at rest
//! per run, each tick through [`measured_tick`] (the one function
//! `tools/cycles` counts, from its entry to its return), then for a
//! dynamic or hybrid tissue a physics update after every `physics_every`
//! ticks (not counted). One build per tissue: the pre-computed one by
//! default ([`precomputed`]), `--features dynamic` ([`dynamic`]) or
//! `--features hybrid` ([`hybrid`]).
//!
//! Output over semihosting: `run <label> points <P> ticks <N> bound <B>`
//! before each run, then one line per tick
//! ([`palpate_script::ticks::write_tick`]), byte for byte the host's
//! `<trajectory>.expected` when the target computes what the host computes;
//! `#` lines are reports.
#![no_std]
#![no_main]

// The pre-computed tissue takes no buffer from the arena.
#[cfg_attr(not(any(feature = "dynamic", feature = "hybrid")), allow(dead_code))]
mod arena;
#[cfg(any(feature = "dynamic", feature = "hybrid"))]
mod buffers;
#[cfg(feature = "dynamic")]
mod dynamic;
#[cfg(feature = "hybrid")]
mod hybrid;
#[cfg(not(any(feature = "dynamic", feature = "hybrid")))]
mod precomputed;

use core::fmt::Write;

use cortex_m_rt::entry;
use cortex_m_semihosting::hio::HostStream;
use cortex_m_semihosting::{debug, hio};
use palpate_kernel::contact::Tissue;
use palpate_kernel::haptic::{ForceOutput, HapticLoop, ToolInput};
use palpate_script::ticks::{Recording, write_tick};

use arena::Arena;
#[cfg(feature = "dynamic")]
use dynamic::Model;
#[cfg(feature = "hybrid")]
use hybrid::Model;
#[cfg(not(any(feature = "dynamic", feature = "hybrid")))]
use precomputed::Model;

/// One recorded run.
struct Run {
    /// `<folder>/<trajectory>`.
    label: &'static str,
    /// The tick's static bound on the target, cycles (`palpate budget
    /// --record`), printed for `tools/cycles`.
    bound_cycles: u64,
    /// The recording (`palpate_script::ticks`).
    ticks: &'static [u8],
}

include!(concat!(env!("OUT_DIR"), "/runs.rs"));

/// What a run can fail on, printed on a `#` line.
type Failed = ();

/// The tissue a build measures: builds a loop of `P` tool points at rest
/// for each run and hands it to the run.
trait Measured {
    /// Builds the loop of `recording` (its settings) over `arena`'s buffers
    /// and runs `body` on it; `Err` after printing why on a `#` line.
    fn with_loop<const P: usize>(
        &self,
        recording: &Recording<'_>,
        arena: &Arena,
        out: &mut HostStream,
        body: impl FnOnce(&mut dyn Ticking<P>, &mut HostStream) -> Result<(), Failed>,
    ) -> Result<(), Failed>;
}

/// A haptic loop as a run drives it: a tick, and the physics update of a
/// dynamic or hybrid tissue (none for the pre-computed one).
trait Ticking<const P: usize> {
    /// One tick through [`measured_tick`]; its output and work counters.
    fn tick(&mut self, tools: &[ToolInput<f32>; P]) -> ForceOutput<f32>;
    /// The last tick's work counters.
    fn counters(&self) -> palpate_kernel::haptic::TickCounters;
    /// A physics update (a failed one faults the following ticks, which
    /// run and print as the host's do).
    fn physics_update(&mut self);
}

/// One tick, kept out of line so that `tools/cycles` counts exactly its
/// instructions (from the entry of each monomorphization to its return;
/// the physics updates run outside it). The host's budget probe calls
/// `tick_tools` the same way (`palpate::budget::budget_tick`).
#[inline(never)]
fn measured_tick<B: Tissue<f32, P>, const P: usize>(
    haptic: &mut HapticLoop<f32, B, P, P>,
    tools: &[ToolInput<f32>; P],
) -> ForceOutput<f32> {
    haptic.tick_tools(tools)
}

/// The dynamic and hybrid loops: a physics update between ticks.
#[cfg(any(feature = "dynamic", feature = "hybrid"))]
impl<B: palpate_kernel::haptic::PhysicsTissue<f32, P>, const P: usize> Ticking<P>
    for HapticLoop<f32, B, P, P>
{
    fn tick(&mut self, tools: &[ToolInput<f32>; P]) -> ForceOutput<f32> {
        measured_tick(self, tools)
    }

    fn counters(&self) -> palpate_kernel::haptic::TickCounters {
        *HapticLoop::counters(self)
    }

    fn physics_update(&mut self) {
        let _ = HapticLoop::physics_update(self);
    }
}

/// Prints `what` on a `#` line; the run fails.
fn refuse(out: &mut HostStream, what: impl core::fmt::Display) -> Failed {
    let _ = writeln!(out, "# {what}");
}

/// Runs every recorded run, then ends the emulation through semihosting
/// with the exit status (success only if every run ran to its end).
#[entry]
fn main() -> ! {
    let ok = run_all().is_ok();
    debug::exit(if ok {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    loop {
        cortex_m::asm::bkpt();
    }
}

fn run_all() -> Result<(), Failed> {
    let mut out = hio::hstdout()?;
    let Some(mut arena) = Arena::take() else {
        let _ = writeln!(out, "# arena already taken");
        return Err(());
    };
    let model = Model::load(&mut out)?;
    for run in RUNS {
        let recording = Recording::parse(run.ticks).map_err(|e| {
            let _ = writeln!(out, "# {}: {e}", run.label);
        })?;
        let header = recording.header();
        let _ = writeln!(
            out,
            "run {} points {} ticks {} bound {}",
            run.label, header.points, header.ticks, run.bound_cycles
        );
        arena.reset();
        match header.points {
            1 => run_points::<1>(&model, &recording, &arena, &mut out),
            2 => run_points::<2>(&model, &recording, &arena, &mut out),
            3 => run_points::<3>(&model, &recording, &arena, &mut out),
            _ => run_points::<4>(&model, &recording, &arena, &mut out),
        }?;
    }
    Ok(())
}

/// The ticks of `recording` on a fresh loop of `P` tool points, each
/// printed; a physics update after every `physics_every` ticks.
fn run_points<const P: usize>(
    model: &Model,
    recording: &Recording<'_>,
    arena: &Arena,
    out: &mut HostStream,
) -> Result<(), Failed> {
    let header = *recording.header();
    let every = header.physics_every as usize;
    model.with_loop::<P>(recording, arena, out, |haptic, out| {
        let mut line = Line::new();
        for k in 0..header.ticks {
            let Some(tools) = recording.tick::<P>(k) else {
                let _ = writeln!(out, "# tick {k}: not in the recording");
                return Err(());
            };
            let output = haptic.tick(&tools);
            line.clear();
            let _ = write_tick(&mut line, k, &output, &haptic.counters());
            out.write_all(line.as_bytes())?;
            if every != 0 && (k + 1) % every == 0 {
                haptic.physics_update();
            }
        }
        Ok(())
    })
}

/// One output line, formatted in place before one semihosting write.
struct Line {
    bytes: [u8; 192],
    len: usize,
}

impl Line {
    fn new() -> Self {
        Self {
            bytes: [0; 192],
            len: 0,
        }
    }

    fn clear(&mut self) {
        self.len = 0;
    }

    fn as_bytes(&self) -> &[u8] {
        self.bytes.get(..self.len).unwrap_or(&[])
    }
}

impl Write for Line {
    fn write_str(&mut self, s: &str) -> core::fmt::Result {
        let end = self.len + s.len();
        let room = self.bytes.get_mut(self.len..end).ok_or(core::fmt::Error)?;
        room.copy_from_slice(s.as_bytes());
        self.len = end;
        Ok(())
    }
}

/// Prints the panic on a `#` line and ends with failure. Not expected to
/// run: `tools/nopanic-check` proves the kernel's step paths panic-free.
#[panic_handler]
fn panic(info: &core::panic::PanicInfo<'_>) -> ! {
    if let Ok(mut out) = hio::hstdout() {
        let _ = writeln!(out, "# panic: {info}");
    }
    debug::exit(debug::EXIT_FAILURE);
    loop {
        cortex_m::asm::bkpt();
    }
}
