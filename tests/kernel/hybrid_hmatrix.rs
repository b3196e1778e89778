//! The hybrid with its interface's condensed stiffness stored as a
//! hierarchical matrix (`palpate::hybrid::hmatrix`, scene `[tables] compress
//! = "hmatrix"`): its product against the dense interface's exact `S u`, the
//! hybrid's steady state against one global linear FEM solve of the whole
//! mesh (`palpate::fem::static_solve`, independent of the condensation), and
//! corrupt hierarchy sections refused at load; and the whole hybrid
//! compressed (the pre-computed region hierarchical, its response over the
//! touchable rows): its steady state against the global solve, its contact
//! force against the dense hybrid's, a corrupt response count refused.

use std::sync::OnceLock;

use nalgebra::Vector3;
use palpate::fem::material::{Material, TetMaterials};
use palpate::fem::static_solve::solve_loaded;
use palpate::hybrid::hmatrix::InterfaceCompression;
use palpate::hybrid::owned::with_hybrid;
use palpate::hybrid::{HybridOptions, HybridTables, build_hybrid};
use palpate::mesh::generate::box_mesh;
use palpate::mesh::{MeshReport, TetMesh};
use palpate::table::build::BuildOptions;
use palpate::table::file::Precision;
use palpate_kernel::hybrid::HybridModel;
use palpate_kernel::precomputed::Constraint;
use palpate_kernel::table::format::SectionKind;
use palpate_kernel::table::{CondensedStiffness, InterfaceTable};
use palpate_kernel::tensor_mass::{DynamicParams, Integrator};
use palpate_kernel::{LoadError, PrecomputedTable};
use palpate_tests::{Lcg, patch_section};

/// The far blocks' relative tolerance of the compressed interface.
const TOLERANCE: f64 = 1e-4;
/// Leaves of 4 connection nodes: the slab's 45 connection nodes then make
/// far blocks (the scene default, 32, would make one leaf of them).
const LEAF_SIZE: usize = 4;
/// 8 × 4 × 3 cm slab of 8 × 4 × 3 cells (180 vertices, 576 tets), base fixed.
const SIZE_M: [f64; 3] = [0.08, 0.04, 0.03];

/// The mesh and the hybrid built twice, dense and compressed interface:
/// the upper layer of cells dynamic (192 tets, the 45 vertices of the plane
/// under it the connection nodes).
struct Built {
    mesh: TetMesh,
    dense: HybridTables,
    compressed: HybridTables,
}

fn material() -> Material {
    Material::new(5000.0, 0.3).expect("material")
}

fn options(compression: Option<InterfaceCompression>) -> HybridOptions {
    HybridOptions {
        interface_compression: compression,
        ..HybridOptions::new(
            material(),
            1000.0,
            vec!["z<0.0001".parse().expect("predicate")],
            Precision::F64,
        )
    }
}

fn built() -> &'static Built {
    static BUILT: OnceLock<Built> = OnceLock::new();
    BUILT.get_or_init(|| {
        let mesh = box_mesh([8, 4, 3], SIZE_M);
        let report = MeshReport {
            source: "slab".into(),
            ..MeshReport::default()
        };
        let upper: Vec<bool> = (0..mesh.tets.len())
            .map(|t| mesh.tet_centroid(t)[2] > SIZE_M[2] * 2.0 / 3.0)
            .collect();
        let compression = InterfaceCompression {
            tolerance: TOLERANCE,
            leaf_size: LEAF_SIZE,
        };
        let build = |c| build_hybrid(&mesh, &report, &upper, &options(c)).expect("hybrid tables");
        let (dense, compressed) = (build(None), build(Some(compression)));
        Built {
            mesh,
            dense,
            compressed,
        }
    })
}

fn interface(tables: &HybridTables) -> InterfaceTable<'_, f64> {
    InterfaceTable::load(tables.interface.bytes()).expect("interface")
}

fn norm(v: &[[f64; 3]]) -> f64 {
    v.iter().flatten().map(|x| x * x).sum::<f64>().sqrt()
}

