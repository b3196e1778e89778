//! The study's run ([`run`]): the quasi-non-linear fit, every model on
//! every mesh at every load and level against the reference, then the
//! stability maps, the trajectories and the memory chart's tables.

use anyhow::Context;
use palpate_kernel::precomputed::QuasiNonLinear;

use super::body::{Body, Load, tip_m};
use super::dynamic::{dynamic, hybrid};
use super::matrix::Matrix;
use super::model::Model;
use super::precomputed::precomputed;
use super::progress::Progress;
use super::reference::{reference, score, score_truth};
use super::results::{Run, Study};
use super::truth::{CONVERGED, truth};
use super::{memory, stability, ticks, trajectory};
use crate::experiment::volume_bend::inverted_tets;
use crate::remap::fit::fit_curves;
use crate::remap::sample::{Sample, linear_response, stvk_curves};
use crate::tensor_mass::run::volume_change;

/// Runs the static part, the stability maps, the trajectories and the
/// memory chart's tables of `matrix`.
pub fn run(matrix: &Matrix, progress: &mut dyn Progress) -> anyhow::Result<Study> {
    anyhow::ensure!(matrix.mesh_count() > 0, "no mesh in the matrix");
    let bodies = matrix.bodies()?;
    let finest = bodies.last().context("no mesh")?;
    let material = finest.material;
    let height_m = finest.length_m;

    // The quasi-non-linear fit: the compression sample of the body's
    // aspect (radius H/5) and material, 25 % compression in 8 steps (less
    // where that finds no equilibrium: [`REMAP_STRAINS`]), cubic (the
    // `palpate remap fit` defaults).
    let sample = Sample::new(finest.length_m, finest.radius_m, material)?;
    let curves = remap_curves(&sample)?;
    let remap = fit_curves(&curves, &linear_response(&sample)?, 3)?;
    let quasi = (remap.kernel::<f64>()?, remap.kernel::<f32>()?);

    let mut references = Vec::new();
    let mut truths = Vec::new();
    let mut runs = Vec::new();
    let mut trajectory_loads = Vec::new();
    for &load in &matrix.loads {
        // Unit-load linear response on the finest mesh: scales the levels.
        let tip_per_unit = finest.tip_per_newton_m(load)?;
        trajectory_loads.push((load, matrix.trajectory.level * height_m / tip_per_unit));
        for &level in &matrix.levels {
            let magnitude = level * height_m / tip_per_unit;
            let reference = reference(finest, load, level, magnitude);
            progress.tick(&format!(
                "reference {} {:.0} %: {}",
                load.name(),
                100.0 * level,
                reference
                    .0
                    .fault
                    .clone()
                    .unwrap_or_else(|| format!("{} Newton iterations", reference.0.iterations))
            ));
            let truth = truth(finest, &matrix.truth, load, level, magnitude);
            progress.tick(&format!(
                "truth {} {:.0} %: {}",
                load.name(),
                100.0 * level,
                truth.change.map_or_else(
                    || "not converged".to_string(),
                    |c| format!("change {c:.1e}")
                )
            ));
            for body in &bodies {
                let same_mesh = core::ptr::eq(body, finest);
                for model in Model::ALL {
                    let (mut run, u) = run_model(
                        body,
                        model,
                        load,
                        (level, magnitude),
                        &quasi,
                        matrix.max_relax_steps,
                    )
                    .with_context(|| {
                        format!("{} on {} {}", model.name(), body.label, load.name())
                    })?;
                    score(&mut run, &u, &reference, same_mesh);
                    score_truth(&mut run, &truth);
                    progress.tick(&format!(
                        "{} {} {:.0} % {}",
                        body.label,
                        load.name(),
                        100.0 * level,
                        model.name()
                    ));
                    runs.push(run);
                }
            }
            references.push(reference.0);
            truths.push(truth);
        }
    }
    let stability = stability::maps(&bodies[0], &matrix.stability, progress)?;
    let trajectories =
        trajectory::trajectories(&bodies, &trajectory_loads, &matrix.trajectory, progress)?;
    let memory = memory::points(
        &matrix.memory_meshes,
        &matrix.memory_encodings,
        material,
        &mut |m| progress.tick(m),
    )?;
    let hybrid_region = bodies
        .iter()
        .map(|b| {
            let tets = b.hybrid_dynamic_tets();
            let dynamic = tets.iter().filter(|&&d| d).count();
            (b.label.clone(), dynamic, tets.len())
        })
        .collect();
    Ok(Study {
        body: matrix.description(),
        hybrid_region,
        height_m,
        material: (material.young_pa, material.poisson),
        reference_mesh: finest.label.clone(),
        references,
        truths,
        truth_levels: truth_levels(matrix, &finest.label),
        runs,
        remap,
        stability,
        trajectories,
        memory,
        ticks: ticks::TickCounts::Skipped {
            reason: "not measured".into(),
        },
    })
}

