//! The series that both the charts ([`super::plot`]) and the report
//! ([`super::report`]) draw from a study: the trajectories' (cost, error)
//! points, each model's cost against mesh size and its log-log slope.

use super::body::Load;
use super::model::Model;
use super::results::{Run, Study};
use super::trajectory::Trajectory;

/// The trajectories of one load with an error, as (cost, error) points:
/// compute time per simulated second (s) and trajectory error.
pub fn trajectory_points(study: &Study, load: Load) -> (Vec<&Trajectory>, Vec<(f64, f64)>) {
    let runs: Vec<&Trajectory> = study
        .trajectories
        .iter()
        .filter(|t| t.load == load && t.error.is_some())
        .collect();
    let points = runs
        .iter()
        .map(|t| (t.cost_per_simulated_s, t.error.unwrap_or(f64::NAN)))
        .collect();
    (runs, points)
}

/// Least-squares slope of `log y` against `log x`.
pub fn log_slope(points: &[(f64, f64)]) -> f64 {
    let logs: Vec<(f64, f64)> = points
        .iter()
        .filter(|p| p.0 > 0.0 && p.1 > 0.0)
        .map(|p| (p.0.ln(), p.1.ln()))
        .collect();
    let n = logs.len() as f64;
    let mx = logs.iter().map(|p| p.0).sum::<f64>() / n;
    let my = logs.iter().map(|p| p.1).sum::<f64>() / n;
    let sxy: f64 = logs.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = logs.iter().map(|p| (p.0 - mx) * (p.0 - mx)).sum();
    sxy / sxx
}

/// Per model, the median time per step on each mesh against its vertex count.
pub fn cost_series(study: &Study, model: Model) -> Vec<(f64, f64)> {
    let mut meshes: Vec<(usize, Vec<f64>)> = Vec::new();
    for r in study.runs.iter().filter(|r| r.model == model) {
        match meshes.iter_mut().find(|m| m.0 == r.vertices) {
            Some(m) => m.1.push(r.step_s),
            None => meshes.push((r.vertices, vec![r.step_s])),
        }
    }
    meshes.sort_by_key(|m| m.0);
    meshes
        .into_iter()
        .map(|(v, mut t)| {
            t.sort_by(f64::total_cmp);
            (v as f64, t[t.len() / 2])
        })
        .collect()
}

/// Which error a selection ([`points`]) measures: against the converged
/// neo-Hookean truth (the Pareto fronts and "cheapest within" tables) or
/// against the Newton St Venant-Kirchhoff reference (the second column).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Against {
    /// [`Run::truth_tip_error`]: none where the truth did not converge.
    Truth,
    /// [`Run::tip_error`].
    Stvk,
}

impl Against {
    /// The run's tip error against this reference, if it has one.
    pub fn tip_error(self, run: &Run) -> Option<f64> {
        match self {
            Against::Truth => run.truth_tip_error,
            Against::Stvk => run.tip_error,
        }
    }
}

/// The runs of one load and level with a tip error `against` a reference,
/// as (cost, error) points: time per step (s) and tip error.
pub fn points(
    study: &Study,
    load: Load,
    level: f64,
    against: Against,
) -> (Vec<&Run>, Vec<(f64, f64)>) {
    let runs: Vec<&Run> = study
        .runs
        .iter()
        .filter(|r| r.load == load && r.level == level && against.tip_error(r).is_some())
        .collect();
    let points = runs
        .iter()
        .map(|r| (r.step_s, against.tip_error(r).unwrap_or(f64::NAN)))
        .collect();
    (runs, points)
}
