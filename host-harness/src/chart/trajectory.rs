//! The dynamic runs' trajectory error: each tensor-mass model and the
//! hybrid (its tensor-mass region stepped, the field over the whole mesh)
//! under a load
//! applied at rest, integrated for [`DURATION_S`] with each integrator at a
//! time step `Δt`, against the same model and integrator at `Δt/16` (the
//! issue's reference; the scheme's own converged motion, so the error is
//! the time discretization's alone).
//!
//! A run: the load of the study at the middle level (5 % of the height),
//! mass-proportional damping [`DAMPING_PER_S`] (the stability maps'), the
//! body at rest at `t = 0`. The error is
//! `max_k ‖u(t_k) − u_ref(t_k)‖₂ / max_k ‖u_ref(t_k)‖₂` over the coarse step
//! times `t_k` (every vertex, L2 over the field). Cost: the median time of
//! one step with that integrator (f64, on the loaded motion) and the
//! compute time per simulated second, `step / Δt`.

use std::collections::HashMap;

use nalgebra::Vector3;
use palpate_kernel::tensor_mass::{DynamicParams, Integrator};
use serde::Serialize;

use super::body::{Body, Load};
use super::measure::median_s;
use super::model::Model;
use super::progress::Progress;
use super::stability::{DAMPING_PER_S, with_params, with_system};
use crate::dispatch::HostDispatch;
use crate::tensor_mass::run::diagonal;
use crate::tensor_mass::stability::omega_max;

/// The models whose trajectories are integrated: the tensor-mass linear and
/// St Venant-Kirchhoff laws and the hybrid (the co-rotational and
/// neo-Hookean laws are charted statically only, which bounds the study's
/// time).
pub const MODELS: [Model; 4] = [
    Model::TensorMassLinear,
    Model::Stvk,
    Model::StvkPenalty,
    Model::Hybrid,
];

/// Simulated time of one trajectory, s (the first bending mode of the
/// cylinder has a period of about 0.8 s: its first swing).
pub const DURATION_S: f64 = 0.5;
/// The reference's step is the run's over this.
pub const REFINEMENT: usize = 16;

/// The trajectories' extent.
#[derive(Clone, Debug)]
pub struct TrajectoryExtent {
    /// How many of the study's meshes (coarsest first) carry trajectories.
    pub meshes: usize,
    /// Time steps as multiples of the mesh's `2/ω_max` (tangent at rest).
    pub dt_factors: Vec<f64>,
    /// The load level (fraction of the height).
    pub level: f64,
}

impl TrajectoryExtent {
    /// The two coarsest meshes, three steps up to 0.9 of the limit.
    pub fn full() -> Self {
        Self {
            meshes: 2,
            dt_factors: vec![0.25, 0.5, 0.9],
            level: 0.05,
        }
    }

    /// The coarsest mesh, one step (half the limit: the co-rotational and
    /// neo-Hookean static runs and the truth took the other's time).
    pub fn quick() -> Self {
        Self {
            meshes: 1,
            dt_factors: vec![0.5],
            level: 0.05,
        }
    }
}

/// One trajectory against its reference.
#[derive(Clone, Debug, Serialize)]
pub struct Trajectory {
    /// `"RxH"`.
    pub mesh: String,
    /// The load.
    pub load: Load,
    /// The level.
    pub level: f64,
    /// The model (a tensor-mass one or the hybrid).
    pub model: Model,
    /// Integrator name.
    pub integrator: &'static str,
    /// Time step, s.
    pub dt_s: f64,
    /// `dt_s` over the mesh's `2/ω_max`.
    pub dt_factor: f64,
    /// `null`, or how the run or its reference failed.
    pub fault: Option<String>,
    /// The trajectory error (module documentation), `null` on a fault.
    pub error: Option<f64>,
    /// Median time of one step with this integrator, f64, s.
    pub step_s: f64,
    /// Compute time per simulated second, `step_s / dt_s`.
    pub cost_per_simulated_s: f64,
}

/// Force evaluations of one step of `integrator` (for the work bound).
pub fn evaluations(integrator: Integrator) -> usize {
    match integrator {
        Integrator::Rk4 => 4,
        _ => 1,
    }
}

/// `2/ω_max` of `body` (the tangent at rest, the linear law's), s.
pub fn two_over_omega_s(body: &Body) -> anyhow::Result<f64> {
    with_params(
        body,
        body.material,
        DynamicParams::linear(0.0, 1.0),
        |model| Ok(2.0 / omega_max(model)),
    )
}

/// Steps of one trajectory at `dt_s`.
pub fn steps(dt_s: f64) -> usize {
    (DURATION_S / dt_s).ceil() as usize
}

