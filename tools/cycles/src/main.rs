//! `palpate-cycles`: counts the Cortex-M4F instructions and cycles of every
//! haptic tick of `tools/cycles-m4f` (each call of its `measured_tick`),
//! emulated by Unicorn, classed by Capstone and timed by the Cortex-M4
//! table of [`timing`]; reports worst and mean per run against the static
//! bound the program prints, and writes the program's output (its tick
//! lines, to compare with the host's).
//!
//! ```text
//! palpate-cycles ELF [--model NAME] [--output FILE] [--csv FILE] [--profile N]
//!                    [--unit-costs] [--wait-states W] [--refill P] [--divide D]
//!                    [--limit PREFIX=CYCLES]... [--warn-limit PREFIX=CYCLES]...
//! ```
//!
//! `--limit` (and `--warn-limit`, which only reports) applies to the runs
//! whose label starts with `PREFIX`. Exit status: 0; 1 when a tick exceeds
//! its run's bound or a `--limit`
//! (zero wait states), a run has fewer ticks than it declares, or the
//! program exits with failure; 2 on a usage or emulation error.
//!
//! GPL-2.0-only, as Unicorn (the `unicorn-engine` crate): a tool of its own
//! workspace, outside the product and its dependency policy.

mod elf;
mod emulate;
mod timing;

use std::fmt::Write as _;
use std::process::ExitCode;

use emulate::Count;
use timing::{Class, Costs};

/// The function whose calls are ticks.
const MEASURED: &str = "measured_tick";

struct Args {
    elf: String,
    model: String,
    output: Option<String>,
    csv: Option<String>,
    profile: usize,
    unit_costs: bool,
    costs: Costs,
    limits: Vec<(String, u64)>,
    warn_limits: Vec<(String, u64)>,
}

const USAGE: &str = "usage: palpate-cycles ELF [--model NAME] [--output FILE] [--csv FILE] \
[--profile N] [--unit-costs] [--wait-states W] [--refill P] [--divide D] [--limit PREFIX=CYCLES]... [--warn-limit PREFIX=CYCLES]...";

fn parse_args() -> Result<Args, String> {
    let mut args = std::env::args().skip(1);
    let mut parsed = Args {
        elf: String::new(),
        model: String::from("-"),
        output: None,
        csv: None,
        profile: 0,
        unit_costs: false,
        costs: Costs::default(),
        limits: Vec::new(),
        warn_limits: Vec::new(),
    };
    let number = |flag: &str, v: Option<String>| -> Result<u64, String> {
        v.as_deref()
            .and_then(|v| v.parse().ok())
            .ok_or_else(|| format!("{flag}: expected a number"))
    };
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--model" => parsed.model = args.next().ok_or("--model: expected a name")?,
            "--output" => parsed.output = Some(args.next().ok_or("--output: expected a file")?),
            "--csv" => parsed.csv = Some(args.next().ok_or("--csv: expected a file")?),
            "--profile" => parsed.profile = number(&arg, args.next())? as usize,
            "--unit-costs" => parsed.unit_costs = true,
            "--wait-states" => parsed.costs.wait_states = number(&arg, args.next())? as u32,
            "--refill" => {
                let p = number(&arg, args.next())? as u32;
                if !(1..=3).contains(&p) {
                    return Err("--refill: P is 1, 2 or 3 cycles on the Cortex-M4".into());
                }
                parsed.costs.refill = p;
            }
            "--divide" => {
                let d = number(&arg, args.next())? as u32;
                if !(2..=12).contains(&d) {
                    return Err("--divide: 2 to 12 cycles on the Cortex-M4".into());
                }
                parsed.costs.divide = d;
            }
            "--limit" | "--warn-limit" => {
                let v = args.next().ok_or("--limit: expected PREFIX=CYCLES")?;
                let (prefix, cycles) =
                    v.split_once('=').ok_or("--limit: expected PREFIX=CYCLES")?;
                let cycles = cycles.parse().map_err(|_| "--limit: CYCLES is a number")?;
                let limits = if arg == "--limit" {
                    &mut parsed.limits
                } else {
                    &mut parsed.warn_limits
                };
                limits.push((prefix.to_string(), cycles));
            }
            "-h" | "--help" => return Err(USAGE.into()),
            a if a.starts_with('-') => return Err(format!("{a}: unknown option\n{USAGE}")),
            a if parsed.elf.is_empty() => parsed.elf = a.to_string(),
            a => return Err(format!("{a}: one ELF file only\n{USAGE}")),
        }
    }
    if parsed.elf.is_empty() {
        return Err(USAGE.into());
    }
    Ok(parsed)
}

