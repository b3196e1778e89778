//! A scene's `[tables]` (`host-harness/src/scene/tables.rs`, `session::model::scene_compression`):
//! each option only with its code and in its range, the defaults of `tables build`, and a
//! pre-computed scene built with the table the scene names (a hierarchical one, f32 or q16, read
//! back by the kernel as such), a hybrid scene's interface hierarchical for `"hmatrix"`, the other
//! codes refused on the other models.

use std::path::Path;

use palpate::scene::{Scene, TableCode};
use palpate::session::model::{SceneModel, SceneTables, scene_compression};
use palpate::table::compress::BlockCode;
use palpate::table::hmatrix::DEFAULT_TOLERANCE;
use palpate_kernel::PrecomputedTable;
use palpate_kernel::table::format::BlockEncoding;

/// A 0.06 × 0.06 × 0.03 m box of 6 × 6 × 3 cells fixed at its base, with `extra` appended.
fn scene(extra: &str) -> Result<Scene, String> {
    let text = format!(
        "fix = [\"z<0.001\"]\n[generated]\nbox_m = [0.06, 0.06, 0.03]\ncells = [6, 6, 3]\n\
         [material]\nyoung_pa = 3000\npoisson = 0.45\n{extra}"
    );
    Scene::from_toml_str_named(&text, "t.toml", Path::new(".")).map_err(|e| e.to_string())
}

#[test]
fn tables_options_take_their_code_and_range() {
    let s = scene("[tables]\ncompress = \"hmatrix\"\ntolerance = 1e-3\n").expect("valid");
    assert_eq!(s.tables.compress, Some(TableCode::Hmatrix));
    let c = scene_compression(&s.tables).expect("compressed");
    assert_eq!((c.code, c.tolerance), (BlockCode::Hmatrix, 1e-3));
    let c = scene_compression(
        &scene("[tables]\ncompress = \"q16\"\ndrop_below = 0.05\n")
            .unwrap()
            .tables,
    )
    .expect("compressed");
    assert_eq!((c.code, c.drop_below), (BlockCode::Q16, 0.05));
    let c = scene_compression(&scene("[tables]\ncompress = \"hmatrix\"\n").unwrap().tables)
        .expect("compressed");
    assert_eq!(c.tolerance, DEFAULT_TOLERANCE);
    let c = scene_compression(
        &scene("[tables]\ncompress = \"hmatrix-q16\"\ntolerance = 3e-3\n")
            .unwrap()
            .tables,
    )
    .expect("compressed");
    assert_eq!((c.code, c.tolerance), (BlockCode::HmatrixQ16, 3e-3));
    assert!(scene_compression(&scene("").unwrap().tables).is_none());
    for (extra, expected) in [
        (
            "[tables]\ncompress = \"q16\"\ntolerance = 1e-3\n",
            "[tables] tolerance",
        ),
        (
            "[tables]\ncompress = \"hmatrix\"\ntolerance = 1.5\n",
            "(0, 1)",
        ),
        (
            "[tables]\ncompress = \"hmatrix\"\ndrop_below = 0.1\n",
            "[tables] drop_below",
        ),
        ("[tables]\ncompress = \"f16\"\ndrop_below = 1\n", "[0, 1)"),
        (
            "[tables]\ncompress = \"hmatrix-q16\"\ndrop_below = 0.1\n",
            "[tables] drop_below",
        ),
        ("[tables]\ntolerance = 1e-3\n", "[tables] tolerance"),
        ("[tables]\ncompress = \"zip\"\n", "unknown variant"),
        ("[tables]\ncompres = \"q16\"\n", "unknown field"),
    ] {
        let error = scene(extra).expect_err(extra);
        assert!(error.contains(expected), "{extra}: {error}");
    }
}

