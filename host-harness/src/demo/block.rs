//! Part one of the demo: the built-in block ([`Scene::built_in`]) on the
//! pre-computed model, pressed by two probes at once, held and released.
//!
//! Its 12 × 12 × 6 cm block of soft tissue (12 × 12 × 6 cells, 5184 tets,
//! E = 3 kPa, ν = 0.45, base fixed). The table is built in memory with the
//! same code as `tables build`, stored in `f32` as on firmware, loaded by
//! the kernel, and every step runs the kernel's force path (the contact
//! solve of the two probes, placed at vertices) and its displacement
//! update (the deformation field from the solution).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use nalgebra::Vector3;
use palpate_kernel::precomputed::PrecomputedModel;
use palpate_kernel::{Constraint, MAX_CONTACTS};

use super::timing::{Costs, mean_max};
use crate::mesh::TetMesh;
use crate::output::vtk;
use crate::scene::{MeshSource, Scene};
use crate::session::options::table_options;
use crate::table::build::build;
use crate::table::load::{AnyModel, TableFile};

/// Steps of each phase of the scripted press-and-release.
const PHASES: [(&str, usize); 3] = [("press", 40), ("hold", 20), ("release", 40)];
/// Simulated time per step, s (the display rate of the VTK series).
const STEP_S: f64 = 0.01;
/// A VTK frame every this many steps.
const FRAME_EVERY: usize = 4;
/// The block's ParaView collection in the demo's folder (the frames
/// `frame_NNNN.vtk` beside it).
pub const COLLECTION: &str = "demo.pvd";

/// Runs part one: the scene and table lines, the force per phase and the
/// timing line to `out`, the VTK frames and [`COLLECTION`] into `dir`.
/// Returns the step costs (force path, displacement update) and the frames
/// written.
pub fn run(dir: &Path, out: &mut dyn Write) -> anyhow::Result<Costs> {
    let scene = Scene::built_in();
    let MeshSource::GeneratedBox { size_m, .. } = scene.mesh else {
        anyhow::bail!("the built-in scene is a generated block");
    };
    let (mesh, mut report) = scene.load_mesh()?;
    report.source = "built-in block".into();
    let options = table_options(&scene, &mesh, &report)?;
    writeln!(
        out,
        "scene: {:.0}x{:.0}x{:.0} cm block, {} vertices, {} tets, E = {} Pa, nu = {}, base fixed",
        size_m[0] * 100.0,
        size_m[1] * 100.0,
        size_m[2] * 100.0,
        mesh.positions.len(),
        mesh.tets.len(),
        options.material.young_pa,
        options.material.poisson
    )?;
    let started = Instant::now();
    let built = build(&mesh, &report, &options)?;
    writeln!(
        out,
        "table: {} free, {} touchable vertices, {:.1} MB (f32), built in {:.3} s",
        built.free_count,
        built.touchable_count,
        built.bytes.len() as f64 / 1e6,
        started.elapsed().as_secs_f64()
    )?;
    let file = TableFile::from_bytes(&built.bytes);
    let AnyModel::F32(model) = file.model().context("built-in table")? else {
        anyhow::bail!("built-in table is not f32");
    };
    let probes = Probes::on_top(&model, &mesh);
    writeln!(
        out,
        "probes: vertex {} pressed to {:?} m, vertex {} pressed to {:?} m",
        probes.vertices[0],
        probes.full_press_m[0].as_slice(),
        probes.vertices[1],
        probes.full_press_m[1].as_slice()
    )?;
    let costs = press_and_release(&model, &mesh, &probes, dir, out)?;
    let (force_mean, force_max) = mean_max(&costs.ticks);
    let (update_mean, update_max) = mean_max(&costs.physics);
    writeln!(
        out,
        "timing over {} steps: force path (2 contacts) mean {force_mean:.2} us, max {force_max:.2} us; \
         displacement update mean {update_mean:.1} us, max {update_max:.1} us",
        costs.ticks.len()
    )?;
    Ok(costs)
}

