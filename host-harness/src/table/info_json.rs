//! `tables info --json` ([`info_json`]): the machine-readable summary of a
//! table, for every kind and encoding: bytes, encoding, the errors measured
//! at build.

use palpate_kernel::Real;
use palpate_kernel::table::format::{BlockEncoding, CompressionRecord, TableKind};
use serde_json::{Value, json};

use super::load::{AnyModel, TableFile};

/// `tables info --json`: `{"bytes", "kind", "precision", "encoding",
/// "interior_encoding", "measured": {"force_error",
/// "touchable_displacement_error", "displacement_error"}}` and, for a
/// hierarchical table, `"hierarchy"` with its counts. A pre-computed
/// table's `encoding` is its surface (contact) part's
/// ([`BlockEncoding::name`]: `uncompressed`, `f16`, `q16`, `hmatrix`); an
/// uncompressed table is its own reference, so its measured errors are 0.
/// Other kinds have `encoding` and `measured` null. `Err` names the load
/// error of a table that fails validation.
pub fn info_json(file: &TableFile) -> Result<Value, String> {
    let bytes = file.bytes().len();
    file.validate().map_err(|e| e.to_string())?;
    let kind = file.kind();
    let precision = match file.raw_header().map(|h| h.scalar_bytes) {
        Some(8) => "f64",
        _ => "f32",
    };
    let kind_name = match kind {
        Some(TableKind::Precomputed) => "precomputed",
        Some(TableKind::TensorMass) => "tensor-mass",
        Some(TableKind::Interface) => "interface",
        None => "unknown",
    };
    let mut out = json!({
        "bytes": bytes,
        "kind": kind_name,
        "precision": precision,
        "encoding": Value::Null,
        "measured": Value::Null,
    });
    if kind != Some(TableKind::Precomputed) {
        return Ok(out);
    }
    let model = file.model().map_err(|e| e.to_string())?;
    let (surface, interior, record, hierarchy) = match &model {
        AnyModel::F32(m) => parts(m.table()),
        AnyModel::F64(m) => parts(m.table()),
    };
    let measured = record.map_or(
        json!({
            "force_error": 0.0,
            "touchable_displacement_error": 0.0,
            "displacement_error": 0.0,
        }),
        |r| {
            json!({
                "force_error": r.max_force_error,
                "touchable_displacement_error": r.max_surface_displacement_error,
                "displacement_error": r.max_displacement_error,
                "probe_count": r.probe_count,
            })
        },
    );
    out["encoding"] = json!(surface.name());
    out["interior_encoding"] = json!(interior.name());
    out["measured"] = measured;
    if let Some(h) = hierarchy {
        out["hierarchy"] = h;
    }
    Ok(out)
}

/// A pre-computed table's part encodings, record and hierarchy summary.
fn parts<T: Real>(
    table: &palpate_kernel::PrecomputedTable<'_, T>,
) -> (
    BlockEncoding,
    BlockEncoding,
    Option<CompressionRecord>,
    Option<Value>,
) {
    let surface = table.surface_blocks();
    let hierarchy = surface.as_hierarchical().map(|h| {
        let r = h.record();
        let far = h.blocks().iter().filter(|b| b.rank > 0).count();
        json!({
            "leaves": h.leaf_count(),
            "blocks": h.blocks().len(),
            "far_blocks": far,
            "max_rank": r.max_rank,
            "max_column_blocks": r.max_column_blocks,
            "tolerance": r.tolerance,
            "eta": r.eta,
            "data_bytes": h.data_len() * h.value_bytes(),
        })
    });
    (
        surface.encoding(),
        table.interior_blocks().encoding(),
        table.compression().copied(),
        hierarchy,
    )
}