/// One model's run (errors filled by [`score`]) and its displacements, m.
fn run_model(
    body: &Body,
    model: Model,
    load: Load,
    (level, magnitude): (f64, f64),
    quasi: &(QuasiNonLinear<f64>, QuasiNonLinear<f32>),
    max_steps: usize,
) -> anyhow::Result<(Run, Vec<[f64; 3]>)> {
    let loads = body.loads(load, magnitude);
    let outcome = match (model, model.tensor_mass(body)) {
        (_, Some((law, penalty))) => dynamic(body, &loads, law, penalty, max_steps)?,
        (Model::PrecomputedQuasi, None) => precomputed(body, &loads, Some(quasi))?,
        (Model::Hybrid, None) => hybrid(body, &loads, max_steps)?,
        (_, None) => precomputed(body, &loads, None)?,
    };
    let alive = vec![true; body.mesh.tets.len()];
    let run = Run {
        mesh: body.label.clone(),
        vertices: body.mesh.positions.len(),
        tets: body.mesh.tets.len(),
        load,
        level,
        model,
        fault: outcome.fault,
        tip_m: tip_m(&loads, &outcome.u),
        tip_error: None,
        force_error: None,
        truth_tip_error: None,
        truth_force_error: None,
        l2_error: None,
        max_error_m: None,
        volume_change: volume_change(&body.mesh, &outcome.u, &alive),
        inverted_tets: inverted_tets(&body.mesh, &outcome.u),
        step_s: outcome.step_s,
        step_f32_s: outcome.step_f32_s,
        steps_to_settle: outcome.steps,
        settle_s: outcome.steps as f64 * outcome.step_s,
    };
    Ok((run, outcome.u))
}

/// The report's description of the truth's levels on `finest`.
fn truth_levels(matrix: &Matrix, finest: &str) -> String {
    format!(
        "{} on the finest chart mesh's geometry (refined by halving every edge), the last the \
         truth; converged when the quantity changes by at most {CONVERGED:e} between the last \
         two.{}",
        matrix
            .truth
            .iter()
            .map(|d| d.label(finest))
            .collect::<Vec<_>>()
            .join(", "),
        matrix.truth_note
    )
}

/// The quasi-non-linear fit's sample compressions, tried in order: the
/// `palpate remap fit` default (25 % of the height), then less where the St
/// Venant-Kirchhoff sample finds no equilibrium (measured at ν = 0.49: none
/// past 6.2 %, St Venant-Kirchhoff collapsing under the nearly
/// incompressible law's large compression); the fit extrapolates beyond.
const REMAP_STRAINS: [f64; 3] = [0.25, 0.125, 0.0625];

/// The St Venant-Kirchhoff compression curves of `sample` at the first of
/// [`REMAP_STRAINS`] that converges (8 steps), or the last one's error.
fn remap_curves(sample: &Sample) -> anyhow::Result<Vec<crate::remap::curves::CurvePoint>> {
    let mut failure = None;
    for strain in REMAP_STRAINS {
        match stvk_curves(sample, strain, 8) {
            Ok(curves) => return Ok(curves),
            Err(e) => failure = Some(e),
        }
    }
    Err(failure
        .unwrap_or_else(|| anyhow::anyhow!("no compression to sample"))
        .context("remap sample curves"))
}
