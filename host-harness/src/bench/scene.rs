//! `palpate bench --scene`: a scene's own model, built and run as `session
//! run` runs it (f32 tables, its rates, its tool radius, its tensor-mass
//! steps dispatched and their per-tet pass on `--threads`), timed stage by
//! stage against the period the stage has in real time:
//!
//! - `physics-update`, every `physics_every` ticks (period
//!   [`Scene::physics_period_s`]): a pre-computed scene's deformation field
//!   (every free vertex for the last contact solution), a dynamic or hybrid
//!   scene's `physics_update` (its substeps of the tensor-mass region, the
//!   held contacts, the surface), with one tool point pressing;
//! - `interface-update` (hybrid only, same period): the pre-computed
//!   region's touchable background at the tensor-mass region's
//!   displacements, the interface part of the physics update;
//! - `haptic-tick` with 1 to [`MAX_CONTACTS`] tool points pressing (period
//!   [`Scene::tick_s`]), no physics update between the timed ticks.
//!
//! The real-time factor of a stage is `period / median cost`: above 1 the
//! stage keeps real time on this machine (one core, plus `--threads` for
//! the tensor-mass steps).
//!
//! The tool points press the surface at spread-out boundary triangles
//! whose vertices are all free (the highest first, then each the farthest
//! from those chosen), by [`PRESS_OF_RADIUS`] tool radii along the inward
//! normal, reached in 10 ticks.
//!
//! Bounded: the sampling is checked as `palpate bench`'s
//! ([`super::run::check_sampling`]) and the run's estimate,
//! [`MAX_SCENE_STAGES`] measurements each of `warmup + samples` samples
//! plus calibration, against [`MAX_BENCH_ESTIMATE_S`] before the tables are
//! built; a call longer than a sample makes samples of one call.

use core::hint::black_box;

use anyhow::{Context, bail};
use nalgebra::Vector3;
use palpate_kernel::MAX_CONTACTS;
use palpate_kernel::PrecomputedTable;
use palpate_kernel::contact::Tissue;
use palpate_kernel::haptic::{HapticLoop, PhysicsTissue, PrecomputedLoop};
use palpate_kernel::math::Portable;
use palpate_kernel::precomputed::PrecomputedTissue;
use palpate_kernel::table::TensorMassTable;
use serde::Serialize;

use super::measure::{Sampling, Timing, estimated_seconds, time};
use super::run::check_sampling;
use crate::dispatch::HostDispatch;
use crate::fix::fixed_vertices;
use crate::limits::MAX_BENCH_ESTIMATE_S;
use crate::mesh::{TetMesh, boundary_surface};
use crate::scene::Scene;
use crate::session::hybrid::HybridSetup;
use crate::session::model::{SceneModel, SceneTables};
use crate::session::setup::{DynamicSetup, loop_config};
use crate::session::tool_points::{ForToolPoints, with_tool_points};
use crate::threads::Threaded;

/// Depth of a pressing tool point, in tool radii.
pub const PRESS_OF_RADIUS: f64 = 0.3;

/// Most measurements of a run: the physics update, the interface update
/// and the tick with 1 to [`MAX_CONTACTS`] tool points.
pub const MAX_SCENE_STAGES: usize = 2 + MAX_CONTACTS;

/// What `palpate bench --scene` measures and how.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneBenchOptions {
    /// How each stage is sampled.
    pub sampling: Sampling,
    /// Threads of the tensor-mass steps' per-tet force pass.
    pub threads: usize,
}

/// The JSON object of `palpate bench --scene --json` (a CLI contract).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SceneBench {
    /// The scene's source (file or built-in name).
    pub scene: String,
    /// `precomputed`, `dynamic` or `hybrid`.
    pub model: &'static str,
    /// Vertices of the mesh.
    pub vertices: usize,
    /// Tets of the mesh.
    pub tets: usize,
    /// Tets of the tensor-mass region (0 for a pre-computed scene).
    pub dynamic_tets: usize,
    /// Threads of the tensor-mass steps' per-tet force pass.
    pub threads: usize,
    /// The stages, in the order of the module docs.
    pub stages: Vec<Stage>,
}

