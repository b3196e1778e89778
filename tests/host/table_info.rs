//! `tables info --json` (`host-harness/src/table/info_json.rs`): the bytes are the file's, the
//! encoding the table's own, and the measured errors those stored at build (an uncompressed
//! table is its own reference: 0), for the reference liver built uncompressed and q16.

use palpate::fem::material::Material;
use palpate::mesh::read_mesh;
use palpate::table::build::{BuildOptions, build};
use palpate::table::compliance::Solver;
use palpate::table::compress::{BlockCode, Compression, ContactBlocks};
use palpate::table::file::Precision;
use palpate::table::info_json::info_json;
use palpate::table::load::TableFile;
use palpate_kernel::PrecomputedTable;
use palpate_tests::reference_dir;

/// The reference liver (181 vertices, 97 touchable) built with `compression`.
fn liver(compression: Option<Compression>) -> TableFile {
    let (mesh, report) = read_mesh(&reference_dir().join("meshes/liver.msh")).expect("liver.msh");
    let options = BuildOptions::precomputed(
        Material::new(3000.0, 0.45).expect("material"),
        vec!["z<=0.01".parse().expect("predicate")],
        Solver::Cholesky,
        Precision::F32,
    )
    .with_compression(compression);
    TableFile::from_bytes(&build(&mesh, &report, &options).expect("build").bytes)
}

#[test]
fn info_json_reports_the_file_bytes_encoding_and_stored_errors() {
    let dense = liver(None);
    let json = info_json(&dense).expect("valid");
    assert_eq!(json["bytes"], dense.bytes().len());
    assert_eq!(json["kind"], "precomputed");
    assert_eq!(json["encoding"], "uncompressed");
    assert_eq!(json["measured"]["force_error"], 0.0);
    assert_eq!(json["measured"]["touchable_displacement_error"], 0.0);

    let q16 = liver(Some(Compression {
        code: BlockCode::Q16,
        drop_below: 0.0,
        contact: ContactBlocks::Coded,
        tolerance: 0.0,
    }));
    let json = info_json(&q16).expect("valid");
    let record = *PrecomputedTable::<f32>::load(q16.bytes())
        .expect("load")
        .compression()
        .expect("a compressed table has a record");
    assert_eq!(json["bytes"], q16.bytes().len());
    assert_eq!(json["encoding"], "q16");
    assert_eq!(json["measured"]["force_error"], record.max_force_error);
    assert_eq!(
        json["measured"]["touchable_displacement_error"],
        record.max_surface_displacement_error
    );
    // A q16 table costs some force accuracy, never none and never more than 1 %.
    let force_error = json["measured"]["force_error"].as_f64().expect("a number");
    assert!(force_error > 0.0 && force_error < 1e-2, "{force_error}");
}

#[test]
fn info_json_refuses_a_corrupted_table_with_the_load_error() {
    let dense = liver(None);
    let mut bytes = dense.bytes().to_vec();
    let last = bytes.len() - 1;
    bytes[last] ^= 0xff;
    let error = info_json(&TableFile::from_bytes(&bytes)).expect_err("checksum");
    assert!(error.contains("checksum"), "{error}");
}
