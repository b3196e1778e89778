//! The stepped models' static runs: the tensor-mass models and the hybrid
//! relaxed to rest, and their time per step.

use anyhow::Context;
use nalgebra::Vector3;
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::tensor_mass::{DynamicParams, ElasticLaw, Integrator, TensorMassModel};

use super::body::Body;
use super::measure::{Outcome, median_s};
use super::model::HYBRID_LAW;
use super::tables::{DENSITY_KG_M3, hybrid_field, hybrid_tables, region_loads, set_loads};
use crate::dispatch::HostDispatch;
use crate::experiment::relax::relax;
use crate::hybrid::owned::with_hybrid;
use crate::table::file::Precision;
use crate::table::tensor_mass::{TensorMassArrays, static_study_table, write_tensor_mass_table};
use crate::tensor_mass::OwnedState;
use crate::tensor_mass::run::diagonal;
use crate::tensor_mass::stability::omega_max;

/// Relaxation tolerance: largest residual force over the largest load on
/// a vertex. At 1e-3 the St Venant-Kirchhoff tip under the 20 % twist on
/// 3×15 was 7e-4 (relative) from its converged value, a bias visible at
/// the 1 % bound; at 1e-5 it is within 1e-5 of it (measured against a
/// relaxation to 1e-7).
pub const RELAX_TOLERANCE: f64 = 1e-5;

/// A tensor-mass model of `body` under the nodal `loads`, relaxed to rest
/// (symplectic Euler at `0.5/ω_max` with kinetic damping,
/// [`relax`]); time per step measured in f64 at the equilibrium and in f32
/// from rest, with the host's CPU-feature dispatch ([`HostDispatch`], as
/// `dynamic run` steps).
pub(super) fn dynamic(
    body: &Body,
    loads: &[[f64; 3]],
    law: ElasticLaw,
    incompressibility_n: Option<f64>,
    max_steps: usize,
) -> anyhow::Result<Outcome> {
    let n = body.mesh.positions.len();
    let file = static_study_table(&body.mesh, &body.materials(), body.fixed.clone());
    let table = TensorMassTable::<f64>::load(file.bytes()).context("tensor-mass table")?;
    let mut state = OwnedState::for_table(&table);
    let bound = 100.0 * diagonal(&body.mesh.positions);
    let params = DynamicParams::linear(0.0, bound)
        .with_law(law)
        .with_incompressibility(incompressibility_n);
    let mut model = TensorMassModel::new(table, state.buffers(), params)?;
    let dt_s = 0.5 / omega_max(&mut model);
    model.reset();
    set_loads(&mut model, loads)?;
    let largest = loads
        .iter()
        .map(|f| Vector3::from(*f).norm())
        .fold(0.0, f64::max);
    let mut u = vec![[0.0; 3]; n];
    let (fault, steps) = relax_outcome(relax(
        &mut model,
        loads,
        dt_s,
        RELAX_TOLERANCE * largest,
        max_steps,
        &mut u,
    ));
    // Time per step: the law's step from the state reached (reset if it
    // faulted, so the step runs).
    if model.fault().is_some() {
        model.reset();
    }
    let dispatch = HostDispatch::detect();
    let step_s = median_s(|| {
        let _ = core::hint::black_box(model.step_with(dispatch, Integrator::SymplecticEuler, dt_s));
    });
    let step_f32_s = dynamic_f32_step(body, loads, law, incompressibility_n, dt_s)?;
    Ok(Outcome {
        u,
        fault,
        step_s,
        step_f32_s: Some(step_f32_s),
        steps,
    })
}

