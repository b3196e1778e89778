//! `palpate experiment volume-bend`: Picinbono 2001 table 2. A body fixed on
//! part of its boundary is loaded by a constant force in stages; at each
//! stage the static equilibria of the linear, St Venant-Kirchhoff and St
//! Venant-Kirchhoff + incompressibility models (the paper's three), and of
//! the co-rotational and neo-Hookean tensor-mass laws, are found by dynamic
//! relaxation ([`super::relax`]) under the same force, and their relative
//! volume changes compared.
//!
//! Two protocols define the stages ([`Protocol`]):
//! - **the paper's loads** ([`Protocol::PaperLoads`]): forces `F`, `2F`,
//!   `3F` (the multiples of [`Scene::paper_loads`]), with `F` the force that
//!   gives the linear model the paper's first-stage volume change (7 % on the
//!   cylinder). Picinbono's table gives the linear model 7 / 28 / 63 %, that
//!   is 7 × 1², 2², 3²: its loads were in ratio 1 : 2 : 3.
//! - **tilts** ([`Protocol::Tilt`]): a stage is defined on the full
//!   non-linear model, St Venant-Kirchhoff + incompressibility: the force is
//!   found (secant iterations) that brings its [`Scene::measure`] to the
//!   stage's target (the cylinder's top-face tilt).
//!
//! Either way the stage's force is then applied to all five models. Plain St Venant-Kirchhoff
//! is not used to define stages because it collapses: under strong
//! compression (stretch below `1/√3`) its stress softens and tets invert
//! (Picinbono 2001 §3.2, the reason for the penalty); such an equilibrium
//! is reported with its inverted-tet count, a diverged one as a fault.

use anyhow::{Context, bail};
use nalgebra::Vector3;
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::tensor_mass::{DynamicParams, ElasticLaw, StvkForm, TensorMassModel};
use serde::Serialize;

use super::relax::{Relaxation, relax};
use crate::fem::material::{Material, TetMaterials};
use crate::mesh::TetMesh;
use crate::table::tensor_mass::static_study_table;
use crate::tensor_mass::OwnedState;
use crate::tensor_mass::run::{diagonal, volume_change};
use crate::tensor_mass::stability::omega_max;

/// What a stage's target is measured on: a scalar of the deformed body.
pub type Measure = Box<dyn Fn(&TetMesh, &[[f64; 3]]) -> f64>;

/// A loaded body.
pub struct Scene {
    /// Short name (JSON key).
    pub name: &'static str,
    /// The rest mesh, m.
    pub mesh: TetMesh,
    /// Fixed vertices.
    pub fixed: Vec<bool>,
    /// Vertices sharing the load equally.
    pub loaded: Vec<u32>,
    /// Unit direction of the load.
    pub direction: Vector3<f64>,
    /// Young's modulus and Poisson ratio.
    pub material: Material,
    /// Incompressibility penalty γ of the third model, N.
    pub incompressibility_n: f64,
    /// What the stage targets are measured on, and its unit.
    pub measure: Measure,
    /// Name and unit of the measure (for the table).
    pub measure_name: &'static str,
    /// Stage targets of the measure, on the St Venant-Kirchhoff +
    /// incompressibility model ([`Protocol::Tilt`]).
    pub targets: Vec<f64>,
    /// The paper's loads ([`Protocol::PaperLoads`]).
    pub paper_loads: PaperLoads,
}

/// Picinbono 2001 table 2's loading: multiples of a force `F` defined by
/// the linear model's relative volume change at `F`.
#[derive(Clone, Debug)]
pub struct PaperLoads {
    /// `(V − V₀)/V₀` of the linear model at `F` (the paper's first stage:
    /// 0.07 for the cylinder, 0.09 for the organ).
    pub first_volume_change: f64,
    /// The stages' forces in units of `F` (1, 2, 3 for the cylinder).
    pub multiples: Vec<f64>,
}

