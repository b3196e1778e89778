//! Hierarchical compliance tables built by the host
//! (`host-harness/src/table/hmatrix/`) and read by the kernel, against the
//! dense compliance of the same mesh: every far block within its stated
//! tolerance, the contact forces and touchable displacements of random
//! contact sets within the team's bound, the errors stored in the record,
//! and corrupted tables refused.

use super::table_compress::f64_compliance;
use nalgebra::Vector3;
use palpate::fem::assembly::FreeOrdering;
use palpate::fem::material::Material;
use palpate::mesh::generate::box_mesh;
use palpate::mesh::{MeshReport, TetMesh};
use palpate::table::build::{BuildOptions, DEFAULT_LIST_TOOL_RADIUS_M, TableKindOptions, build};
use palpate::table::compliance::{Compliance, Solver};
use palpate::table::compress::{BlockCode, Compression, ContactBlocks};
use palpate::table::file::Precision;
use palpate::table::load::TableFile;
use palpate_kernel::table::format::{
    BlockEncoding, HIERARCHY_BLOCK_LEN, HIERARCHY_MAX_RANK, PROBE_SET_SAMPLED, SectionKind,
    surface_block_index,
};
use palpate_kernel::{Constraint, LoadError, MAX_CONTACTS, PrecomputedModel, PrecomputedTable};
use palpate_tests::{Lcg, patch_section};

const TOLERANCE: f64 = 1e-4;

/// A 0.2 × 0.1 × 0.1 m box of 16 × 8 × 8 cells (1377 vertices, 6144 tets),
/// its base fixed: 705 touchable vertices, enough for far blocks between
/// leaves of 32.
fn mesh() -> (TetMesh, MeshReport, BuildOptions) {
    let mesh = box_mesh([16, 8, 8], [0.2, 0.1, 0.1]);
    let options = BuildOptions::precomputed(
        Material::new(5000.0, 0.45).expect("material"),
        vec!["z<0.001".parse().expect("predicate")],
        Solver::Cholesky,
        Precision::F32,
    );
    (mesh, MeshReport::default(), options)
}

fn table(mesh: &TetMesh, report: &MeshReport, options: &BuildOptions, hmatrix: bool) -> TableFile {
    coded_table(mesh, report, options, hmatrix.then_some(BlockCode::Hmatrix))
}