/// One timed stage.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Stage {
    /// `physics-update`, `interface-update` or `haptic-tick`.
    pub stage: &'static str,
    /// Tool points pressing.
    pub tool_points: usize,
    /// Of those, the points in contact when the stage was timed.
    pub contacts: usize,
    /// Median cost per call, s.
    pub median_s: f64,
    /// First quartile, s.
    pub q1_s: f64,
    /// Third quartile, s.
    pub q3_s: f64,
    /// Samples kept.
    pub samples: usize,
    /// The stage's period in real time, s.
    pub period_s: f64,
    /// `period_s / median_s`.
    pub real_time_factor: f64,
}

impl Stage {
    fn of(
        stage: &'static str,
        tool_points: usize,
        contacts: usize,
        t: Timing,
        period_s: f64,
    ) -> Self {
        Self {
            stage,
            tool_points,
            contacts,
            median_s: t.median_s,
            q1_s: t.q1_s,
            q3_s: t.q3_s,
            samples: t.samples,
            period_s,
            real_time_factor: period_s / t.median_s,
        }
    }
}

/// Checks `options` (the sampling, and the estimate of at most
/// [`MAX_SCENE_STAGES`] measurements against [`MAX_BENCH_ESTIMATE_S`]) and
/// returns the estimated seconds of the measurements (the table build not
/// included).
pub fn check_scene_bench(options: &SceneBenchOptions) -> anyhow::Result<f64> {
    check_sampling(&options.sampling)?;
    let s = &options.sampling;
    let seconds = MAX_SCENE_STAGES as f64 * estimated_seconds(s, s.sample_s);
    if seconds > MAX_BENCH_ESTIMATE_S {
        bail!(
            "{MAX_SCENE_STAGES} measurements estimated at {seconds:.0} s, more than \
             {MAX_BENCH_ESTIMATE_S} s (MAX_BENCH_ESTIMATE_S): fewer --samples or a shorter --sample-ms"
        );
    }
    Ok(seconds)
}

/// Builds `scene`'s tables and times its stages (module docs), after
/// [`check_scene_bench`].
pub fn bench_scene(scene: &Scene, options: &SceneBenchOptions) -> anyhow::Result<SceneBench> {
    check_scene_bench(options)?;
    let (mesh, report) = scene.load_mesh()?;
    let picks = picks(scene, &mesh, &report.unreferenced_vertices);
    if picks.is_empty() {
        bail!(
            "{}: no boundary triangle with free vertices to press",
            scene.source
        );
    }
    let tables = SceneModel::of(scene, &mesh, &report)?.tables(scene, &mesh, &report, None)?;
    let load = |e| anyhow::anyhow!("scene table: {e}");
    let bench = Bench {
        scene,
        picks: &picks,
        sampling: options.sampling,
        threads: options.threads,
    };
    let (model, dynamic_tets) = match &tables {
        SceneTables::Precomputed(_) => ("precomputed", 0),
        SceneTables::Dynamic(..) => ("dynamic", mesh.tets.len()),
        SceneTables::Hybrid(files, _) => {
            ("hybrid", files.dynamic_tet.iter().filter(|&&d| d).count())
        }
    };
    let tissue = match &tables {
        SceneTables::Precomputed(file) => {
            BenchTissue::Precomputed(PrecomputedTable::<f32>::load(file.bytes()).map_err(load)?)
        }
        SceneTables::Dynamic(file, spec) => {
            let table = TensorMassTable::<f32>::load(file.bytes()).map_err(load)?;
            BenchTissue::Dynamic(DynamicSetup::of(scene, spec, table)?)
        }
        SceneTables::Hybrid(files, spec) => {
            BenchTissue::Hybrid(Box::new(HybridSetup::of(scene, spec, files)?))
        }
    };
    let mut stages = Vec::new();
    for points in 1..=picks.len().min(MAX_CONTACTS) {
        let measured = with_tool_points(
            points,
            Points {
                bench: &bench,
                tissue: &tissue,
                physics: points == 1,
            },
        )
        .with_context(|| format!("{}: {points} tool points", scene.source))?;
        stages.extend(measured);
    }
    // The physics stages first, then the ticks by tool points.
    stages.sort_by_key(|s| (s.stage == "haptic-tick", s.stage == "interface-update"));
    Ok(SceneBench {
        scene: scene.source.clone(),
        model,
        vertices: mesh.positions.len(),
        tets: mesh.tets.len(),
        dynamic_tets,
        threads: options.threads,
        stages,
    })
}

