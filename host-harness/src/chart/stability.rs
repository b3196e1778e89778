//! The stability maps: for each integrator, a grid of time step × Young's
//! modulus on the coarsest body, each cell a loaded St Venant-Kirchhoff
//! run from rest classified by its outcome, beside the measured critical
//! step ([`critical_dt`], bisection on the linear model) and `2/ω_max`.
//!
//! A trial: the bend load at 5 % of the height (scaled with E, so the same
//! strain at every E) applied at rest, [`TRIAL_STEPS`] steps with damping
//! [`DAMPING_PER_S`]. Outcome, first that applies: **diverged** (a step
//! faulted), **inverted** (tets inverted at the end), **energy growth** (the
//! total energy `K + W_el − f·u`, zero at the start and non-increasing for
//! the damped motion, exceeded [`ENERGY_GROWTH`] times the work `f·u_lin`
//! of the load on the linear equilibrium), **stable**.

use anyhow::Context;
use nalgebra::Vector3;
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::tensor_mass::{
    DynamicParams, ElasticLaw, Integrator, StvkForm, TensorMassModel,
};
use serde::Serialize;

use super::{Body, Load, Progress};
use crate::fem::material::{Material, TetMaterials};
use crate::fem::static_solve::solve_loaded;
use crate::table::tensor_mass::static_study_table;
use crate::tensor_mass::OwnedState;
use crate::tensor_mass::run::diagonal;
use crate::tensor_mass::stability::{critical_dt, omega_max};

/// Steps of one trial.
pub const TRIAL_STEPS: usize = 1000;
/// Mass-proportional damping of the trials, 1/s.
pub const DAMPING_PER_S: f64 = 5.0;
/// Energy-growth threshold over the load's work on the linear equilibrium.
pub const ENERGY_GROWTH: f64 = 10.0;

/// The grid of a map.
#[derive(Clone, Debug)]
pub struct MapExtent {
    /// Young's moduli, Pa.
    pub young_pa: Vec<f64>,
    /// Time steps as multiples of `2/ω_max` at the tissue's E (5 kPa).
    pub dt_factors: Vec<f64>,
}

impl MapExtent {
    /// 4 moduli × 9 steps.
    pub fn full() -> Self {
        Self {
            young_pa: vec![1250.0, 5000.0, 20_000.0, 80_000.0],
            dt_factors: (-4..=4).map(|k| 2f64.powf(f64::from(k) / 2.0)).collect(),
        }
    }

    /// 3 moduli × 5 steps.
    pub fn quick() -> Self {
        Self {
            young_pa: vec![1250.0, 5000.0, 20_000.0],
            dt_factors: (-2..=2).map(|k| 2f64.powf(f64::from(k) / 2.0)).collect(),
        }
    }

    /// Trials of one map.
    pub fn trials(&self) -> usize {
        self.young_pa.len() * self.dt_factors.len()
    }
}

/// How a trial ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Outcome {
    /// Ran without any of the failures below.
    Stable,
    /// A step faulted (displacement bound or non-finite state).
    Diverged,
    /// Tets inverted at the end.
    Inverted,
    /// The total energy grew past the threshold.
    EnergyGrowth,
}

/// One trial.
#[derive(Clone, Debug, Serialize)]
pub struct Cell {
    /// Young's modulus, Pa.
    pub young_pa: f64,
    /// Time step, s.
    pub dt_s: f64,
    /// Outcome.
    pub outcome: Outcome,
}

/// One integrator's map.
#[derive(Clone, Debug, Serialize)]
pub struct Map {
    /// Integrator name.
    pub integrator: &'static str,
    /// The mesh, `"RxH"`.
    pub mesh: String,
    /// Damping, 1/s.
    pub damping_per_s: f64,
    /// E at which the critical step was measured, Pa.
    pub reference_young_pa: f64,
    /// `ω_max` there, rad/s.
    pub omega_max: f64,
    /// Measured critical step there (bisection, linear model), s; it scales
    /// as `1/√E` (ω ∝ √E for a linear model).
    pub critical_dt_s: f64,
    /// `2/ω_max` there, s.
    pub two_over_omega_s: f64,
    /// The trials.
    pub cells: Vec<Cell>,
}

