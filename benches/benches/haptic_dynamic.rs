//! The haptic loop over the dynamic tensor-mass model
//! (`kernel/src/haptic/dynamic_tissue.rs`), f32, on the tissue cube
//! (0.1 m, base fixed) of 6³ and 12³ cells (1296 and 10 368 tets):
//! - `tick` for m = 1..4 tool points each pressing 2 mm into the top face:
//!   tracking on the re-binned surface, the extrapolated force (local
//!   stiffness from the vertex and edge tensors) and the supervisor, as it
//!   runs at 1 kHz between physics updates;
//! - `physics_update` with one contact and one symplectic-Euler step: the
//!   imposed triangle, the step, the held forces (a full force pass) and
//!   the re-binning, with `rebin` alone for its share.
//!
//! Printed after the group: the RAM of the loop object,
//! `size_of::<DynamicLoop<f32, P, P>>()` (the model's and the surface's
//! arrays are the caller's buffers, sized by the table).
//!
//! Run: `RUSTFLAGS="-C target-cpu=native" cargo bench -p palpate-benches --bench haptic_dynamic`.

use core::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use palpate::table::load::TableFile;
use palpate::tensor_mass::{OwnedState, OwnedSurface};
use palpate_benches::{haptic_config, haptic_tool, tensor_cube_table};
use palpate_kernel::haptic::DynamicLoop;
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::tensor_mass::{DynamicParams, Integrator, TensorMassModel};
use palpate_kernel::tensor_mass::{DynamicTissue, Extrapolation, PhysicsConfig};

fn params() -> DynamicParams<f32> {
    DynamicParams::linear(30.0, 0.2)
}

const PHYSICS: PhysicsConfig<f32> = PhysicsConfig {
    extrapolation: Extrapolation::Secant,
    integrator: Integrator::SymplecticEuler,
    dt_s: 5e-4,
    substeps: 1,
    cut_capacity_tets: 8,
    cut_force_n: 0.2,
    tearing: None,
};

/// Presses `P` points 2 mm in (a physics update after every tick), then
/// hands the loop, in contact, to `bench`.
fn pressed<const P: usize>(
    table: TensorMassTable<'_, f32>,
    bench: impl FnOnce(&mut DynamicLoop<'_, '_, f32, P, P>),
) {
    let mut state = OwnedState::for_table(&table).without_split_terms();
    let model = TensorMassModel::new(table, state.buffers(), params()).expect("model");
    let mut owned = OwnedSurface::for_model(&model);
    let (buffers, forces) = owned.buffers();
    let tissue = DynamicTissue::<f32, P>::new(model, buffers, forces, PHYSICS).expect("tissue");
    let mut haptic = DynamicLoop::<f32, P, P>::new(tissue, haptic_config()).expect("loop");
    haptic.tick(&core::array::from_fn(|p| haptic_tool(p, -0.001)));
    for k in 0..=20 {
        haptic.tick(&core::array::from_fn(|p| haptic_tool(p, 0.0001 * k as f32)));
        haptic.physics_update().expect("stable");
    }
    assert_eq!(
        haptic.contacts().iter().flatten().count(),
        P,
        "all in contact"
    );
    bench(&mut haptic);
}

fn tick_with<const P: usize>(
    c: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    table: TensorMassTable<'_, f32>,
    cells: usize,
) {
    pressed::<P>(table, |haptic| {
        let mut k = 0u32;
        c.bench_function(
            BenchmarkId::new(format!("tick_m{P}"), format!("{cells}cells")),
            |b| {
                b.iter(|| {
                    // Two depths alternate: the tool moves every tick.
                    k = k.wrapping_add(1);
                    let depth = if k.is_multiple_of(2) { 0.002 } else { 0.0021 };
                    let tool = core::array::from_fn(|p| haptic_tool(p, depth));
                    black_box(haptic.tick(black_box(&tool)))
                })
            },
        );
    });
}

fn dynamic(c: &mut Criterion) {
    let mut group = c.benchmark_group("haptic_dynamic");
    for cells in [6, 12] {
        let file = TableFile::from_bytes(&tensor_cube_table(cells));
        let table = TensorMassTable::<f32>::load(file.bytes()).expect("table");
        tick_with::<1>(&mut group, table, cells);
        tick_with::<2>(&mut group, table, cells);
        tick_with::<3>(&mut group, table, cells);
        tick_with::<4>(&mut group, table, cells);
        pressed::<1>(table, |haptic| {
            group.bench_function(
                BenchmarkId::new("physics_update", format!("{cells}cells")),
                |b| b.iter(|| black_box(haptic.physics_update())),
            );
            // Every measured update was a real step, not an early refusal.
            assert!(haptic.physics_update().is_ok(), "physics update faulted");
        });
        let mut state = OwnedState::for_table(&table).without_split_terms();
        let model = TensorMassModel::new(table, state.buffers(), params()).expect("model");
        let mut owned = OwnedSurface::for_model(&model);
        let (buffers, _) = owned.buffers();
        let mut surface =
            palpate_kernel::tensor_mass::DeformingSurface::new(&model, buffers).expect("surface");
        let u = vec![[0.0f32, 0.0, 0.001]; table.vertex_count()];
        group.bench_function(BenchmarkId::new("rebin", format!("{cells}cells")), |b| {
            b.iter(|| black_box(surface.rebin(black_box(&u))))
        });
    }
    group.finish();
    println!(
        "dynamic loop object: {} B (P = 1), {} B (P = 4), f32",
        core::mem::size_of::<DynamicLoop<'_, '_, f32, 1, 1>>(),
        core::mem::size_of::<DynamicLoop<'_, '_, f32, 4, 4>>()
    );
}

criterion_group!(benches, dynamic);
criterion_main!(benches);
