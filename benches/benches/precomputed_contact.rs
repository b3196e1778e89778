//! The pre-computed model's step (`kernel/src/precomputed`), f32 tables (the
//! firmware precision) of tissue cubes with the base fixed.
//!
//! - `force_path`: `contact_forces::<4>` for m = 1..=4 vertex contacts and one
//!   barycentric contact, on two mesh sizes (its cost depends on m only).
//!   Target (the pre-computed model's speed target): at most 1 µs for up to 4 contacts.
//! - `displacement_update`: `free_displacements` (free-index order) and
//!   `displacements` (vertex order, the call a renderer makes) for m = 1 and 4
//!   vertex contacts on three mesh sizes, each next to a `copy_from_slice` of
//!   the bytes it reads and writes, measured in the same run. Bytes, f32
//!   tables (`add_column_rows` in `kernel/src/precomputed/model.rs`):
//!   per contact vertex `k` one compliance column, `F` blocks of 9 f32
//!   (36 bytes): rows `n ≤ k` contiguous in the packed surface part, rows
//!   `k < n < S` one block each from column `n` (strided), interior rows
//!   contiguous. `free_displacements` writes `F` outputs of 12 bytes, so its
//!   copy moves `m·36·F + 12·F` bytes; `displacements` also reads the
//!   free-vertex list (4 bytes per free vertex) and writes all `N` vertices
//!   (12 bytes each), so its copy moves `m·36·F + 4·F + 12·N` bytes.
//!   Target: within 1.5× of the copy. Both ratios are printed after the group
//!   (medians of 31 `Instant` batches, criterion does not compute ratios).
//!
//! Run: `cargo bench -p palpate-benches --bench precomputed_contact`.

use core::hint::black_box;
use std::time::Instant;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use nalgebra::Vector3;
use palpate::table::load::{AnyModel, TableFile};
use palpate_benches::{cube_table, top_vertices};
use palpate_kernel::{Constraint, MAX_CONTACTS, PrecomputedModel};

fn model_of(file: &TableFile) -> PrecomputedModel<'_, f32> {
    match file.model().expect("valid table") {
        AnyModel::F32(model) => model,
        AnyModel::F64(_) => unreachable!("benches build f32 tables"),
    }
}

fn contacts(cells: usize, m: usize) -> Vec<Constraint<f32>> {
    top_vertices(cells)
        .iter()
        .take(m)
        .map(|&v| Constraint::at_vertex(v, Vector3::new(0.0005, -0.0003, -0.004)))
        .collect()
}

fn force_path(c: &mut Criterion) {
    let mut group = c.benchmark_group("force_path");
    for cells in [6, 12] {
        let file = TableFile::from_bytes(&cube_table(cells).bytes);
        let model = model_of(&file);
        let vertices = model.table().vertex_count();
        for m in 1..=MAX_CONTACTS {
            let set = contacts(cells, m);
            let id = BenchmarkId::new(format!("{m}_contacts"), format!("{vertices}v"));
            group.bench_function(id, |b| {
                b.iter(|| {
                    model
                        .contact_forces::<MAX_CONTACTS>(black_box(&set))
                        .expect("solve")
                })
            });
        }
        let [a, ..] = top_vertices(cells);
        let n = cells as u32 + 1;
        // A top-face triangle of the Kuhn split: (i, j), (i+1, j), (i+1, j+1).
        let triangle = [a, a + 1, a + n + 1];
        let set = [Constraint::on_triangle(
            triangle,
            [0.2, 0.3, 0.5],
            Vector3::new(0.0, 0.0, -0.003),
        )];
        let id = BenchmarkId::new("1_barycentric", format!("{vertices}v"));
        group.bench_function(id, |b| {
            b.iter(|| {
                model
                    .contact_forces::<MAX_CONTACTS>(black_box(&set))
                    .expect("solve")
            })
        });
    }
    group.finish();
}

