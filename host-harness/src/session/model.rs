//! How a scene's tissue is modelled (MODELS.md §5, RR-3510 §6.2): without
//! zones, as its `[model]` says; with zones, as their partition
//! ([`crate::partition`]) says: no dynamic tet → pre-computed, every tet
//! dynamic → tensor-mass, both → the hybrid. The dynamic region's law is
//! the plan's (St Venant-Kirchhoff where a large-deformation zone asks for
//! it, the penalty when ν ≥ 0.45) or `[model]`'s, whichever is the more
//! demanding; its step, integrator and damping are `[model]`'s.

use anyhow::{Context, anyhow, bail};
use palpate_kernel::tensor_mass::{ElasticLaw, StvkForm};

use super::options::{precomputed_options, tensor_mass_options};
use crate::fem::penalty::penalty_n;
use crate::fix::fixed_vertices;
use crate::hybrid::{HybridOptions, HybridTables, build_hybrid};
use crate::mesh::{MeshReport, TetMesh};
use crate::output::atomic::AtomicFile;
use crate::partition::{Partition, RegionModel, cost::sub_mesh};
use crate::scene::{DynamicSpec, ModelSpec, Scene};
use crate::scene::{TableCode, TablesSpec};
use crate::table::build::build;
use crate::table::compress::{BlockCode, Compression, ContactBlocks};
use crate::table::estimate::SizeLimits;
use crate::table::file::Precision;
use crate::table::hmatrix::DEFAULT_TOLERANCE;
use crate::table::load::TableFile;
use std::io::Write as _;
use std::path::{Path, PathBuf};

/// A scene's model, resolved.
pub enum SceneModel {
    /// The pre-computed model of the whole mesh.
    Precomputed,
    /// The tensor-mass model of the whole mesh.
    Dynamic(DynamicSpec),
    /// The hybrid: the tensor-mass region's settings and the partition.
    Hybrid {
        /// The tensor-mass region's settings.
        spec: DynamicSpec,
        /// The partition the zones chose.
        partition: Partition,
    },
}

impl SceneModel {
    /// The model of `scene` on its loaded `mesh` (module docs). A scene
    /// whose zones make tets dynamic needs `[model] kind = "dynamic"` for
    /// their step: otherwise a one-line error naming the scene.
    pub fn of(scene: &Scene, mesh: &TetMesh, report: &MeshReport) -> anyhow::Result<Self> {
        scene.check_on_mesh(mesh)?;
        if scene.zones.is_empty() {
            return Ok(match scene.model {
                ModelSpec::Precomputed => {
                    // A piece held by no fixed vertex makes the stiffness
                    // singular: said as `scene plan` says it, before the
                    // build (which names a `fix` that matches nothing).
                    let (fixed, _) =
                        fixed_vertices(&mesh.positions, &scene.fix, &report.unreferenced_vertices);
                    if fixed.contains(&true) {
                        Partition::of_scene(scene, mesh, report).map_err(|e| anyhow!("{e}"))?;
                    }
                    Self::Precomputed
                }
                ModelSpec::Dynamic(spec) => Self::Dynamic(spec),
            });
        }
        let partition = Partition::of_scene(scene, mesh, report).map_err(|e| anyhow!("{e}"))?;
        let dynamic: Vec<u32> = (0..mesh.tets.len() as u32)
            .filter(|&t| partition.dynamic[t as usize])
            .collect();
        if dynamic.is_empty() {
            return Ok(Self::Precomputed);
        }
        let ModelSpec::Dynamic(spec) = scene.model else {
            bail!(
                "{}: the zones make {} tets dynamic: give their step in [model] (kind = \"dynamic\", dt_s, integrator, damping_per_s)",
                scene.source,
                dynamic.len()
            );
        };
        let stvk = partition.regions.iter().any(|r| {
            matches!(
                r.model,
                RegionModel::TensorMass {
                    law: ElasticLaw::StVenantKirchhoff(_),
                    ..
                }
            )
        });
        let penalty = partition.regions.iter().any(|r| {
            matches!(
                r.model,
                RegionModel::TensorMass {
                    incompressibility: true,
                    ..
                }
            )
        });
        let law = match (spec.law, stvk) {
            (ElasticLaw::Linear, true) => ElasticLaw::StVenantKirchhoff(StvkForm::PerTet),
            (law, _) => law,
        };
        // The penalty corrects St Venant-Kirchhoff's softening in
        // compression; a scene's neo-Hookean law has its own volume energy
        // and a co-rotational one is linear in volume: neither takes it.
        let penalty = penalty && matches!(law, ElasticLaw::StVenantKirchhoff(_));
        let incompressibility_n = match (spec.incompressibility_n, penalty) {
            (None, true) => {
                let (region, _) = sub_mesh(mesh, &dynamic);
                Some(penalty_n(&region, &scene.material.elastic))
            }
            (given, _) => given,
        };
        let spec = DynamicSpec {
            law,
            incompressibility_n,
            ..spec
        };
        Ok(if dynamic.len() == mesh.tets.len() {
            Self::Dynamic(spec)
        } else {
            Self::Hybrid { spec, partition }
        })
    }