/// How the stages' forces are chosen.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Protocol {
    /// Forces `k F` ([`PaperLoads`]); a stage's `target` is `k`.
    PaperLoads,
    /// Forces bringing the penalized model to [`Scene::targets`]; a
    /// stage's `target` is the measure's.
    Tilt,
}

/// One model's equilibrium at a stage.
#[derive(Clone, Debug, Serialize)]
pub struct Equilibrium {
    /// `null`, or why the relaxation diverged (the other fields are then
    /// those of the last state before the fault: not an equilibrium).
    pub fault: Option<String>,
    /// Tets whose deformed volume is negative (inverted).
    pub inverted_tets: usize,
    /// `(V − V₀)/V₀` of the whole body.
    pub volume_change: f64,
    /// The scene's measure at this equilibrium.
    pub measure: f64,
    /// Relaxation steps.
    pub steps: usize,
    /// Largest residual force on a free vertex at the end, N.
    pub residual_n: f64,
}

/// One stage: the force and the five equilibria.
#[derive(Clone, Debug, Serialize)]
pub struct Stage {
    /// [`Protocol::Tilt`]: target of the measure on the penalized St
    /// Venant-Kirchhoff model; [`Protocol::PaperLoads`]: the force in units
    /// of `F`.
    pub target: f64,
    /// Total applied force, N.
    pub force_n: f64,
    /// Linear tensor-mass model.
    pub linear: Equilibrium,
    /// St Venant-Kirchhoff.
    pub stvk: Equilibrium,
    /// St Venant-Kirchhoff with the incompressibility penalty.
    pub stvk_incompressible: Equilibrium,
    /// Co-rotational linear elasticity (not in the paper).
    pub corotational: Equilibrium,
    /// Compressible neo-Hookean (not in the paper).
    pub neo_hookean: Equilibrium,
}

/// A scene's results.
#[derive(Clone, Debug, Serialize)]
pub struct SceneResult {
    /// Scene name.
    pub name: &'static str,
    /// Vertices and tets of the mesh.
    pub vertices: usize,
    /// Tets.
    pub tets: usize,
    /// Lamé λ and μ, Pa.
    pub lame_pa: (f64, f64),
    /// γ of the incompressible model, N.
    pub incompressibility_n: f64,
    /// Name and unit of the stage measure.
    pub measure: &'static str,
    /// How the stages' forces were chosen.
    pub protocol: Protocol,
    /// The stages.
    pub stages: Vec<Stage>,
}

/// Relaxation controls.
#[derive(Clone, Copy, Debug)]
pub struct Controls {
    /// Residual tolerance as a fraction of the load on one loaded vertex.
    pub residual_fraction: f64,
    /// Step limit per relaxation.
    pub max_steps: usize,
    /// Tolerance of the stage search on the measure (measure units).
    pub target_tolerance: f64,
    /// Secant iterations per stage at most.
    pub max_iterations: usize,
}

impl Default for Controls {
    fn default() -> Self {
        Self {
            residual_fraction: 1e-3,
            max_steps: 400_000,
            target_tolerance: 0.25,
            max_iterations: 12,
        }
    }
}

/// A model of the scene with its own state, loaded by a total force.
struct Body<'a> {
    model: TensorMassModel<'a, 'a, f64>,
    loads: Vec<[f64; 3]>,
    dt_s: f64,
    /// Displacements at the last step before a fault, m.
    last: Vec<[f64; 3]>,
}