/// Every trajectory of `extent` on `bodies` under `loads`, each with its
/// total force or torque (N, N·m) at `extent.level`.
pub fn trajectories(
    bodies: &[Body],
    loads: &[(Load, f64)],
    extent: &TrajectoryExtent,
    progress: &mut dyn Progress,
) -> anyhow::Result<Vec<Trajectory>> {
    let mut out = Vec::new();
    for body in bodies.iter().take(extent.meshes) {
        let two_over_omega = two_over_omega_s(body)?;
        // Time per step of (model, integrator): load-independent to the
        // timing's noise, measured once per mesh.
        let mut step_times: HashMap<(&'static str, &'static str), f64> = HashMap::new();
        for &(load, magnitude) in loads {
            let nodal = body.loads(load, magnitude);
            for model in MODELS {
                let Some((law, penalty)) = model.dynamic_law(body) else {
                    continue;
                };
                let params =
                    DynamicParams::linear(DAMPING_PER_S, 10.0 * diagonal(&body.mesh.positions))
                        .with_law(law)
                        .with_incompressibility(penalty);
                for integrator in Integrator::ALL {
                    for &factor in &extent.dt_factors {
                        let dt_s = factor * two_over_omega;
                        let reference = run(
                            body,
                            model,
                            params,
                            &nodal,
                            integrator,
                            dt_s / REFINEMENT as f64,
                            REFINEMENT,
                            steps(dt_s),
                        )?;
                        let coarse = run(
                            body,
                            model,
                            params,
                            &nodal,
                            integrator,
                            dt_s,
                            1,
                            steps(dt_s),
                        )?;
                        let key = (model.name(), integrator.name());
                        let step_s = match step_times.get(&key) {
                            Some(&t) => t,
                            None => {
                                let t = step_time(body, model, params, &nodal, integrator, dt_s)?;
                                step_times.insert(key, t);
                                t
                            }
                        };
                        let (fault, error) = match (&reference, &coarse) {
                            (Err(f), _) => {
                                (Some(format!("reference at Δt/{REFINEMENT}: {f}")), None)
                            }
                            (_, Err(f)) => (Some(f.clone()), None),
                            (Ok(r), Ok(c)) => (None, Some(error(c, r))),
                        };
                        progress.tick(&format!(
                            "trajectory {} {} {} {} Δt = {dt_s:.2e} s: {}",
                            body.label,
                            load.name(),
                            model.name(),
                            integrator.name(),
                            error.map_or_else(
                                || fault.clone().unwrap_or_default(),
                                |e| format!("error {e:.2e}")
                            )
                        ));
                        out.push(Trajectory {
                            mesh: body.label.clone(),
                            load,
                            level: extent.level,
                            model,
                            integrator: integrator.name(),
                            dt_s,
                            dt_factor: factor,
                            fault,
                            error,
                            step_s,
                            cost_per_simulated_s: step_s / dt_s,
                        });
                    }
                }
            }
        }
    }
    Ok(out)
}

/// The displacements after every `every` steps of `dt_s` (`samples` of
/// them) of `model` from rest under the nodal `loads`, or the fault that
/// ended the run.
#[allow(clippy::too_many_arguments)]
fn run(
    body: &Body,
    model: Model,
    params: DynamicParams<f64>,
    loads: &[[f64; 3]],
    integrator: Integrator,
    dt_s: f64,
    every: usize,
    samples: usize,
) -> anyhow::Result<Result<Vec<Vec<[f64; 3]>>, String>> {
    let n = body.mesh.positions.len();
    with_system(body, model, body.material, params, loads, |system, _| {
        let mut out = Vec::with_capacity(samples);
        for k in 0..samples * every {
            if let Err(e) = system.advance(integrator, dt_s) {
                return Ok(Err(format!(
                    "diverged at t = {:.3e} s: {e}",
                    k as f64 * dt_s
                )));
            }
            if (k + 1) % every == 0 {
                match system.field(n) {
                    Ok(u) => out.push(u),
                    Err(e) => return Ok(Err(format!("{e:#}"))),
                }
            }
        }
        Ok(Ok(out))
    })
}

/// Median time of one step of `integrator` at `dt_s` of `model` under
/// `loads`, timed on the motion from rest (from rest again after a
/// fault), s.
fn step_time(
    body: &Body,
    model: Model,
    params: DynamicParams<f64>,
    loads: &[[f64; 3]],
    integrator: Integrator,
    dt_s: f64,
) -> anyhow::Result<f64> {
    with_system(body, model, body.material, params, loads, |system, _| {
        let dispatch = HostDispatch::detect();
        Ok(median_s(|| {
            if system.region().fault().is_some() {
                system.reset();
            }
            let _ = core::hint::black_box(system.advance_dispatched(dispatch, integrator, dt_s));
        }))
    })
}

/// `max_k ‖u_k − r_k‖₂ / max_k ‖r_k‖₂` (the module's trajectory error).
pub fn error(u: &[Vec<[f64; 3]>], reference: &[Vec<[f64; 3]>]) -> f64 {
    let norm = |a: &[[f64; 3]], b: Option<&[[f64; 3]]>| -> f64 {
        a.iter()
            .enumerate()
            .map(|(v, x)| {
                let d = Vector3::from(*x) - b.map_or(Vector3::zeros(), |b| Vector3::from(b[v]));
                d.norm_squared()
            })
            .sum::<f64>()
            .sqrt()
    };
    let difference = u
        .iter()
        .zip(reference)
        .map(|(a, r)| norm(a, Some(r)))
        .fold(0.0, f64::max);
    let scale = reference.iter().map(|r| norm(r, None)).fold(0.0, f64::max);
    difference / scale
}