    /// The f32 tables of the model (the scene's materials per tet, density
    /// and supports), built in memory with the pipeline of `palpate tables
    /// build`; a pre-computed model's compliance compressed with
    /// `compression` (`tables build --compress`), else as the scene's
    /// `[tables]` says ([`scene_compression`]); a hybrid's interface as
    /// [`hybrid_tables`] says (`--compress` refused); a tensor-mass model's
    /// refused.
    pub fn tables(
        self,
        scene: &Scene,
        mesh: &TetMesh,
        report: &MeshReport,
        compression: Option<Compression>,
    ) -> anyhow::Result<SceneTables> {
        if compression.is_some() && !matches!(self, Self::Precomputed) {
            bail!(
                "{}: --compress applies to a pre-computed scene (its compliance table)",
                scene.source
            );
        }
        if scene.tables.compress.is_some() && matches!(self, Self::Dynamic(_)) {
            bail!(
                "{}: [tables] compress applies to a pre-computed scene (its compliance table) \
                 or a hybrid (compress = \"hmatrix\": its interface); this scene's model is \
                 dynamic (tensor-mass)",
                scene.source,
            );
        }
        let compression = compression.or_else(|| scene_compression(&scene.tables));
        let single = |options| -> anyhow::Result<TableFile> {
            let built = build(mesh, report, &options).with_context(|| scene.source.clone())?;
            Ok(TableFile::from_bytes(&built.bytes))
        };
        Ok(match self {
            Self::Precomputed => {
                let options = precomputed_options(scene, mesh, report)?;
                SceneTables::Precomputed(single(options.with_compression(compression))?)
            }
            Self::Dynamic(spec) => {
                SceneTables::Dynamic(single(tensor_mass_options(scene, mesh, report)?)?, spec)
            }
            Self::Hybrid { spec, partition } => {
                let tables = hybrid_tables(scene, mesh, report, &partition, Precision::F32)?;
                SceneTables::Hybrid(
                    Box::new(HybridFiles {
                        precomputed: tables.precomputed,
                        dynamic: tables.dynamic,
                        interface: tables.interface,
                        dynamic_tet: partition.dynamic,
                    }),
                    spec,
                )
            }
        })
    }
}

/// The compression a scene's `[tables]` asks for, `None` for the f32 table
/// (defaults: the build's hmatrix tolerance, nothing dropped, the contact
/// blocks coded).
pub fn scene_compression(tables: &TablesSpec) -> Option<Compression> {
    let code = match tables.compress? {
        TableCode::F16 => BlockCode::F16,
        TableCode::Q16 => BlockCode::Q16,
        TableCode::Hmatrix => BlockCode::Hmatrix,
        TableCode::HmatrixQ16 => BlockCode::HmatrixQ16,
    };
    Some(Compression {
        code,
        drop_below: tables.drop_below.unwrap_or(0.0),
        contact: ContactBlocks::Coded,
        tolerance: tables.tolerance.unwrap_or(DEFAULT_TOLERANCE),
    })
}

