//! `palpate dynamic critical-dt`: the largest stable step of an integrator,
//! measured by bisection, next to the estimate `2/ω_max` (MODELS.md §3);
//! and [`stable_step_limit`], the same limit from `ω_max` and each scheme's
//! stability condition, fast enough to check a scene when it is loaded.

use anyhow::bail;
use nalgebra::Vector3;
use palpate_kernel::tensor_mass::{Integrator, TensorMassModel, VertexMode};
use serde::Serialize;

use super::OwnedState;
use super::run::{diagonal, f64_table, host_params};
use crate::mesh::{MeshReport, TetMesh};
use crate::output::number::shown;
use crate::table::build::BuildOptions;

/// Steps of the loading scenario per trial.
pub const TRIAL_STEPS: usize = 2000;
/// A trial is unstable when the total energy exceeds its start by this
/// factor. Large on purpose: near its limit a stable scheme's energy
/// oscillates by a large factor (symplectic Euler's modified energy by
/// `1/(1 − (ωΔt/2)²)`), while an unstable mode grows without bound.
pub const ENERGY_GROWTH_LIMIT: f64 = 1e6;
/// Bisection halvings of the bracket (relative width 2⁻³⁰ of the start).
pub const BISECTIONS: usize = 30;

/// Most iterations of the power iteration of [`omega_max`] (each one force pass).
pub const POWER_ITERATIONS: usize = 500;

/// Steps (force passes) of one critical-step measurement at most: the power iteration's and
/// [`BISECTIONS`] trials of [`TRIAL_STEPS`] steps (checked against
/// [`crate::limits::MAX_RUN_TET_STEPS`] before it starts).
pub const CRITICAL_DT_STEPS: u64 = (POWER_ITERATIONS + BISECTIONS * TRIAL_STEPS) as u64;

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

/// The scale of the displacement fields whose forces give `K x` in
/// [`omega_max`] and [`lanczos_omega_max`] (`x` has unit norm): `2⁻³⁰`, so a
/// field of about 1 nm, where a non-linear law (St Venant-Kirchhoff, its
/// penalty) is its tangent at rest to ~1e-7 relative. A power of two, so a
/// linear law's `K x` is bit-identical to the unscaled product. At a unit
/// (metre) scale a St Venant-Kirchhoff model's cubic terms dominated and
/// the estimate was ×140 too high on the 2×10 chart cylinder.
const TANGENT_SCALE: f64 = 1.0 / (1u64 << 30) as f64;

/// `K x` of the tangent stiffness at rest, `out = −K x` (N per m): the
/// elastic forces of the field `x` scaled by [`TANGENT_SCALE`], less
/// `at_rest` (the forces of the zero field: a hybrid's passed force),
/// unscaled.
fn rest_tangent_forces(
    model: &TensorMassModel<'_, '_, f64>,
    at_rest: &[[f64; 3]],
    x: &mut [[f64; 3]],
    out: &mut [[f64; 3]],
) {
    x.iter_mut().for_each(|v| *v = v.map(|c| c * TANGENT_SCALE));
    model.elastic_forces_of(x, out);
    x.iter_mut().for_each(|v| *v = v.map(|c| c / TANGENT_SCALE));
    for (f, f0) in out.iter_mut().zip(at_rest) {
        *f = [0, 1, 2].map(|k| (f[k] - f0[k]) / TANGENT_SCALE);
    }
}

/// The elastic forces (N) of the zero displacement field.
fn forces_at_rest(model: &TensorMassModel<'_, '_, f64>) -> Vec<[f64; 3]> {
    let n = model.modes().len();
    let mut f = vec![[0.0; 3]; n];
    model.elastic_forces_of(&vec![[0.0; 3]; n], &mut f);
    f
}

/// `ω_max = sqrt(λ_max(M⁻¹K))` by power iteration (500 iterations from the
/// `perturbation` pattern), rad/s, `K` the tangent stiffness at rest
/// (`rest_tangent_forces`; the stiffness itself for the linear law).
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
    let at_rest = forces_at_rest(model);
    let mut lambda = 0.0;
    for _ in 0..POWER_ITERATIONS {
        rest_tangent_forces(model, &at_rest, &mut x, &mut f);
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
    check_critical_dt_work(mesh.tets.len(), 1)?;
    with_moving_model(mesh, report, options, damping_per_s, |model| {
        let young_pa = options.material.young_pa;
        // Checked before the bisection, which would run its every trial on
        // a bracket of NaN or zero.
        let omega = checked_omega(omega_max(model), young_pa)?;
        let amplitude = 1e-3 * diagonal(&mesh.positions);
        let result = critical_dt(model, integrator, amplitude);
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
    })
}

