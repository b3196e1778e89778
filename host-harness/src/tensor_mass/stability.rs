//! `palpate dynamic critical-dt`: the largest stable step of an integrator,
//! measured by bisection, next to the estimate `2/ω_max` (MODELS.md §3).

use anyhow::bail;
use nalgebra::Vector3;
use palpate_kernel::tensor_mass::{Integrator, TensorMassModel, VertexMode};
use serde::Serialize;

use super::OwnedState;
use super::run::{diagonal, f64_table, host_params};
use crate::mesh::{MeshReport, TetMesh};
use crate::table::build::BuildOptions;

/// Steps of the loading scenario per trial.
pub const TRIAL_STEPS: usize = 2000;
/// A trial is unstable when the total energy exceeds its start by this
/// factor. Large on purpose: near its limit a stable scheme's energy
/// oscillates by a large factor (symplectic Euler's modified energy by
/// `1/(1 − (ωΔt/2)²)`), while an unstable mode grows without bound.
pub const ENERGY_GROWTH_LIMIT: f64 = 1e6;
/// Bisection halvings of the bracket (relative width 2⁻³⁰ of the start).
const BISECTIONS: usize = 30;

/// The JSON object `dynamic critical-dt --json` prints.
#[derive(Serialize, Debug)]
pub struct CriticalDt {
    /// Integrator name.
    pub integrator: &'static str,
    /// Largest stable step found, s.
    pub critical_dt: f64,
    /// Largest circular eigenfrequency of `M⁻¹K`, rad/s (power iteration).
    pub omega_max: f64,
    /// `2/ω_max`, s: the bound of the central-difference and symplectic
    /// schemes for an undamped system.
    pub estimate_2_over_omega_max: f64,
    /// The stability criterion, in words.
    pub criterion: String,
}

/// Total energy `½ uᵀKu + ½ Σ m v²`, J.
fn energy(model: &TensorMassModel<'_, '_, f64>, scratch: &mut [[f64; 3]]) -> Option<f64> {
    let u = model.displacements_m().ok()?;
    let v = model.velocities_m_s().ok()?;
    model.elastic_forces_of(u, scratch);
    let elastic: f64 = u
        .iter()
        .zip(scratch.iter())
        .map(|(u, f)| -0.5 * Vector3::from(*u).dot(&Vector3::from(*f)))
        .sum();
    let kinetic: f64 = v
        .iter()
        .zip(model.masses_kg())
        .map(|(v, m)| 0.5 * m * Vector3::from(*v).norm_squared())
        .sum();
    Some(elastic + kinetic)
}

/// A deterministic displacement pattern exciting every mode: alternating
/// signs per vertex and axis (the highest modes) scaled to `amplitude_m`.
fn perturbation(vertex: usize, amplitude_m: f64) -> Vector3<f64> {
    let sign = |k: usize| {
        if (vertex * 3 + k).is_multiple_of(2) {
            1.0
        } else {
            -1.0
        }
    };
    let jitter = ((vertex * 7919) % 101) as f64 / 101.0;
    Vector3::new(sign(0), sign(1) * (0.5 + jitter), sign(2)) * amplitude_m
}

/// Resets `model` to the scenario's start: every free vertex displaced by
/// [`perturbation`], at rest.
fn start(model: &mut TensorMassModel<'_, '_, f64>, amplitude_m: f64) {
    model.reset();
    let free: Vec<u32> = (0..model.modes().len() as u32)
        .filter(|&v| {
            model.modes()[v as usize] == VertexMode::Free && model.masses_kg()[v as usize] > 0.0
        })
        .collect();
    for &v in &free {
        // Free vertices with mass accept both calls.
        let _ = model.impose(v, perturbation(v as usize, amplitude_m));
        let _ = model.release(v);
    }
}

/// `true` if `integrator` at `dt_s` keeps the energy of the scenario below
/// [`ENERGY_GROWTH_LIMIT`] times its start for [`TRIAL_STEPS`] steps without
/// a fault.
pub fn is_stable(
    model: &mut TensorMassModel<'_, '_, f64>,
    integrator: Integrator,
    dt_s: f64,
    amplitude_m: f64,
) -> bool {
    start(model, amplitude_m);
    let mut scratch = vec![[0.0; 3]; model.modes().len()];
    let Some(initial) = energy(model, &mut scratch) else {
        return false;
    };
    for step in 0..TRIAL_STEPS {
        // A fault (divergence) or any refusal ends the trial as unstable.
        if model.step(integrator, dt_s).is_err() {
            return false;
        }
        if step % 10 == 9 {
            match energy(model, &mut scratch) {
                Some(e) if e <= ENERGY_GROWTH_LIMIT * initial => {}
                _ => return false,
            }
        }
    }
    true
}

