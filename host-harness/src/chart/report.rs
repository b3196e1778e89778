//! `report.md` and `index.html` of `palpate chart`.

use core::fmt::Write;

use super::body::{HYBRID_DYNAMIC_FRACTION, Load};
use super::model::Model;
use super::results::Study;
use super::select::{cheapest_within, pareto_front};
use super::series::{Against, cost_series, log_slope, points, trajectory_points};
use super::stability::Outcome;
use super::ticks::TickCounts;
use super::trajectory::REFINEMENT;

/// Error bounds of the report's "cheapest within" columns.
pub const BOUNDS: [f64; 3] = [0.01, 0.05, 0.20];

/// The cheapest trajectory of `load` within `bound`, `model, integrator at
/// Δt on mesh`, or `None`.
pub fn cheapest_trajectory(study: &Study, load: Load, bound: f64) -> Option<String> {
    let (runs, points) = trajectory_points(study, load);
    cheapest_within(&points, bound).map(|i| {
        let t = runs[i];
        format!(
            "{}, {} at {:.2} ms on {}",
            t.model.name(),
            t.integrator,
            1e3 * t.dt_s,
            t.mesh
        )
    })
}

/// `model on mesh` of the cheapest run within `bound` of the tip error
/// `against` a reference, or `none`.
pub fn cheapest(
    study: &Study,
    load: Load,
    level: f64,
    bound: f64,
    against: Against,
) -> Option<String> {
    let (runs, points) = points(study, load, level, against);
    cheapest_within(&points, bound).map(|i| format!("{} on {}", runs[i].model.name(), runs[i].mesh))
}

/// The Pareto members of one load and level (tip error `against` a
/// reference), `model on mesh`.
pub fn pareto_members(study: &Study, load: Load, level: f64, against: Against) -> Vec<String> {
    let (runs, points) = points(study, load, level, against);
    runs.iter()
        .zip(pareto_front(&points))
        .filter(|(_, f)| *f)
        .map(|(r, _)| format!("{} on {}", r.model.name(), r.mesh))
        .collect()
}

/// The section of the haptic tick's instruction counts.
fn tick_counts(out: &mut String, study: &Study) {
    let _ = writeln!(out, "\n## Per-tick instructions of the haptic tick\n");
    match &study.ticks {
        TickCounts::Skipped { reason } => {
            let _ = writeln!(out, "Not measured: {reason}.");
        }
        TickCounts::Measured { counts } => {
            let _ = writeln!(
                out,
                "Callgrind instructions (Ir) of one haptic tick (`palpate budget`'s measurement) on \
                 each model's built-in scene, its `{}` trajectory with 1 to 4 probes held pressed \
                 (one contact each), f32: the pre-computed models on the block (the \
                 quasi-non-linear tissue with the remap fitted above), the tensor-mass models on \
                 the same block, dynamic, with their law, the hybrid on the built-in organ. The \
                 dynamic models' physics updates run outside the tick (every 10th), as in \
                 `palpate budget`: the law costs the step above, not the tick.\n",
                super::ticks::TICK_TRAJECTORY
            );
            let _ = writeln!(
                out,
                "| model | scene | contacts | ticks | mean Ir | max Ir |"
            );
            let _ = writeln!(out, "|---|---|---|---|---|---|");
            for c in counts {
                let _ = writeln!(
                    out,
                    "| {} | {} | {} | {} | {:.0} | {} |",
                    c.model.name(),
                    c.scene,
                    c.contacts,
                    c.ticks,
                    c.mean_ir,
                    c.max_ir
                );
            }
        }
    }
}