/// A pressing tool point: the centroid of a boundary triangle (m) and its
/// unit outward normal.
#[derive(Clone, Copy, Debug)]
struct Pick {
    touch_m: [f64; 3],
    normal: [f64; 3],
}

/// Up to [`MAX_CONTACTS`] boundary triangles with all vertices free,
/// spread out: the highest centroid first, then each the farthest from
/// those chosen.
fn picks(scene: &Scene, mesh: &TetMesh, unreferenced: &[u32]) -> Vec<Pick> {
    let (fixed, _) = fixed_vertices(&mesh.positions, &scene.fix, unreferenced);
    let p = |v: u32| mesh.positions[v as usize];
    let candidates: Vec<Pick> = boundary_surface(mesh)
        .triangles
        .iter()
        .filter(|t| t.iter().all(|&v| !fixed[v as usize]))
        .filter_map(|&[a, b, c]| {
            let (a, b, c) = (p(a), p(b), p(c));
            let n = cross(sub(b, a), sub(c, a));
            let length = dot(n, n).sqrt();
            (length > 0.0).then(|| Pick {
                touch_m: core::array::from_fn(|i| (a[i] + b[i] + c[i]) / 3.0),
                normal: n.map(|x| x / length),
            })
        })
        .collect();
    let mut chosen: Vec<Pick> = Vec::new();
    let highest = candidates
        .iter()
        .max_by(|x, y| x.touch_m[2].total_cmp(&y.touch_m[2]));
    chosen.extend(highest);
    while chosen.len() < MAX_CONTACTS.min(candidates.len()) {
        let distance = |q: &Pick| {
            chosen
                .iter()
                .map(|c| {
                    let d = sub(q.touch_m, c.touch_m);
                    dot(d, d)
                })
                .fold(f64::INFINITY, f64::min)
        };
        let Some(next) = candidates
            .iter()
            .max_by(|x, y| distance(x).total_cmp(&distance(y)))
        else {
            break;
        };
        chosen.push(*next);
    }
    chosen
}

/// The run's settings.
struct Bench<'b> {
    scene: &'b Scene,
    picks: &'b [Pick],
    sampling: Sampling,
    threads: usize,
}

