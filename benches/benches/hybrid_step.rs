//! The hybrid model (`kernel/src/hybrid`, RR-3510 §6.2) on the voxel-carved
//! liver-like organ (`organ_mesh`, 5868 tets, E = 5 kPa, ν = 0.4, 1000 kg/m³,
//! lowest vertices fixed),
//! f32, with dynamic fractions of about 10, 20 and 40 % of the tets (the
//! tets with the lowest centroid x: the left lobe first).
//!
//! - `step`: one symplectic-Euler step of the hybrid, of its tensor-mass
//!   region alone (its table, uncoupled), of the organ all tensor-mass; and
//!   `interface`: the coupling's share of a force pass (the coupled force
//!   pass minus the uncoupled one, `9c²` multiply-adds). Targets: hybrid ≤
//!   1.3 × (region alone + interface), and ≥ 3× faster than all
//!   tensor-mass at 20 %.
//! - `tick`: one haptic tick of the hybrid loop with a probe held on the
//!   pre-computed region, one on the tensor-mass region, and both (2 + 2
//!   contacts: 4), at each fraction. Target ≤ 2 µs, independent of the
//!   pre-computed region's size.
//! - `hybrid_hmatrix`, `force_pass_coupled_hmatrix`: the same with the
//!   interface's condensed stiffness hierarchical (`[tables] compress =
//!   "hmatrix"`, default tolerance).
//! - Printed after the groups: per fraction the regions' tets, the
//!   connection nodes, the three tables' sizes and build time, next to the
//!   organ's pure pre-computed table; and the condensed stiffness's scalars
//!   and the interface's bytes, dense and hierarchical.
//!
//! Run: `RUSTFLAGS="-C target-cpu=native" cargo bench -p palpate-benches --bench hybrid_step`.

use core::hint::black_box;
use std::time::Instant;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use nalgebra::Vector3;
use palpate::fem::material::Material;
use palpate::hybrid::hmatrix::InterfaceCompression;
use palpate::hybrid::owned::{OwnedHybridBuffers, with_hybrid_tissue};
use palpate::hybrid::{HybridOptions, HybridTables, build_hybrid};
use palpate::mesh::generate::{ORGAN_CUBE_M, organ_mesh};
use palpate::mesh::{MeshReport, TetMesh};
use palpate::table::build::{BuildOptions, build};
use palpate::table::compliance::Solver;
use palpate::table::file::Precision;
use palpate::tensor_mass::OwnedState;
use palpate_benches::haptic_config;
use palpate_kernel::PrecomputedTable;
use palpate_kernel::haptic::HybridLoop;
use palpate_kernel::hybrid::HybridModel;
use palpate_kernel::table::{CondensedStiffness, InterfaceTable, TensorMassTable};
use palpate_kernel::tensor_mass::{DynamicParams, Integrator, PhysicsConfig, TensorMassModel};

const FRACTIONS: [f64; 3] = [0.1, 0.2, 0.4];
const DT_S: f32 = 1e-5;

fn material() -> Material {
    Material::new(5000.0, 0.4).expect("material")
}

fn fix(mesh: &TetMesh) -> Vec<palpate::fix::FixPredicate> {
    let z_min = mesh
        .positions
        .iter()
        .map(|p| p[2])
        .fold(f64::INFINITY, f64::min);
    vec![format!("z<{}", z_min + 1e-6).parse().expect("predicate")]
}

fn params() -> DynamicParams<f32> {
    DynamicParams::linear(30.0, 0.2)
}

/// The `fraction` of the tets with the lowest centroid x.
fn dynamic_tets(mesh: &TetMesh, fraction: f64) -> Vec<bool> {
    let x = |t: usize| mesh.tet_centroid(t)[0];
    let mut order: Vec<usize> = (0..mesh.tets.len()).collect();
    order.sort_by(|&a, &b| x(a).total_cmp(&x(b)));
    let mut dynamic = vec![false; mesh.tets.len()];
    for &t in order
        .iter()
        .take((fraction * mesh.tets.len() as f64).round() as usize)
    {
        dynamic[t] = true;
    }
    dynamic
}

struct Built {
    fraction: f64,
    tables: HybridTables,
    /// The same with the interface's condensed stiffness hierarchical
    /// (`[tables] compress = "hmatrix"`, default tolerance and leaves).
    hmatrix: HybridTables,
    build_s: f64,
}

