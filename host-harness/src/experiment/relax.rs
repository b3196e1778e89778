//! Static equilibrium by dynamic relaxation: the kernel's own step
//! (symplectic Euler) with kinetic damping, i.e. every velocity is zeroed at
//! each peak of the kinetic energy (Cundall's method), until the residual
//! force is small. The same code path for every elastic law, so the laws are
//! compared at equilibria found the same way.
//!
//! The step: the load is applied at once, so the first swing overshoots the
//! equilibrium, and a law that stiffens in compression (neo-Hookean: `g''(J)`
//! grows as `J` falls) can leave the step's stability region on the way. At
//! `0.5/ω_max` (of the tangent at rest) the neo-Hookean relaxation of the
//! chart's cylinders under a 20 % press diverged (the kernel's displacement
//! bound faulted) where `0.3/ω_max` settled (on 1×5 on Newton's own
//! equilibrium: `tests/host/neo_hookean_kernel.rs`).

use nalgebra::Vector3;
use palpate_kernel::tensor_mass::{Integrator, StepError, TensorMassModel, VertexMode};

/// How a relaxation ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Relaxation {
    /// Steps taken.
    pub steps: usize,
    /// Largest `|f_int + f_ext|` over the free vertices at the end, N.
    pub residual_n: f64,
    /// `residual_n ≤` the requested tolerance.
    pub converged: bool,
}

/// Relaxes `model` (undamped parameters expected) under the constant
/// external forces `loads_n` (one per vertex, N, as set on the model) with
/// step `dt_s`, until the largest residual force on a free vertex is at
/// most `tolerance_n` (checked every 100 steps) or `max_steps` have run.
/// A fault (divergence) is an error. `last` receives the displacements (m)
/// after the last good step, the equilibrium when it converged.
pub fn relax(
    model: &mut TensorMassModel<'_, '_, f64>,
    loads_n: &[[f64; 3]],
    dt_s: f64,
    tolerance_n: f64,
    max_steps: usize,
    last: &mut [[f64; 3]],
) -> Result<Relaxation, StepError> {
    let n = model.modes().len();
    let mut forces = vec![[0.0; 3]; n];
    let mut previous_kinetic = 0.0;
    let mut residual_n = f64::INFINITY;
    let mut steps = 0;
    while steps < max_steps {
        let kinetic = model
            .step(Integrator::SymplecticEuler, dt_s)?
            .kinetic_energy_j;
        steps += 1;
        if let Ok(u) = model.displacements_m() {
            last.copy_from_slice(u);
        }
        if kinetic < previous_kinetic {
            stop(model);
            previous_kinetic = 0.0;
        } else {
            previous_kinetic = kinetic;
        }
        if steps % 100 == 0 {
            residual_n = residual(model, loads_n, &mut forces);
            if residual_n <= tolerance_n {
                break;
            }
        }
    }
    Ok(Relaxation {
        steps,
        residual_n,
        converged: residual_n <= tolerance_n,
    })
}

/// Zeroes the velocity of every free vertex (a kinetic-energy peak).
fn stop(model: &mut TensorMassModel<'_, '_, f64>) {
    for v in 0..model.modes().len() {
        if model.modes()[v] == VertexMode::Free {
            // Free vertices accept any finite velocity.
            let _ = model.set_velocity(v as u32, Vector3::zeros());
        }
    }
}

/// Largest `|f_int + f_ext|` over the free vertices with mass, N.
fn residual(
    model: &TensorMassModel<'_, '_, f64>,
    loads_n: &[[f64; 3]],
    forces: &mut [[f64; 3]],
) -> f64 {
    model.elastic_forces_n(forces);
    let free = |v: usize| model.modes()[v] == VertexMode::Free && model.masses_kg()[v] > 0.0;
    (0..forces.len())
        .filter(|&v| free(v))
        .map(|v| (Vector3::from(forces[v]) + Vector3::from(loads_n[v])).norm())
        .fold(0.0, f64::max)
}