/// The tissue of the scene's model.
enum BenchTissue<'t> {
    Precomputed(PrecomputedTable<'t, f32>),
    Dynamic(DynamicSetup<'t>),
    Hybrid(Box<HybridSetup<'t>>),
}

/// The stages measured with `P` tool points: the tick, and with `physics`
/// the physics (and interface) update.
struct Points<'b, 't> {
    bench: &'b Bench<'b>,
    tissue: &'b BenchTissue<'t>,
    physics: bool,
}

impl ForToolPoints for Points<'_, '_> {
    type Output = anyhow::Result<Vec<Stage>>;

    fn call<const P: usize>(self) -> Self::Output {
        let b = self.bench;
        let physics_s = b.scene.physics_period_s();
        let mut stages = Vec::new();
        match self.tissue {
            BenchTissue::Precomputed(table) => {
                let tissue = PrecomputedTissue::new(table);
                let mut haptic = PrecomputedLoop::<f32, P, P>::new(tissue, loop_config(b.scene))
                    .map_err(|e| anyhow::anyhow!("haptic loop: {e}"))?;
                let contacts = b.press(&mut haptic);
                if self.physics {
                    let model = *haptic.tissue().model();
                    let solution = *haptic.solution().context("no contact solution")?;
                    let mut field = vec![[0.0f32; 3]; table.vertex_count()];
                    let t = time(&b.sampling, || {
                        black_box(model.displacements(black_box(&solution), &mut field)).ok();
                    });
                    stages.push(Stage::of("physics-update", P, contacts, t, physics_s));
                }
                stages.push(b.time_tick(&mut haptic)?);
            }
            BenchTissue::Dynamic(setup) => {
                let dispatch = Threaded::new(HostDispatch::detect(), b.threads);
                setup.with_loop::<P, _, _>(dispatch, |haptic| {
                    b.physics_and_tick(haptic, self.physics, &mut stages)
                })?;
            }
            BenchTissue::Hybrid(setup) => {
                let dispatch = Threaded::new(Portable, b.threads);
                setup.with_loop::<P, _, _>(dispatch, |haptic| {
                    b.physics_and_tick(haptic, self.physics, &mut stages)
                })?;
                if self.physics {
                    let t = setup.with_tissue::<P, _, _>(dispatch, |mut tissue| {
                        let t = time(&b.sampling, || {
                            black_box(tissue.update_background()).ok();
                        });
                        tissue
                            .update_background()
                            .map_err(|f| anyhow::anyhow!("interface update: {f}"))?;
                        Ok(t)
                    })?;
                    stages.push(Stage::of("interface-update", P, 0, t, physics_s));
                }
            }
        }
        Ok(stages)
    }
}

impl Bench<'_> {
    /// The tool point `p` at `depth` (m) below first touch of its pick.
    fn tool<const P: usize>(&self, depth: f64) -> [Vector3<f32>; P] {
        let r = self.scene.tool.radius_m;
        core::array::from_fn(|p| {
            let pick = &self.picks[p % self.picks.len()];
            Vector3::from(core::array::from_fn(|i| {
                (pick.touch_m[i] + pick.normal[i] * (r - depth)) as f32
            }))
        })
    }

    /// Approaches from a radius above and presses in 10 ticks; the points
    /// in contact.
    fn press<B: Tissue<f32, P>, const P: usize>(
        &self,
        haptic: &mut HapticLoop<f32, B, P, P>,
    ) -> usize {
        let r = self.scene.tool.radius_m;
        haptic.tick(&self.tool(-r));
        for k in 0..=10 {
            haptic.tick(&self.tool(PRESS_OF_RADIUS * r * f64::from(k) / 10.0));
        }
        haptic.contacts().iter().flatten().count()
    }

    /// Presses, then times the tick alternating between the pressed depth
    /// and 1.1 times it.
    fn time_tick<B: Tissue<f32, P>, const P: usize>(
        &self,
        haptic: &mut HapticLoop<f32, B, P, P>,
    ) -> anyhow::Result<Stage> {
        let contacts = self.press(haptic);
        let r = self.scene.tool.radius_m;
        let depths = [PRESS_OF_RADIUS * r, 1.1 * PRESS_OF_RADIUS * r];
        let positions = depths.map(|d| self.tool::<P>(d));
        let mut k = 0usize;
        let t = time(&self.sampling, || {
            k = k.wrapping_add(1);
            black_box(haptic.tick(black_box(&positions[k % 2])));
        });
        Ok(Stage::of(
            "haptic-tick",
            P,
            contacts,
            t,
            self.scene.tick_s(),
        ))
    }

    /// The tick; then, with `physics`, the physics update with the points
    /// pressing (an error if it faults).
    fn physics_and_tick<B: PhysicsTissue<f32, P>, const P: usize>(
        &self,
        haptic: &mut HapticLoop<f32, B, P, P>,
        physics: bool,
        stages: &mut Vec<Stage>,
    ) -> anyhow::Result<()> {
        stages.push(self.time_tick(haptic)?);
        if physics {
            let contacts = self.press(haptic);
            let t = time(&self.sampling, || {
                black_box(haptic.physics_update()).ok();
            });
            haptic
                .physics_update()
                .map_err(|e| anyhow::anyhow!("physics update: {e}"))?;
            let period = self.scene.physics_period_s();
            stages.push(Stage::of("physics-update", P, contacts, t, period));
        }
        Ok(())
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