/// The report in Markdown; `charts` are the chart names (PNG beside it).
pub fn markdown(
    study: &Study,
    loads: &[Load],
    levels: &[f64],
    charts: &[String],
    volume_table: &str,
) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "# Speed against accuracy: palpate chart\n");
    let _ = writeln!(
        out,
        "{}, length {} m, E = {} Pa, ν = {}. Truth: the compressible neo-Hookean equilibrium \
         (Newton) on mesh {}'s geometry at the levels below; a load and level is scored against it \
         only where it converged (the charted quantity changes by at most {:e} between the two \
         finest levels), and the Pareto fronts, the charts and the first \"cheapest within\" table \
         measure against it (\"no converged truth\" elsewhere: never against a wrong truth). \
         Second reference: Newton St Venant-Kirchhoff on mesh {} (the \"StVK\" columns and the \
         second table; the Pareto charts of a case without a converged truth, as their axis says). \
         Error: the loaded face's displacement (work-conjugate mean of the consistent face loads); \
         cost: median time of one step (f64).\n",
        study.body,
        study.height_m,
        study.material.0,
        study.material.1,
        study.reference_mesh,
        super::truth::CONVERGED,
        study.reference_mesh
    );
    truth_section(&mut out, study);
    let regions: Vec<String> = study
        .hybrid_region
        .iter()
        .map(|(mesh, dynamic, all)| format!("{dynamic} of {all} tets on {mesh}"))
        .collect();
    let _ = writeln!(
        out,
        "The hybrid: St Venant-Kirchhoff tensor-mass on the tets within {:.0} % of the length from \
         the loaded end (and every tet touching a loaded vertex): {}; the rest pre-computed linear, \
         condensed onto the connection nodes. The bend's and twist's rotations grow towards the \
         loaded end, where a tool would also touch and cut; the largest strains of the bend are at \
         the supports, in the linear region.\n",
        100.0 * HYBRID_DYNAMIC_FRACTION,
        regions.join(", ")
    );
    cheapest_table(&mut out, study, (loads, levels), Against::Truth);
    cheapest_table(&mut out, study, (loads, levels), Against::Stvk);
    let _ = writeln!(out, "\n## Every run\n");
    let _ = writeln!(
        out,
        "| load | level | mesh | model | tip error (truth) | force error (truth) | tip error (StVK) | force error (StVK) | L2 error (StVK) | max error mm (StVK) | ΔV/V₀ % | inverted | step µs f64 | step µs f32 | steps to settle | settle ms | fault |"
    );
    let _ = writeln!(
        out,
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    let opt = |x: Option<f64>, scale: f64| x.map_or("-".into(), |x| format!("{:.3}", scale * x));
    for r in &study.runs {
        let _ = writeln!(
            out,
            "| {} | {:.0} % | {} | {} | {} | {} | {} | {} | {} | {} | {:+.3} | {} | {:.2} | {} | {} | {:.3} | {} |",
            r.load.name(),
            100.0 * r.level,
            r.mesh,
            r.model.name(),
            opt(r.truth_tip_error, 1.0),
            opt(r.truth_force_error, 1.0),
            opt(r.tip_error, 1.0),
            opt(r.force_error, 1.0),
            opt(r.l2_error, 1.0),
            opt(r.max_error_m, 1e3),
            100.0 * r.volume_change,
            r.inverted_tets,
            1e6 * r.step_s,
            opt(r.step_f32_s, 1e6),
            r.steps_to_settle,
            1e3 * r.settle_s,
            r.fault.as_deref().unwrap_or("")
        );
    }
    tick_counts(&mut out, study);
    trajectories(&mut out, study, loads);
    let _ = writeln!(out, "\n## Where the methods fail\n");
    for line in failures(study) {
        let _ = writeln!(out, "- {line}");
    }
    let _ = writeln!(out, "\n## Cost against mesh size\n");
    for model in Model::ALL {
        let series = cost_series(study, model);
        if series.len() >= 2 {
            let _ = writeln!(
                out,
                "- {}: time per step ∝ vertices^{:.2}",
                model.name(),
                log_slope(&series)
            );
        }
    }
    memory_section(&mut out, study);
    if !volume_table.is_empty() {
        let _ = writeln!(out, "\n## Picinbono 2001 table 2\n\n```\n{volume_table}```");
    }
    let _ = writeln!(out, "\n## Charts\n");
    for name in charts {
        let _ = writeln!(out, "![{name}]({name}.png)\n");
    }
    out
}

/// The "cheapest within" table with the Pareto members, of the tip error
/// `against` the truth (a case without a converged truth says so) or the
/// St Venant-Kirchhoff reference.
fn cheapest_table(
    out: &mut String,
    study: &Study,
    (loads, levels): (&[Load], &[f64]),
    against: Against,
) {
    let what = match against {
        Against::Truth => "the neo-Hookean truth",
        Against::Stvk => "the Newton St Venant-Kirchhoff reference",
    };
    let _ = writeln!(
        out,
        "## Cheapest model within an error bound of {what}\n\n\
         Tip error against {what}; the Pareto front of time per step against it.\n\n\
         | load | level | within 1 % | within 5 % | within 20 % | Pareto front |\n\
         |---|---|---|---|---|---|"
    );
    for &load in loads {
        for &level in levels {
            let cell =
                |b: f64| cheapest(study, load, level, b, against).unwrap_or_else(|| "none".into());
            let truth = study
                .truths
                .iter()
                .find(|t| t.load == load && t.level == level);
            let front = match truth.filter(|t| against == Against::Truth && !t.converged()) {
                Some(t) => t.verdict(),
                None => pareto_members(study, load, level, against).join(", "),
            };
            let _ = writeln!(
                out,
                "| {} | {:.0} % | {} | {} | {} | {} |",
                load.name(),
                100.0 * level,
                cell(BOUNDS[0]),
                cell(BOUNDS[1]),
                cell(BOUNDS[2]),
                front
            );
        }
    }
    let _ = writeln!(out);
}

