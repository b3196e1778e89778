//! Run-time CPU-feature dispatch (`host-harness/src/dispatch.rs`): the
//! kernel's passes run at every level this CPU has
//! (`HostDispatch::available()`: AVX2 + FMA, AVX-512) give the same results
//! as the portable passes.
//!
//! Tolerance: none, bit for bit. Rust never contracts `a * b + c` into a
//! fused multiply-add, so code compiled for AVX2, FMA or AVX-512 performs
//! the same IEEE-754 operations in the same order, in wider registers; the
//! kernel's passes have no reductions the compiler may reorder (no
//! fast-math). A difference here means a pass computes differently when
//! dispatched, which the firmware comparison (portable on both sides) would
//! not see. On a CPU without AVX2 and FMA the only level is the portable one
//! and the test compares it with itself (the levels are printed). The
//! pre-computed update is compared on dense and compressed tables (f16,
//! q16 with dropped blocks: the kernel decodes them inside the dispatched
//! pass), linear and quasi-non-linear.

use nalgebra::Vector3;
use palpate::dispatch::HostDispatch;
use palpate::fem::material::Material;
use palpate::mesh::generate::{box_mesh, cylinder_mesh};
use palpate::mesh::{MeshReport, TetMesh};
use palpate::table::build::{BuildOptions, DEFAULT_LIST_TOOL_RADIUS_M, TableKindOptions, build};
use palpate::table::compliance::Solver;
use palpate::table::compress::{BlockCode, Compression, ContactBlocks};
use palpate::table::file::Precision;
use palpate::table::load::TableFile;
use palpate::tensor_mass::OwnedState;
use palpate::tensor_mass::run::host_params;
use palpate::threads::{OwnedSplit, split_model};
use palpate_kernel::math::{Dispatch, Portable};
use palpate_kernel::precomputed::{QuasiNonLinear, Remap};
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::tensor_mass::{ElasticLaw, Integrator, TensorMassModel};
use palpate_kernel::{Constraint, MAX_CONTACTS, PrecomputedModel, PrecomputedTable, Real};

/// The meshes: the cylinder of 6 × 6 × 4 cells (245 vertices, 864 tets:
/// 108 full blocks of 8 tets in the per-tet pass) and a 3³-cell box (64
/// vertices, 162 tets: the last block has 2 tets, and 3 parts do not divide
/// the blocks evenly). Shared with `host::threads`.
pub fn meshes() -> [TetMesh; 2] {
    [cylinder_mesh(0.04, 3, 4), box_mesh([3; 3], [0.03; 3])]
}

/// The tensor-mass table options of the stepped cases (E 5 kPa, ν 0.4, the base fixed).
pub fn options(precision: Precision) -> BuildOptions {
    BuildOptions::tensor_mass(
        Material::new(5000.0, 0.4).unwrap(),
        1000.0,
        vec!["z<1e-9".parse().unwrap()],
        precision,
    )
}

/// The displacements and velocities after 4 steps of `integrator` from a
/// 20 % shear with a load on the top and tets 5 and 17 removed, the passes
/// through `dispatch` (the per-tet pass split when it has more than one
/// part). Shared with `host::threads`.
pub fn stepped<T: Real>(
    mesh: &TetMesh,
    file: &TableFile,
    law: ElasticLaw,
    penalty: Option<f64>,
    integrator: Integrator,
    dispatch: impl Dispatch,
) -> Vec<[T; 3]> {
    let table = TensorMassTable::<T>::load(file.bytes()).unwrap();
    let mut state = OwnedState::for_table(&table);
    let mut split: Option<OwnedSplit<T>> = None;
    let params = host_params(&mesh.positions, 3.0)
        .with_law(law)
        .with_incompressibility(penalty.map(T::of_f64));
    let model = TensorMassModel::new(table, state.buffers(), params).unwrap();
    let mut model = split_model(model, &mut split, dispatch.parts()).unwrap();
    for tet in [5, 17] {
        model.remove_tet(tet).unwrap();
    }
    let top = mesh.positions.len() as u32 - 1;
    for (v, p) in mesh.positions.iter().enumerate() {
        let d = Vector3::new(T::of_f64(0.2 * p[2]), T::zero(), T::of_f64(-0.05 * p[2]));
        if model.impose(v as u32, d).is_ok() {
            model.release(v as u32).unwrap();
        }
    }
    model
        .set_external_force(top, Vector3::new(T::zero(), T::of_f64(0.01), T::zero()))
        .unwrap();
    for _ in 0..4 {
        model
            .step_with(dispatch, integrator, T::of_f64(2e-4))
            .unwrap();
    }
    let mut out = model.displacements_m().unwrap().to_vec();
    out.extend_from_slice(model.velocities_m_s().unwrap());
    out
}