/// Every integrator's map on `body`.
pub fn maps(
    body: &Body,
    extent: &MapExtent,
    progress: &mut dyn Progress,
) -> anyhow::Result<Vec<Map>> {
    let reference = body.material;
    let mut maps = Vec::new();
    for integrator in Integrator::ALL {
        // The measured critical step on the linear model at the tissue's E.
        let (omega, critical) = with_model(body, reference, ElasticLaw::Linear, |model| {
            let amplitude = 1e-3 * diagonal(&body.mesh.positions);
            let c = critical_dt(model, integrator, amplitude);
            Ok((omega_max(model), c.critical_dt))
        })?;
        let two_over_omega = 2.0 / omega;
        let mut cells = Vec::new();
        for &young_pa in &extent.young_pa {
            let material = Material {
                young_pa,
                ..reference
            };
            for &factor in &extent.dt_factors {
                let dt_s = factor * two_over_omega;
                let outcome = trial(body, material, integrator, dt_s)?;
                progress.tick(&format!(
                    "stability {} E = {young_pa} Pa, dt = {dt_s:.2e} s: {outcome:?}",
                    integrator.name()
                ));
                cells.push(Cell {
                    young_pa,
                    dt_s,
                    outcome,
                });
            }
        }
        maps.push(Map {
            integrator: integrator.name(),
            mesh: body.label.clone(),
            damping_per_s: DAMPING_PER_S,
            reference_young_pa: reference.young_pa,
            omega_max: omega,
            critical_dt_s: critical,
            two_over_omega_s: two_over_omega,
            cells,
        });
    }
    Ok(maps)
}

/// Builds the f64 model of `body` with `material` and `law`, damping
/// [`DAMPING_PER_S`], and runs `f`.
fn with_model<R>(
    body: &Body,
    material: Material,
    law: ElasticLaw,
    f: impl FnOnce(&mut TensorMassModel<'_, '_, f64>) -> anyhow::Result<R>,
) -> anyhow::Result<R> {
    let params =
        DynamicParams::linear(DAMPING_PER_S, 10.0 * diagonal(&body.mesh.positions)).with_law(law);
    with_params(body, material, params, f)
}

/// Builds the f64 model of `body` with `material` and `params` and runs `f`.
pub(super) fn with_params<R>(
    body: &Body,
    material: Material,
    params: DynamicParams<f64>,
    f: impl FnOnce(&mut TensorMassModel<'_, '_, f64>) -> anyhow::Result<R>,
) -> anyhow::Result<R> {
    let materials = TetMaterials::uniform(material, body.mesh.tets.len());
    let file = static_study_table(&body.mesh, &materials, body.fixed.clone());
    let table = TensorMassTable::<f64>::load(file.bytes()).context("tensor-mass table")?;
    let mut state = OwnedState::for_table(&table);
    let mut model = TensorMassModel::new(table, state.buffers(), params)?;
    f(&mut model)
}

/// One trial (module documentation).
fn trial(
    body: &Body,
    material: Material,
    integrator: Integrator,
    dt_s: f64,
) -> anyhow::Result<Outcome> {
    let materials = TetMaterials::uniform(material, body.mesh.tets.len());
    let unit = body.loads(Load::Bend, 1.0);
    let (u_unit, _) = solve_loaded(
        &body.mesh.positions,
        &body.mesh.tets,
        &materials,
        &body.fixed,
        &[],
        &unit,
    )?;
    let scale = 0.05 * super::HEIGHT_M / super::tip_m(&unit, &u_unit);
    let loads: Vec<[f64; 3]> = unit.iter().map(|f| f.map(|x| x * scale)).collect();
    let work: f64 = loads
        .iter()
        .zip(&u_unit)
        .map(|(f, u)| scale * Vector3::from(*f).dot(&Vector3::from(*u)))
        .sum();
    let law = ElasticLaw::StVenantKirchhoff(StvkForm::PerTet);
    with_model(body, material, law, |model| {
        for (v, f) in loads.iter().enumerate() {
            if f.iter().any(|&x| x != 0.0) {
                model.set_external_force(v as u32, Vector3::from(*f))?;
            }
        }
        let n = loads.len();
        let mut scratch = vec![[0.0; 3]; n];
        let mut grew = false;
        for step in 0..TRIAL_STEPS {
            if model.step(integrator, dt_s).is_err() {
                return Ok(Outcome::Diverged);
            }
            if step % 10 == 9 && !grew {
                let (Ok(u), Ok(v)) = (model.displacements_m(), model.velocities_m_s()) else {
                    return Ok(Outcome::Diverged);
                };
                let kinetic: f64 = v
                    .iter()
                    .zip(model.masses_kg())
                    .map(|(v, m)| 0.5 * m * Vector3::from(*v).norm_squared())
                    .sum();
                let external: f64 = loads
                    .iter()
                    .zip(u)
                    .map(|(f, u)| Vector3::from(*f).dot(&Vector3::from(*u)))
                    .sum();
                let energy = kinetic + model.elastic_energy_of(u, &mut scratch) - external;
                grew = energy.is_nan() || energy > ENERGY_GROWTH * work;
            }
        }
        let Ok(u) = model.displacements_m() else {
            return Ok(Outcome::Diverged);
        };
        Ok(
            if crate::experiment::volume_bend::inverted_tets(&body.mesh, u) > 0 {
                Outcome::Inverted
            } else if grew {
                Outcome::EnergyGrowth
            } else {
                Outcome::Stable
            },
        )
    })
}