fn build_all(mesh: &TetMesh) -> Vec<Built> {
    FRACTIONS
        .iter()
        .map(|&fraction| {
            let options = HybridOptions::new(material(), 1000.0, fix(mesh), Precision::F32);
            let start = Instant::now();
            let tables = build_hybrid(
                mesh,
                &MeshReport::default(),
                &dynamic_tets(mesh, fraction),
                &options,
            )
            .expect("hybrid tables");
            let build_s = start.elapsed().as_secs_f64();
            let options = HybridOptions {
                interface_compression: Some(InterfaceCompression::default()),
                ..options
            };
            let hmatrix = build_hybrid(
                mesh,
                &MeshReport::default(),
                &dynamic_tets(mesh, fraction),
                &options,
            )
            .expect("hybrid tables");
            Built {
                fraction,
                tables,
                hmatrix,
                build_s,
            }
        })
        .collect()
}

/// Two touchable vertices of the top of each region, at least 8 mm apart:
/// the highest of the pre-computed table's touchable ones, and of the
/// tensor-mass region's surface vertices that are no connection node
/// (mesh numbers).
fn top_vertices(built: &HybridTables, mesh: &TetMesh) -> ([u32; 2], [u32; 2]) {
    let table = PrecomputedTable::<f32>::load(built.precomputed.bytes()).expect("table");
    let z = |v: &u32| mesh.positions[*v as usize][2];
    let two = |mut candidates: Vec<u32>| -> [u32; 2] {
        candidates.sort_by(|a, b| z(b).total_cmp(&z(a)));
        let first = candidates[0];
        let p = mesh.positions[first as usize];
        let far = |v: &&u32| {
            let q = mesh.positions[**v as usize];
            (0..3).map(|i| (p[i] - q[i]).powi(2)).sum::<f64>() > 0.008f64.powi(2)
        };
        [
            first,
            *candidates.iter().find(far).expect("a second vertex"),
        ]
    };
    let touchable = table.free_vertices()[..table.touchable_count()].to_vec();
    let surface = palpate::mesh::boundary_surface(mesh);
    let dynamic = surface
        .vertices
        .iter()
        .copied()
        .filter(|&v| {
            built.split.dynamic_index[v as usize].is_some()
                && !built.split.in_precomputed[v as usize]
        })
        .collect();
    (two(touchable), two(dynamic))
}

fn step(c: &mut Criterion) {
    let mesh = organ_mesh(ORGAN_CUBE_M);
    let built = build_all(&mesh);
    let mut group = c.benchmark_group("hybrid_step");
    let whole_file = palpate_benches::base_fixed_table(&mesh);
    let whole = TensorMassTable::<f32>::load(whole_file.bytes()).expect("table");
    let mut whole_state = OwnedState::for_table(&whole);
    let mut whole_model =
        TensorMassModel::new(whole, whole_state.buffers(), params()).expect("model");
    group.bench_function("all_tensor_mass", |b| {
        b.iter(|| whole_model.step(black_box(Integrator::SymplecticEuler), DT_S))
    });
    for b in &built {
        let label = format!("{:.0}%", b.fraction * 100.0);
        let dynamic = TensorMassTable::<f32>::load(b.tables.dynamic.bytes()).expect("table");
        let n = dynamic.vertex_count();
        let mut alone_state = OwnedState::for_table(&dynamic);
        let mut alone =
            TensorMassModel::new(dynamic, alone_state.buffers(), params()).expect("model");
        group.bench_function(BenchmarkId::new("region_alone", &label), |bench| {
            bench.iter(|| alone.step(black_box(Integrator::SymplecticEuler), DT_S))
        });
        let mut forces = vec![[0.0f32; 3]; n];
        let u = vec![[1e-4f32; 3]; n];
        group.bench_function(BenchmarkId::new("force_pass_alone", &label), |bench| {
            bench.iter(|| alone.elastic_forces_of(black_box(&u), &mut forces))
        });
        for (kind, tables) in [("", &b.tables), ("_hmatrix", &b.hmatrix)] {
            let precomputed =
                PrecomputedTable::<f32>::load(tables.precomputed.bytes()).expect("table");
            let dynamic = TensorMassTable::<f32>::load(tables.dynamic.bytes()).expect("table");
            let interface = InterfaceTable::<f32>::load(tables.interface.bytes()).expect("table");
            let mut state = OwnedState::for_table(&dynamic);
            let mut owned = OwnedHybridBuffers::for_tables(&precomputed, &dynamic, &interface);
            let model = TensorMassModel::new(dynamic, state.buffers(), params()).expect("model");
            let (coupling, _) = owned.buffers();
            let mut hybrid =
                HybridModel::new(model, precomputed, interface, coupling).expect("hybrid");
            group.bench_function(BenchmarkId::new(format!("hybrid{kind}"), &label), |bench| {
                bench.iter(|| hybrid.step(black_box(Integrator::SymplecticEuler), DT_S))
            });
            let name = format!("force_pass_coupled{kind}");
            group.bench_function(BenchmarkId::new(name, &label), |bench| {
                bench.iter(|| {
                    hybrid
                        .dynamic()
                        .elastic_forces_of(black_box(&u), &mut forces)
                })
            });
        }
    }
    group.finish();
    let start = Instant::now();
    let pure = build(
        &mesh,
        &MeshReport::default(),
        &BuildOptions::precomputed(material(), fix(&mesh), Solver::Cholesky, Precision::F32),
    )
    .expect("pre-computed table");
    let pure_s = start.elapsed().as_secs_f64();
    println!(
        "\norgan tables (f32): fraction, dynamic tets, connection nodes, pre-computed + tensor-mass + interface bytes, build s"
    );
    for b in &built {
        let s = &b.tables.split;
        println!(
            "{:4.0}% {:5} {:4} {:9} + {:8} + {:9} = {:9} bytes {:6.2} s",
            b.fraction * 100.0,
            s.dynamic_tet_count(),
            s.connection.len(),
            b.tables.precomputed.bytes().len(),
            b.tables.dynamic.bytes().len(),
            b.tables.interface.bytes().len(),
            b.tables.precomputed.bytes().len()
                + b.tables.dynamic.bytes().len()
                + b.tables.interface.bytes().len(),
            b.build_s
        );
    }
    println!(
        "pure pre-computed: {} bytes {pure_s:.2} s",
        pure.bytes.len()
    );
    println!(
        "\ninterface S, dense vs hierarchical (f32): fraction, connection nodes, S scalars (one multiply-add each per product), interface bytes"
    );
    for b in &built {
        let c = b.tables.split.connection.len();
        let interface = InterfaceTable::<f32>::load(b.hmatrix.interface.bytes()).expect("table");
        let CondensedStiffness::Hierarchical { blocks, .. } = interface.condensed() else {
            panic!("a dense interface");
        };
        println!(
            "{:4.0}% {c:4} {:8} vs {:8} scalars, {:9} vs {:9} bytes",
            b.fraction * 100.0,
            9 * c * c,
            blocks.data_len(),
            b.tables.interface.bytes().len(),
            b.hmatrix.interface.bytes().len(),
        );
    }
}