/// `S̃ u` of the hierarchical interface against the dense interface's `S u`
/// on random `u`: `‖S̃ u − S u‖ ≤ ‖S̃ − S‖_F ‖u‖ ≤ tol · ‖S‖_F ‖u‖` (each far
/// block within `tol` of its own Frobenius norm, the near blocks exact),
/// and the quadratic form within `tol · ‖S‖_F ‖u‖²`; a slack of 1e-12
/// relative for the f64 rounding of the two sums. The hierarchy holds far
/// blocks (else the test would compare the dense matrix with itself).
#[test]
fn hierarchical_product_is_the_dense_product_within_the_tolerance() {
    let b = built();
    let (dense, hier) = (interface(&b.dense), interface(&b.compressed));
    let c = dense.connection_count();
    assert_eq!(hier.connection_count(), c);
    let CondensedStiffness::Hierarchical { blocks, .. } = hier.condensed() else {
        panic!("the compressed interface is not hierarchical");
    };
    let far = blocks.blocks().iter().filter(|b| b.rank > 0).count();
    println!(
        "{c} connection nodes: {} blocks, {far} far, {} scalars (dense {})",
        blocks.blocks().len(),
        blocks.data_len(),
        9 * c * c
    );
    assert!(far > 0, "no far block");
    let s_frobenius = (0..c)
        .flat_map(|j| (0..c).map(move |k| (j, k)))
        .flat_map(|(j, k)| dense.condensed_block(j, k).expect("block"))
        .map(|x| x * x)
        .sum::<f64>()
        .sqrt();
    let mut rng = Lcg(7);
    for trial in 0..4 {
        let u: Vec<[f64; 3]> = (0..c)
            .map(|_| [rng.signed(), rng.signed(), rng.signed()])
            .collect();
        let (mut exact, mut approx) = (vec![[0.0; 3]; c], vec![[0.0; 3]; c]);
        dense.add_condensed_product(&u, 1.0, &mut exact);
        hier.add_condensed_product(&u, 1.0, &mut approx);
        let difference: Vec<[f64; 3]> = exact
            .iter()
            .zip(&approx)
            .map(|(e, a)| [e[0] - a[0], e[1] - a[1], e[2] - a[2]])
            .collect();
        let bound = (TOLERANCE + 1e-12) * s_frobenius * norm(&u);
        let error = norm(&difference);
        let quadratic = (dense.condensed_quadratic(&u) - hier.condensed_quadratic(&u)).abs();
        println!(
            "u #{trial}: |S̃u − Su| {error:.3e} (bound {bound:.3e}), uᵀ(S̃ − S)u {quadratic:.3e}"
        );
        assert!(error <= bound, "u #{trial}: {error:e} > {bound:e}");
        assert!(quadratic <= bound * norm(&u), "u #{trial}: {quadratic:e}");
        // And `S u` itself is no small number next to the error.
        assert!(
            norm(&exact) > 1e3 * error,
            "u #{trial}: |Su| {}",
            norm(&exact)
        );
    }
    // Every diagonal block read back exactly (near blocks keep entries).
    for j in 0..c {
        let (d, h) = (dense.condensed_block(j, j), hier.condensed_block(j, j));
        let (d, h) = (d.expect("dense"), h.expect("hierarchical"));
        let worst = d
            .iter()
            .zip(&h)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
        assert!(worst <= 1e-12 * s_frobenius, "S_{j}{j}: {worst:e}");
    }
}

/// The nodal loads of the whole mesh: `force` (N) on `vertex`, none elsewhere.
fn loads(mesh: &TetMesh, vertex: u32, force: [f64; 3]) -> Vec<[f64; 3]> {
    let mut loads = vec![[0.0; 3]; mesh.positions.len()];
    for (l, f) in loads[vertex as usize].iter_mut().zip(force) {
        *l += f;
    }
    loads
}