/// The table of `mesh` with the compliance coded as `code` (`None`: f32).
fn coded_table(
    mesh: &TetMesh,
    report: &MeshReport,
    options: &BuildOptions,
    code: Option<BlockCode>,
) -> TableFile {
    let compression = code.map(|code| Compression {
        code,
        drop_below: 0.0,
        contact: ContactBlocks::Coded,
        tolerance: TOLERANCE,
    });
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

/// `C_nk` (mesh vertices `vn`, `vk`, both touchable) of the dense compliance.
fn dense_block(c: &Compliance, ordering: &FreeOrdering, vn: u32, vk: u32) -> [f64; 9] {
    let (n, k) = (
        ordering.vertex_slot[vn as usize].expect("free") as usize,
        ordering.vertex_slot[vk as usize].expect("free") as usize,
    );
    if n <= k {
        c.surface[surface_block_index(n, k)]
    } else {
        let b = c.surface[surface_block_index(k, n)];
        core::array::from_fn(|i| b[3 * (i % 3) + i / 3])
    }
}

#[test]
fn far_blocks_are_within_their_tolerance_and_near_blocks_exact() {
    let (mesh, report, options) = mesh();
    let file = table(&mesh, &report, &options, true);
    let t = PrecomputedTable::<f32>::load(file.bytes()).expect("loads");
    let (c, ordering) = f64_compliance(&mesh, &report, &options);
    let h = *t.surface_blocks().as_hierarchical().expect("hierarchical");
    let touchable = &t.free_vertices()[..t.touchable_count()];
    let mut far = 0;
    for b in h.blocks() {
        let (mut diff2, mut norm2, mut largest) = (0.0f64, 0.0f64, 0.0f64);
        for n in b.row_start as usize..b.row_end as usize {
            for k in b.col_start as usize..b.col_end as usize {
                let got = h.block(n, k).expect("in range");
                let want = dense_block(&c, &ordering, touchable[n], touchable[k]);
                for (g, w) in got.iter().zip(want) {
                    diff2 += (f64::from(*g) - w).powi(2);
                    norm2 += w * w;
                    largest = largest.max((f64::from(*g) - w).abs() / w.abs().max(1e-30));
                }
            }
        }
        let rel = (diff2 / norm2).sqrt();
        if b.rank > 0 {
            far += 1;
            assert!(b.rank as usize <= HIERARCHY_MAX_RANK);
            // The truncation's bound plus the f32 rounding of the factors
            // (relative 6e-8 per scalar, summed over a rank of at most 64).
            assert!(rel <= TOLERANCE * 1.001 + 1e-5, "far block {b:?}: {rel:e}");
        } else {
            // Near blocks are the f32 entries (a far block stored as
            // entries: within its tolerance).
            assert!(rel <= TOLERANCE * 1.001 + 1e-6, "near block {b:?}: {rel:e}");
        }
    }
    assert!(far > 0, "the box has far blocks");
    let dense_bytes = table(&mesh, &report, &options, false).bytes().len();
    assert!(
        file.bytes().len() * 2 < dense_bytes,
        "{} vs {dense_bytes}",
        file.bytes().len()
    );
}

#[test]
fn contact_forces_and_touchable_displacements_match_the_dense_table() {
    let (mesh, report, options) = mesh();
    let (hfile, dfile) = (
        table(&mesh, &report, &options, true),
        table(&mesh, &report, &options, false),
    );
    let h = PrecomputedModel::new(PrecomputedTable::<f32>::load(hfile.bytes()).expect("h"));
    let d = PrecomputedModel::new(PrecomputedTable::<f32>::load(dfile.bytes()).expect("d"));
    let record = h.table().compression().expect("record");
    // 705 touchable vertices: the sampled probe set; the team's bound.
    assert_eq!(record.probe_set, PROBE_SET_SAMPLED);
    assert!(record.max_force_error <= 1e-3, "{record:?}");
    assert!(record.max_surface_displacement_error <= 1e-3, "{record:?}");
    assert!(record.max_force_error > 0.0 && record.probe_count == 5 * 256);
    let touchable = d.table().free_vertices()[..d.table().touchable_count()].to_vec();
    let slot = |t: &PrecomputedTable<'_, f32>, v: u32| {
        t.free_vertices()
            .iter()
            .position(|&w| w == v)
            .expect("free")
    };
    let mut rng = Lcg(7);
    let (mut uh, mut ud) = (
        vec![[0.0f32; 3]; h.table().free_count()],
        vec![[0.0f32; 3]; d.table().free_count()],
    );
    for _ in 0..40 {
        let m = 1 + (rng.unit() * 3.0) as usize;
        let mut set: Vec<Constraint<f32>> = Vec::new();
        while set.len() < m {
            let v = touchable[(rng.unit() * touchable.len() as f64) as usize];
            if set
                .iter()
                .any(|c| c.point == palpate_kernel::ContactPoint::Vertex(v))
            {
                continue;
            }
            let dir = Vector3::new(rng.signed(), rng.signed(), -1.0) * 1e-3;
            set.push(Constraint::at_vertex(v, dir.cast()));
        }
        let (gh, gd) = (
            h.contact_forces::<MAX_CONTACTS>(&set).expect("h solves"),
            d.contact_forces::<MAX_CONTACTS>(&set).expect("d solves"),
        );
        let scale = gd
            .contact_forces_n()
            .iter()
            .map(|g| g.norm())
            .fold(0.0f32, f32::max);
        for (a, b) in gh.contact_forces_n().iter().zip(gd.contact_forces_n()) {
            // The team's bound on a hierarchical table's force error.
            assert!((a - b).norm() <= 1e-3 * scale, "{a:?} vs {b:?}");
        }
        h.free_displacements(&gh, &mut uh).expect("h");
        d.free_displacements(&gd, &mut ud).expect("d");
        let scale = ud
            .iter()
            .map(|u| Vector3::from(*u).norm())
            .fold(0.0f32, f32::max);
        for &v in &touchable {
            let (a, b) = (
                Vector3::from(uh[slot(h.table(), v)]),
                Vector3::from(ud[slot(d.table(), v)]),
            );
            assert!((a - b).norm() <= 1e-3 * scale, "vertex {v}: {a:?} vs {b:?}");
        }
    }
}

