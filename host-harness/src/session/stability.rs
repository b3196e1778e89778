//! Whether a dynamic scene's time step is stable on its mesh, checked when the scene and its
//! mesh are loaded for a run, instead of a divergence fault at the first press.
//!
//! [`check_stable_step`] builds the scene's tensor-mass model in f64, estimates the largest
//! eigenfrequency `ω_max` of `M⁻¹K` (Lanczos, [`crate::tensor_mass::stability::stable_step_limit`])
//! and the integrator's largest stable step from it, and refuses a `dt_s` above
//! [`STABLE_STEP_SAFETY`] times that step with the number and a `dt_s` that validates.

use anyhow::Context;
use palpate_kernel::tensor_mass::Integrator;

use crate::mesh::{MeshReport, TetMesh};
use crate::scene::{MAX_SUBSTEPS, ModelSpec, Scene, SceneError};
use crate::table::build::BuildOptions;
use crate::table::file::Precision;
use crate::tensor_mass::stability::{StableStep, stable_step_limit};

/// A scene's `dt_s` may be at most this fraction of the estimated largest stable step.
///
/// Below 1 because the estimate errs on the unsafe side only: `ω_max` is the largest Ritz value
/// of the Lanczos iteration, which never exceeds the true one (to rounding), so the step derived
/// from it is never below the true limit of the linear model at rest. Its own error is small (it
/// stops when `ω_max²` settles to 1e-10; on a 64-vertex box it agrees with the power iteration
/// to 3e-9 and with the bisection's measured step to 1e-5, see the tests), so the margin is for
/// what that analysis does not see: the run's f32 table (1e-7), St Venant-Kirchhoff stiffening
/// under strain (the uniaxial tangent modulus is `(3λ² − 1)/2` of `E` at stretch `λ`: a 5 %
/// shorter step absorbs 11 % more stiffness, 3.5 % strain in the stiffest element), and
/// tets removed by cutting or tearing, which take their mass share from the vertices they leave.
/// Past that the run's divergence fault still stops the model. Not smaller: every step below
/// the limit is stable for the linear model, so a smaller factor refuses scenes that run (the
/// built-in dynamic scene, 0.5 ms against a limit of 1.88 ms, is far from either).
pub const STABLE_STEP_SAFETY: f64 = 0.95;

/// For a dynamic scene, the largest stable step of its integrator on `mesh` (the scene's
/// material, density, fixed vertices and damping; the table built as the run builds it, in
/// f64), and an error when [`Scene`]'s `dt_s` exceeds [`STABLE_STEP_SAFETY`] times it. `Ok(None)`
/// for the pre-computed model, which is unconditionally stable.
///
/// The error is one line, a [`SceneError::Invalid`] on `[model] dt_s` naming the scene source:
/// the limit, how it follows from `ω_max`, and a `dt_s` that divides the physics period into a
/// whole number of steps at or below the bound (`physics_period_s / ceil(period / bound)`), so
/// the scene validates with it. A mesh on which the table cannot be built, or with nothing free,
/// is an error naming the scene.
///
/// Cost: linear in the mesh (a table build and at most a few hundred force passes, no
/// stepping): 0.1 s on a 6144-tet cylinder (the table build 55 ms of it).
pub fn check_stable_step(
    scene: &Scene,
    mesh: &TetMesh,
    report: &MeshReport,
) -> anyhow::Result<Option<StableStep>> {
    let ModelSpec::Dynamic(dynamic) = &scene.model else {
        return Ok(None);
    };
    let materials = scene.tet_materials(mesh, report)?;
    let options = BuildOptions::tensor_mass(
        materials.default_material(),
        scene.material.density_kg_m3,
        scene.fix.clone(),
        Precision::F64,
    )
    .with_tet_materials(materials);
    let step = stable_step_limit(
        mesh,
        report,
        &options,
        dynamic.damping_per_s,
        dynamic.integrator,
    )
    .with_context(|| {
        format!(
            "{}: the largest stable step of {} on the mesh {}",
            scene.source,
            integrator_name(dynamic.integrator),
            report.source
        )
    })?;
    let bound = STABLE_STEP_SAFETY * step.limit_dt_s;
    let dt_s = dynamic.dt_s;
    if dt_s <= bound {
        return Ok(Some(step));
    }
    let name = integrator_name(dynamic.integrator);
    let omega = format!("omega_max = {:.0} rad/s", step.omega_max);
    let msg = if step.limit_dt_s <= 0.0 {
        format!(
            "{name} is unstable at every step without damping (it amplifies every mode by \
             sqrt(1 + (omega dt)^2) per step; {omega}); give damping_per_s > 0, or integrator = \
             \"symplectic\" or \"central\""
        )
    } else {
        let damping = match dynamic.integrator {
            Integrator::CentralDifference => String::new(),
            _ if dynamic.damping_per_s == 0.0 => String::new(),
            _ => format!(", c = {} 1/s", dynamic.damping_per_s),
        };
        let above = if dt_s > step.limit_dt_s {
            "above the largest stable step".to_owned()
        } else {
            format!("above {STABLE_STEP_SAFETY} of the largest stable step (STABLE_STEP_SAFETY)")
        };
        format!(
            "{above} of {name} on this mesh, {} s ({}; {omega}{damping}); use dt_s <= {}{} or \
             a coarser mesh",
            decimal(step.limit_dt_s, 3, f64::round),
            step.rule,
            decimal(bound, 3, f64::floor),
            suggestion(scene, bound)
        )
    };
    Err(SceneError::Invalid {
        file: scene.source.clone(),
        key: format!("[model] dt_s = {dt_s}"),
        msg,
    }
    .into())
}

