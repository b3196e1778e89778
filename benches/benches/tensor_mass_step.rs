//! One step of the dynamic tensor-mass model (`kernel/src/tensor_mass`), f32
//! tables (the firmware precision), per integrator, on tissue cubes of
//! 5³, 10³ and 20³ cells (750, 6000 and 48 000 tets), base fixed, after a
//! perturbation so every vertex moves.
//!
//! Target (the dynamic model's speed target): a symplectic-Euler step on ~6000 tets in ≤ 50 µs on one
//! core (20 kHz), cost linear in the mesh size. Printed after the group:
//! steps per second per mesh and the ratio of a step to a memcpy of the bytes
//! one force pass touches (`40·(N+E)` bytes of tensors and CSR, `12·N` each
//! for `u`, `v`, `f`, masses `4·N`), measured in the same run.
//!
//! `tet_removal`: the cost of one cut, `remove_tet` over 100 consecutive
//! tets (indices 2700–2799, a band of cells mid-height) of the 6000-tet cube
//! (10 blocks and 4 mass shares each, plus the hanging check), reset untimed
//! between runs, without and with the St Venant-Kirchhoff split terms
//! (about 250 more values per tet, recomputed from the rest shape); the
//! figure is tets removed per microsecond.
//!
//! Run: `RUSTFLAGS="-C target-cpu=native" cargo bench -p palpate-benches --bench tensor_mass_step`.

use core::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use nalgebra::Vector3;
use palpate::table::load::TableFile;
use palpate::tensor_mass::OwnedState;
use palpate_benches::tensor_cube_table;
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::tensor_mass::{DynamicParams, Integrator, TensorMassModel};

fn table(cells: usize) -> TableFile {
    TableFile::from_bytes(&tensor_cube_table(cells))
}

fn params() -> DynamicParams<f32> {
    DynamicParams::linear(5.0, 1.0).with_gravity(Vector3::new(0.0, 0.0, -9.81))
}

fn step(c: &mut Criterion) {
    let mut group = c.benchmark_group("tensor_mass_step");
    let mut report = Vec::new();
    for cells in [5, 10, 20] {
        let file = table(cells);
        let table = TensorMassTable::<f32>::load(file.bytes()).expect("table");
        let (n, e, tets) = (table.vertex_count(), table.edge_count(), table.tet_count());
        let mut state = OwnedState::for_table(&table);
        let mut model = TensorMassModel::new(table, state.buffers(), params()).expect("model");
        let top = (n - 1) as u32;
        for integrator in Integrator::ALL {
            model.reset();
            model
                .set_velocity(top, Vector3::new(0.0, 0.0, -0.01))
                .expect("free vertex");
            let id = BenchmarkId::new(integrator.name(), format!("{tets}tets"));
            // Δt = 1 µs: below every scheme's limit here (forward Euler with
            // damping c needs Δt < c/ω_max²); a fault would reset the model.
            group.bench_function(id, |b| {
                b.iter(|| {
                    if model.step(black_box(integrator), 1e-6).is_err() {
                        model.reset();
                    }
                })
            });
        }
        let bytes = 40 * (n + e) + 40 * n;
        let source = vec![1u8; bytes];
        let mut target = vec![0u8; bytes];
        group.bench_function(BenchmarkId::new("memcpy", format!("{tets}tets")), |b| {
            b.iter(|| target.copy_from_slice(black_box(&source)))
        });
        report.push((n, e, tets, bytes));
    }
    group.finish();
    println!("\nmesh sizes (vertices, edges, tets, bytes per force pass):");
    for (n, e, tets, bytes) in report {
        println!("{n:7} {e:7} {tets:7} {bytes:9}");
    }
}

fn tet_removal(c: &mut Criterion) {
    let file = table(10);
    let table = TensorMassTable::<f32>::load(file.bytes()).expect("table");
    let tets: Vec<u32> = (0..100).map(|i| 2700 + i).collect();
    let mut group = c.benchmark_group("tet_removal");
    group.throughput(criterion::Throughput::Elements(tets.len() as u64));
    for (name, state) in [
        (
            "100_tets_of_6000",
            OwnedState::for_table(&table).without_split_terms(),
        ),
        (
            "100_tets_of_6000_with_split_terms",
            OwnedState::for_table(&table),
        ),
    ] {
        let mut state = state;
        let mut model = TensorMassModel::new(table, state.buffers(), params()).expect("model");
        group.bench_function(name, |b| {
            b.iter_custom(|iterations| {
                let mut total = core::time::Duration::ZERO;
                for _ in 0..iterations {
                    model.reset();
                    let start = std::time::Instant::now();
                    for &t in &tets {
                        black_box(model.remove_tet(black_box(t)).ok());
                    }
                    total += start.elapsed();
                }
                total
            })
        });
    }
    group.finish();
}

criterion_group!(benches, step, tet_removal);
criterion_main!(benches);
