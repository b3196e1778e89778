//! The stability maps: for St Venant-Kirchhoff, the co-rotational and the
//! neo-Hookean tensor-mass laws and for the hybrid ([`MAP_MODELS`]) and each
//! integrator, a grid of time step × Young's modulus on the coarsest body,
//! each cell a loaded run of the model's law from rest (the hybrid's: St
//! Venant-Kirchhoff on its tensor-mass region) classified by its outcome, beside the measured critical step ([`critical_dt`],
//! bisection on the linear law; the hybrid's region's) and `2/ω_max`.
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
use palpate_kernel::tensor_mass::{DynamicParams, ElasticLaw, Integrator, TensorMassModel};
use serde::Serialize;

use super::body::{Body, Load, tip_m};
use super::model::{HYBRID_LAW, Model};
use super::progress::Progress;
use super::tables::{hybrid_field, hybrid_tables, region_loads, set_loads};
use crate::dispatch::HostDispatch;
use crate::fem::material::{Material, TetMaterials};
use crate::fem::static_solve::solve_loaded;
use crate::hybrid::owned::with_hybrid;
use crate::table::file::Precision;
use crate::table::tensor_mass::static_study_table;
use crate::tensor_mass::OwnedState;
use crate::tensor_mass::run::diagonal;
use crate::tensor_mass::stability::{critical_dt, omega_max};
use palpate_kernel::hybrid::HybridModel;
use palpate_kernel::tensor_mass::StepError;

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
    /// The model: St Venant-Kirchhoff or the hybrid.
    pub model: Model,
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

/// The models mapped: St Venant-Kirchhoff, co-rotational and neo-Hookean
/// on the whole mesh, and the hybrid (St Venant-Kirchhoff on its region,
/// [`Model::Hybrid`]).
pub const MAP_MODELS: [Model; 4] = [
    Model::Stvk,
    Model::Corotational,
    Model::NeoHookean,
    Model::Hybrid,
];

/// Maps of one body: one per model of [`MAP_MODELS`] and integrator.
pub fn map_count() -> usize {
    MAP_MODELS.len() * Integrator::ALL.len()
}