fn main() -> ExitCode {
    match run() {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(1),
        Err(e) => {
            eprintln!("palpate-cycles: {e}");
            ExitCode::from(2)
        }
    }
}

/// One run of the program: its `run` line's fields and its ticks.
struct Run<'e> {
    label: String,
    points: u32,
    declared_ticks: usize,
    bound: u64,
    ticks: &'e [Count],
    functions: &'e [Vec<(usize, u64)>],
}

fn run() -> Result<bool, String> {
    let args = parse_args()?;
    let bytes = std::fs::read(&args.elf).map_err(|e| format!("{}: {e}", args.elf))?;
    let program = elf::Program::parse(&bytes)?;
    let entries = program.entries(MEASURED);
    if entries.is_empty() {
        return Err(format!("{}: no function named {MEASURED}", args.elf));
    }
    let emulation = emulate::run(&program, &entries, args.costs)?;
    if let Some(path) = &args.output {
        std::fs::write(path, &emulation.output).map_err(|e| format!("{path}: {e}"))?;
    }
    let runs = split_runs(&emulation)?;
    let mut ok = emulation.success;
    if !ok {
        eprintln!(
            "the program exited with failure (its output: {:?})",
            args.output
        );
    }
    let w = args.costs.wait_states;
    let mut text = format!(
        "{:<10} {:<16} {:>2} {:>6} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>6}\n",
        "model",
        "run",
        "m",
        "ticks",
        "mean ins",
        "max ins",
        "mean cyc",
        "max cyc",
        &format!("mean@{w}ws"),
        &format!("max@{w}ws"),
        "bound",
        "max/b"
    );
    for run in &runs {
        let n = run.ticks.len().max(1) as f64;
        let mean = |f: &dyn Fn(&Count) -> u64| run.ticks.iter().map(f).sum::<u64>() as f64 / n;
        let max = |f: &dyn Fn(&Count) -> u64| run.ticks.iter().map(f).max().unwrap_or(0);
        let worst = max(&|c| c.cycles);
        let _ = writeln!(
            text,
            "{:<10} {:<16} {:>2} {:>6} {:>9.0} {:>9} {:>9.0} {:>9} {:>9.0} {:>9} {:>9} {:>6.3}",
            args.model,
            run.label,
            run.points,
            run.ticks.len(),
            mean(&|c| c.instructions),
            max(&|c| c.instructions),
            mean(&|c| c.cycles),
            worst,
            mean(&|c| c.cycles_at(w)),
            max(&|c| c.cycles_at(w)),
            run.bound,
            worst as f64 / run.bound.max(1) as f64
        );
        if run.ticks.len() != run.declared_ticks {
            eprintln!(
                "{}: {} ticks counted, {} declared",
                run.label,
                run.ticks.len(),
                run.declared_ticks
            );
            ok = false;
        }
        if worst > run.bound {
            eprintln!(
                "{}: a tick of {worst} cycles exceeds the bound {}",
                run.label, run.bound
            );
            ok = false;
        }
        for (prefix, limit) in &args.limits {
            if run.label.starts_with(prefix.as_str()) && worst > *limit {
                eprintln!(
                    "{}: a tick of {worst} cycles exceeds the limit {limit}",
                    run.label
                );
                ok = false;
            }
        }
        for (prefix, limit) in &args.warn_limits {
            if run.label.starts_with(prefix.as_str()) && worst > *limit {
                eprintln!(
                    "warning: {}: a tick of {worst} cycles exceeds the target {limit} \
                     (reported, not enforced)",
                    run.label
                );
            }
        }
    }
    print!("{text}");
    let work = tick_work(&emulation.output);
    if args.profile > 0 {
        print!("{}", profile(&program, &runs, &work, args.profile, w));
    }
    if args.unit_costs {
        print!("{}", unit_costs(&runs, &work));
    }
    if let Some(path) = &args.csv {
        std::fs::write(path, csv(&args.model, &runs, &work, w))
            .map_err(|e| format!("{path}: {e}"))?;
    }
    Ok(ok)
}