#[test]
fn a_precomputed_scene_builds_the_table_its_tables_name() {
    let s = scene("[tables]\ncompress = \"hmatrix\"\n").expect("valid");
    let (mesh, report) = s.load_mesh().expect("mesh");
    let tables = SceneModel::of(&s, &mesh, &report)
        .expect("model")
        .tables(&s, &mesh, &report, None)
        .expect("tables");
    let SceneTables::Precomputed(file) = tables else {
        panic!("a pre-computed scene");
    };
    let table = PrecomputedTable::<f32>::load(file.bytes()).expect("load");
    assert_eq!(
        table.surface_blocks().encoding(),
        BlockEncoding::Hierarchical
    );
    // The same in 16-bit fixed point (`tables build --compress hmatrix-q16`).
    let s = scene("[tables]\ncompress = \"hmatrix-q16\"\ntolerance = 3e-3\n").expect("valid");
    let SceneTables::Precomputed(file) = SceneModel::of(&s, &mesh, &report)
        .expect("model")
        .tables(&s, &mesh, &report, None)
        .expect("tables")
    else {
        panic!("a pre-computed scene");
    };
    let table = PrecomputedTable::<f32>::load(file.bytes()).expect("load");
    assert_eq!(
        table.surface_blocks().encoding(),
        BlockEncoding::HierarchicalQ16
    );

    let dynamic =
        scene("[model]\nkind = \"dynamic\"\ndamping_per_s = 2\n[tables]\ncompress = \"q16\"\n")
            .expect("valid");
    let (mesh, report) = dynamic.load_mesh().expect("mesh");
    let error = SceneModel::of(&dynamic, &mesh, &report)
        .expect("model")
        .tables(&dynamic, &mesh, &report, None)
        .err()
        .expect("refused");
    assert!(
        error
            .to_string()
            .contains("applies to a pre-computed scene"),
        "{error}"
    );
}

/// A hybrid scene (a cut sphere in the block) with `compress = "hmatrix"`: its interface's
/// condensed stiffness and its pre-computed region's table hierarchical, read back by the
/// kernel as such (the far-block tolerance the scene's, in the hierarchy records), the
/// interface's response over the region's touchable rows only; `"q16"` refused on a hybrid.
#[test]
fn a_hybrid_scene_builds_a_hierarchical_interface() {
    use palpate_kernel::table::{ComplianceBlocks, CondensedStiffness, InterfaceTable};
    let hybrid = "[model]\nkind = \"dynamic\"\ndamping_per_s = 2\n[[zone]]\nkind = \"cut\"\n\
                  shape = \"sphere\"\ncenter_m = [0.03, 0.03, 0.03]\nradius_m = 0.005\n";
    let s = scene(&format!(
        "{hybrid}[tables]\ncompress = \"hmatrix\"\ntolerance = 1e-3\n"
    ))
    .expect("valid");
    let (mesh, report) = s.load_mesh().expect("mesh");
    let tables = SceneModel::of(&s, &mesh, &report)
        .expect("model")
        .tables(&s, &mesh, &report, None)
        .expect("tables");
    let SceneTables::Hybrid(files, _) = tables else {
        panic!("a hybrid scene");
    };
    let interface = InterfaceTable::<f32>::load(files.interface.bytes()).expect("load");
    let CondensedStiffness::Hierarchical { blocks, .. } = interface.condensed() else {
        panic!("a dense interface");
    };
    assert_eq!(blocks.record().tolerance, 1e-3);
    assert_eq!(blocks.touchable_count(), interface.connection_count());
    let region = PrecomputedTable::<f32>::load(files.precomputed.bytes()).expect("region");
    let ComplianceBlocks::Hierarchical(region_blocks) = region.surface_blocks() else {
        panic!("a dense pre-computed region");
    };
    assert_eq!(region_blocks.record().tolerance, 1e-3);
    assert_eq!(interface.response_rows(), region.touchable_count());

    for code in ["q16", "hmatrix-q16"] {
        let coded = scene(&format!("{hybrid}[tables]\ncompress = \"{code}\"\n")).expect("valid");
        let error = SceneModel::of(&coded, &mesh, &report)
            .expect("model")
            .tables(&coded, &mesh, &report, None)
            .err()
            .expect("refused")
            .to_string();
        assert!(
            error.contains(&format!(
                "compress = \"{code}\" applies to a pre-computed scene"
            )) && error.contains("a hybrid takes compress = \"hmatrix\""),
            "{error}"
        );
    }
}