/// Every model's and integrator's map on `body`. The hybrid's critical
/// step and `ω_max` are its tensor-mass region's (the only stepped part;
/// the condensed region's force is in each of its force evaluations).
pub fn maps(
    body: &Body,
    extent: &MapExtent,
    progress: &mut dyn Progress,
) -> anyhow::Result<Vec<Map>> {
    let reference = body.material;
    let mut maps = Vec::new();
    for model in MAP_MODELS {
        for integrator in Integrator::ALL {
            // The measured critical step on the linear law at the tissue's E.
            let params =
                DynamicParams::linear(DAMPING_PER_S, 10.0 * diagonal(&body.mesh.positions))
                    .with_law(ElasticLaw::Linear);
            let (omega, critical) =
                with_system(body, model, reference, params, &[], |system, _| {
                    let region = system.region();
                    let amplitude = 1e-3 * diagonal(&body.mesh.positions);
                    let c = critical_dt(region, integrator, amplitude);
                    Ok((omega_max(region), c.critical_dt))
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
                    let outcome = trial(body, model, material, integrator, dt_s)?;
                    progress.tick(&format!(
                        "stability {} {} E = {young_pa} Pa, dt = {dt_s:.2e} s: {outcome:?}",
                        model.name(),
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
                model,
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
    }
    Ok(maps)
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

/// A stepped model of the maps and trajectories: a tensor-mass model, or
/// the hybrid (its tensor-mass region stepped, the condensed region's
/// force in every force evaluation).
pub(crate) trait System<'a, 's> {
    /// One step of `integrator` at `dt_s`.
    fn advance(&mut self, integrator: Integrator, dt_s: f64) -> Result<(), StepError>;
    /// The same with the host's CPU-feature dispatch where the model has
    /// one (the tensor-mass step; the hybrid's step has none), to be timed.
    fn advance_dispatched(
        &mut self,
        dispatch: HostDispatch,
        integrator: Integrator,
        dt_s: f64,
    ) -> Result<(), StepError>;
    /// Back to rest (both regions of the hybrid).
    fn reset(&mut self);
    /// The stepped tensor-mass model (the hybrid's region).
    fn region(&mut self) -> &mut TensorMassModel<'a, 's, f64>;
    /// The displacement field of the whole mesh (`n` vertices), m.
    fn field(&mut self, n: usize) -> anyhow::Result<Vec<[f64; 3]>>;
}

impl<'a, 's> System<'a, 's> for TensorMassModel<'a, 's, f64> {
    fn advance(&mut self, integrator: Integrator, dt_s: f64) -> Result<(), StepError> {
        self.step(integrator, dt_s).map(|_| ())
    }
    fn advance_dispatched(
        &mut self,
        dispatch: HostDispatch,
        integrator: Integrator,
        dt_s: f64,
    ) -> Result<(), StepError> {
        self.step_with(dispatch, integrator, dt_s).map(|_| ())
    }
    fn reset(&mut self) {
        TensorMassModel::reset(self);
    }
    fn region(&mut self) -> &mut TensorMassModel<'a, 's, f64> {
        self
    }
    fn field(&mut self, _: usize) -> anyhow::Result<Vec<[f64; 3]>> {
        Ok(self
            .displacements_m()
            .map_err(|e| anyhow::anyhow!("no displacements: {e}"))?
            .to_vec())
    }
}

impl<'a, 's> System<'a, 's> for HybridModel<'a, 's, f64> {
    fn advance(&mut self, integrator: Integrator, dt_s: f64) -> Result<(), StepError> {
        self.step(integrator, dt_s).map(|_| ())
    }
    fn advance_dispatched(
        &mut self,
        _: HostDispatch,
        integrator: Integrator,
        dt_s: f64,
    ) -> Result<(), StepError> {
        self.advance(integrator, dt_s)
    }
    fn reset(&mut self) {
        HybridModel::reset(self);
    }
    fn region(&mut self) -> &mut TensorMassModel<'a, 's, f64> {
        self.dynamic_mut()
    }
    fn field(&mut self, n: usize) -> anyhow::Result<Vec<[f64; 3]>> {
        hybrid_field(self, n)
    }
}

/// Builds `model` of `body` (a tensor-mass model, or [`Model::Hybrid`]:
/// its tables with `material`, [`hybrid_tables`]) with `material`
/// and `params`, sets the nodal `loads` (on the hybrid's region, in its
/// numbering), and runs `f` on it with the loads as set.
pub(crate) fn with_system<R>(
    body: &Body,
    model: Model,
    material: Material,
    params: DynamicParams<f64>,
    loads: &[[f64; 3]],
    f: impl FnOnce(&mut dyn System<'_, '_>, &[[f64; 3]]) -> anyhow::Result<R>,
) -> anyhow::Result<R> {
    if model == Model::Hybrid {
        let tables = hybrid_tables(body, material, Precision::F64)?;
        let local = region_loads(&tables, loads)?;
        with_hybrid(&tables, params, |h| {
            set_loads(h.dynamic_mut(), &local)?;
            f(h, &local)
        })?
    } else {
        with_params(body, material, params, |m| {
            set_loads(m, loads)?;
            f(m, loads)
        })
    }
}

/// One trial of `model` (module documentation), with its law. The hybrid's energy is
/// its tensor-mass region's (kinetic, elastic, the load's work): the
/// condensed region's linear strain energy, never negative, is left out.
fn trial(
    body: &Body,
    model: Model,
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
    let scale = 0.05 * body.length_m / tip_m(&unit, &u_unit);
    let loads: Vec<[f64; 3]> = unit.iter().map(|f| f.map(|x| x * scale)).collect();
    let work: f64 = loads
        .iter()
        .zip(&u_unit)
        .map(|(f, u)| scale * Vector3::from(*f).dot(&Vector3::from(*u)))
        .sum();
    // The model's law; the hybrid's region St Venant-Kirchhoff.
    let law = model.tensor_mass(body).map_or(HYBRID_LAW, |(law, _)| law);
    let params =
        DynamicParams::linear(DAMPING_PER_S, 10.0 * diagonal(&body.mesh.positions)).with_law(law);
    with_system(body, model, material, params, &loads, |system, loads| {
        let mut scratch = vec![[0.0; 3]; loads.len()];
        let mut grew = false;
        for step in 0..TRIAL_STEPS {
            if system.advance(integrator, dt_s).is_err() {
                return Ok(Outcome::Diverged);
            }
            if step % 10 == 9 && !grew {
                let region = system.region();
                let (Ok(u), Ok(v)) = (region.displacements_m(), region.velocities_m_s()) else {
                    return Ok(Outcome::Diverged);
                };
                let kinetic: f64 = v
                    .iter()
                    .zip(region.masses_kg())
                    .map(|(v, m)| 0.5 * m * Vector3::from(*v).norm_squared())
                    .sum();
                let external: f64 = loads
                    .iter()
                    .zip(u)
                    .map(|(f, u)| Vector3::from(*f).dot(&Vector3::from(*u)))
                    .sum();
                let energy = kinetic + region.elastic_energy_of(u, &mut scratch) - external;
                grew = energy.is_nan() || energy > ENERGY_GROWTH * work;
            }
        }
        let Ok(u) = system.field(body.mesh.positions.len()) else {
            return Ok(Outcome::Diverged);
        };
        Ok(
            if crate::experiment::volume_bend::inverted_tets(&body.mesh, &u) > 0 {
                Outcome::Inverted
            } else if grew {
                Outcome::EnergyGrowth
            } else {
                Outcome::Stable
            },
        )
    })
}