impl Body<'_> {
    /// Applies the total force `force_n` and relaxes to equilibrium.
    fn relax(
        &mut self,
        scene: &Scene,
        force_n: f64,
        controls: &Controls,
    ) -> anyhow::Result<(Relaxation, Vec<[f64; 3]>)> {
        let share = scene.direction * (force_n / scene.loaded.len() as f64);
        for &v in &scene.loaded {
            self.model.set_external_force(v, share)?;
            self.loads[v as usize] = share.into();
        }
        let tolerance = controls.residual_fraction * share.norm();
        let relaxation = relax(
            &mut self.model,
            &self.loads,
            self.dt_s,
            tolerance,
            controls.max_steps,
            &mut self.last,
        )
        .map_err(|e| anyhow::anyhow!("{}: relaxation at {force_n:.4e} N: {e}", scene.name))?;
        Ok((relaxation, self.last.clone()))
    }

    /// The equilibrium under `force_n`, or the state the relaxation faulted
    /// in (then the model is reset, so the next stage starts from rest).
    fn equilibrium(
        &mut self,
        scene: &Scene,
        force_n: f64,
        controls: &Controls,
    ) -> anyhow::Result<Equilibrium> {
        let (fault, steps, residual_n, u) = match self.relax(scene, force_n, controls) {
            Ok((relaxation, u)) => (None, relaxation.steps, relaxation.residual_n, u),
            Err(e) => {
                let u = self.last.clone();
                self.model.reset();
                self.loads.fill([0.0; 3]);
                (Some(format!("{e:#}")), 0, f64::NAN, u)
            }
        };
        let alive = vec![true; scene.mesh.tets.len()];
        Ok(Equilibrium {
            fault,
            inverted_tets: inverted_tets(&scene.mesh, &u),
            volume_change: volume_change(&scene.mesh, &u, &alive),
            measure: (scene.measure)(&scene.mesh, &u),
            steps,
            residual_n,
        })
    }
}

/// Tets of `mesh` with a negative volume when displaced by `u` (m).
pub fn inverted_tets(mesh: &TetMesh, u: &[[f64; 3]]) -> usize {
    let x = |v: u32| Vector3::from(mesh.positions[v as usize]) + Vector3::from(u[v as usize]);
    mesh.tets
        .iter()
        .filter(|&&[a, b, c, d]| (x(b) - x(a)).dot(&(x(c) - x(a)).cross(&(x(d) - x(a)))) < 0.0)
        .count()
}

/// The models of each stage, in the order of [`Stage`]'s equilibria: the
/// law and the incompressibility penalty (`true`: the scene's γ).
const MODELS: [(ElasticLaw, bool); 5] = [
    (ElasticLaw::Linear, false),
    (ElasticLaw::StVenantKirchhoff(StvkForm::PerTet), false),
    (ElasticLaw::StVenantKirchhoff(StvkForm::PerTet), true),
    (ElasticLaw::Corotational, false),
    (ElasticLaw::NeoHookean, false),
];

/// Relaxations [`run_scene`] runs at most (each of at most
/// `controls.max_steps` steps): under [`Protocol::PaperLoads`] the probe of
/// the unit force and five models per stage; under [`Protocol::Tilt`] per
/// stage the force search's two first evaluations and
/// `controls.max_iterations` secant ones, then five models.
pub fn relaxations_bound(scene: &Scene, protocol: Protocol, controls: &Controls) -> usize {
    let models = MODELS.len();
    match protocol {
        Protocol::PaperLoads => 1 + models * scene.paper_loads.multiples.len(),
        Protocol::Tilt => scene.targets.len() * (controls.max_iterations + 2 + models),
    }
}