/// The global linear FEM solution of `mesh` (base `z = 0` fixed) under `force` (N) at vertex
/// `top`, m, and its largest displacement component (the error scale).
fn global_solution(mesh: &TetMesh, top: u32, force: [f64; 3]) -> (Vec<[f64; 3]>, f64) {
    let fixed: Vec<bool> = mesh.positions.iter().map(|p| p[2] < 1e-9).collect();
    let (global, _) = solve_loaded(
        &mesh.positions,
        &mesh.tets,
        &TetMaterials::uniform(material(), mesh.tets.len()),
        &fixed,
        &[],
        &loads(mesh, top, force),
    )
    .expect("global solve");
    let scale = global.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    (global, scale)
}

/// A point load on the dynamic region's top: the settled hybrid with the
/// hierarchical interface equals the global solve. The condensation is
/// exact, so the error is the compression's: the connection displacements
/// solve `(K_d + S̃) u = f` instead of `(K_d + S) u = f`, and only the far
/// blocks of `S̃` differ from `S`, each by at most `tol` of its own norm;
/// they are the small, smooth part of `S` (its coupling between distant
/// connection nodes), so the field's relative error stays below `tol`
/// itself (bound `TOLERANCE`; measured 2.1e-6). The dense interface's
/// error, the settling's alone (~1e-12), is checked at 1e-6 alongside.
#[test]
fn compressed_interface_steady_state_is_the_global_solve() {
    let b = built();
    let mesh = &b.mesh;
    // (4, 2, 3) cm: the middle of the top, in the dynamic region.
    let top = 3 * 45 + 2 * 9 + 4;
    let force = [0.0, 0.0, -0.05];
    let (global, scale) = global_solution(mesh, top, force);
    let mut errors = Vec::new();
    for tables in [&b.dense, &b.compressed] {
        let d = tables.split.dynamic_index[top as usize].expect("dynamic vertex");
        let field = with_hybrid(tables, DynamicParams::linear(150.0, f64::INFINITY), |h| {
            h.dynamic_mut()
                .set_external_force(d, Vector3::from(force))
                .expect("load");
            let mut field = vec![[0.0; 3]; mesh.positions.len()];
            let mut previous = field.clone();
            for step in 0..40_000 {
                h.step(Integrator::SymplecticEuler, 2e-4)
                    .expect("stable step");
                if step % 100 == 99 {
                    h.displacements::<1>(None, &mut field).expect("field");
                    let change = field
                        .iter()
                        .flatten()
                        .zip(previous.iter().flatten())
                        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
                    if change < 1e-12 * scale {
                        break;
                    }
                    previous.clone_from(&field);
                }
            }
            field
        })
        .expect("hybrid");
        let error = field
            .iter()
            .flatten()
            .zip(global.iter().flatten())
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
            / scale;
        errors.push(error);
    }
    println!(
        "relative max error against the global solve: dense {:.2e}, hierarchical {:.2e}",
        errors[0], errors[1]
    );
    assert!(errors[0] <= 1e-6, "dense interface: {:e}", errors[0]);
    assert!(errors[1] <= TOLERANCE, "hierarchical: {:e}", errors[1]);
}

/// The hierarchical interface's own sections corrupted behind a valid
/// checksum: refused at load with the section named, never coupled.
#[test]
fn corrupt_interface_hierarchy_is_refused() {
    let bytes = built().compressed.interface.bytes();
    let refused = |bytes: Vec<u8>, section: &str| {
        let error = InterfaceTable::<f64>::load(&bytes).expect_err("corrupt table loaded");
        let message = error.to_string();
        println!("{message}");
        assert!(
            matches!(error, LoadError::BadHierarchy { .. }) && message.contains(section),
            "{message}"
        );
    };
    let put = |b: &mut [u8], at: usize, v: u32| b[at..at + 4].copy_from_slice(&v.to_le_bytes());
    let get = |b: &[u8], at: usize| u32::from_le_bytes(b[at..at + 4].try_into().unwrap());
    // Two hierarchy indices mapped to one connection node.
    refused(
        patch_section(bytes, SectionKind::HierarchyOrder, |b| {
            let other = get(b, 8);
            put(b, 0, other)
        }),
        "hierarchy-order",
    );
    // A connection node's inverse entry pointing elsewhere.
    refused(
        patch_section(bytes, SectionKind::HierarchyOrder, |b| {
            let i = get(b, 4);
            put(b, 4, i + 1)
        }),
        "hierarchy-order",
    );
    // A block's rows beyond the connection nodes (row_end, bytes 4..8).
    refused(
        patch_section(bytes, SectionKind::HierarchyBlocks, |b| put(b, 4, 10_000)),
        "hierarchy-blocks",
    );
    // The leaf count one off (bytes 0..4 of the record).
    refused(
        patch_section(bytes, SectionKind::HierarchyRecord, |b| {
            let n = get(b, 0);
            put(b, 0, n + 1)
        }),
        "hierarchy-record",
    );
}