/// The runs of `emulation`, from its `run <label> points <P> ticks <N> bound
/// <B>` lines.
fn split_runs(emulation: &emulate::Emulation) -> Result<Vec<Run<'_>>, String> {
    let mut runs = Vec::new();
    for (i, (start, line)) in emulation.runs.iter().enumerate() {
        let end = emulation
            .runs
            .get(i + 1)
            .map_or(emulation.calls.len(), |(s, _)| *s);
        let fields: Vec<&str> = line.split(' ').collect();
        let [_, label, "points", points, "ticks", ticks, "bound", bound] = fields[..] else {
            return Err(format!("program output `{line}`: not a run line"));
        };
        let number = |v: &str| v.parse::<u64>().map_err(|_| format!("`{line}`: {v}"));
        runs.push(Run {
            label: label.to_string(),
            points: number(points)? as u32,
            declared_ticks: number(ticks)? as usize,
            bound: number(bound)?,
            ticks: &emulation.calls[*start..end],
            functions: &emulation.call_functions[*start..end],
        });
    }
    Ok(runs)
}

/// For each run, the worst tick (cycles at zero wait states), the worst
/// steady tick (every point in contact, no triangle tested, no edge
/// crossed: the tracked contacts' solve alone) and the worst hovering tick
/// (no contact, triangles tested: detection alone), each by class and with
/// its `top` functions by cycles. `work` is every tick's, in run order.
fn profile(program: &elf::Program, runs: &[Run<'_>], work: &[Work], top: usize, w: u32) -> String {
    let mut text = String::new();
    let mut first = 0;
    for run in runs {
        let work = work.get(first..first + run.ticks.len()).unwrap_or(&[]);
        first += run.ticks.len();
        let steady = |k: usize| {
            work.get(k)
                .is_some_and(|t| t.contacts == u64::from(run.points) && t.tests == 0 && t.walk == 0)
        };
        let hovering = |k: usize| work.get(k).is_some_and(|t| t.contacts == 0 && t.tests > 0);
        let worst_where = |keep: &dyn Fn(usize) -> bool| {
            run.ticks
                .iter()
                .enumerate()
                .filter(|(k, _)| keep(*k))
                .max_by_key(|(_, c)| c.cycles)
        };
        let worst = worst_where(&|_| true);
        for (what, tick) in [
            ("", worst),
            ("steady ", worst_where(&steady)),
            ("hovering ", worst_where(&hovering)),
        ] {
            if let Some((k, c)) = tick {
                profile_tick(&mut text, program, run, what, k, c, top, w);
            }
        }
    }
    text
}

/// One tick's profile (see [`profile`]).
#[allow(clippy::too_many_arguments)]
fn profile_tick(
    text: &mut String,
    program: &elf::Program,
    run: &Run<'_>,
    what: &str,
    k: usize,
    worst: &emulate::Count,
    top: usize,
    w: u32,
) {
    let _ = writeln!(
        text,
        "\n{} {what}tick {k}: {} instructions, {} cycles ({} at {w} wait states: {} instruction \
         words fetched, {} words loaded from flash), {} taken branches",
        run.label,
        worst.instructions,
        worst.cycles,
        worst.cycles_at(w),
        worst.fetch_words,
        worst.flash_words,
        worst.taken
    );
    for class in Class::ALL {
        let (n, c) = (
            worst.class_instructions[class.index()],
            worst.class_cycles[class.index()],
        );
        if n > 0 {
            let _ = writeln!(
                text,
                "  {:<22} {n:>7} instructions {c:>8} cycles",
                class.name()
            );
        }
    }
    let mut functions = run.functions[k].clone();
    functions.sort_by_key(|(_, c)| std::cmp::Reverse(*c));
    for (f, c) in functions.iter().take(top) {
        let _ = writeln!(text, "  {c:>8} cycles  {}", program.function_name(*f));
    }
}

/// What a tick's output line says it did: contacts after it, triangles
/// tested, edges crossed, solves.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Work {
    contacts: u64,
    tests: u64,
    walk: u64,
    solves: u64,
}