/// The memory/accuracy section: what the tables are, then each one's bytes
/// and errors.
fn memory_section(out: &mut String, study: &Study) {
    if study.memory.is_empty() {
        return;
    }
    let mut meshes: Vec<String> = Vec::new();
    for p in &study.memory {
        let mesh = format!(
            "{} ({} vertices, {} tets, {} touchable, `--fix '{}'`)",
            p.mesh, p.vertices, p.tets, p.touchable, p.fix
        );
        if !meshes.contains(&mesh) {
            meshes.push(mesh);
        }
    }
    let _ = writeln!(
        out,
        "\n## Table memory against accuracy\n\n\
         Pre-computed f32 tables (E = {} Pa, ν = {}) of {}, each built as `palpate tables build \
         MESH --young E --poisson NU --fix PRED` with the flags below; bytes and errors as \
         `palpate tables info --json` gives them (`measured`: the largest over the build's probe \
         set of contacts, relative; the 16-bit and dropped tables against the dense f32 table, \
         the hierarchical ones against the exact compliance; the dense table is its own \
         reference, 0). Dropping interior blocks costs no contact force, dropping touchable ones \
         does; a hierarchical table stores no interior displacements (its displacement error is \
         the touchable one). Charts: memory (contact-force error), memory-displacement \
         (touchable displacement error); data: memory.json.\n",
        study.material.0,
        study.material.1,
        meshes.join(" and ")
    );
    let _ = writeln!(
        out,
        "| mesh | flags | bytes | bytes / dense | force error | touchable displacement error | \
         displacement error |\n|---|---|---|---|---|---|---|"
    );
    for p in &study.memory {
        let dense = study
            .memory
            .iter()
            .find(|d| d.mesh == p.mesh && d.family == "dense")
            .map_or(f64::NAN, |d| d.bytes as f64);
        let _ = writeln!(
            out,
            "| {} | {} | {} | {:.3} | {:.2e} | {:.2e} | {:.2e} |",
            p.mesh,
            p.flags,
            p.bytes,
            p.bytes as f64 / dense,
            p.force_error,
            p.touchable_displacement_error,
            p.displacement_error
        );
    }
}

/// The truth's section: per load and level, the quantity on every level
/// and the change between the last two.
fn truth_section(out: &mut String, study: &Study) {
    let _ = writeln!(out, "## The neo-Hookean truth\n");
    let _ = writeln!(out, "Levels: {}.\n", study.truth_levels);
    let Some(first) = study.truths.first() else {
        return;
    };
    let names: Vec<&str> = first.levels.iter().map(|l| l.label.as_str()).collect();
    let _ = writeln!(
        out,
        "| load | level | {} | change of the last two | truth | StVK reference mm |",
        names
            .iter()
            .map(|n| format!("{n} mm (nodes, s)"))
            .collect::<Vec<_>>()
            .join(" | ")
    );
    let _ = writeln!(out, "|---|---|{}---|---|---|", "---|".repeat(names.len()));
    for t in &study.truths {
        let cells: Vec<String> = t
            .levels
            .iter()
            .map(|l| match &l.fault {
                Some(f) => format!("failed: {f}"),
                None => format!("{:.5} ({}, {:.1})", 1e3 * l.tip_m, l.nodes, l.seconds),
            })
            .collect();
        let stvk = study
            .references
            .iter()
            .find(|r| r.load == t.load && r.level == t.level)
            .map_or(f64::NAN, |r| 1e3 * r.tip_m);
        let _ = writeln!(
            out,
            "| {} | {:.0} % | {} | {} | {} | {:.5} |",
            t.load.name(),
            100.0 * t.level,
            cells.join(" | "),
            t.change.map_or("-".into(), |c| format!("{c:.2e}")),
            t.verdict(),
            stvk
        );
    }
    let _ = writeln!(out);
}