/// The hybrid's three tables for `partition` of `scene` (its materials per
/// tet, density and supports) in `precision`, built in memory
/// ([`build_hybrid`]); with `[tables] compress = "hmatrix"` (its
/// `tolerance`) the interface's condensed stiffness and the pre-computed
/// region's table hierarchical, the response over the region's touchable
/// rows ([`HybridOptions::compress_region`]); `"f16"` or `"q16"` refused.
pub fn hybrid_tables(
    scene: &Scene,
    mesh: &TetMesh,
    report: &MeshReport,
    partition: &Partition,
    precision: Precision,
) -> anyhow::Result<HybridTables> {
    let interface_compression = match scene.tables.compress {
        None | Some(TableCode::Hmatrix) => scene.tables.interface_compression(),
        Some(code) => bail!(
            "{}: [tables] compress = \"{}\" applies to a pre-computed scene; a hybrid takes \
             compress = \"hmatrix\" (its interface's condensed stiffness)",
            scene.source,
            code.name()
        ),
    };
    let materials = scene.tet_materials(mesh, report)?;
    let options = HybridOptions::new(
        materials.default_material(),
        scene.material.density_kg_m3,
        scene.fix.clone(),
        precision,
    )
    .with_tet_materials(materials);
    // The pre-computed region's candidate lists serve the scene's tool, as a pre-computed
    // scene's table does (`precomputed_options`).
    let options = HybridOptions {
        build: options.build.with_tool_radius(scene.tool.radius_m),
        limits: SizeLimits {
            print_estimate: true,
            ..options.limits
        },
        compress_region: interface_compression.is_some(),
        interface_compression,
        ..options
    };
    build_hybrid(mesh, report, &partition.dynamic, &options).with_context(|| scene.source.clone())
}

/// A scene's tables, by its model.
pub enum SceneTables {
    /// The pre-computed table.
    Precomputed(TableFile),
    /// The tensor-mass table and the model's settings.
    Dynamic(TableFile, DynamicSpec),
    /// The hybrid's three tables and its tensor-mass region's settings.
    Hybrid(Box<HybridFiles>, DynamicSpec),
}

/// The three tables of a hybrid and its partition.
pub struct HybridFiles {
    /// The pre-computed region's table.
    pub precomputed: TableFile,
    /// The tensor-mass region's table.
    pub dynamic: TableFile,
    /// The interface table.
    pub interface: TableFile,
    /// Per mesh tet: in the tensor-mass region.
    pub dynamic_tet: Vec<bool>,
}

impl SceneTables {
    /// The files of the tables with base path `base`: the table itself, or
    /// for a hybrid `BASE.precomputed`, `BASE.dynamic`, `BASE.interface`.
    pub fn paths(&self, base: &Path) -> Vec<PathBuf> {
        match self {
            Self::Hybrid(..) => HYBRID_PARTS
                .iter()
                .map(|part| base.with_extension(part))
                .collect(),
            _ => vec![base.to_path_buf()],
        }
    }

    /// Writes the tables to [`Self::paths`]`(base)` (the budget's work
    /// files; each written whole, [`AtomicFile`]).
    pub fn write(&self, base: &Path) -> anyhow::Result<()> {
        let files: Vec<&TableFile> = match self {
            Self::Precomputed(file) | Self::Dynamic(file, _) => vec![file],
            Self::Hybrid(h, _) => vec![&h.precomputed, &h.dynamic, &h.interface],
        };
        for (path, file) in self.paths(base).iter().zip(files) {
            let mut out = AtomicFile::create(path)?;
            out.write_all(file.bytes())?;
            out.commit()?;
        }
        Ok(())
    }

    /// Reads the tables of `model` (resolved on the scene's mesh, whose
    /// tets `mesh_tets` counts) back from [`Self::paths`]`(base)`.
    pub fn read(model: SceneModel, base: &Path) -> anyhow::Result<Self> {
        let read = |path: PathBuf| TableFile::read(&path);
        Ok(match model {
            SceneModel::Precomputed => Self::Precomputed(read(base.to_path_buf())?),
            SceneModel::Dynamic(spec) => Self::Dynamic(read(base.to_path_buf())?, spec),
            SceneModel::Hybrid { spec, partition } => {
                let [p, d, i] = HYBRID_PARTS.map(|part| base.with_extension(part));
                Self::Hybrid(
                    Box::new(HybridFiles {
                        precomputed: read(p)?,
                        dynamic: read(d)?,
                        interface: read(i)?,
                        dynamic_tet: partition.dynamic,
                    }),
                    spec,
                )
            }
        })
    }
}

/// The extensions of a hybrid's three table files ([`SceneTables::paths`]).
const HYBRID_PARTS: [&str; 3] = ["precomputed", "dynamic", "interface"];