// ---- The whole hybrid compressed: the pre-computed region hierarchical, its
// response over the touchable rows (scene `[tables] compress = "hmatrix"`). ----

/// The far blocks' tolerance of the fully compressed hybrid: the scene
/// default (`palpate::table::hmatrix::DEFAULT_TOLERANCE`), the one the
/// pre-computed hmatrix's measured errors are stated at.
const REGION_TOLERANCE: f64 = 1e-5;

/// The slab with a dynamic window in its top layer (cells 2..6 × 1..3 of
/// the upper layer: 48 tets, 27 connection nodes), built in f32 twice: all
/// dense, and all compressed (region hierarchical, touchable response, `S`
/// in leaves of 4). The region then has 78 touchable vertices (three
/// leaves of the region's cluster tree, so its touchable order is a real
/// permutation) and 27 interior ones.
struct Window {
    mesh: TetMesh,
    dense: HybridTables,
    compressed: HybridTables,
}

fn window() -> &'static Window {
    static BUILT: OnceLock<Window> = OnceLock::new();
    BUILT.get_or_init(|| {
        let mesh = box_mesh([8, 4, 3], SIZE_M);
        let report = MeshReport {
            source: "slab".into(),
            ..MeshReport::default()
        };
        let dynamic: Vec<bool> = (0..mesh.tets.len())
            .map(|t| {
                let [x, y, z] = mesh.tet_centroid(t);
                z > 0.02 && (0.02..0.06).contains(&x) && (0.01..0.03).contains(&y)
            })
            .collect();
        let f32_options = |compress: bool| HybridOptions {
            build: BuildOptions {
                precision: Precision::F32,
                ..options(None).build
            },
            interface_compression: compress.then_some(InterfaceCompression {
                tolerance: REGION_TOLERANCE,
                leaf_size: LEAF_SIZE,
            }),
            compress_region: compress,
            ..options(None)
        };
        let build = |compress| {
            build_hybrid(&mesh, &report, &dynamic, &f32_options(compress)).expect("hybrid tables")
        };
        let (dense, compressed) = (build(false), build(true));
        Window {
            mesh,
            dense,
            compressed,
        }
    })
}

/// Steps `hybrid` (f32) until its field changes by less than `1e-6` of
/// `scale` over 100 steps (the f32 field's rounding is about 1e-7 of it),
/// running `each` before every step; returns the field (m).
fn settle_f32(
    hybrid: &mut HybridModel<'_, '_, f32>,
    scale: f64,
    mut each: impl FnMut(&mut HybridModel<'_, '_, f32>),
) -> Vec<[f64; 3]> {
    let n = hybrid.interface().vertex_count();
    let mut field = vec![[0.0f32; 3]; n];
    let mut previous = field.clone();
    for step in 0..40_000 {
        each(hybrid);
        hybrid
            .step(Integrator::SymplecticEuler, 2e-4)
            .expect("stable step");
        if step % 100 == 99 {
            hybrid.displacements::<1>(None, &mut field).expect("field");
            let change = field
                .iter()
                .flatten()
                .zip(previous.iter().flatten())
                .fold(0.0f64, |m, (x, y)| m.max(f64::from((x - y).abs())));
            if change < 1e-6 * scale {
                break;
            }
            previous.clone_from(&field);
        }
    }
    field.iter().map(|u| u.map(f64::from)).collect()
}