/// Checks `measurements` critical-step measurements on `tets` tets
/// ([`CRITICAL_DT_STEPS`] steps each) against the offline runs' work limit
/// before anything is built.
pub fn check_critical_dt_work(tets: usize, measurements: u64) -> anyhow::Result<()> {
    crate::limits::check_tet_steps(
        "dynamic critical-dt",
        tets as u64,
        CRITICAL_DT_STEPS.saturating_mul(measurements),
        "use a coarser mesh (the bisection's steps are fixed); a dynamic scene's session checks \
         its dt_s against the Lanczos estimate of the stable step, linear in the mesh",
    )
}

/// Builds the f64 model of `mesh` (the tensor-mass table `options`,
/// damping `damping_per_s`, 1/s) and runs `body` on it; an error when no
/// vertex can move (every one fixed or in no tet): nothing is unstable.
fn with_moving_model<R>(
    mesh: &TetMesh,
    report: &MeshReport,
    options: &BuildOptions,
    damping_per_s: f64,
    body: impl FnOnce(&mut TensorMassModel<'_, '_, f64>) -> anyhow::Result<R>,
) -> anyhow::Result<R> {
    let file = f64_table(mesh, report, options)?;
    let table = palpate_kernel::table::TensorMassTable::<f64>::load(file.bytes())?;
    let mut state = OwnedState::for_table(&table);
    let params = host_params(&mesh.positions, damping_per_s);
    let mut model = TensorMassModel::new(table, state.buffers(), params)?;
    let moving = (0..model.modes().len())
        .any(|v| model.modes()[v] == VertexMode::Free && model.masses_kg()[v] > 0.0);
    if !moving {
        bail!(
            "every vertex is fixed (by the fix predicates, or unreferenced by any tet): nothing \
             moves, so no step is unstable and there is no critical step"
        );
    }
    body(&mut model)
}

/// `omega` (rad/s) if finite and positive, else the error naming the units
/// to check (E `young_pa`, Pa).
fn checked_omega(omega: f64, young_pa: f64) -> anyhow::Result<f64> {
    if !(omega.is_finite() && omega > 0.0) {
        bail!(
            "the largest eigenfrequency of M^-1 K is {omega} rad/s (f64 overflow or underflow \
             with E = {young_pa:e} Pa and this mesh and density): give E in Pa, the density in \
             kg/m3 and the mesh in metres (SI units)"
        );
    }
    Ok(omega)
}

/// The largest stable step of an integrator on a mesh, from `ω_max`
/// ([`stable_step_limit`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StableStep {
    /// Largest circular eigenfrequency of `M⁻¹K` over the moving vertices,
    /// rad/s (Lanczos, from below).
    pub omega_max: f64,
    /// The integrator's largest stable step for every mode up to
    /// `omega_max` with the scene's damping, s (0 when no step is stable).
    pub limit_dt_s: f64,
    /// How `limit_dt_s` follows from `omega_max`, in words.
    pub rule: &'static str,
}

/// Largest number of Lanczos steps of [`lanczos_omega_max`].
pub const LANCZOS_MAX_STEPS: usize = 300;
/// [`lanczos_omega_max`] stops when the largest Ritz value grew by at most
/// this fraction over the last [`LANCZOS_WINDOW`] steps.
pub const LANCZOS_TOLERANCE: f64 = 1e-10;
/// Steps over which [`lanczos_omega_max`] measures its progress.
pub const LANCZOS_WINDOW: usize = 10;