/// Median wall time of `f` over `runs` batches of `reps` calls, s per call.
fn median_time(runs: usize, reps: usize, mut f: impl FnMut()) -> f64 {
    let mut times: Vec<f64> = (0..runs)
        .map(|_| {
            let start = Instant::now();
            for _ in 0..reps {
                f();
            }
            start.elapsed().as_secs_f64() / reps as f64
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[runs / 2]
}

fn displacement_update(c: &mut Criterion) {
    let mut group = c.benchmark_group("displacement_update");
    let mut ratios = Vec::new();
    for cells in [6, 12, 16] {
        let file = TableFile::from_bytes(&cube_table(cells).bytes);
        let model = model_of(&file);
        let vertices = model.table().vertex_count();
        let free = model.table().free_count();
        let mut out = vec![[0.0f32; 3]; free];
        let mut by_vertex = vec![[0.0f32; 3]; vertices];
        for m in [1, 4] {
            let solution = model
                .contact_forces::<MAX_CONTACTS>(&contacts(cells, m))
                .expect("solve");
            let bytes = m * free * 36 + 12 * free;
            let bytes_vertex_order = m * free * 36 + 4 * free + 12 * vertices;
            let source = vec![1u8; bytes_vertex_order.max(bytes)];
            let mut target = vec![0u8; bytes_vertex_order.max(bytes)];
            let size = format!("{vertices}v");
            group.bench_function(BenchmarkId::new(format!("{m}_contacts"), &size), |b| {
                b.iter(|| model.free_displacements(black_box(&solution), &mut out))
            });
            group.bench_function(
                BenchmarkId::new(format!("{m}_contacts_vertex_order"), &size),
                |b| b.iter(|| model.displacements(black_box(&solution), &mut by_vertex)),
            );
            group.bench_function(
                BenchmarkId::new(format!("memcpy_{m}_contacts"), &size),
                |b| {
                    b.iter(|| {
                        target[..bytes].copy_from_slice(black_box(&source[..bytes]));
                    })
                },
            );
            group.bench_function(
                BenchmarkId::new(format!("memcpy_{m}_contacts_vertex_order"), &size),
                |b| {
                    b.iter(|| {
                        target[..bytes_vertex_order]
                            .copy_from_slice(black_box(&source[..bytes_vertex_order]));
                    })
                },
            );
            let reps = (2_000_000 / bytes).max(3);
            let update = median_time(31, reps, || {
                model
                    .free_displacements(black_box(&solution), &mut out)
                    .expect("buffer");
            });
            let copy = median_time(31, reps, || {
                target[..bytes].copy_from_slice(black_box(&source[..bytes]));
            });
            ratios.push(("free", vertices, m, bytes, update, copy));
            let update = median_time(31, reps, || {
                model
                    .displacements(black_box(&solution), &mut by_vertex)
                    .expect("buffer");
            });
            let copy = median_time(31, reps, || {
                target[..bytes_vertex_order]
                    .copy_from_slice(black_box(&source[..bytes_vertex_order]));
            });
            ratios.push(("vertex", vertices, m, bytes_vertex_order, update, copy));
        }
    }
    group.finish();
    let cold = cold_ratio(16);
    println!("\ndisplacement update vs memcpy of the bytes it reads and writes (median of 31):");
    println!("order   vertices  m   bytes       update      memcpy      ratio");
    for (order, vertices, m, bytes, update, copy) in ratios {
        println!(
            "{order:6}  {vertices:8}  {m}  {bytes:9}  {:8.2} us  {:8.2} us  {:5.2}",
            update * 1e6,
            copy * 1e6,
            update / copy
        );
    }
    let (vertices, bytes, update, copy) = cold;
    println!(
        "cold, 1 contact walking over every touchable vertex: {vertices} vertices, {bytes} bytes, \
         update {:.1} us, memcpy {:.1} us, ratio {:.2}",
        update * 1e6,
        copy * 1e6,
        update / copy
    );
}

/// The cold-cache ratio on the `cells³` cube: one contact per call, on the
/// next touchable vertex each time; the copy reads the next `bytes` of a
/// 256 MB buffer each time. Returns `(N, bytes, update s, copy s)`.
fn cold_ratio(cells: usize) -> (usize, usize, f64, f64) {
    let file = TableFile::from_bytes(&cube_table(cells).bytes);
    let model = model_of(&file);
    let vertices = model.table().vertex_count();
    let touchable = &model.table().free_vertices()[..model.table().touchable_count()];
    let solutions: Vec<_> = touchable
        .iter()
        .map(|&v| {
            let contact = Constraint::at_vertex(v, Vector3::new(0.0, 0.0, -0.002));
            model
                .contact_forces::<MAX_CONTACTS>(&[contact])
                .expect("solve")
        })
        .collect();
    let free = model.table().free_count();
    let mut out = vec![[0.0f32; 3]; free];
    let bytes = free * 36 + 12 * free;
    let source = vec![1u8; 256 << 20];
    let mut target = vec![0u8; bytes];
    let calls = touchable.len();
    let (mut next_solution, mut next_offset) = (0, 0);
    let update = median_time(15, calls, || {
        next_solution = (next_solution + 1) % solutions.len();
        model
            .free_displacements(black_box(&solutions[next_solution]), &mut out)
            .expect("buffer");
    });
    let copy = median_time(15, calls, || {
        next_offset = (next_offset + bytes) % (source.len() - bytes);
        target.copy_from_slice(black_box(&source[next_offset..next_offset + bytes]));
    });
    (vertices, bytes, update, copy)
}

criterion_group!(benches, force_path, displacement_update);
criterion_main!(benches);