/// The mesh vertices the compressed region does not move: its interior
/// free vertices (free indices at or beyond the interface's response rows).
fn interior(tables: &HybridTables) -> Vec<bool> {
    let region = PrecomputedTable::<f32>::load(tables.precomputed.bytes()).expect("region");
    let rows = InterfaceTable::<f32>::load(tables.interface.bytes())
        .expect("interface")
        .response_rows();
    assert_eq!(rows, region.touchable_count(), "touchable rows only");
    assert!(
        region.free_count() > rows,
        "the region has interior vertices"
    );
    // More than one leaf of the region's cluster tree (32 vertices).
    assert!(rows > 32, "{rows} touchable vertices");
    let mut flags = vec![false; region.vertex_count()];
    for &v in &region.free_vertices()[rows..] {
        flags[v as usize] = true;
    }
    flags
}

/// The largest `|a − b|` over the vertices not `skip`ped, relative to
/// `scale`.
fn max_error(a: &[[f64; 3]], b: &[[f64; 3]], skip: &[bool], scale: f64) -> f64 {
    a.iter()
        .zip(b)
        .zip(skip)
        .filter(|(_, s)| !**s)
        .flat_map(|((x, y), _)| x.iter().zip(y).map(|(p, q)| (p - q).abs()))
        .fold(0.0f64, f64::max)
        / scale
}

/// A point load on the dynamic window's top: the settled, fully compressed
/// f32 hybrid equals the global solve at every vertex it moves, and its
/// region's interior vertices report zero (the documented contract: not
/// stored, as a hierarchical pre-computed table's). The error sources: the
/// compressed `S` (below its tolerance, 1e-5, as argued for the f64 test
/// above), the f32 storage of `S` and `H` (relative rounding 6e-8,
/// amplified by the slab's conditioning) and the settling's stop (1e-6 of
/// the field per 100 steps, about 1e-6 of it after the geometric tail):
/// bound 1e-5 (measured 3.4e-7; dense 2.0e-7). The dense f32 hybrid's
/// error, measured alongside, is held to the same bound.
#[test]
fn compressed_region_steady_state_is_the_global_solve() {
    let w = window();
    let mesh = &w.mesh;
    // (4, 2, 3) cm: the middle of the window's top.
    let top = 3 * 45 + 2 * 9 + 4;
    let force = [0.0, 0.0, -0.05];
    let (global, scale) = global_solution(mesh, top, force);
    let skip = interior(&w.compressed);
    let mut errors = Vec::new();
    for tables in [&w.dense, &w.compressed] {
        let d = tables.split.dynamic_index[top as usize].expect("dynamic vertex");
        let field = with_hybrid(tables, DynamicParams::linear(150.0, f32::INFINITY), |h| {
            h.dynamic_mut()
                .set_external_force(d, Vector3::from(force.map(|x| x as f32)))
                .expect("load");
            settle_f32(h, scale, |_| {})
        })
        .expect("hybrid");
        errors.push(max_error(&field, &global, &skip, scale));
        if core::ptr::eq(tables, &w.compressed) {
            let moved = field
                .iter()
                .zip(&skip)
                .filter(|(u, s)| **s && **u != [0.0; 3]);
            assert_eq!(
                moved.count(),
                0,
                "an interior vertex reported a displacement"
            );
        }
    }
    println!(
        "relative max error against the global solve (f32): dense {:.2e}, compressed {:.2e}",
        errors[0], errors[1]
    );
    assert!(errors[0] <= 1e-5, "dense: {:e}", errors[0]);
    assert!(errors[1] <= 1e-5, "compressed: {:e}", errors[1]);
}