/// The trajectories' section: the cheapest within each bound per load,
/// then every trajectory.
fn trajectories(out: &mut String, study: &Study, loads: &[Load]) {
    if study.trajectories.is_empty() {
        return;
    }
    let _ = writeln!(
        out,
        "\n## Dynamic runs: trajectory error against Δt/{REFINEMENT}\n\n\
         Each tensor-mass model and the hybrid, each integrator, the load applied at rest, {} s simulated with \
         damping {} 1/s, against the same model and integrator at a step {REFINEMENT}× smaller: \
         error = max over the steps of ‖u − u_ref‖₂ / max ‖u_ref‖₂; cost = time per step / Δt \
         (compute seconds per simulated second, f64).\n",
        super::trajectory::DURATION_S,
        super::stability::DAMPING_PER_S
    );
    let _ = writeln!(
        out,
        "| load | cheapest within 1 % | within 5 % | within 20 % |\n|---|---|---|---|"
    );
    for &load in loads {
        let cell = |b: f64| cheapest_trajectory(study, load, b).unwrap_or_else(|| "none".into());
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} |",
            load.name(),
            cell(BOUNDS[0]),
            cell(BOUNDS[1]),
            cell(BOUNDS[2])
        );
    }
    let _ = writeln!(
        out,
        "\n| mesh | load | model | integrator | Δt ms | Δt·ω_max/2 | error | step µs | s per simulated s | fault |\n|---|---|---|---|---|---|---|---|---|---|"
    );
    for t in &study.trajectories {
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {:.3} | {:.2} | {} | {:.2} | {:.3} | {} |",
            t.mesh,
            t.load.name(),
            t.model.name(),
            t.integrator,
            1e3 * t.dt_s,
            t.dt_factor,
            t.error.map_or("-".into(), |e| format!("{e:.2e}")),
            1e6 * t.step_s,
            t.cost_per_simulated_s,
            t.fault.as_deref().unwrap_or("")
        );
    }
}

/// The failure regions, in words, from the runs and the maps.
pub fn failures(study: &Study) -> Vec<String> {
    let mut lines = Vec::new();
    for r in &study.references {
        if let Some(f) = &r.fault {
            lines.push(format!(
                "Newton St Venant-Kirchhoff has no equilibrium for {} at {:.0} % (collapse): {f}",
                r.load.name(),
                100.0 * r.level
            ));
        } else if r.inverted_tets > 0 {
            lines.push(format!(
                "the St Venant-Kirchhoff reference itself collapses under {} at {:.0} % (past the \
                 buckling load its stable equilibrium): {} inverted tets, ΔV/V₀ {:+.1} %, tip {:.1} mm",
                r.load.name(),
                100.0 * r.level,
                r.inverted_tets,
                100.0 * r.volume_change,
                1e3 * r.tip_m
            ));
        }
    }
    for r in &study.runs {
        if r.fault.is_some() || r.inverted_tets > 0 {
            lines.push(format!(
                "{} on {} under {} at {:.0} %: {}{} inverted tets",
                r.model.name(),
                r.mesh,
                r.load.name(),
                100.0 * r.level,
                r.fault
                    .as_deref()
                    .map_or(String::new(), |f| format!("{f}; ")),
                r.inverted_tets
            ));
        }
    }
    // The linear models' volume gain under rotation: the largest.
    if let Some(r) = study
        .runs
        .iter()
        .filter(|r| matches!(r.model, Model::PrecomputedLinear | Model::TensorMassLinear))
        .max_by(|a, b| a.volume_change.total_cmp(&b.volume_change))
    {
        lines.push(format!(
            "linear swelling under rotation: {} gains {:+.2} % volume under {} at {:.0} % on {} \
             (St Venant-Kirchhoff reference: {:+.2} %)",
            r.model.name(),
            100.0 * r.volume_change,
            r.load.name(),
            100.0 * r.level,
            r.mesh,
            study
                .references
                .iter()
                .find(|x| x.load == r.load && x.level == r.level)
                .map_or(f64::NAN, |x| 100.0 * x.volume_change)
        ));
    }
    for map in &study.stability {
        let unstable: Vec<String> = map
            .cells
            .iter()
            .filter(|c| c.outcome != Outcome::Stable)
            .map(|c| {
                format!(
                    "{:?} at E = {} Pa, Δt = {:.2e} s",
                    c.outcome, c.young_pa, c.dt_s
                )
            })
            .collect();
        lines.push(format!(
            "{} {}: measured critical step {:.3e} s, 2/ω_max {:.3e} s at E = {} Pa; {} of {} trials fail{}",
            map.model.name(),
            map.integrator,
            map.critical_dt_s,
            map.two_over_omega_s,
            map.reference_young_pa,
            unstable.len(),
            map.cells.len(),
            unstable
                .first()
                .map_or(String::new(), |f| format!(" (first: {f})"))
        ));
    }
    lines
}

/// The HTML page: the report's Markdown in a `<pre>` and the images.
pub fn html(markdown: &str, charts: &[String]) -> String {
    let escaped = markdown
        .replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;");
    let mut out = String::from(
        "<!doctype html>\n<html><head><meta charset=\"utf-8\"><title>palpate chart</title></head>\n<body>\n",
    );
    for name in charts {
        let _ = writeln!(
            out,
            "<figure><img src=\"{name}.svg\" alt=\"{name}\" width=\"800\"><figcaption>{name}</figcaption></figure>"
        );
    }
    let _ = writeln!(out, "<pre>\n{escaped}</pre>\n</body></html>");
    out
}
