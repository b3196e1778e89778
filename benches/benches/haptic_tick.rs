//! One haptic tick (`kernel/src/haptic`) with the pre-computed model, f32:
//! contact tracking in the collision grid, the contact solve and the safety
//! supervisor, for m = 1..4 tool points each pressing 2 mm into the top of
//! a tissue cube (0.1 m, base fixed) of 6³ and 12³ cells; and the collision
//! query alone (detection of a crossing by a swept sphere).
//!
//! Target (the haptic loop's speed target): a full tick with up to 4 contacts in ≤ 2 µs on the
//! host, independent of the mesh size. Printed after the group: the RAM of
//! the loop state, `size_of::<PrecomputedLoop<f32, P, P>>()`.
//!
//! Run: `RUSTFLAGS="-C target-cpu=native" cargo bench -p palpate-benches --bench haptic_tick`.

use core::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use palpate::table::load::TableFile;
use palpate_benches::{TOOL_RADIUS_M, cube_table, haptic_config as config, haptic_tool as tool};
use palpate_kernel::PrecomputedTable;
use palpate_kernel::contact::{ContactWork, SurfaceGeometry};
use palpate_kernel::haptic::PrecomputedLoop;
use palpate_kernel::precomputed::PrecomputedTissue;

fn tick_with<const P: usize>(
    c: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    table: &PrecomputedTable<'_, f32>,
    cells: usize,
) {
    let mut haptic =
        PrecomputedLoop::<f32, P, P>::new(PrecomputedTissue::new(table), config()).expect("loop");
    // Approach from 1 mm above, then press to 2 mm: every point in contact.
    haptic.tick(&core::array::from_fn(|p| tool(p, -0.001)));
    for k in 0..=20 {
        haptic.tick(&core::array::from_fn(|p| tool(p, 0.0001 * k as f32)));
    }
    assert_eq!(
        haptic.contacts().iter().flatten().count(),
        P,
        "all in contact"
    );
    let mut k = 0u32;
    c.bench_function(
        BenchmarkId::new(format!("m{P}"), format!("{cells}cells")),
        |b| {
            b.iter(|| {
                // Alternate between two depths so the solve has work to do.
                k = k.wrapping_add(1);
                let depth = if k.is_multiple_of(2) { 0.002 } else { 0.0021 };
                black_box(haptic.tick(black_box(&core::array::from_fn(|p| tool(p, depth)))))
            })
        },
    );
}

fn tick(c: &mut Criterion) {
    let mut group = c.benchmark_group("haptic_tick");
    for cells in [6, 12] {
        let built = cube_table(cells);
        let file = TableFile::from_bytes(&built.bytes);
        let table = PrecomputedTable::<f32>::load(file.bytes()).expect("table");
        tick_with::<1>(&mut group, &table, cells);
        tick_with::<2>(&mut group, &table, cells);
        tick_with::<3>(&mut group, &table, cells);
        tick_with::<4>(&mut group, &table, cells);
        let surface = SurfaceGeometry::new(&table);
        let (from, to) = (tool(0, -0.001), tool(0, 0.0005));
        group.bench_function(BenchmarkId::new("detect", format!("{cells}cells")), |b| {
            b.iter(|| {
                let mut work = ContactWork::default();
                black_box(surface.detect(
                    0,
                    Some(black_box(&from)),
                    black_box(&to),
                    TOOL_RADIUS_M,
                    &mut work,
                ))
            })
        });
    }
    group.finish();
    println!(
        "loop state RAM: {} B (P = 1), {} B (P = 4), f32",
        core::mem::size_of::<PrecomputedLoop<'_, f32, 1, 1>>(),
        core::mem::size_of::<PrecomputedLoop<'_, f32, 4, 4>>()
    );
}

criterion_group!(benches, tick);
criterion_main!(benches);
