//! The study's truth: the Newton St Venant-Kirchhoff equilibrium of each
//! load and level on the finest mesh ([`reference`]), and the errors of a
//! run against it ([`score`]).

use nalgebra::Vector3;

use super::body::{Body, Load, tip_m};
use super::results::{Reference, Run};
use super::truth::Truth;
use crate::experiment::volume_bend::inverted_tets;
use crate::fem::newton::{NewtonOptions, solve_stvk};
use crate::tensor_mass::run::volume_change;

/// Newton load increments of the reference per 1 % of tip displacement
/// (at least one).
const NEWTON_STEPS_PER_PERCENT: f64 = 0.5;

/// The Newton St Venant-Kirchhoff equilibrium of `load` at `magnitude` on
/// `body`, and its displacement field (`None` when Newton failed).
///
/// Past a loss of stability Newton follows the stable equilibria
/// ([`NewtonOptions::descent`]: each load increment minimizes the total
/// potential energy from the previous equilibrium, and the end state's
/// tangent must be positive definite). That is what the press beyond
/// ~2.7 % needs: the free-top column's Euler load (`π²EI/4L²`, 2.5 % of
/// `EA` here) is passed, and the press's lateral imperfection
/// ([`PRESS_IMPERFECTION`]) picks the bend direction. Measured on 3×15
/// (`NEWTON_STEPS_PER_PERCENT` increments): plain load-stepped Newton fails
/// there with or without the imperfection (1e-3, 1e-2, 3e-2 of the axial
/// force; up to 640 increments at 5 %: no convergence near 2.7 %, a limit
/// point), because St Venant-Kirchhoff's post-buckling branch is unstable:
/// the bending strains of the buckled column at the base exceed the ~42 %
/// compression where St Venant-Kirchhoff's stress peaks, and the column
/// snaps into its collapse. The stable equilibrium at 5 % and 20 % is that
/// collapse (tip 0.186 m and 0.214 m, past the base; 484 and 962 of 3240
/// tets inverted, ΔV/V₀ −29 % and −59 %): the reference of the law the
/// study compares against, which the models that do not buckle (linear,
/// pre-computed) or resist the collapse (the penalty) miss. The same state
/// at 3, 10 and 60 increments at 5 % (tip to 6 digits), within 0.3 % at 20 %
/// (3 against 10 and 60); with a 1e-2 imperfection the 5 % tip moves by
/// 0.07 %.
pub(super) fn reference(
    body: &Body,
    load: Load,
    level: f64,
    magnitude: f64,
) -> (Reference, Option<Vec<[f64; 3]>>) {
    let loads = body.loads(load, magnitude);
    let materials = body.materials();
    let problem = body.static_problem(&materials, &loads);
    let options = NewtonOptions {
        load_steps: ((100.0 * level * NEWTON_STEPS_PER_PERCENT).ceil() as usize).max(1),
        max_iterations: 400,
        tolerance: 1e-10,
        descent: true,
    };
    let alive = vec![true; body.mesh.tets.len()];
    match solve_stvk(&problem, &options) {
        Ok(e) => (
            Reference {
                load,
                level,
                magnitude,
                fault: None,
                iterations: e.iterations,
                tip_m: tip_m(&loads, &e.u),
                volume_change: volume_change(&body.mesh, &e.u, &alive),
                inverted_tets: inverted_tets(&body.mesh, &e.u),
            },
            Some(e.u),
        ),
        Err(e) => (
            Reference {
                load,
                level,
                magnitude,
                fault: Some(format!("{e:#}")),
                iterations: 0,
                tip_m: f64::NAN,
                volume_change: f64::NAN,
                inverted_tets: 0,
            },
            None,
        ),
    }
}

/// Fills the errors of `run` (displacements `u`) against `reference`
/// (full fields when `same_mesh`, the reference's mesh).
pub(super) fn score(
    run: &mut Run,
    u: &[[f64; 3]],
    reference: &(Reference, Option<Vec<[f64; 3]>>),
    same_mesh: bool,
) {
    let (reference, field) = reference;
    if run.fault.is_some() || reference.fault.is_some() || !run.tip_m.is_finite() {
        return;
    }
    run.tip_error = Some((run.tip_m - reference.tip_m).abs() / reference.tip_m.abs());
    run.force_error = Some((reference.tip_m / run.tip_m - 1.0).abs());
    if let (true, Some(field)) = (same_mesh, field) {
        let (mut diff, mut norm, mut max) = (0.0, 0.0, 0.0f64);
        for (a, b) in u.iter().zip(field) {
            let d = (Vector3::from(*a) - Vector3::from(*b)).norm();
            diff += d * d;
            norm += Vector3::from(*b).norm_squared();
            max = max.max(d);
        }
        run.l2_error = Some((diff / norm).sqrt());
        run.max_error_m = Some(max);
    }
}

/// Fills the errors of `run` against the neo-Hookean `truth` (its tip);
/// none when the run has no tip or the truth did not converge
/// ([`Truth::converged`]): a run is never scored against an unconverged
/// truth.
pub(super) fn score_truth(run: &mut Run, truth: &Truth) {
    if run.fault.is_some() || !run.tip_m.is_finite() || !truth.converged() {
        return;
    }
    run.truth_tip_error = Some((run.tip_m - truth.tip_m).abs() / truth.tip_m.abs());
    run.truth_force_error = Some((truth.tip_m / run.tip_m - 1.0).abs());
}