/// A press on a touchable vertex of the pre-computed region (solved every
/// step against the background, its force passed to the connection nodes):
/// the settled contact force of the fully compressed hybrid equals the
/// dense f32 hybrid's within 1e-4: the region's far blocks and `S̃`'s are
/// each within 1e-5 of their own norm, the press's force a sum of a few
/// compliance and `H` rows (measured 8e-9: this region's far blocks are
/// few); and both equal the global solve's reaction within 1e-4 (f32
/// storage and settling, measured 4.6e-8).
#[test]
fn compressed_region_contact_force_is_the_dense_hybrids() {
    let w = window();
    let mesh = &w.mesh;
    // (1, 2, 3) cm: the top, outside the window.
    let vertex = 3 * 45 + 2 * 9 + 1;
    let press = [0.0, 0.0, -0.0005];
    let (global, reactions) = solve_loaded(
        &mesh.positions,
        &mesh.tets,
        &TetMaterials::uniform(material(), mesh.tets.len()),
        &mesh
            .positions
            .iter()
            .map(|p| p[2] < 1e-9)
            .collect::<Vec<_>>(),
        &[(vertex, press)],
        &[],
    )
    .expect("global solve");
    let scale = global.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    let reaction = Vector3::from(reactions[0]);
    let mut forces = Vec::new();
    for tables in [&w.dense, &w.compressed] {
        assert!(tables.split.dynamic_index[vertex as usize].is_none());
        let contact = [Constraint::at_vertex(
            vertex,
            Vector3::from(press.map(|x| x as f32)),
        )];
        let force = with_hybrid(tables, DynamicParams::linear(150.0, f32::INFINITY), |h| {
            let touchable = h.region().precomputed().table().touchable_count();
            let mut last = None;
            settle_f32(h, scale, |h| {
                h.update_background(touchable).expect("background");
                let solution = h.contact_forces::<1>(&contact).expect("contact");
                h.pass_contact_forces(Some(&solution));
                last = Some(solution.contact_forces_n()[0]);
            });
            last.expect("solved").map(f64::from)
        })
        .expect("hybrid");
        forces.push(force);
    }
    let relative = |a: Vector3<f64>, b: Vector3<f64>| (a - b).norm() / b.norm();
    let (dense, compressed) = (forces[0], forces[1]);
    println!(
        "contact force: dense {:.5e} N, compressed {:.5e} N, global {:.5e} N; compressed vs \
         dense {:.2e}, dense vs global {:.2e}",
        dense.norm(),
        compressed.norm(),
        reaction.norm(),
        relative(compressed, dense),
        relative(dense, reaction)
    );
    assert!(relative(compressed, dense) <= 1e-4);
    assert!(relative(dense, reaction) <= 1e-4);
    assert!(relative(compressed, reaction) <= 1e-4);
}

/// The touchable response's row count corrupted behind a valid checksum
/// (its directory entry one row of `c` triples short): refused at load
/// with the section named; and the section's declared count checked
/// against the header's `3·S·c`.
#[test]
fn corrupt_touchable_response_count_is_refused() {
    use palpate_kernel::table::format::{CRC_LEN, CRC32, HEADER_LEN, SECTION_ENTRY_LEN};
    let bytes = window().compressed.interface.bytes();
    let table = InterfaceTable::<f32>::load(bytes).expect("interface");
    let c = table.connection_count() as u64;
    let u32_at = |b: &[u8], at: usize| u32::from_le_bytes(b[at..at + 4].try_into().unwrap());
    let sections = u32_at(bytes, 20) as usize;
    let entry = (0..sections)
        .map(|i| HEADER_LEN + i * SECTION_ENTRY_LEN)
        .find(|&at| u32_at(bytes, at) == SectionKind::TouchableResponse as u32)
        .expect("touchable-response section");
    let count = u64::from_le_bytes(bytes[entry + 16..entry + 24].try_into().unwrap());
    assert_eq!(count, 3 * table.response_rows() as u64 * c);
    for corrupt in [count - c, count + c] {
        let mut b = bytes.to_vec();
        b[entry + 16..entry + 24].copy_from_slice(&corrupt.to_le_bytes());
        let body = b.len() - CRC_LEN;
        let crc = crc::Crc::<u32>::new(&CRC32).checksum(&b[..body]);
        b[body..].copy_from_slice(&crc.to_le_bytes());
        let error = InterfaceTable::<f32>::load(&b).expect_err("corrupt count loaded");
        println!("{error}");
        assert!(
            matches!(
                error,
                LoadError::SectionSize { .. } | LoadError::SectionBounds { .. }
            ) && error.to_string().contains("touchable-response"),
            "{error}"
        );
    }
}