#[test]
fn corrupted_hierarchies_are_refused() {
    let (mesh, report, options) = mesh();
    let file = table(&mesh, &report, &options, true);
    let bytes = file.bytes();
    let u32_at = |b: &[u8], at: usize| u32::from_le_bytes(b[at..at + 4].try_into().unwrap());
    let put = |b: &mut [u8], at: usize, x: u32| b[at..at + 4].copy_from_slice(&x.to_le_bytes());
    let refused = |patched: Vec<u8>| {
        let file = TableFile::from_bytes(&patched);
        matches!(
            PrecomputedTable::<f32>::load(file.bytes()),
            Err(LoadError::BadHierarchy { .. })
        )
    };
    // The record's max rank above the kernel's bound (bytes 8..12).
    assert!(refused(patch_section(
        bytes,
        SectionKind::HierarchyRecord,
        |b| { put(b, 8, HIERARCHY_MAX_RANK as u32 + 1) }
    )));
    // The block count one off (bytes 4..8).
    assert!(refused(patch_section(
        bytes,
        SectionKind::HierarchyRecord,
        |b| {
            let n = u32_at(b, 4);
            put(b, 4, n - 1)
        }
    )));
    // A far block's right factor past the data; a block's rank above max.
    let far = |b: &[u8]| {
        (0..b.len() / HIERARCHY_BLOCK_LEN)
            .find(|&i| u32_at(b, i * HIERARCHY_BLOCK_LEN + 16) > 0)
            .expect("a far block")
            * HIERARCHY_BLOCK_LEN
    };
    assert!(refused(patch_section(
        bytes,
        SectionKind::HierarchyBlocks,
        |b| {
            let at = far(b);
            put(b, at + 24, u32::MAX - 8)
        }
    )));
    assert!(refused(patch_section(
        bytes,
        SectionKind::HierarchyBlocks,
        |b| {
            let at = far(b);
            put(b, at + 16, HIERARCHY_MAX_RANK as u32 + 1)
        }
    )));
    // A column list that does not tile: its first two entries swapped.
    assert!(refused(patch_section(
        bytes,
        SectionKind::HierarchyColumnBlocks,
        |b| {
            let (x, y) = (u32_at(b, 0), u32_at(b, 4));
            put(b, 0, y);
            put(b, 4, x);
        }
    )));
}

