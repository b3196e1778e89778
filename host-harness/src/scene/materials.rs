//! Per-region materials of a scene (heterogeneous tissue, e.g. a stiff nodule under the surface):
//!
//! ```toml
//! [[region]]                   # per-region materials; tets of other regions take [material]
//! id = 2                       # MSH physical tag (first tag, 2.2 and 4.1), VTK cell field
//! young_pa = 30000.0           # "region" (integer), TetGen region attribute
//! poisson = 0.45               # 0 <= nu <= 0.4999, as [material]
//! density_kg_m3 = 1000.0       # optional; a table has one density: [material]'s (only that
//!                              # value is accepted)
//! ```
//!
//! The region ids are the mesh reader's ([`MeshReport::tet_regions`]). A scene's checks without
//! the mesh are [`check_regions`] (run by [`crate::scene::Scene::validate`]); with the mesh,
//! [`tet_materials`] (`Scene::tet_materials`) gives every consumer the material of each tet, refusing a region id
//! no tet has.

use super::error::SceneError;
use crate::fem::material::{
    MAX_STIFFNESS_CONTRAST, Material, MaterialError, POISSON_RANGE, TetMaterials,
};
use crate::mesh::{MeshReport, TetMesh};
use crate::output::number::shown;

/// Default density, kg/m³ (water; soft tissue is 1000–1100).
pub const DEFAULT_DENSITY_KG_M3: f64 = 1000.0;

/// The tissue material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaterialSpec {
    /// The elastic material (Young's modulus `E`, Pa, finite and > 0; Poisson ratio `ν`,
    /// `0 ≤ ν ≤ MAX_POISSON`), built once when the scene is and checked by its validation: the
    /// one every table build and model takes.
    pub elastic: Material,
    /// Mass density, kg/m³, finite and > 0 (the dynamic model's lumped masses).
    pub density_kg_m3: f64,
}

/// One `[[region]]` of a scene: the material of the tets whose region id is `id`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RegionSpec {
    /// The region id (MSH physical tag, VTK `region` cell value, TetGen region attribute).
    pub id: u32,
    /// The region's elastic material (the ranges of [`MaterialSpec::elastic`]), built once
    /// when the scene is and checked by [`check_regions`].
    pub elastic: Material,
    /// Mass density, kg/m³: `None`, or the `[material]`'s (a table has one density).
    pub density_kg_m3: Option<f64>,
}

impl RegionSpec {
    /// The scene key that names this region in messages: `[[region]] id = 2`.
    pub fn key(&self) -> String {
        format!("[[region]] id = {}", self.id)
    }
}

/// The checks of `regions` that need no mesh, given the `[material]` Young's modulus (Pa) and
/// density (kg/m³): each region's `E` and `ν` in [`Material::new`]'s ranges, its `E` within
/// [`MAX_STIFFNESS_CONTRAST`] of the `[material]`'s, its density absent or the `[material]`'s,
/// and no id twice. Errors are `(key, message)`.
pub fn check_regions(
    regions: &[RegionSpec],
    young_pa: f64,
    density_kg_m3: f64,
) -> Result<(), (String, String)> {
    for (k, region) in regions.iter().enumerate() {
        let key = region.key();
        match region.elastic.check() {
            Err(MaterialError::YoungModulus(e)) => {
                return Err((
                    format!("{key}: young_pa = {}", shown(e)),
                    "must be finite and > 0 Pa".into(),
                ));
            }
            Err(MaterialError::PoissonRatio(nu)) => {
                return Err((
                    format!("{key}: poisson = {}", shown(nu)),
                    format!("must satisfy {POISSON_RANGE}"),
                ));
            }
            Ok(()) => {}
        }
        let contrast = region.elastic.young_pa / young_pa;
        if !(1.0 / MAX_STIFFNESS_CONTRAST..=MAX_STIFFNESS_CONTRAST).contains(&contrast) {
            return Err((
                format!("{key}: young_pa = {}", shown(region.elastic.young_pa)),
                format!(
                    "is {contrast:.1e} times [material] young_pa = {}: a [[region]] may be at \
                     most {} times stiffer or softer (beyond, the table build's stiffness is \
                     singular)",
                    shown(young_pa),
                    format_args!("{MAX_STIFFNESS_CONTRAST:e}")
                ),
            ));
        }
        if let Some(density) = region.density_kg_m3
            && density != density_kg_m3
        {
            return Err((
                format!("{key}: density_kg_m3 = {density}"),
                format!(
                    "differs from [material] density_kg_m3 = {density_kg_m3}: a table has one density (the lumped masses and a cut's mass share); leave it out"
                ),
            ));
        }
        if regions[..k].iter().any(|other| other.id == region.id) {
            return Err((key, "given twice: one [[region]] per id".into()));
        }
    }
    Ok(())
}

/// The material of every tet of `mesh` (read with `report`): a tet whose region id
/// ([`MeshReport::tet_regions`]) has a `[[region]]` takes that material, every other tet the
/// `[material]` (the default, which the table header records). Without `[[region]]`, every
/// tet takes `[material]` ([`TetMaterials::uniform`]).
///
/// Errors, naming the scene `source`, the key `[[region]] id = N` and the mesh: a region id that no
/// tet has, or a mesh without region ids.
pub fn tet_materials(
    source: &str,
    material: &MaterialSpec,
    regions: &[RegionSpec],
    mesh: &TetMesh,
    report: &MeshReport,
) -> Result<TetMaterials, SceneError> {
    let invalid = |key: String, msg: String| SceneError::Invalid {
        file: source.to_owned(),
        key,
        msg,
    };
    let default = material.elastic;
    let Some(first) = regions.first() else {
        return Ok(TetMaterials::uniform(default, mesh.tets.len()));
    };
    let Some(tet_regions) = report.tet_regions.as_deref() else {
        return Err(invalid(
            first.key(),
            format!(
                "the mesh {} has no region ids (give an MSH physical tag, a VTK CELL_DATA field `region` or a TetGen region attribute per tet)",
                report.source
            ),
        ));
    };
    let mut by_id = Vec::with_capacity(regions.len());
    for region in regions {
        if !tet_regions.contains(&region.id) {
            let mut present: Vec<u32> = tet_regions.to_vec();
            present.sort_unstable();
            present.dedup();
            let shown: Vec<String> = present.iter().take(16).map(u32::to_string).collect();
            let more = if present.len() > 16 { ", ..." } else { "" };
            return Err(invalid(
                region.key(),
                format!(
                    "no tet of the mesh {} has region {} (its regions: {}{more})",
                    report.source,
                    region.id,
                    shown.join(", ")
                ),
            ));
        }
        by_id.push((region.id, region.elastic));
    }
    Ok(TetMaterials::from_regions(default, tet_regions, &by_id))
}