fn check_steps<T: Real>(mesh: &TetMesh, precision: Precision, detected: HostDispatch) -> usize {
    let file = TableFile::from_bytes(
        &build(mesh, &MeshReport::default(), &options(precision))
            .unwrap()
            .bytes,
    );
    let mut compared = 0;
    for law in ElasticLaw::ALL {
        for penalty in [None, Some(0.05)] {
            if law == ElasticLaw::Linear && penalty.is_some() {
                continue;
            }
            for integrator in Integrator::ALL {
                let portable = stepped::<T>(mesh, &file, law, penalty, integrator, Portable);
                let dispatched = stepped::<T>(mesh, &file, law, penalty, integrator, detected);
                assert!(
                    portable.iter().flatten().any(|x| *x != T::zero()),
                    "the state moved"
                );
                let same = portable
                    .iter()
                    .flatten()
                    .zip(dispatched.iter().flatten())
                    .all(|(a, b)| bits(*a) == bits(*b));
                assert!(
                    same,
                    "{law:?} penalty {penalty:?} {integrator:?} {precision:?}: dispatched ({}) differs from portable",
                    detected.name()
                );
                compared += 1;
            }
        }
    }
    compared
}

/// The bit pattern of a scalar, as f64 bits (f32 widened exactly).
pub fn bits<T: Real>(x: T) -> u64 {
    x.as_f64().to_bits()
}

#[test]
fn dispatched_steps_equal_portable_steps_bit_for_bit() {
    let levels = HostDispatch::available();
    println!(
        "dispatch levels on this CPU: {:?}",
        levels.iter().map(|l| l.name()).collect::<Vec<_>>()
    );
    let mut compared = 0;
    for &level in &levels {
        for mesh in meshes() {
            compared += check_steps::<f32>(&mesh, Precision::F32, level);
            compared += check_steps::<f64>(&mesh, Precision::F64, level);
        }
    }
    // 9 laws (linear; St Venant-Kirchhoff per tet and split terms,
    // co-rotational and neo-Hookean, each with and without the penalty) × 4
    // integrators × 2 precisions × 2 meshes, per level.
    assert_eq!(compared, 9 * 4 * 2 * 2 * levels.len());
}

/// The pre-computed tables of the update check: dense, and (f32) compressed
/// with f16 codes, and with q16 codes whose interior blocks below 0.2 of
/// their column's largest are dropped (the kept-block bitmap read).
fn update_tables(mesh: &TetMesh, precision: Precision) -> Vec<(String, TableFile)> {
    let dense = BuildOptions::precomputed(
        Material::new(5000.0, 0.4).unwrap(),
        vec!["z<1e-9".parse().unwrap()],
        Solver::Cholesky,
        precision,
    );
    let coded = [
        (BlockCode::F16, 0.0, ContactBlocks::Coded),
        (BlockCode::Q16, 0.2, ContactBlocks::Coded),
    ];
    let compressed = coded
        .into_iter()
        .filter(|_| precision == Precision::F32)
        .map(|(code, drop_below, contact)| {
            let compression = Compression {
                code,
                drop_below,
                contact,
                tolerance: palpate::table::hmatrix::DEFAULT_TOLERANCE,
            };
            let options = BuildOptions {
                kind: TableKindOptions::Precomputed {
                    solver: Solver::Cholesky,
                    compression: Some(compression),
                    tool_radius_m: DEFAULT_LIST_TOOL_RADIUS_M,
                },
                ..dense.clone()
            };
            (format!("{code:?} drop {drop_below}"), options)
        });
    core::iter::once(("dense".to_owned(), dense.clone()))
        .chain(compressed)
        .map(|(name, options)| {
            let bytes = build(mesh, &MeshReport::default(), &options).unwrap().bytes;
            (name, TableFile::from_bytes(&bytes))
        })
        .collect()
}

