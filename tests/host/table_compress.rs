//! Compressed compliance tables built by the host (`host-harness/src/table/compress.rs`) and
//! read by the kernel: the binary16 encoder against the kernel's decoder (every code, the
//! rounding ties), each stored value against the f64 compliance within the code's stated bound
//! (q16: half a quantum; f16: half an ulp), the dropped blocks exactly those below the
//! threshold, the contact forces against the f64 solve within the bound the code's error and
//! each block's condition number give, the errors stored in the record equal to a measurement
//! of the table, and the haptic loop's force over the scenes' generated trajectories against
//! the f32 table's.

use nalgebra::{Matrix3, Vector3};
use palpate::budget::trajectories;
use palpate::fem::assembly::FreeOrdering;
use palpate::fix::fixed_vertices;
use palpate::mesh::{MeshReport, TetMesh, boundary_surface, read_mesh};
use palpate::scene::{ModelSpec, Scene, Trajectory};
use palpate::session::options::precomputed_options;
use palpate::session::run::ticks;
use palpate::session::setup::loop_config;
use palpate::session::tool_points::{ForToolPoints, with_tool_points};
use palpate::table::build::{BuildOptions, DEFAULT_LIST_TOOL_RADIUS_M, TableKindOptions, build};
use palpate::table::compliance::{Compliance, Solver, compute_compliance};
use palpate::table::compress::{BlockCode, Compression, ContactBlocks, f16_bits, measure};
use palpate::table::load::TableFile;
use palpate_kernel::haptic::PrecomputedLoop;
use palpate_kernel::precomputed::PrecomputedTissue;
use palpate_kernel::table::format::{f16_to_f32, surface_block_index};
use palpate_kernel::{Constraint, PrecomputedModel, PrecomputedTable};
use palpate_tests::reference_dir;

#[test]
fn f16_encoder_inverts_the_decoder_and_rounds_ties_to_even() {
    for code in 0..=u16::MAX {
        if (code >> 10) & 0x1f == 0x1f {
            continue;
        }
        assert_eq!(f16_bits(f64::from(f16_to_f32(code))), code, "{code:#06x}");
    }
    let cases = [
        (1.0 + 2f64.powi(-11), 0x3c00), // halfway 1 → 1 + 2^-10: to even, 1
        (1.0 + 3.0 * 2f64.powi(-11), 0x3c02), // halfway 1 + 2^-10 → 1 + 2^-9: to even
        (1.0 + 1.5 * 2f64.powi(-11), 0x3c01), // above halfway: up
        (2f64.powi(-25), 0x0000),       // half the smallest subnormal: to even, 0
        (3.0 * 2f64.powi(-25), 0x0002), // halfway 1 → 2 quanta: to even
        (2f64.powi(-14) - 2f64.powi(-25), 0x0400), // halfway to the smallest normal: even
        (65504.0, 0x7bff),
        (65519.99, 0x7bff), // below halfway to 2^16
        (65520.0, 0x7c00),  // halfway to 2^16: infinity
        (-1e9, 0xfc00),
        (-2.0, 0xc000),
        (-0.0, 0x8000),
    ];
    for (x, code) in cases {
        assert_eq!(f16_bits(x), code, "{x:e}");
    }
    assert_eq!(f16_bits(f64::NAN) & 0x7e00, 0x7e00);
}

/// The reference cube (216 vertices, 116 touchable) and its f64 compliance.
fn cube() -> (TetMesh, MeshReport, BuildOptions, Compliance, usize) {
    let (mesh, report) = read_mesh(&reference_dir().join("meshes/cube.msh")).expect("cube.msh");
    let options = BuildOptions::precomputed(
        palpate::fem::material::Material::new(5000.0, 0.45).expect("material"),
        vec!["z<0.001".parse().expect("predicate")],
        Solver::Cholesky,
        palpate::table::file::Precision::F32,
    );
    let (compliance, ordering) = f64_compliance(&mesh, &report, &options);
    (mesh, report, options, compliance, ordering.touchable_count)
}