/// `ω_max = sqrt(λ_max(M⁻¹K))` by power iteration (500 iterations from the
/// [`perturbation`] pattern), rad/s.
pub fn omega_max(model: &mut TensorMassModel<'_, '_, f64>) -> f64 {
    model.reset();
    let n = model.modes().len();
    let free: Vec<bool> = (0..n)
        .map(|v| model.modes()[v] == VertexMode::Free && model.masses_kg()[v] > 0.0)
        .collect();
    let mut x: Vec<[f64; 3]> = (0..n)
        .map(|v| {
            if free[v] {
                perturbation(v, 1.0).into()
            } else {
                [0.0; 3]
            }
        })
        .collect();
    let mut f = vec![[0.0; 3]; n];
    let mut lambda = 0.0;
    for _ in 0..500 {
        model.elastic_forces_of(&x, &mut f);
        let mut norm = 0.0;
        for v in 0..n {
            let y = if free[v] {
                -Vector3::from(f[v]) / model.masses_kg()[v]
            } else {
                Vector3::zeros()
            };
            x[v] = y.into();
            norm += y.norm_squared();
        }
        let norm = norm.sqrt();
        let previous: f64 = lambda;
        lambda = norm;
        for xv in &mut x {
            *xv = (Vector3::from(*xv) / norm).into();
        }
        if (lambda - previous).abs() <= 1e-10 * lambda {
            break;
        }
    }
    lambda.sqrt()
}

/// Bisection for the largest stable step, starting from the bracket
/// `[0, 8/ω_max]` (no explicit scheme is stable beyond `2.8/ω_max`, RK4's
/// limit on the imaginary axis).
pub fn critical_dt(
    model: &mut TensorMassModel<'_, '_, f64>,
    integrator: Integrator,
    amplitude_m: f64,
) -> CriticalDt {
    let omega = omega_max(model);
    let (mut stable, mut unstable) = (0.0, 8.0 / omega);
    for _ in 0..BISECTIONS {
        let mid = 0.5 * (stable + unstable);
        if is_stable(model, integrator, mid, amplitude_m) {
            stable = mid;
        } else {
            unstable = mid;
        }
    }
    CriticalDt {
        integrator: integrator.name(),
        critical_dt: stable,
        omega_max: omega,
        estimate_2_over_omega_max: 2.0 / omega,
        criterion: format!(
            "every free vertex displaced by a fixed alternating pattern, released at rest; \
             stable if {TRIAL_STEPS} steps run without a fault and the total energy stays \
             below {ENERGY_GROWTH_LIMIT:e} times its start"
        ),
    }
}

/// `dynamic critical-dt`: builds the f64 model of `mesh` (the tensor-mass
/// table `options`, damping `damping_per_s`, 1/s) and measures `integrator`'s critical step, with a
/// perturbation of 1e-3 of the bounding-box diagonal.
pub fn critical_dt_of_mesh(
    mesh: &TetMesh,
    report: &MeshReport,
    options: &BuildOptions,
    damping_per_s: f64,
    integrator: Integrator,
) -> anyhow::Result<CriticalDt> {
    let file = f64_table(mesh, report, options)?;
    let table = palpate_kernel::table::TensorMassTable::<f64>::load(file.bytes())?;
    let mut state = OwnedState::for_table(&table);
    let params = host_params(&mesh.positions, damping_per_s);
    let mut model = TensorMassModel::new(table, state.buffers(), params)?;
    let moving = (0..model.modes().len())
        .filter(|&v| model.modes()[v] == VertexMode::Free && model.masses_kg()[v] > 0.0)
        .count();
    if moving == 0 {
        bail!(
            "every vertex is fixed (by --fix, or unreferenced by any tet): nothing moves, \
             so no step is unstable and there is no critical step"
        );
    }
    let young_pa = options.material.young_pa;
    // Checked before the bisection, which would run its every trial on a
    // bracket of NaN or zero.
    let omega = omega_max(&mut model);
    if !(omega.is_finite() && omega > 0.0) {
        bail!(
            "the largest eigenfrequency of M^-1 K is {omega} rad/s (f64 overflow or underflow \
             with E = {young_pa:e} Pa and this mesh and density): give E in Pa, the density in \
             kg/m3 and the mesh in metres (SI units)"
        );
    }
    let amplitude = 1e-3 * diagonal(&mesh.positions);
    let result = critical_dt(&mut model, integrator, amplitude);
    if !(result.critical_dt.is_finite() && result.critical_dt > 0.0) {
        bail!(
            "no stable step found: {} is unstable even at {:e} s (2/omega_max = {:e} s): the \
             energies overflow f64 with E = {young_pa:e} Pa on this mesh; give E in Pa, the \
             density in kg/m3 and the mesh in metres (SI units)",
            result.integrator,
            8.0 / omega / f64::from(1u32 << BISECTIONS),
            result.estimate_2_over_omega_max
        );
    }
    Ok(result)
}
