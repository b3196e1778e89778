//! The pre-computed model's step on compressed tables (`kernel/src/table/compressed.rs`,
//! decoded on the fly by `kernel/src/precomputed/model.rs`) next to the f32 table of the same
//! compliance, on the built-in scene's block (1183 vertices, 409 touchable) and the built-in
//! hybrid scene's organ all pre-computed (1386 vertices, 612 touchable):
//!
//! - `force_path`: `contact_forces::<4>` for m = 1 and 4 vertex contacts and one barycentric
//!   contact (the haptic loop's kind: 9 blocks);
//! - `displacement_update`: `free_displacements` for m = 1 and 4 vertex contacts (`F` blocks per
//!   contact vertex).
//!
//! Tables: `f32`; `f16` and `q16` (`--compress`, nothing dropped); `q16-drop0.05`
//! (`--drop-below 0.05`: the interior blocks through the kept-block bitmap); `q16-contact-drop0.05`
//! (`--contact-blocks dropped` too: the force path's blocks through the bitmap as well);
//! `q16-surface-only` (`--drop-below 0.99`: every interior block dropped).
//!
//! Run: `cargo bench -p palpate-benches --bench precomputed_compressed`.

use core::hint::black_box;
use core::time::Duration;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use nalgebra::Vector3;
use palpate::scene::Scene;
use palpate::table::compress::{BlockCode, Compression, ContactBlocks};
use palpate::table::load::{AnyModel, TableFile};
use palpate_benches::scene_table;
use palpate_kernel::table::VertexSlot;
use palpate_kernel::{Constraint, MAX_CONTACTS, PrecomputedModel};

/// The compressions benched, by name (`None`: the f32 table).
fn settings() -> Vec<(&'static str, Option<Compression>)> {
    let q16 = |drop_below, contact| Compression {
        code: BlockCode::Q16,
        drop_below,
        contact,
        tolerance: palpate::table::hmatrix::DEFAULT_TOLERANCE,
    };
    vec![
        ("f32", None),
        (
            "f16",
            Some(Compression {
                code: BlockCode::F16,
                drop_below: 0.0,
                contact: ContactBlocks::Coded,
                tolerance: palpate::table::hmatrix::DEFAULT_TOLERANCE,
            }),
        ),
        ("q16", Some(q16(0.0, ContactBlocks::Coded))),
        ("q16-drop0.05", Some(q16(0.05, ContactBlocks::Coded))),
        (
            "q16-contact-drop0.05",
            Some(q16(0.05, ContactBlocks::Dropped)),
        ),
        ("q16-surface-only", Some(q16(0.99, ContactBlocks::Coded))),
    ]
}

fn model_of(file: &TableFile) -> PrecomputedModel<'_, f32> {
    match file.model().expect("valid table") {
        AnyModel::F32(model) => model,
        AnyModel::F64(_) => unreachable!("benches build f32 tables"),
    }
}

/// `m` vertex contacts spread over the touchable vertices (free indices `0, S/4, S/2, 3S/4`),
/// each pressed 4 mm down and slightly sideways.
fn vertex_contacts(model: &PrecomputedModel<'_, f32>, m: usize) -> Vec<Constraint<f32>> {
    let s = model.table().touchable_count();
    let touchable = &model.table().free_vertices()[..s];
    (0..m)
        .map(|p| Constraint::at_vertex(touchable[p * s / 4], Vector3::new(0.0005, -0.0003, -0.004)))
        .collect()
}

/// One barycentric contact on the first surface triangle whose three vertices are touchable.
fn triangle_contact(model: &PrecomputedModel<'_, f32>) -> Constraint<f32> {
    let table = model.table();
    let touchable = |v: u32| matches!(table.slot(v), Some(VertexSlot::Free(i)) if i.get() < table.touchable_count());
    let triangle = *table
        .surface_triangles()
        .iter()
        .find(|t| t.iter().all(|&v| touchable(v)))
        .expect("a touchable triangle");
    Constraint::on_triangle(triangle, [0.2, 0.3, 0.5], Vector3::new(0.0, 0.0, -0.003))
}

fn compressed(c: &mut Criterion) {
    for (mesh, scene) in [
        ("block", Scene::built_in()),
        ("organ", Scene::built_in_hybrid()),
    ] {
        let mut force = c.benchmark_group(format!("force_path_{mesh}"));
        force
            .warm_up_time(Duration::from_millis(500))
            .measurement_time(Duration::from_secs(2));
        let tables: Vec<(&str, TableFile)> = settings()
            .into_iter()
            .map(|(name, compression)| {
                (
                    name,
                    TableFile::from_bytes(&scene_table(&scene, compression).bytes),
                )
            })
            .collect();
        for (name, file) in &tables {
            let model = model_of(file);
            for m in [1, MAX_CONTACTS] {
                let set = vertex_contacts(&model, m);
                force.bench_function(BenchmarkId::new(format!("{m}_contacts"), name), |b| {
                    b.iter(|| {
                        model
                            .contact_forces::<MAX_CONTACTS>(black_box(&set))
                            .expect("solve")
                    })
                });
            }
            let set = [triangle_contact(&model)];
            force.bench_function(BenchmarkId::new("1_barycentric", name), |b| {
                b.iter(|| {
                    model
                        .contact_forces::<MAX_CONTACTS>(black_box(&set))
                        .expect("solve")
                })
            });
        }
        force.finish();
        let mut update = c.benchmark_group(format!("displacement_update_{mesh}"));
        update
            .warm_up_time(Duration::from_millis(500))
            .measurement_time(Duration::from_secs(2));
        for (name, file) in &tables {
            let model = model_of(file);
            let mut out = vec![[0.0f32; 3]; model.table().free_count()];
            for m in [1, MAX_CONTACTS] {
                let solution = model
                    .contact_forces::<MAX_CONTACTS>(&vertex_contacts(&model, m))
                    .expect("solve");
                update.bench_function(BenchmarkId::new(format!("{m}_contacts"), name), |b| {
                    b.iter(|| model.free_displacements(black_box(&solution), &mut out))
                });
            }
        }
        update.finish();
    }
}

criterion_group!(benches, compressed);
criterion_main!(benches);