/// `--compress hmatrix-q16` on the same box: every entry of a block stored
/// entry by entry within half its q16 quantum of the dense compliance,
/// every factored block within its tolerance plus the factors' q16
/// rounding, the measured force error within the team's bound; and
/// corrupted codes and scales refused at load.
#[test]
fn q16_hierarchy_is_within_its_bound_and_corrupted_codes_are_refused() {
    // The box at a coarser 12 × 4 × 4 cells (325 vertices):
    // still near, factored and far blocks, at a fraction of the build.
    let (_, report, options) = mesh();
    let mesh = box_mesh([12, 4, 4], [0.2, 0.1, 0.1]);
    let file = coded_table(&mesh, &report, &options, Some(BlockCode::HmatrixQ16));
    let t = PrecomputedTable::<f32>::load(file.bytes()).expect("loads");
    assert_eq!(
        t.surface_blocks().encoding(),
        BlockEncoding::HierarchicalQ16
    );
    let record = t.compression().expect("record");
    // The team's bound on a hierarchical table's force error (the f32
    // hierarchy's test above): the q16 rounding must not break it.
    assert!(record.max_force_error <= 1e-3, "{record:?}");
    let (c, ordering) = f64_compliance(&mesh, &report, &options);
    let h = *t.surface_blocks().as_hierarchical().expect("hierarchical");
    assert!(h.is_q16() && h.value_bytes() == 2);
    let touchable = &t.free_vertices()[..t.touchable_count()];
    let (mut near, mut far) = (0, 0);
    for b in h.blocks() {
        let pairs = || {
            (b.row_start as usize..b.row_end as usize)
                .flat_map(|n| (b.col_start as usize..b.col_end as usize).map(move |k| (n, k)))
        };
        let want = |n: usize, k: usize| dense_block(&c, &ordering, touchable[n], touchable[k]);
        let largest = pairs()
            .flat_map(|(n, k)| want(n, k))
            .fold(0.0f64, |m, x| m.max(x.abs()));
        let (mut diff2, mut norm2, mut count) = (0.0f64, 0.0f64, 0.0f64);
        for (n, k) in pairs() {
            let got = h.block(n, k).expect("in range");
            for (g, w) in got.iter().zip(want(n, k)) {
                let e = f64::from(*g) - w;
                diff2 += e * e;
                norm2 += w * w;
                count += 1.0;
            }
        }
        if b.rank == 0 {
            near += 1;
            // Entries: exact, or a far block's truncated product (within
            // its tolerance), then each within half the quantum
            // `largest / 32767` (its f32 rounding 1e-6; the f32 product's
            // and the diagonal's symmetrization: relative 1e-6).
            let q16 = count.sqrt() * 0.5 * largest / 32767.0 * (1.0 + 1e-6);
            let bound = (TOLERANCE * 1.001 + 1e-6) * norm2.sqrt() + q16;
            assert!(
                diff2.sqrt() <= bound,
                "near block {b:?}: {diff2:e} vs {bound:e}"
            );
        } else {
            far += 1;
            // The truncation's bound plus the factors' q16 rounding: each
            // factor within half a quantum (2^-16 of its largest) per
            // number; over a rank of at most 64, a relative 1e-3 of the
            // block at most (the balanced factors' product).
            let rel = (diff2 / norm2).sqrt();
            assert!(rel <= TOLERANCE * 1.001 + 1e-3, "far block {b:?}: {rel:e}");
        }
    }
    assert!(near > 0 && far > 0, "{near} near, {far} far blocks");
    assert_q16_corruptions_refused(file.bytes());
}

/// A q16 hierarchy with a code −32768, a scale pair missing, a near
/// block's second scale not 0, or a scale ≤ 0 is refused.
fn assert_q16_corruptions_refused(bytes: &[u8]) {
    let refused = |patched: Vec<u8>, section: SectionKind| {
        let file = TableFile::from_bytes(&patched);
        match PrecomputedTable::<f32>::load(file.bytes()) {
            Err(LoadError::BadHierarchy { kind, .. }) => kind == section,
            other => panic!("{section:?}: {:?}", other.err()),
        }
    };
    let codes = SectionKind::HierarchyCodes;
    assert!(refused(
        patch_section(bytes, codes, |b| b[0..2]
            .copy_from_slice(&0x8000u16.to_le_bytes())),
        codes
    ));
    let scales = SectionKind::HierarchyScales;
    // Block 0 is the first leaf's diagonal block: near, `[s0, 0]`.
    let put = |b: &mut [u8], at: usize, x: f32| b[at..at + 4].copy_from_slice(&x.to_le_bytes());
    assert!(refused(
        patch_section(bytes, scales, |b| put(b, 4, 1e-9)),
        scales
    ));
    assert!(refused(
        patch_section(bytes, scales, |b| put(b, 0, -1e-9)),
        scales
    ));
    assert!(refused(
        patch_section(bytes, scales, |b| put(b, 0, f32::NAN)),
        scales
    ));
    // The record's block count one less: the scales no longer match it
    // (the blocks section's check comes first and names the record).
    let blocks = SectionKind::HierarchyRecord;
    assert!(refused(
        patch_section(bytes, blocks, |b| {
            let n = u32::from_le_bytes(b[4..8].try_into().unwrap());
            b[4..8].copy_from_slice(&(n - 1).to_le_bytes());
        }),
        blocks
    ));
}
