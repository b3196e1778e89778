//! The study's checks before any work: the output folder and every body's
//! hybrid.

use std::path::Path;

use anyhow::Context;

use super::body::Body;
use super::tables::DENSITY_KG_M3;
use crate::hybrid::{HybridOptions, check_hybrid};
use crate::table::file::Precision;

/// The checks of a study that would otherwise fail late, run before any work: `out` can be
/// written (the nearest folder that exists on its path takes a file; nothing is created or
/// left there), and every body has a hybrid ([`check_hybrid`] of its tables in f64 and f32:
/// its loaded end is neither none nor all of it, its pre-computed region has a free vertex,
/// its tables are within the limits). Each error is one line naming the path or the mesh.
pub fn preflight(bodies: &[Body], out: &Path) -> anyhow::Result<()> {
    let existing = out
        .ancestors()
        .find(|p| p.as_os_str().is_empty() || p.exists())
        .map(|p| {
            if p.as_os_str().is_empty() {
                Path::new(".")
            } else {
                p
            }
        })
        .unwrap_or(Path::new("."));
    if !existing.is_dir() {
        anyhow::bail!(
            "--out {}: {} is not a folder: refused before the study",
            out.display(),
            existing.display()
        );
    }
    let probe = existing.join(format!(".palpate-chart-probe-{}", std::process::id()));
    match std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
    {
        Ok(_) => std::fs::remove_file(&probe).with_context(|| {
            format!("--out {}: cannot remove {}", out.display(), probe.display())
        })?,
        Err(e) => anyhow::bail!(
            "--out {}: cannot write in {} ({e}): refused before the study",
            out.display(),
            existing.display()
        ),
    }
    for body in bodies {
        let dynamic = body.hybrid_dynamic_tets();
        for precision in [Precision::F64, Precision::F32] {
            let options =
                HybridOptions::new(body.material, DENSITY_KG_M3, body.fix.clone(), precision);
            check_hybrid(&body.mesh, &body.report, &dynamic, &options).with_context(|| {
                format!(
                    "mesh {}: no hybrid model of it for the study (its tensor-mass region is \
                     the loaded end, {} of its {} tets): refused before the study",
                    body.label,
                    dynamic.iter().filter(|&&d| d).count(),
                    dynamic.len()
                )
            })?;
        }
    }
    Ok(())
}