/// The hybrid of `body` ([`Model::Hybrid`]) under the nodal `loads` (all
/// on its tensor-mass region), relaxed to rest as [`dynamic`] relaxes the
/// tensor-mass models (the condensed region's force is part of every force
/// evaluation, so the residual is the whole body's); time per step of the
/// coupled step in f64 at the equilibrium and in f32 from rest.
pub(super) fn hybrid(body: &Body, loads: &[[f64; 3]], max_steps: usize) -> anyhow::Result<Outcome> {
    let n = body.mesh.positions.len();
    // A mesh whose loaded end is all of it (or none) has no hybrid: a
    // fault of the run, not of the study.
    let tables = match hybrid_tables(body, body.material, Precision::F64) {
        Ok(tables) => tables,
        Err(e) => {
            return Ok(Outcome {
                u: vec![[0.0; 3]; n],
                fault: Some(format!("no hybrid of this mesh: {e:#}")),
                step_s: f64::NAN,
                step_f32_s: None,
                steps: 0,
            });
        }
    };
    let local = region_loads(&tables, loads)?;
    let largest = loads
        .iter()
        .map(|f| Vector3::from(*f).norm())
        .fold(0.0, f64::max);
    let bound = 100.0 * diagonal(&body.mesh.positions);
    let params = DynamicParams::linear(0.0, bound).with_law(HYBRID_LAW);
    let (u, fault, steps, step_s, dt_s) = with_hybrid(&tables, params, |h| {
        let dt_s = 0.5 / omega_max(h.dynamic_mut());
        h.reset();
        set_loads(h.dynamic_mut(), &local)?;
        let mut last = vec![[0.0; 3]; local.len()];
        let relaxed = relax(
            h.dynamic_mut(),
            &local,
            dt_s,
            RELAX_TOLERANCE * largest,
            max_steps,
            &mut last,
        );
        let (fault, steps) = relax_outcome(relaxed);
        let u = match fault {
            None => hybrid_field(h, n)?,
            Some(_) => vec![[0.0; 3]; n],
        };
        if h.dynamic().fault().is_some() {
            h.reset();
        }
        let step_s = median_s(|| {
            let _ = core::hint::black_box(h.step(Integrator::SymplecticEuler, dt_s));
        });
        anyhow::Ok((u, fault, steps, step_s, dt_s))
    })??;
    let tables32 = hybrid_tables(body, body.material, Precision::F32)?;
    let params32 = DynamicParams::linear(0.0f32, bound as f32).with_law(HYBRID_LAW);
    let step_f32_s = with_hybrid(&tables32, params32, |h| {
        set_loads(h.dynamic_mut(), &local)?;
        anyhow::Ok(median_s(|| {
            if h.dynamic().fault().is_some() {
                h.reset();
            }
            let _ = core::hint::black_box(h.step(Integrator::SymplecticEuler, dt_s as f32));
        }))
    })??;
    Ok(Outcome {
        u,
        fault,
        step_s,
        step_f32_s: Some(step_f32_s),
        steps,
    })
}

/// The fault (`None` when settled) and the steps of a relaxation.
fn relax_outcome(
    relaxed: Result<crate::experiment::relax::Relaxation, palpate_kernel::tensor_mass::StepError>,
) -> (Option<String>, usize) {
    match relaxed {
        Ok(r) if r.converged => (None, r.steps),
        Ok(r) => (
            Some(format!(
                "not settled in {} steps (residual {:.2e} N)",
                r.steps, r.residual_n
            )),
            r.steps,
        ),
        Err(e) => (Some(format!("diverged: {e}")), 0),
    }
}

/// Median time of one f32 symplectic-Euler step of the same model, s.
fn dynamic_f32_step(
    body: &Body,
    loads: &[[f64; 3]],
    law: ElasticLaw,
    incompressibility_n: Option<f64>,
    dt_s: f64,
) -> anyhow::Result<f64> {
    let arrays = TensorMassArrays::new(
        &body.mesh,
        &body.materials(),
        DENSITY_KG_M3,
        body.fixed.clone(),
    );
    let bytes = write_tensor_mass_table(
        &body.mesh,
        &crate::mesh::boundary_surface(&body.mesh).triangles,
        &arrays,
        Precision::F32,
    );
    let file = crate::table::load::TableFile::from_bytes(&bytes);
    let table = TensorMassTable::<f32>::load(file.bytes()).context("f32 tensor-mass table")?;
    let mut state = OwnedState::for_table(&table);
    let bound = 100.0 * diagonal(&body.mesh.positions);
    let params = DynamicParams::linear(0.0f32, bound as f32)
        .with_law(law)
        .with_incompressibility(incompressibility_n.map(|g| g as f32));
    let mut model = TensorMassModel::new(table, state.buffers(), params)?;
    set_loads(&mut model, loads)?;
    let dt = dt_s as f32;
    let dispatch = HostDispatch::detect();
    Ok(median_s(|| {
        if model.fault().is_some() {
            model.reset();
        }
        let _ = core::hint::black_box(model.step_with(dispatch, Integrator::SymplecticEuler, dt));
    }))
}
