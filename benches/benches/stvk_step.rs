//! One symplectic-Euler step of the tensor-mass model per elastic law
//! (`kernel/src/tensor_mass`), f32 tables (the firmware precision): linear,
//! St Venant-Kirchhoff per tet, St Venant-Kirchhoff by Picinbono's split
//! terms, per tet with the incompressibility penalty, co-rotational and
//! neo-Hookean (per tet, the same blocks). Meshes: the
//! generated cylinder (3240 tets), the liver-like organ (5868 tets, the size
//! of Picinbono's 6342-tet liver) and a 20³-cell tissue cube (48 000 tets);
//! each fixed at its base, deformed by a 20 % shear first so that every
//! tet is strained.
//!
//! Targets (the non-linear model's speed targets): a St Venant-Kirchhoff step on ~6000 tets in ≤ 200 µs
//! (5 kHz) on one core; non-linear/linear cost ratio ≤ 2.5 (Picinbono 2001
//! §3.3: 5×, 9 Hz for 6342 tets on a 600 MHz PIII); co-rotational ≤ 1.6× the
//! linear step, neo-Hookean ≤ 1.3× St Venant-Kirchhoff per tet. Printed after the group:
//! steps per second and the ratio to the linear step, per mesh.
//!
//! Run: `RUSTFLAGS="-C target-cpu=native" cargo bench -p palpate-benches --bench stvk_step`.

use core::hint::black_box;
use std::time::Instant;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use nalgebra::Vector3;
use palpate::mesh::TetMesh;
use palpate::mesh::generate::{ORGAN_CUBE_M, box_mesh, cylinder_mesh, organ_mesh};
use palpate::table::load::TableFile;
use palpate::tensor_mass::OwnedState;
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::tensor_mass::{
    DynamicParams, ElasticLaw, Integrator, StvkForm, TensorMassModel,
};

/// The laws timed, with their penalty γ (N) and a name.
const LAWS: [(&str, ElasticLaw, Option<f32>); 6] = [
    ("linear", ElasticLaw::Linear, None),
    (
        "stvk_per_tet",
        ElasticLaw::StVenantKirchhoff(StvkForm::PerTet),
        None,
    ),
    (
        "stvk_tensors",
        ElasticLaw::StVenantKirchhoff(StvkForm::Tensors),
        None,
    ),
    (
        "stvk_per_tet_incompressible",
        ElasticLaw::StVenantKirchhoff(StvkForm::PerTet),
        Some(0.5),
    ),
    ("corotational", ElasticLaw::Corotational, None),
    ("neo_hookean", ElasticLaw::NeoHookean, None),
];

fn meshes() -> Vec<(&'static str, TetMesh)> {
    vec![
        ("cylinder", cylinder_mesh(0.1, 3, 15)),
        ("organ", organ_mesh(ORGAN_CUBE_M)),
        ("cube20", box_mesh([20; 3], [0.1; 3])),
    ]
}

fn table(mesh: &TetMesh) -> TableFile {
    palpate_benches::base_fixed_table(mesh)
}

fn params(law: ElasticLaw, incompressibility_n: Option<f32>) -> DynamicParams<f32> {
    DynamicParams::linear(5.0, 10.0)
        .with_law(law)
        .with_incompressibility(incompressibility_n)
}

fn step(c: &mut Criterion) {
    let mut group = c.benchmark_group("stvk_step");
    let mut summary = Vec::new();
    for (name, mesh) in meshes() {
        let file = table(&mesh);
        let table = TensorMassTable::<f32>::load(file.bytes()).expect("table");
        let z_min = mesh
            .positions
            .iter()
            .map(|p| p[2])
            .fold(f64::INFINITY, f64::min);
        let mut per_law = Vec::new();
        for (law_name, law, gamma) in LAWS {
            let mut state = OwnedState::for_table(&table);
            let mut model =
                TensorMassModel::new(table, state.buffers(), params(law, gamma)).expect("model");
            let shear = |model: &mut TensorMassModel<'_, '_, f32>| {
                model.reset();
                for (v, p) in mesh.positions.iter().enumerate() {
                    let d = Vector3::new(0.2 * (p[2] - z_min) as f32, 0.0, 0.0);
                    // Fixed vertices refuse; the rest take the shear.
                    if model.impose(v as u32, d).is_ok() {
                        let _ = model.release(v as u32);
                    }
                }
            };
            shear(&mut model);
            let id = BenchmarkId::new(law_name, format!("{name}_{}tets", mesh.tets.len()));
            group.bench_function(id, |b| {
                b.iter(|| {
                    if model
                        .step(black_box(Integrator::SymplecticEuler), 1e-6)
                        .is_err()
                    {
                        shear(&mut model);
                    }
                })
            });
            // A plain timing of 2000 steps for the summary table.
            shear(&mut model);
            let start = Instant::now();
            for _ in 0..2000 {
                let _ = black_box(model.step(Integrator::SymplecticEuler, 1e-6));
            }
            per_law.push((law_name, start.elapsed().as_secs_f64() / 2000.0));
        }
        summary.push((name, mesh.tets.len(), per_law));
    }
    group.finish();
    println!("\nsteps per second (2000-step timing) and cost relative to the linear step:");
    for (name, tets, per_law) in summary {
        let linear = per_law[0].1;
        for (law, seconds) in per_law {
            println!(
                "{name:9} {tets:6} tets  {law:28} {:8.1} µs  {:9.0} steps/s  {:5.2}× linear",
                seconds * 1e6,
                1.0 / seconds,
                seconds / linear
            );
        }
    }
}

criterion_group!(benches, step);
criterion_main!(benches);