/// The work of every tick line (`tick <k> ... contacts <c> ... work <tests>
/// <walk> <solves>`) of `output`, in order.
fn tick_work(output: &[u8]) -> Vec<Work> {
    let text = String::from_utf8_lossy(output);
    text.lines()
        .filter(|l| l.starts_with("tick "))
        .map(|l| {
            let fields: Vec<&str> = l.split(' ').collect();
            let after = |key: &str, n: usize| {
                fields
                    .iter()
                    .position(|f| *f == key)
                    .and_then(|i| fields.get(i + 1 + n))
                    .and_then(|v| v.parse().ok())
                    .unwrap_or(0)
            };
            Work {
                contacts: after("contacts", 0),
                tests: after("work", 0),
                walk: after("work", 1),
                solves: after("work", 2),
            }
        })
        .collect()
}

/// One CSV line per tick: the counts, and the work of the tick's output
/// line.
fn csv(model: &str, runs: &[Run<'_>], work: &[Work], w: u32) -> String {
    let mut work = work.iter();
    let mut out = format!(
        "model,run,m,tick,instructions,cycles,cycles_at_{w}ws,fetch_words,flash_words,taken,\
         contacts,triangles_tested,walk_steps,solves\n"
    );
    for run in runs {
        for (k, c) in run.ticks.iter().enumerate() {
            let t = work.next().copied().unwrap_or_default();
            let _ = writeln!(
                out,
                "{model},{},{},{k},{},{},{},{},{},{},{},{},{},{}",
                run.label,
                run.points,
                c.instructions,
                c.cycles,
                c.cycles_at(w),
                c.fetch_words,
                c.flash_words,
                c.taken,
                t.contacts,
                t.tests,
                t.walk,
                t.solves
            );
        }
    }
    out
}

/// The largest per-unit costs (cycles at zero wait states) of the static
/// bound's terms (`palpate::budget::UnitCosts`), as the host's were derived
/// (one probe first, then the solve over the larger loops), each the
/// largest residual after the terms before it: `base` the largest tick
/// without contact, test or walk of a one-point loop; `track` (a tracked
/// contact with its solve) the largest `cycles − base` of one-point ticks
/// with a contact but no test or walk; `triangle` the largest `(cycles −
/// base − contacts·track) / tests` of one-point ticks with tests; `walk`
/// the same per edge crossed of one-point ticks with walks and no test;
/// then the solve per solve per cubed capacity `M³` (the block LDLᵀ),
/// the largest `(cycles − base − M·track) / (solves·M³)` of ticks of loops
/// of `M ≥ 2` points without test or walk, and the same per `M` (the
/// dynamic model's solve, linear in the capacity).
fn unit_costs(runs: &[Run<'_>], work: &[Work]) -> String {
    let ticks: Vec<(u64, u64, Work)> = runs
        .iter()
        .flat_map(|r| r.ticks.iter().map(|c| (u64::from(r.points), c.cycles)))
        .zip(work.iter().copied())
        .map(|((m, cycles), w)| (m, cycles, w))
        .collect();
    let max = |f: &dyn Fn(u64, f64, &Work) -> Option<f64>| {
        ticks
            .iter()
            .filter_map(|(m, c, w)| f(*m, *c as f64, w))
            .fold(0.0f64, f64::max)
            .ceil()
    };
    let quiet = |w: &Work| w.tests == 0 && w.walk == 0;
    let base = max(&|m, c, w| (m == 1 && w.contacts == 0 && quiet(w)).then_some(c));
    let track = max(&|m, c, w| (m == 1 && w.contacts > 0 && quiet(w)).then_some(c - base));
    let one = |c: f64, w: &Work| c - base - w.contacts as f64 * track;
    let triangle = max(&|m, c, w| (m == 1 && w.tests > 0).then(|| one(c, w) / w.tests as f64));
    let walk =
        max(&|m, c, w| (m == 1 && w.walk > 0 && w.tests == 0).then(|| one(c, w) / w.walk as f64));
    let solved = |m: u64, c: f64, w: &Work, per: u64| {
        (m >= 2 && quiet(w) && w.solves > 0)
            .then(|| (c - base - (m as f64) * track) / (w.solves * per) as f64)
    };
    let cubic = max(&|m, c, w| solved(m, c, w, m * m * m));
    let linear = max(&|m, c, w| solved(m, c, w, m));
    format!(
        "unit costs (cycles, zero wait states, largest measured): base {base}, track {track}, \
         triangle {triangle}, walk {walk}, solve per M^3 {cubic} (or per M {linear})\n"
    )
}