/// The largest stable step of `integrator` with mass-proportional damping
/// `damping_per_s` (`c`, 1/s) on the tensor-mass model of `mesh` (table
/// `options`, built in f64): `ω_max` by [`lanczos_omega_max`] on the linear
/// model at rest, then the scheme's stability condition on the modal
/// equation `ü = −c u̇ − ω² u` of every mode `ω ≤ ω_max` (the kernel's
/// updates, `palpate_kernel::tensor_mass::Integrator`; MODELS.md §3):
///
/// - symplectic Euler: the update matrix has determinant `1 − cΔt` and trace
///   `2 − cΔt − (ωΔt)²`; both roots lie in the unit disk iff
///   `(ωΔt)² + 2cΔt ≤ 4`, i.e. `Δt ≤ 4/(c + sqrt(c² + 4ω²))`: `2/ω_max`
///   undamped, slightly less with damping (0.985 × `2/ω_max` on the
///   reference cube with `c = 2/s`, as the bisection measures);
/// - central difference (damping in the coefficients):
///   `(1 + cΔt/2) z² − (2 − (ωΔt)²) z + (1 − cΔt/2)`, stable iff
///   `ωΔt ≤ 2` whatever `c ≥ 0`: `2/ω_max`;
/// - explicit Euler: determinant `1 − cΔt + (ωΔt)²`, so an under-damped mode
///   needs `Δt ≤ c/ω²` and an over-damped one `Δt ≤ 4/(c + sqrt(c² − 4ω²))`
///   `≥ 2/c`: `min(c/ω_max², 2/c)`, zero undamped (no step is stable). This
///   is the asymptotic limit; the bisection's finite trial passes far longer
///   steps, on which the energy grows by under 1e6 in its 2000 steps (3.5×
///   with `c = 30/s`, 44× with `c = 2/s` on a 64-vertex box);
/// - RK4: `|R(λΔt)| ≤ 1` with `R(z) = 1 + z + z²/2 + z³/6 + z⁴/24` for
///   every eigenvalue `λ = −c/2 ± i sqrt(ω² − c²/4)` of a mode `ω ≤ ω_max`
///   (256 modes spread over `(c/2, ω_max]`) and for `λ = −c` (the
///   over-damped modes' bound), each by the radius of RK4's stability region
///   along `λ`: `2√2/ω_max` undamped.
///
/// The limit is that of the linear model at rest; St Venant-Kirchhoff
/// stiffens under strain, and removing tets (cutting, tearing) removes
/// their masses too, which can raise `ω_max`: a caller checking a scene
/// keeps a margin ([`crate::session::stability`]).
///
/// Cost: the f64 table build and up to [`LANCZOS_MAX_STEPS`] force passes
/// (no stepping), linear in the mesh: 0.1 s for a 6144-tet cylinder, the
/// table build 55 ms and the Lanczos iteration 8 ms of it (the bisection of
/// [`critical_dt_of_mesh`] takes 2.5 s there). Errors: nothing free to move,
/// a table that does not build, a non-finite `ω_max`.
pub fn stable_step_limit(
    mesh: &TetMesh,
    report: &MeshReport,
    options: &BuildOptions,
    damping_per_s: f64,
    integrator: Integrator,
) -> anyhow::Result<StableStep> {
    if !(damping_per_s.is_finite() && damping_per_s >= 0.0) {
        bail!(
            "the damping must be finite and >= 0 1/s, got {}",
            shown(damping_per_s)
        );
    }
    with_moving_model(mesh, report, options, damping_per_s, |model| {
        stable_step_of_model(model, options.material.young_pa, damping_per_s, integrator)
    })
}

/// The largest stable step of `integrator` with damping `damping_per_s` (1/s) on `model` (f64,
/// at rest): `ω_max` by Lanczos, checked finite and positive (an error naming E `young_pa`,
/// Pa, otherwise), and the integrator's condition. The one computation of [`stable_step_limit`]
/// (a scene's check) and of `scene plan`'s tensor-mass regions.
pub fn stable_step_of_model(
    model: &mut TensorMassModel<'_, '_, f64>,
    young_pa: f64,
    damping_per_s: f64,
    integrator: Integrator,
) -> anyhow::Result<StableStep> {
    let omega = checked_omega(lanczos_omega_max(model), young_pa)?;
    let (limit_dt_s, rule) = integrator_limit(integrator, omega, damping_per_s);
    Ok(StableStep {
        omega_max: omega,
        limit_dt_s,
        rule,
    })
}

