//! `palpate precomputed replay`: the firmware's scripted sequence run on the
//! host through the same code ([`palpate_script::replay`]), so the two
//! outputs can be compared byte for byte (`tools/firmware-check.sh`).

use anyhow::{Context, bail};

use crate::table::load::{AnyModel, TableFile};

/// Replays `sequence` on an f32 table and returns the output lines (format:
/// `palpate_script` crate docs). Errors name the table as `table_name` or
/// the sequence as `sequence_name` (the file each is about).
pub fn replay(
    file: &TableFile,
    table_name: &str,
    sequence: &str,
    sequence_name: &str,
) -> anyhow::Result<String> {
    let model = match file
        .model()
        .with_context(|| format!("{table_name}: invalid table"))?
    {
        AnyModel::F32(model) => model,
        AnyModel::F64(_) => {
            bail!(
                "{table_name}: an f64 table; replay runs the firmware precision: build the table with --precision f32"
            )
        }
    };
    let mut displacements = vec![[0.0f32; 3]; model.table().vertex_count()];
    let mut out = String::new();
    palpate_script::replay(&model, sequence, &mut displacements, &mut out)
        .with_context(|| sequence_name.to_owned())?;
    Ok(out)
}