#[test]
fn dispatched_displacement_update_equals_the_portable_one_bit_for_bit() {
    let [mesh, _] = meshes();
    let mut compared = 0;
    for (detected, precision) in HostDispatch::available()
        .into_iter()
        .flat_map(|level| [(level, Precision::F32), (level, Precision::F64)])
    {
        for (name, file) in update_tables(&mesh, precision) {
            println!("{} {precision:?} {name}", detected.name());
            if name.starts_with("Q16") {
                // Blocks are dropped: the pass reads the kept-block bitmap.
                let table = PrecomputedTable::<f32>::load(file.bytes()).unwrap();
                let interior = table.interior_blocks();
                assert!(interior.stored_len() < interior.len());
            }
            // Linear, then quasi-non-linear (the remap after the dispatched pass).
            for remap in [false, true] {
                match precision {
                    Precision::F32 => check_update::<f32>(&file, detected, remap),
                    Precision::F64 => check_update::<f64>(&file, detected, remap),
                }
                compared += 1;
            }
        }
    }
    // Per level: dense f32 and f64, f16 and q16 with drops, each linear and remapped.
    assert_eq!(compared, 2 * 4 * HostDispatch::available().len());
}

/// A quasi-non-linear remap that changes every displacement it touches:
/// `φ(x) = x + 50 x²` (m), `ψ(x) = 1.5 x` (N).
fn remap<T: Real>() -> QuasiNonLinear<T> {
    let f = T::of_f64;
    QuasiNonLinear {
        radial: Remap::new([f(1.0), f(50.0), f(0.0), f(0.0), f(0.0)], f(0.01)).unwrap(),
        force: Remap::new([f(1.5), f(0.0), f(0.0), f(0.0), f(0.0)], f(1.0)).unwrap(),
    }
}

fn check_update<T: Real>(file: &TableFile, detected: HostDispatch, remapped: bool) {
    let mut model = PrecomputedModel::new(PrecomputedTable::<T>::load(file.bytes()).unwrap());
    if remapped {
        model = model.with_remap(remap());
    }
    let touchable = &model.table().free_vertices()[..model.table().touchable_count()];
    // Four contacts spread over the touchable vertices.
    let step = touchable.len() / MAX_CONTACTS;
    let contacts: Vec<Constraint<T>> = (0..MAX_CONTACTS)
        .map(|i| {
            let d = Vector3::new(
                T::of_f64(1e-3),
                T::of_f64(-5e-4),
                T::of_f64(-2e-3 * (i + 1) as f64),
            );
            Constraint::at_vertex(touchable[i * step], d)
        })
        .collect();
    let solution = model.contact_forces::<MAX_CONTACTS>(&contacts).unwrap();
    let free = model.table().free_count();
    let vertices = model.table().vertex_count();
    let (mut a, mut b) = (vec![[T::zero(); 3]; free], vec![[T::zero(); 3]; free]);
    model
        .free_displacements_with(Portable, &solution, &mut a)
        .unwrap();
    model
        .free_displacements_with(detected, &solution, &mut b)
        .unwrap();
    assert!(a.iter().flatten().any(|x| *x != T::zero()));
    if remapped {
        // The remap did change the field (else the remapped check is the linear one).
        let linear = PrecomputedModel::new(*model.table());
        let solution = linear.contact_forces::<MAX_CONTACTS>(&contacts).unwrap();
        let mut l = vec![[T::zero(); 3]; free];
        linear.free_displacements(&solution, &mut l).unwrap();
        assert_ne!(a, l);
    }
    assert!(
        a.iter()
            .flatten()
            .zip(b.iter().flatten())
            .all(|(x, y)| bits(*x) == bits(*y))
    );
    let (mut a, mut b) = (
        vec![[T::zero(); 3]; vertices],
        vec![[T::zero(); 3]; vertices],
    );
    model
        .displacements_with(Portable, &solution, &mut a)
        .unwrap();
    model
        .displacements_with(detected, &solution, &mut b)
        .unwrap();
    assert!(
        a.iter()
            .flatten()
            .zip(b.iter().flatten())
            .all(|(x, y)| bits(*x) == bits(*y))
    );
    // And the default (portable) entry points are the same passes.
    let mut c = vec![[T::zero(); 3]; vertices];
    model.displacements(&solution, &mut c).unwrap();
    assert_eq!(a, c);
}