/// The largest stable step of `integrator` for every mode up to `omega`
/// (rad/s) with damping `c` (1/s), s, and its rule (see
/// [`stable_step_limit`]).
pub fn integrator_limit(integrator: Integrator, omega: f64, c: f64) -> (f64, &'static str) {
    match integrator {
        Integrator::SymplecticEuler if c == 0.0 => (
            2.0 / omega,
            "2/omega_max, symplectic Euler's undamped bound",
        ),
        Integrator::SymplecticEuler => (
            4.0 / (c + c.hypot(2.0 * omega)),
            "4/(c + sqrt(c^2 + 4 omega_max^2)), symplectic Euler's bound with damping c \
             (2/omega_max undamped)",
        ),
        Integrator::CentralDifference => (
            2.0 / omega,
            "2/omega_max, the central difference's bound whatever the damping",
        ),
        Integrator::ExplicitEuler if c == 0.0 => (
            0.0,
            "none: explicit Euler amplifies every undamped mode by sqrt(1 + (omega dt)^2) per step",
        ),
        Integrator::ExplicitEuler => (
            (c / (omega * omega)).min(2.0 / c),
            "min(c/omega_max^2, 2/c), explicit Euler's bound with damping c",
        ),
        Integrator::Rk4 => (
            rk4_limit(omega, c),
            "min over the eigenvalues lambda of the modes of RK4's stability radius along \
             lambda over |lambda|, lambda = -c/2 +- i sqrt(omega^2 - c^2/4) for omega <= \
             omega_max and -c (2 sqrt(2)/omega_max undamped)",
        ),
    }
}

/// Modes of [`rk4_limit`] spread over `(c/2, ω_max]`.
const RK4_MODES: usize = 256;

/// The largest `Δt` for which RK4 is stable on every eigenvalue of the modes
/// `ω ≤ omega` with damping `c` (see [`stable_step_limit`]).
fn rk4_limit(omega: f64, c: f64) -> f64 {
    let mut limit = f64::INFINITY;
    if c > 0.0 {
        // Over-damped modes: real eigenvalues in [-c, 0).
        limit = rk4_radius(-1.0, 0.0) / c;
    }
    let lowest = 0.5 * c;
    if omega > lowest {
        for k in 0..RK4_MODES {
            let w = omega - (omega - lowest) * k as f64 / RK4_MODES as f64;
            let im = (w * w - lowest * lowest).max(0.0).sqrt();
            // |λ| = w for an under-damped mode.
            limit = limit.min(rk4_radius(-lowest / w, im / w) / w);
        }
    }
    limit
}