fn tick(c: &mut Criterion) {
    let mesh = organ_mesh(ORGAN_CUBE_M);
    let built = build_all(&mesh);
    let mut group = c.benchmark_group("hybrid_tick");
    for b in &built {
        let label = format!("{:.0}%", b.fraction * 100.0);
        let (p, d) = top_vertices(&b.tables, &mesh);
        let at = |v: u32| {
            let x = mesh.positions[v as usize].map(|c| c as f32);
            Vector3::new(x[0], x[1], x[2] + palpate_benches::TOOL_RADIUS_M - 0.0005)
        };
        tick_case::<1>(&mut group, "precomputed_1", &label, &b.tables, [at(p[0])]);
        tick_case::<1>(&mut group, "dynamic_1", &label, &b.tables, [at(d[0])]);
        tick_case::<4>(
            &mut group,
            "both_4",
            &label,
            &b.tables,
            [at(p[0]), at(p[1]), at(d[0]), at(d[1])],
        );
    }
    group.finish();
}

/// Benches one tick of the hybrid loop with `P` probes held 0.5 mm into
/// the surface at `tools` (lowered from 1 cm above, one physics update).
fn tick_case<const P: usize>(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    name: &str,
    label: &str,
    tables: &HybridTables,
    tools: [Vector3<f32>; P],
) {
    let files = [&tables.precomputed, &tables.dynamic, &tables.interface];
    let physics = PhysicsConfig::new(Integrator::SymplecticEuler, DT_S, 1);
    with_hybrid_tissue::<f32, P, P, _>(files, params(), physics, |tissue| {
        let mut haptic = HybridLoop::<f32, P, P>::new(tissue, haptic_config()).expect("loop");
        for k in 0..=20 {
            let lift = 0.01 * (1.0 - k as f32 / 20.0);
            haptic.tick(&tools.map(|t| t + Vector3::new(0.0, 0.0, lift)));
        }
        haptic.physics_update().expect("update");
        let contacts = haptic.tick(&tools).contacts as usize;
        assert_eq!(contacts, P, "{name} at {label}: contacts made");
        group.bench_function(BenchmarkId::new(name, label), |bench| {
            bench.iter(|| haptic.tick(black_box(&tools)))
        });
    })
    .expect("hybrid tissue");
}

criterion_group!(benches, step, tick);
criterion_main!(benches);