/// The two probes: the touchable vertices nearest two points of the top
/// face, and how far each is pressed at the deepest.
struct Probes {
    vertices: [u32; 2],
    full_press_m: [Vector3<f32>; 2],
}

impl Probes {
    fn on_top(model: &PrecomputedModel<'_, f32>, mesh: &TetMesh) -> Self {
        let nearest = |target: [f64; 3]| -> u32 {
            let touchable = &model.table().free_vertices()[..model.table().touchable_count()];
            let dist = |v: u32| {
                let p = mesh.positions[v as usize];
                (0..3).map(|i| (p[i] - target[i]).powi(2)).sum::<f64>()
            };
            touchable
                .iter()
                .copied()
                .min_by(|&a, &b| dist(a).total_cmp(&dist(b)))
                .unwrap_or(0)
        };
        Self {
            vertices: [nearest([0.04, 0.06, 0.06]), nearest([0.08, 0.06, 0.06])],
            full_press_m: [
                Vector3::new(0.0f32, 0.0, -0.006),
                Vector3::new(0.002f32, 0.0, -0.004),
            ],
        }
    }
}

/// The scripted [`PHASES`]: each step's contact solve and displacement
/// update timed, a VTK frame every [`FRAME_EVERY`] steps, one line per
/// phase (device force at its end, its peak, each contact's force), then
/// the collection.
fn press_and_release(
    model: &PrecomputedModel<'_, f32>,
    mesh: &TetMesh,
    probes: &Probes,
    dir: &Path,
    out: &mut dyn Write,
) -> anyhow::Result<Costs> {
    let mut displacement = vec![[0.0f32; 3]; mesh.positions.len()];
    let mut frames: Vec<(f64, PathBuf)> = Vec::new();
    let mut costs = Costs::default();
    let mut step = 0usize;
    writeln!(
        out,
        "phase    steps  device force at end (N)          |F| peak (N)  contact forces at end (N)"
    )?;
    for (phase, steps) in PHASES {
        let mut peak = 0.0f32;
        let mut last = None;
        for i in 1..=steps {
            let amount = match phase {
                "press" => i as f32 / steps as f32,
                "hold" => 1.0,
                _ => 1.0 - i as f32 / steps as f32,
            };
            let contacts: Vec<Constraint<f32>> = probes
                .vertices
                .iter()
                .zip(&probes.full_press_m)
                .map(|(&v, d)| Constraint::at_vertex(v, d * amount))
                .collect();
            let t0 = Instant::now();
            let solution = model.contact_forces::<MAX_CONTACTS>(&contacts)?;
            let t1 = Instant::now();
            model.displacements(&solution, &mut displacement)?;
            let t2 = Instant::now();
            costs.ticks.push(t1 - t0);
            costs.physics.push(t2 - t1);
            peak = peak.max(solution.device_force_n().norm());
            step += 1;
            if step.is_multiple_of(FRAME_EVERY) {
                let path = dir.join(format!("frame_{step:04}.vtk"));
                let u: Vec<[f64; 3]> = displacement.iter().map(|u| u.map(f64::from)).collect();
                vtk::write_frame(&path, &mesh.positions, &mesh.tets, &u)?;
                frames.push((step as f64 * STEP_S, path));
            }
            last = Some(solution);
        }
        if let Some(s) = last {
            let f = s.device_force_n();
            let g: Vec<String> = s
                .contact_forces_n()
                .iter()
                .map(|g| format!("({:+.4}, {:+.4}, {:+.4})", g.x, g.y, g.z))
                .collect();
            writeln!(
                out,
                "{phase:<8} {steps:>5}  ({:+.4}, {:+.4}, {:+.4})  {peak:>11.4}  {}",
                f.x,
                f.y,
                f.z,
                g.join(" ")
            )?;
        }
    }
    vtk::write_collection(&dir.join(COLLECTION), &frames)?;
    costs.frames = frames.len();
    Ok(costs)
}