/// The first `r > 0` at which `|R(r·d)| > 1` for RK4's amplification factor
/// `R` along the unit direction `d = (re, im)` (`re ≤ 0`): marched in steps
/// of 1/256, then bisected. RK4's stability region lies within `|z| < 3` in
/// the left half-plane, so the march ends by `r = 4`.
fn rk4_radius(re: f64, im: f64) -> f64 {
    let unstable = |r: f64| {
        let (x, y) = (r * re, r * im);
        // R(z) = 1 + z(1 + z/2 (1 + z/3 (1 + z/4))), Horner in complex form.
        let mut a = (1.0, 0.0);
        for k in [4.0, 3.0, 2.0, 1.0] {
            a = (1.0 + (x * a.0 - y * a.1) / k, (x * a.1 + y * a.0) / k);
        }
        a.0 * a.0 + a.1 * a.1 > 1.0 + 1e-12
    };
    let step = 1.0 / 256.0;
    let mut r = step;
    while r < 4.0 && !unstable(r) {
        r += step;
    }
    let (mut lo, mut hi) = (r - step, r);
    for _ in 0..50 {
        let mid = 0.5 * (lo + hi);
        if unstable(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    lo
}

/// `ω_max = sqrt(λ_max(M⁻¹K))`, rad/s, over the free vertices with mass, by
/// the Lanczos iteration on the symmetric `M^{-1/2} K M^{-1/2}` from the
/// `perturbation` pattern (three vectors, no reorthogonalization): its
/// largest Ritz value never exceeds `λ_max` (to rounding, Paige 1980) and
/// grows towards it, converging far faster than the power iteration of
/// [`omega_max`] when the top of the spectrum is clustered, as on a fine
/// mesh. Stops when the Ritz value grew by at most [`LANCZOS_TOLERANCE`]
/// over [`LANCZOS_WINDOW`] steps, at an invariant subspace, or after
/// [`LANCZOS_MAX_STEPS`] steps. `K` is the model's tangent stiffness at
/// rest (`rest_tangent_forces`).
pub fn lanczos_omega_max(model: &mut TensorMassModel<'_, '_, f64>) -> f64 {
    model.reset();
    let n = model.modes().len();
    let inv_sqrt_mass: Vec<f64> = (0..n)
        .map(|v| {
            let m = model.masses_kg()[v];
            if model.modes()[v] == VertexMode::Free && m > 0.0 {
                1.0 / m.sqrt()
            } else {
                0.0
            }
        })
        .collect();
    let dot = |a: &[[f64; 3]], b: &[[f64; 3]]| -> f64 {
        a.iter()
            .zip(b)
            .map(|(a, b)| a[0] * b[0] + a[1] * b[1] + a[2] * b[2])
            .sum()
    };
    let mut q: Vec<[f64; 3]> = (0..n)
        .map(|v| {
            if inv_sqrt_mass[v] > 0.0 {
                perturbation(v, 1.0).into()
            } else {
                [0.0; 3]
            }
        })
        .collect();
    let norm = dot(&q, &q).sqrt();
    if norm == 0.0 {
        return 0.0;
    }
    q.iter_mut().for_each(|x| *x = x.map(|c| c / norm));
    let mut q_previous = vec![[0.0; 3]; n];
    let mut x = vec![[0.0; 3]; n];
    let mut w = vec![[0.0; 3]; n];
    let (mut alphas, mut betas) = (Vec::new(), Vec::new());
    let mut ritz: Vec<f64> = Vec::new();
    let mut beta_previous = 0.0;
    let at_rest = forces_at_rest(model);
    for _ in 0..LANCZOS_MAX_STEPS {
        // w = M^{-1/2} K M^{-1/2} q, with K u = -(elastic forces of u).
        for v in 0..n {
            x[v] = q[v].map(|c| c * inv_sqrt_mass[v]);
        }
        rest_tangent_forces(model, &at_rest, &mut x, &mut w);
        for v in 0..n {
            w[v] = w[v].map(|c| -c * inv_sqrt_mass[v]);
        }
        let alpha = dot(&q, &w);
        for v in 0..n {
            for k in 0..3 {
                w[v][k] -= alpha * q[v][k] + beta_previous * q_previous[v][k];
            }
        }
        alphas.push(alpha);
        let theta = tridiagonal_max(&alphas, &betas);
        ritz.push(theta);
        let beta = dot(&w, &w).sqrt();
        let settled = ritz.len() > LANCZOS_WINDOW
            && theta - ritz[ritz.len() - 1 - LANCZOS_WINDOW] <= LANCZOS_TOLERANCE * theta;
        if settled || !beta.is_finite() || beta <= 1e-12 * theta.abs() {
            break;
        }
        betas.push(beta);
        beta_previous = beta;
        core::mem::swap(&mut q_previous, &mut q);
        for v in 0..n {
            q[v] = w[v].map(|c| c / beta);
        }
    }
    ritz.last().copied().unwrap_or(0.0).max(0.0).sqrt()
}

/// Largest eigenvalue of the symmetric tridiagonal matrix with diagonal
/// `alphas` and off-diagonal `betas` (one fewer), by bisection on the Sturm
/// count (the number of negative pivots of `T − x I`) inside the
/// Gershgorin bounds.
fn tridiagonal_max(alphas: &[f64], betas: &[f64]) -> f64 {
    let off = |i: usize| betas.get(i).copied().unwrap_or(0.0).abs();
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (i, &a) in alphas.iter().enumerate() {
        let radius = off(i) + if i > 0 { off(i - 1) } else { 0.0 };
        lo = lo.min(a - radius);
        hi = hi.max(a + radius);
    }
    // Eigenvalues below x.
    let below = |x: f64| {
        let mut count = 0;
        let mut d = 1.0;
        for (i, &a) in alphas.iter().enumerate() {
            let coupling = match i.checked_sub(1) {
                Some(j) => betas[j] * betas[j] / d,
                None => 0.0,
            };
            d = a - x - coupling;
            if d == 0.0 {
                d = -f64::EPSILON * (x.abs() + a.abs()).max(f64::MIN_POSITIVE);
            }
            if d < 0.0 {
                count += 1;
            }
        }
        count
    };
    let n = alphas.len();
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if below(mid) < n {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}