/// The f64 compliance a build with `options` computes (uncompressed: the
/// touchable vertices in ascending order), and its free ordering.
pub(super) fn f64_compliance(
    mesh: &TetMesh,
    report: &MeshReport,
    options: &BuildOptions,
) -> (Compliance, FreeOrdering) {
    let (fixed, _) = fixed_vertices(&mesh.positions, &options.fix, &report.unreferenced_vertices);
    let surface = boundary_surface(mesh);
    let ordering = FreeOrdering::new(mesh.positions.len(), &fixed, &surface.vertices);
    let materials = options.materials_for(mesh.tets.len()).expect("materials");
    let compliance = compute_compliance(
        &mesh.positions,
        &mesh.tets,
        &materials,
        &ordering,
        Solver::Cholesky,
        false,
    )
    .expect("compliance");
    (compliance, ordering)
}

/// The table of `mesh` built with `options`, compressed as `compression` says.
fn table_bytes(
    mesh: &TetMesh,
    report: &MeshReport,
    options: &BuildOptions,
    compression: Option<Compression>,
) -> TableFile {
    let options = BuildOptions {
        kind: TableKindOptions::Precomputed {
            solver: Solver::Cholesky,
            compression,
            tool_radius_m: DEFAULT_LIST_TOOL_RADIUS_M,
        },
        ..options.clone()
    };
    TableFile::from_bytes(&build(mesh, report, &options).expect("build").bytes)
}

fn compression(code: BlockCode, drop_below: f64, contact: ContactBlocks) -> Compression {
    Compression {
        code,
        drop_below,
        contact,
        tolerance: palpate::table::hmatrix::DEFAULT_TOLERANCE,
    }
}

