//! `palpate demo`: the built-in scene ([`Scene::built_in`]), needing no
//! input file.
//!
//! Its 12 × 12 × 6 cm block of soft tissue (12 × 12 × 6 cells, 5184 tets,
//! E = 3 kPa, ν = 0.45, base fixed) is pressed by two probes at once, held
//! and released. The table is built in memory with the same code as
//! `tables build`, stored in `f32` as on firmware, loaded by the kernel, and
//! every step runs the kernel's force path and displacement update.

use core::time::Duration;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use nalgebra::Vector3;
use palpate_kernel::{Constraint, MAX_CONTACTS};

use crate::output::atomic::SeriesDir;
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

/// Runs the demo, writing the VTK series into the folder `out_dir`, whole
/// or not at all ([`SeriesDir`]: a fresh folder, or one a previous run
/// wrote, replaced when the series is complete; anything else is refused
/// before the run), then printing forces per phase and timings to `out`.
/// The report is printed once the series is in place, so a reader that
/// closes `out` early (`palpate demo | head`) cannot stop the series.
pub fn run(out_dir: &Path, printed: &mut dyn Write) -> anyhow::Result<()> {
    let mut report_text = Vec::new();
    let out: &mut dyn Write = &mut report_text;
    let series = SeriesDir::create(out_dir)?;
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

    // Two probes on the top face, at the touchable vertices nearest these points.
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
    let probes = [nearest([0.04, 0.06, 0.06]), nearest([0.08, 0.06, 0.06])];
    let full_press_m = [
        Vector3::new(0.0f32, 0.0, -0.006),
        Vector3::new(0.002f32, 0.0, -0.004),
    ];
    writeln!(
        out,
        "probes: vertex {} pressed to {:?} m, vertex {} pressed to {:?} m",
        probes[0],
        full_press_m[0].as_slice(),
        probes[1],
        full_press_m[1].as_slice()
    )?;

    let mut displacement = vec![[0.0f32; 3]; mesh.positions.len()];
    let mut frames: Vec<(f64, PathBuf)> = Vec::new();
    let mut force_time = Vec::new();
    let mut update_time = Vec::new();
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
                .iter()
                .zip(&full_press_m)
                .map(|(&v, d)| Constraint::at_vertex(v, d * amount))
                .collect();
            let t0 = Instant::now();
            let solution = model.contact_forces::<MAX_CONTACTS>(&contacts)?;
            let t1 = Instant::now();
            model.displacements(&solution, &mut displacement)?;
            let t2 = Instant::now();
            force_time.push(t1 - t0);
            update_time.push(t2 - t1);
            peak = peak.max(solution.device_force_n().norm());
            step += 1;
            if step.is_multiple_of(FRAME_EVERY) {
                let path = series.dir().join(format!("frame_{step:04}.vtk"));
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
    // The collection last, then the whole folder into place.
    vtk::write_collection(&series.dir().join("demo.pvd"), &frames)?;
    series.commit()?;
    let collection = out_dir.join("demo.pvd");
    let (force_mean, force_max) = stats(&force_time);
    let (update_mean, update_max) = stats(&update_time);
    writeln!(
        out,
        "timing over {step} steps: force path (2 contacts) mean {force_mean:.2} us, max {force_max:.2} us; \
         displacement update mean {update_mean:.1} us, max {update_max:.1} us"
    )?;
    writeln!(
        out,
        "wrote {} VTK frames and {} (open in ParaView)",
        frames.len(),
        collection.display()
    )?;
    printed.write_all(&report_text)?;
    Ok(())
}

/// Mean and maximum, µs.
fn stats(samples: &[Duration]) -> (f64, f64) {
    let us: Vec<f64> = samples.iter().map(|d| d.as_secs_f64() * 1e6).collect();
    let mean = us.iter().sum::<f64>() / us.len().max(1) as f64;
    (mean, us.iter().copied().fold(0.0, f64::max))
}