/// Runs every stage of `scene` under `protocol`; `progress` receives one
/// line per relaxation.
pub fn run_scene(
    scene: &Scene,
    protocol: Protocol,
    controls: &Controls,
    mut progress: impl FnMut(&str),
) -> anyhow::Result<SceneResult> {
    // The fixed flags are the scene's own (no predicates): the arrays and
    // the writer of the table build, without its predicate stage.
    let materials = TetMaterials::uniform(scene.material, scene.mesh.tets.len());
    let file = static_study_table(&scene.mesh, &materials, scene.fixed.clone());
    let table = TensorMassTable::<f64>::load(file.bytes()).context("tensor-mass table")?;
    let n = scene.mesh.positions.len();

    let mut states: Vec<OwnedState<f64>> = MODELS
        .iter()
        .map(|_| OwnedState::for_table(&table))
        .collect();
    let mut bodies = Vec::new();
    let mut dt_s = 0.0;
    for ((law, penalized), state) in MODELS.into_iter().zip(states.iter_mut()) {
        let gamma = penalized.then_some(scene.incompressibility_n);
        // The linear model's equilibria at the later stages lie several body
        // sizes away (its large-rotation error is the point of the
        // experiment): only a displacement of 100 body sizes is divergence.
        let params = DynamicParams::linear(0.0, 100.0 * diagonal(&scene.mesh.positions))
            .with_law(law)
            .with_incompressibility(gamma);
        let mut model = TensorMassModel::new(table, state.buffers(), params)?;
        if dt_s == 0.0 {
            // A quarter of the linear stability limit 2/ω_max: zeroing the
            // (staggered) symplectic-Euler velocity at a kinetic-energy peak
            // can feed energy into the stiffest modes near the limit
            // (measured: diverges at ω_max·Δt = 1, converges at 0.5), and
            // the non-linear models stiffen under stretch.
            dt_s = 0.5 / omega_max(&mut model);
            model.reset();
        }
        bodies.push(Body {
            model,
            loads: vec![[0.0; 3]; n],
            dt_s,
            last: vec![[0.0; 3]; n],
        });
    }
    let [linear, stvk, incompressible, corotational, neo_hookean] = &mut bodies[..] else {
        bail!("five models expected");
    };

    let (targets, unit_force_n) = match protocol {
        Protocol::Tilt => (&scene.targets, 0.0),
        Protocol::PaperLoads => (
            &scene.paper_loads.multiples,
            paper_force(scene, linear, controls, &mut progress)?,
        ),
    };
    let mut stages = Vec::new();
    let mut force_n = 0.0;
    for &target in targets {
        force_n = match protocol {
            Protocol::Tilt => find_force(
                scene,
                incompressible,
                target,
                force_n,
                controls,
                &mut progress,
            )?,
            Protocol::PaperLoads => target * unit_force_n,
        };
        let mut solve = |body: &mut Body<'_>, name: &str| -> anyhow::Result<Equilibrium> {
            let e = body.equilibrium(scene, force_n, controls)?;
            progress(&format!(
                "{} stage {target}: {name} ΔV/V₀ = {:+.3} % ({} steps, {} inverted tets{})",
                scene.name,
                100.0 * e.volume_change,
                e.steps,
                e.inverted_tets,
                e.fault
                    .as_deref()
                    .map_or(String::new(), |f| format!(", fault: {f}"))
            ));
            Ok(e)
        };
        stages.push(Stage {
            target,
            force_n,
            stvk_incompressible: solve(incompressible, "stvk+incompressibility")?,
            linear: solve(linear, "linear")?,
            stvk: solve(stvk, "stvk")?,
            corotational: solve(corotational, "corotational")?,
            neo_hookean: solve(neo_hookean, "neo-hookean")?,
        });
    }
    Ok(SceneResult {
        name: scene.name,
        vertices: n,
        tets: scene.mesh.tets.len(),
        lame_pa: scene.material.lame(),
        incompressibility_n: scene.incompressibility_n,
        measure: scene.measure_name,
        protocol,
        stages,
    })
}