fn largest(b: &[f64; 9]) -> f64 {
    b.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// Every stored value is the f64 compliance's within the code's bound: q16, half a quantum `s`
/// plus the f32 product's rounding (`2⁻²⁴` of the value); f16, half an ulp of binary16 (`2⁻¹¹`
/// relative, or `2⁻²⁵ s` among the subnormals) plus the same rounding. The diagonal blocks are
/// coded symmetrized, so they are compared with `(C + Cᵀ)/2`.
#[test]
fn stored_values_are_within_half_a_quantum() {
    let (mesh, report, options, compliance, s) = cube();
    let rows = compliance.interior.len() / s;
    for code in [BlockCode::Q16, BlockCode::F16] {
        let file = table_bytes(
            &mesh,
            &report,
            &options,
            Some(compression(code, 0.0, ContactBlocks::Coded)),
        );
        let table = PrecomputedTable::<f32>::load(file.bytes()).expect("load");
        let mut worst = 0.0f64;
        let mut check = |stored: [f32; 9], exact: &[f64; 9], column_max: f64| {
            let scale = match code {
                BlockCode::Q16 => f64::from((column_max / 32767.0) as f32),
                BlockCode::F16 => f64::from(column_max as f32),
                BlockCode::Hmatrix | BlockCode::HmatrixQ16 => unreachable!("16-bit codes only"),
            };
            for (&got, &x) in stored.iter().zip(exact) {
                let error = (f64::from(got) - x).abs();
                let bound = match code {
                    BlockCode::Q16 => scale / 2.0,
                    BlockCode::F16 => (x.abs() * 2f64.powi(-11)).max(scale * 2f64.powi(-25)),
                    BlockCode::Hmatrix | BlockCode::HmatrixQ16 => unreachable!("16-bit codes only"),
                } * (1.0 + 1e-12)
                    + x.abs() * 2f64.powi(-24);
                assert!(
                    error <= bound,
                    "{code:?}: {got:e} for {x:e}, bound {bound:e}"
                );
                worst = worst.max(error / bound);
            }
        };
        for k in 0..s {
            let column: Vec<usize> = (0..=k).map(|n| surface_block_index(n, k)).collect();
            let column_max = column
                .iter()
                .map(|&j| largest(&compliance.surface[j]))
                .fold(0.0, f64::max);
            for (n, &j) in column.iter().enumerate() {
                let mut exact = compliance.surface[j];
                if n == k {
                    let c = exact;
                    for a in 0..3 {
                        for b in 0..3 {
                            exact[3 * a + b] = 0.5 * (c[3 * a + b] + c[3 * b + a]);
                        }
                    }
                }
                check(
                    table.surface_blocks().block(j, k).unwrap(),
                    &exact,
                    column_max,
                );
            }
            let blocks = &compliance.interior[k * rows..(k + 1) * rows];
            let column_max = blocks.iter().map(largest).fold(0.0, f64::max);
            for (i, exact) in blocks.iter().enumerate() {
                let stored = table.interior_blocks().block(k * rows + i, k).unwrap();
                check(stored, exact, column_max);
            }
        }
        println!("{code:?}: largest error / bound over the cube's values: {worst:.3}");
    }
}

/// A block is dropped exactly when its largest entry is below `REL` of its column's (an
/// interior block) or of both its columns' (a surface block, `--contact-blocks dropped`);
/// surface blocks are never dropped by default.
#[test]
fn dropped_blocks_are_those_below_the_threshold() {
    let (mesh, report, options, compliance, s) = cube();
    let rows = compliance.interior.len() / s;
    let mut m = vec![0.0f64; s];
    for k in 0..s {
        for n in 0..=k {
            let x = largest(&compliance.surface[surface_block_index(n, k)]);
            m[k] = m[k].max(x);
            m[n] = m[n].max(x);
        }
        for b in &compliance.interior[k * rows..(k + 1) * rows] {
            m[k] = m[k].max(largest(b));
        }
    }
    let rel = 0.05;
    for contact in [ContactBlocks::Coded, ContactBlocks::Dropped] {
        let file = table_bytes(
            &mesh,
            &report,
            &options,
            Some(compression(BlockCode::Q16, rel, contact)),
        );
        let table = PrecomputedTable::<f32>::load(file.bytes()).expect("load");
        let (mut dropped_interior, mut dropped_surface) = (0, 0);
        for k in 0..s {
            for i in 0..rows {
                let j = k * rows + i;
                let keep = largest(&compliance.interior[j]) >= rel * m[k];
                assert_eq!(
                    table.interior_blocks().is_stored(j),
                    keep,
                    "interior {i}, {k}"
                );
                dropped_interior += usize::from(!keep);
            }
            for n in 0..=k {
                let j = surface_block_index(n, k);
                let keep = contact == ContactBlocks::Coded
                    || n == k
                    || largest(&compliance.surface[j]) >= rel * m[n].min(m[k]);
                assert_eq!(
                    table.surface_blocks().is_stored(j),
                    keep,
                    "surface {n}, {k}"
                );
                dropped_surface += usize::from(!keep);
            }
        }
        println!(
            "{contact:?}: {dropped_interior} of {} interior and {dropped_surface} of {} surface \
             blocks dropped below {rel}",
            compliance.interior.len(),
            compliance.surface.len()
        );
        assert!(
            dropped_interior > 0,
            "the threshold drops something on the cube"
        );
        assert_eq!(dropped_surface > 0, contact == ContactBlocks::Dropped);
    }
}

/// A press at one touchable vertex: the force is `C_kk⁻¹ d`. With `δC` the coded block's error
/// (each entry within the code's bound `e`, so `‖δC‖₂ ≤ 3e`) the relative force error is at
/// most `κ r / (1 − κ r)`, `r = 3e / ‖C_kk‖₂`, `κ` the block's condition number (both from the
/// f64 block's eigenvalues), plus the f32 solve's own rounding (`10⁻⁵ κ`, generous for a 3×3
/// Cholesky in f32). Checked at every touchable vertex of the cube, along each axis, against
/// the f64 solve of the f64 block.
#[test]
fn single_press_forces_are_within_the_bound_of_the_code() {
    let (mesh, report, options, compliance, s) = cube();
    for code in [BlockCode::Q16, BlockCode::F16] {
        let file = table_bytes(
            &mesh,
            &report,
            &options,
            Some(compression(code, 0.0, ContactBlocks::Coded)),
        );
        let model = PrecomputedModel::new(PrecomputedTable::<f32>::load(file.bytes()).unwrap());
        let (mut worst, mut worst_bound) = (0.0f64, 0.0f64);
        for k in 0..s {
            let column_max = (0..=k)
                .map(|n| largest(&compliance.surface[surface_block_index(n, k)]))
                .fold(0.0, f64::max);
            let c = Matrix3::from_row_slice(&compliance.surface[surface_block_index(k, k)]);
            let c = (c + c.transpose()) * 0.5;
            let eigen = c.symmetric_eigenvalues();
            let (lo, hi) = (eigen.min(), eigen.max());
            let kappa = hi / lo;
            let entry = match code {
                BlockCode::Q16 => column_max / 65534.0,
                BlockCode::F16 => column_max * 2f64.powi(-11),
                BlockCode::Hmatrix | BlockCode::HmatrixQ16 => unreachable!("16-bit codes only"),
            } + column_max * 2f64.powi(-24);
            let r = 3.0 * entry / hi;
            let bound = kappa * r / (1.0 - kappa * r) + 1e-5 * kappa;
            let vertex = model.table().free_vertices()[k];
            for axis in 0..3 {
                let mut d = Vector3::zeros();
                d[axis] = 1e-3;
                let exact = c.try_inverse().unwrap() * d;
                let got = model
                    .contact_forces::<1>(&[Constraint::at_vertex(vertex, d.cast::<f32>())])
                    .unwrap()
                    .contact_forces_n()[0]
                    .cast::<f64>();
                let error = (got - exact).norm() / exact.norm();
                assert!(
                    error <= bound,
                    "{code:?} vertex {vertex} axis {axis}: {error:e} > {bound:e}"
                );
                worst = worst.max(error);
                worst_bound = worst_bound.max(bound);
            }
        }
        println!(
            "{code:?}: worst single-press force error {worst:.3e} (largest bound {worst_bound:.3e})"
        );
    }
}

/// The errors a compressed table's record holds are what a measurement of that table against
/// the f32 table gives, over the documented probe set (5 contact sets per touchable vertex),
/// and q16 keeps the force within the 1 % target by a wide margin.
#[test]
fn the_record_holds_the_errors_measured_against_the_f32_table() {
    let (mesh, report, options, _, s) = cube();
    let reference = table_bytes(&mesh, &report, &options, None);
    let reference =
        PrecomputedModel::new(PrecomputedTable::<f32>::load(reference.bytes()).unwrap());
    for (c, force_bound) in [
        (compression(BlockCode::Q16, 0.0, ContactBlocks::Coded), 1e-3),
        (compression(BlockCode::F16, 0.0, ContactBlocks::Coded), 5e-3),
        (
            compression(BlockCode::Q16, 0.05, ContactBlocks::Coded),
            1e-3,
        ),
        (compression(BlockCode::Q16, 0.05, ContactBlocks::F32), 0.0),
    ] {
        let file = table_bytes(&mesh, &report, &options, Some(c));
        let table = PrecomputedTable::<f32>::load(file.bytes()).unwrap();
        let record = *table.compression().expect("a record");
        let measured = measure(&reference, &PrecomputedModel::new(table));
        assert_eq!(measured.probes, 5 * s as u64);
        assert_eq!(measured.refused, 0);
        assert_eq!(record.probe_count, measured.probes);
        assert_eq!(record.max_force_error, measured.max_force_error);
        assert_eq!(
            record.max_displacement_error,
            measured.max_displacement_error
        );
        assert_eq!(
            record.max_surface_displacement_error,
            measured.max_surface_displacement_error
        );
        assert_eq!(record.drop_below, c.drop_below);
        assert!(record.max_force_error <= force_bound, "{c:?}: {record:?}");
        // Dropping interior blocks moves no touchable vertex and no force.
        if c.drop_below > 0.0 {
            assert!(record.max_displacement_error > record.max_surface_displacement_error);
        }
        println!("{c:?}: {record:?}");
    }
}

/// The scene's model all pre-computed (the organ of the built-in hybrid scene has a cut zone).
fn precomputed(mut scene: Scene) -> Scene {
    scene.zones.clear();
    scene.model = ModelSpec::Precomputed;
    scene
}

/// The device force of every tick of `trajectory` through the haptic loop over `file`.
struct Forces<'a> {
    scene: &'a Scene,
    trajectory: &'a Trajectory,
    file: &'a TableFile,
}