/// The integrator's name in messages.
fn integrator_name(integrator: Integrator) -> &'static str {
    match integrator {
        Integrator::ExplicitEuler => "explicit Euler",
        Integrator::SymplecticEuler => "symplectic Euler",
        Integrator::Rk4 => "RK4",
        Integrator::CentralDifference => "the central difference",
    }
}

/// ` (e.g. physics_every = 1 at 1000 Hz with dt_s = 0.00025, 4 steps per physics update)`: the
/// largest `dt_s <= bound` that divides the physics period into whole steps, checked to validate
/// as printed; or why there is none.
fn suggestion(scene: &Scene, bound: f64) -> String {
    let period = scene.physics_period_s();
    let steps = (period / bound).ceil();
    if !(steps.is_finite() && steps >= 1.0 && steps <= f64::from(MAX_SUBSTEPS)) {
        return format!(
            ", which needs more than {MAX_SUBSTEPS} steps per physics update of {period} s \
             (MAX_SUBSTEPS): lower physics_every,"
        );
    }
    let dt = period / steps;
    // 12 significant digits keep `period / dt` within 1e-11 of `steps`, inside the 1e-9 the
    // whole-step check allows; rounded down, so never above the bound.
    let printed = [decimal(dt, 12, f64::floor), dt.to_string()]
        .into_iter()
        .find(|text| {
            let Ok(value) = text.parse::<f64>() else {
                return false;
            };
            let mut candidate = scene.clone();
            if let ModelSpec::Dynamic(d) = &mut candidate.model {
                d.dt_s = value;
            }
            value <= bound && candidate.validate().is_ok()
        })
        .unwrap_or_else(|| dt.to_string());
    format!(
        " (e.g. physics_every = {} at {} Hz with dt_s = {printed}, {steps} steps per physics \
         update)",
        scene.rates.physics_every, scene.rates.haptic_hz
    )
}

/// `x > 0` in decimal with `digits` significant digits, rounded by `round` (`f64::floor`: never
/// above `x`), trailing zeros trimmed: `decimal(0.00045912, 3, f64::round)` is `0.000459`.
fn decimal(x: f64, digits: i32, round: fn(f64) -> f64) -> String {
    if !(x.is_finite() && x > 0.0) {
        return x.to_string();
    }
    let shift = digits - 1 - x.log10().floor() as i32;
    let scaled = round(x * 10f64.powi(shift)) / 10f64.powi(shift);
    let text = format!("{scaled:.*}", shift.max(0) as usize);
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        text
    }
}