/// The paper's unit force `F` (N): the force under which the linear model's
/// `(V − V₀)/V₀` is [`PaperLoads::first_volume_change`]. The linear model's
/// equilibrium under `sP` is `s` times its equilibrium `u` under `P`, so one
/// relaxation at a probe force `P` and a bisection on `s` of the volume
/// change of `s u` (exact, no further relaxation) give `F = sP`.
fn paper_force(
    scene: &Scene,
    linear: &mut Body<'_>,
    controls: &Controls,
    progress: &mut impl FnMut(&str),
) -> anyhow::Result<f64> {
    let probe_n = 1e-3 * scene.material.young_pa * bounding_area(&scene.mesh);
    let (relaxation, u) = linear.relax(scene, probe_n, controls)?;
    let alive = vec![true; scene.mesh.tets.len()];
    let volume = |s: f64| {
        let scaled: Vec<[f64; 3]> = u.iter().map(|d| d.map(|x| s * x)).collect();
        volume_change(&scene.mesh, &scaled, &alive)
    };
    let target = scene.paper_loads.first_volume_change;
    // Bracket the scale by doubling, then bisect: 64 halvings of a bracket
    // at most 2^64 wide reach f64 resolution.
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..64 {
        if volume(hi) >= target {
            break;
        }
        (lo, hi) = (hi, 2.0 * hi);
    }
    if volume(hi) < target {
        bail!(
            "{}: the linear model's volume change does not reach {target} below {hi:.3e} × {probe_n:.4e} N",
            scene.name
        );
    }
    for _ in 0..64 {
        let mid = 0.5 * (lo + hi);
        if volume(mid) < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let force_n = hi * probe_n;
    progress(&format!(
        "{} paper loads: F = {force_n:.4e} N gives the linear model ΔV/V₀ = {:+.3} % \
         (probe {probe_n:.4e} N relaxed in {} steps)",
        scene.name,
        100.0 * volume(hi),
        relaxation.steps
    ));
    Ok(force_n)
}

/// The total force that brings `body`'s measure to
/// `target`: a proportional first step from `previous_n` (or a small probe),
/// then secant iterations, each relaxation continuing from the last
/// equilibrium.
fn find_force(
    scene: &Scene,
    body: &mut Body<'_>,
    target: f64,
    previous_n: f64,
    controls: &Controls,
    progress: &mut impl FnMut(&str),
) -> anyhow::Result<f64> {
    let mut evaluate = |force_n: f64| -> anyhow::Result<f64> {
        let (relaxation, u) = body.relax(scene, force_n, controls)?;
        let measure = (scene.measure)(&scene.mesh, &u);
        progress(&format!(
            "{} search for {target}: {force_n:.4e} N -> {measure:.3} ({} steps, residual {:.1e} N)",
            scene.name, relaxation.steps, relaxation.residual_n
        ));
        Ok(measure)
    };
    let (mut f0, mut m0) = if previous_n > 0.0 {
        (previous_n, evaluate(previous_n)?)
    } else {
        let probe = 1e-3 * scene.material.young_pa * bounding_area(&scene.mesh);
        (probe, evaluate(probe)?)
    };
    let mut f1 = f0 * target / m0;
    let mut m1 = evaluate(f1)?;
    for _ in 0..controls.max_iterations {
        if (m1 - target).abs() <= controls.target_tolerance {
            return Ok(f1);
        }
        let slope = (m1 - m0) / (f1 - f0);
        let next = if slope > 0.0 && slope.is_finite() {
            f1 + (target - m1) / slope
        } else {
            f1 * target / m1
        };
        // Never more than double or less than halve per iteration.
        let next = next.clamp(0.5 * f1, 2.0 * f1);
        (f0, m0) = (f1, m1);
        f1 = next;
        m1 = evaluate(f1)?;
    }
    if (m1 - target).abs() <= controls.target_tolerance {
        Ok(f1)
    } else {
        bail!(
            "{}: no force reaches {target} within {} iterations (last {m1:.3} at {f1:.4e} N)",
            scene.name,
            controls.max_iterations
        )
    }
}

/// Largest face area of the bounding box, m² (scale of the first probe).
fn bounding_area(mesh: &TetMesh) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in &mesh.positions {
        for i in 0..3 {
            lo[i] = lo[i].min(p[i]);
            hi[i] = hi[i].max(p[i]);
        }
    }
    let d = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
    (d[0] * d[1]).max(d[1] * d[2]).max(d[0] * d[2])
}