impl ForToolPoints for Forces<'_> {
    type Output = Vec<Vector3<f64>>;

    fn call<const P: usize>(self) -> Vec<Vector3<f64>> {
        let table = PrecomputedTable::<f32>::load(self.file.bytes()).expect("load");
        let mut haptic = PrecomputedLoop::<f32, P, P>::new(
            PrecomputedTissue::new(&table),
            loop_config(self.scene),
        )
        .expect("loop");
        ticks::<P>(self.trajectory, self.scene.tick_s(), &self.scene.tool)
            .expect("ticks")
            .map(|(_, tools)| haptic.tick_tools(&tools).force_n.cast::<f64>())
            .collect()
    }
}

/// The haptic loop over the q16 table (contact blocks coded, every interior block dropped: the
/// largest compression) against the f32 table, over each of the scene's generated
/// trajectories (`palpate budget`'s): per trajectory the largest force difference over the
/// ticks relative to the largest force, within 10⁻³ (the 1 % target with a tenfold margin;
/// the probe set measures 1.5·10⁻⁴ at most on these meshes).
#[test]
fn trajectory_forces_match_the_f32_table() {
    for scene in [Scene::built_in(), precomputed(Scene::built_in_hybrid())] {
        let (mesh, report) = scene.load_mesh().expect("mesh");
        let options = precomputed_options(&scene, &mesh, &report).expect("options");
        let reference = table_bytes(&mesh, &report, &options, None);
        for c in [
            compression(BlockCode::Q16, 0.0, ContactBlocks::Coded),
            compression(BlockCode::Q16, 0.99, ContactBlocks::Coded),
            compression(BlockCode::F16, 0.0, ContactBlocks::Coded),
        ] {
            let file = table_bytes(&mesh, &report, &options, Some(c));
            for (name, trajectory) in trajectories(&scene).expect("trajectories") {
                let run = |file| {
                    with_tool_points(
                        scene.tool.kernel_points(),
                        Forces {
                            scene: &scene,
                            trajectory: &trajectory,
                            file,
                        },
                    )
                };
                let (want, got) = (run(&reference), run(&file));
                let peak = want.iter().map(|f| f.norm()).fold(0.0, f64::max);
                let diff = want
                    .iter()
                    .zip(&got)
                    .map(|(a, b)| (a - b).norm())
                    .fold(0.0, f64::max);
                println!(
                    "{} {name} ({} ticks, peak {peak:.3} N): {:?} drop {} contact {:?}: \
                     largest force difference {:.3e} N = {:.3e} of the peak",
                    scene.source,
                    want.len(),
                    c.code,
                    c.drop_below,
                    c.contact,
                    diff,
                    diff / peak
                );
                assert!(peak > 0.1, "{name}: the trajectory presses");
                let bound = match c.code {
                    BlockCode::Q16 => 1e-3,
                    BlockCode::F16 => 1e-2,
                    BlockCode::Hmatrix | BlockCode::HmatrixQ16 => unreachable!("16-bit codes only"),
                };
                assert!(diff <= bound * peak, "{name} {c:?}: {diff:e} N of {peak} N");
            }
        }
    }
}