/// Picinbono 2001 table 2, relative volume change in %: the cylinder's three
/// stages and the liver, for the linear, St Venant-Kirchhoff and
/// incompressible models.
pub const PAPER_TABLE_2: [(&str, [&[f64]; 3]); 2] = [
    (
        "cylinder",
        [&[7.0, 28.0, 63.0], &[0.3, 1.0, 2.0], &[0.2, 0.5, 1.0]],
    ),
    ("organ", [&[9.0], &[1.5], &[0.7]]),
];

/// The results as a text table beside the paper's numbers (the co-rotational
/// and neo-Hookean columns have none).
pub fn table(results: &[SceneResult]) -> String {
    use core::fmt::Write;
    let mut out = String::new();
    let stages = match results.first().map(|r| r.protocol) {
        Some(Protocol::PaperLoads) => "at the paper's loads F, 2F, 3F",
        _ => "at the penalized model's tilts",
    };
    let _ = writeln!(
        out,
        "relative volume change (V − V₀)/V₀, %, {stages} (paper: Picinbono 2001 table 2)"
    );
    let _ = writeln!(
        out,
        "{:<9} {:>8} {:>11} | {:>10} {:>7} | {:>10} {:>7} | {:>10} {:>7} | {:>10} | {:>10} | {:>9}",
        "scene",
        "stage",
        "force N",
        "linear",
        "paper",
        "StVK",
        "paper",
        "StVK+inc",
        "paper",
        "co-rot",
        "neo-Hooke",
        "measure"
    );
    for result in results {
        let paper = PAPER_TABLE_2
            .iter()
            .find(|(name, _)| *name == result.name)
            .map(|(_, p)| *p);
        for (k, stage) in result.stages.iter().enumerate() {
            let p = |model: usize| {
                paper
                    .and_then(|p| p[model].get(k))
                    .map_or("-".to_string(), |x| format!("{x}"))
            };
            // `*`: tets inverted (a collapse, not a volume law); `!`: diverged.
            let v = |e: &Equilibrium| {
                let mark = match (&e.fault, e.inverted_tets) {
                    (Some(_), _) => "!",
                    (None, 0) => " ",
                    (None, _) => "*",
                };
                format!("{:+.3}{mark}", 100.0 * e.volume_change)
            };
            let stage_label = match result.protocol {
                Protocol::Tilt => format!("{:.1}", stage.target),
                Protocol::PaperLoads => format!("{}F", stage.target),
            };
            let _ = writeln!(
                out,
                "{:<9} {:>8} {:>11.4e} | {:>10} {:>7} | {:>10} {:>7} | {:>10} {:>7} | {:>10} | {:>10} | {:>9.1}",
                result.name,
                stage_label,
                stage.force_n,
                v(&stage.linear),
                p(0),
                v(&stage.stvk),
                p(1),
                v(&stage.stvk_incompressible),
                p(2),
                v(&stage.corotational),
                v(&stage.neo_hookean),
                stage.stvk_incompressible.measure,
            );
        }
        let stages = match result.protocol {
            Protocol::Tilt => "stages: the penalized model's measure",
            Protocol::PaperLoads => {
                "stages: multiples of F, the force giving the linear model the paper's first stage"
            }
        };
        let _ = writeln!(
            out,
            "  {}: {} vertices, {} tets, λ = {:.0} Pa, μ = {:.0} Pa, γ = {:.3e} N; {stages}; \
             measure: the penalized model's {}",
            result.name,
            result.vertices,
            result.tets,
            result.lame_pa.0,
            result.lame_pa.1,
            result.incompressibility_n,
            result.measure,
        );
    }
    let _ = writeln!(
        out,
        "* some tets inverted (plain St Venant-Kirchhoff collapses under strong compression); ! relaxation diverged; \
         co-rot, neo-Hooke: the co-rotational and neo-Hookean laws (not in the paper)"
    );
    out
}
