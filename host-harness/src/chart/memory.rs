//! The memory/accuracy chart: a pre-computed table's bytes against its
//! contact-force and touchable-displacement errors for each way of storing
//! the compliance ([`Encoding`]: the dense `f32` table, the 16-bit codes,
//! the far-field drops, the hierarchical matrix in `f32` and in q16 at
//! several tolerances), on two sizes of one geometry ([`MemoryMesh`]).
//!
//! Each table is built by the one build pipeline ([`crate::table::build`],
//! as `palpate tables build` with [`Encoding::flags`]) and measured there:
//! the errors are `tables info --json`'s `measured` (the largest over the
//! build's probe set, relative: the coded and dropped tables against the
//! dense `f32` table, the hierarchical ones against the exact compliance
//! columns; 0 for the dense table, its own reference). Every build solves
//! its own compliance: `table::build` takes the options, not a
//! factorization, so one per table, not one per mesh.

use anyhow::Context;
use serde::Serialize;

use crate::fem::material::Material;
use crate::fix::FixPredicate;
use crate::mesh::generate::{ORGAN_CUBE_M, box_mesh, organ_mesh};
use crate::mesh::{MeshReport, TetMesh};
use crate::table::build::{BuildOptions, build};
use crate::table::compliance::Solver;
use crate::table::compress::{BlockCode, Compression, ContactBlocks};
use crate::table::hmatrix::DEFAULT_TOLERANCE;
use crate::table::info_json::info_json;
use crate::table::load::TableFile;
use crate::table::precision::Precision;

/// How a table stores its compliance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Encoding {
    /// Every block in `f32` (`tables build` without `--compress`).
    Dense,
    /// The 16-bit code `code` (`F16` or `Q16`), nothing dropped
    /// (`--compress f16|q16`).
    Coded(BlockCode),
    /// `--compress q16 --drop-below below`: the interior blocks below
    /// `below` of their column's largest dropped, and with `contact` the
    /// touchable ones too (`--contact-blocks dropped`).
    Dropped {
        /// The drop threshold, a fraction of a column's largest entry.
        below: f64,
        /// Whether the touchable–touchable blocks are dropped too.
        contact: bool,
    },
    /// `--compress hmatrix|hmatrix-q16 --tolerance tolerance`.
    Hmatrix {
        /// The far blocks' relative truncation tolerance.
        tolerance: f64,
        /// Numbers in 16-bit fixed point (`hmatrix-q16`).
        q16: bool,
    },
}

impl Encoding {
    /// The `tables build` options that make it (`None`: the dense table).
    pub fn compression(self) -> Option<Compression> {
        let compression = |code, drop_below, contact, tolerance| Compression {
            code,
            drop_below,
            contact,
            tolerance,
        };
        match self {
            Encoding::Dense => None,
            Encoding::Coded(code) => Some(compression(code, 0.0, ContactBlocks::Coded, 0.0)),
            Encoding::Dropped { below, contact } => {
                let contact = if contact {
                    ContactBlocks::Dropped
                } else {
                    ContactBlocks::Coded
                };
                Some(compression(BlockCode::Q16, below, contact, 0.0))
            }
            Encoding::Hmatrix { tolerance, q16 } => {
                let code = if q16 {
                    BlockCode::HmatrixQ16
                } else {
                    BlockCode::Hmatrix
                };
                Some(compression(code, 0.0, ContactBlocks::Coded, tolerance))
            }
        }
    }

    /// The family, the chart's series: `dense`, `f16`, `q16`, `q16 drop`,
    /// `q16 drop contact`, `hmatrix`, `hmatrix-q16`.
    pub fn family(self) -> &'static str {
        match self {
            Encoding::Dense => "dense",
            Encoding::Coded(BlockCode::F16) => "f16",
            Encoding::Coded(_) => "q16",
            Encoding::Dropped { contact: false, .. } => "q16 drop",
            Encoding::Dropped { contact: true, .. } => "q16 drop contact",
            Encoding::Hmatrix { q16: false, .. } => "hmatrix",
            Encoding::Hmatrix { q16: true, .. } => "hmatrix-q16",
        }
    }

    /// The series' parameter: the drop threshold or the tolerance.
    pub fn parameter(self) -> Option<f64> {
        match self {
            Encoding::Dropped { below, .. } => Some(below),
            Encoding::Hmatrix { tolerance, .. } => Some(tolerance),
            Encoding::Dense | Encoding::Coded(_) => None,
        }
    }

    /// Its `palpate tables build` flags (`(none)` for the dense table).
    pub fn flags(self) -> String {
        match self {
            Encoding::Dense => "(none)".into(),
            Encoding::Coded(BlockCode::F16) => "--compress f16".into(),
            Encoding::Coded(_) => "--compress q16".into(),
            Encoding::Dropped { below, contact } => format!(
                "--compress q16 --drop-below {below:e}{}",
                if contact {
                    " --contact-blocks dropped"
                } else {
                    ""
                }
            ),
            Encoding::Hmatrix { tolerance, q16 } => format!(
                "--compress {} --tolerance {tolerance:e}",
                if q16 { "hmatrix-q16" } else { "hmatrix" }
            ),
        }
    }
}

/// The hierarchical encoding at `tolerance` (`q16`: `hmatrix-q16`).
const fn hmatrix(tolerance: f64, q16: bool) -> Encoding {
    Encoding::Hmatrix { tolerance, q16 }
}

/// The q16 encoding dropping blocks below `below` (`contact`: the
/// touchable ones too).
const fn dropped(below: f64, contact: bool) -> Encoding {
    Encoding::Dropped { below, contact }
}

/// The encodings of the full chart: every family, the drops at 1e-2 and
/// 5e-2 (with and without the touchable blocks; 1e-3 dropped nothing on
/// either organ), the hierarchical tables
/// from 1e-2 to 1e-5 (the default) in `f32` and from 1e-2 to 1e-4 in q16
/// (whose rounding, half a quantum of each number, already dominates at
/// 1e-4: measured on the `--quick` boxes, force errors 2.6e-4 to 2.8e-4
/// against 4.9e-5 to 7.3e-5 in `f32`).
pub const FULL_ENCODINGS: [Encoding; 14] = [
    Encoding::Dense,
    Encoding::Coded(BlockCode::F16),
    Encoding::Coded(BlockCode::Q16),
    dropped(1e-2, false),
    dropped(5e-2, false),
    dropped(1e-2, true),
    dropped(5e-2, true),
    hmatrix(1e-2, false),
    hmatrix(1e-3, false),
    hmatrix(1e-4, false),
    hmatrix(1e-5, false),
    hmatrix(1e-2, true),
    hmatrix(1e-3, true),
    hmatrix(1e-4, true),
];

/// The encodings of `--quick`: every family, one drop level each, two
/// tolerances per hierarchical code (the `f32` one's tighter: the default,
/// [`DEFAULT_TOLERANCE`]).
pub const QUICK_ENCODINGS: [Encoding; 9] = [
    Encoding::Dense,
    Encoding::Coded(BlockCode::F16),
    Encoding::Coded(BlockCode::Q16),
    dropped(1e-2, false),
    dropped(1e-2, true),
    hmatrix(1e-2, false),
    hmatrix(DEFAULT_TOLERANCE, false),
    hmatrix(1e-2, true),
    hmatrix(1e-4, true),
];

/// A mesh of the memory chart.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MemoryMesh {
    /// The generated voxel organ ([`organ_mesh`]) of cube edge
    /// [`ORGAN_CUBE_M`] × `scale`, its lowest layer of vertices fixed.
    Organ {
        /// The cube edge over [`ORGAN_CUBE_M`].
        scale: f64,
    },
    /// A generated box of `cells`, 10 × 10 × 3 cm, its base fixed.
    Box {
        /// Cells along x, y, z.
        cells: [usize; 3],
    },
}

/// The meshes of the full chart: the generated organ at twice its default
/// cube edge and at it (1386 vertices, 5868 tets: the organ of the volume
/// experiments, `experiment::scenes::organ`).
pub const FULL_MESHES: [MemoryMesh; 2] = [
    MemoryMesh::Organ { scale: 2.0 },
    MemoryMesh::Organ { scale: 1.0 },
];

/// The meshes of `--quick`: two small boxes (147 and 243 vertices, 73 and
/// 145 touchable), each with far blocks in the hierarchical matrix (more
/// than two leaves of 32 touchable vertices); their 18 tables take about
/// 1 s of CPU time (debug profile), where the 10×10×3 box's nine took 2.7 s.
pub const QUICK_MESHES: [MemoryMesh; 2] = [
    MemoryMesh::Box { cells: [6, 6, 2] },
    MemoryMesh::Box { cells: [8, 8, 2] },
];

/// A mesh of the chart, loaded.
pub struct LoadedMesh {
    /// Its label in the chart and report.
    pub label: String,
    /// The mesh, m.
    pub mesh: TetMesh,
    /// The fixed vertices' predicates.
    pub fix: Vec<FixPredicate>,
}

impl MemoryMesh {
    /// The mesh, its label and its supports: the vertices within `depth`
    /// of the lowest (half a cube of the organ, 1 µm of the box's base).
    pub fn load(self) -> anyhow::Result<LoadedMesh> {
        let (label, mesh, depth) = match self {
            MemoryMesh::Organ { scale } => {
                let cube = ORGAN_CUBE_M * scale;
                let label = format!("organ h={:.1} mm", 1e3 * cube);
                (label, organ_mesh(cube), 0.5 * cube)
            }
            MemoryMesh::Box { cells } => {
                let [x, y, z] = cells;
                let label = format!("box {x}x{y}x{z}");
                (label, box_mesh(cells, [0.1, 0.1, 0.03]), 1e-6)
            }
        };
        let lowest = mesh
            .positions
            .iter()
            .map(|p| p[2])
            .fold(f64::INFINITY, f64::min);
        let fix = format!("z<={}", lowest + depth)
            .parse()
            .map_err(anyhow::Error::msg)?;
        Ok(LoadedMesh {
            label,
            mesh,
            fix: vec![fix],
        })
    }
}

/// One table of the chart.
#[derive(Clone, Debug, Serialize)]
pub struct MemoryPoint {
    /// The mesh's label.
    pub mesh: String,
    /// Its vertices.
    pub vertices: usize,
    /// Its tets.
    pub tets: usize,
    /// Its touchable vertices.
    pub touchable: usize,
    /// Its `--fix` predicates, comma-separated.
    pub fix: String,
    /// [`Encoding::family`].
    pub family: &'static str,
    /// [`Encoding::parameter`].
    pub parameter: Option<f64>,
    /// [`Encoding::flags`].
    pub flags: String,
    /// The table file's bytes.
    pub bytes: usize,
    /// `measured.force_error` of `tables info --json`: the largest
    /// relative contact-force error over the probe set.
    pub force_error: f64,
    /// `measured.touchable_displacement_error`: the largest relative
    /// displacement error of the touchable vertices.
    pub touchable_displacement_error: f64,
    /// `measured.displacement_error`: the same over every vertex (the
    /// touchable one for a hierarchical table, which stores no interior).
    pub displacement_error: f64,
}

impl MemoryPoint {
    /// Its `error`.
    pub fn error(&self, error: MemoryError) -> f64 {
        match error {
            MemoryError::Force => self.force_error,
            MemoryError::TouchableDisplacement => self.touchable_displacement_error,
        }
    }
}

/// The error a memory chart draws against the table's bytes (`plot`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MemoryError {
    /// [`MemoryPoint::force_error`] (`memory`).
    Force,
    /// [`MemoryPoint::touchable_displacement_error`] (`memory-displacement`).
    TouchableDisplacement,
}

impl MemoryError {
    /// Both, in the order drawn.
    pub const ALL: [MemoryError; 2] = [MemoryError::Force, MemoryError::TouchableDisplacement];

    /// The chart's file name, without extension.
    pub fn chart(self) -> &'static str {
        match self {
            MemoryError::Force => "memory",
            MemoryError::TouchableDisplacement => "memory-displacement",
        }
    }

    /// The chart's caption.
    pub fn caption(self) -> &'static str {
        match self {
            MemoryError::Force => "table bytes against contact-force error",
            MemoryError::TouchableDisplacement => {
                "table bytes against touchable displacement error"
            }
        }
    }

    /// The y axis's description.
    pub fn axis(self) -> String {
        let error = match self {
            MemoryError::Force => "contact-force error",
            MemoryError::TouchableDisplacement => "touchable displacement error",
        };
        format!("{error} (dense f32 table: drawn at {ERROR_FLOOR:e})")
    }
}

/// Where a memory chart draws an error of 0 (the dense table's, its own
/// reference) on its log axis: below every measured error (the smallest,
/// q16's rounding and the tightest hierarchical tolerance's, are above
/// 1e-7).
pub const ERROR_FLOOR: f64 = 1e-8;

/// Builds every encoding's table of every mesh with `material` and reads
/// its size and measured errors; `tick` after each table.
pub fn points(
    meshes: &[MemoryMesh],
    encodings: &[Encoding],
    material: Material,
    tick: &mut dyn FnMut(&str),
) -> anyhow::Result<Vec<MemoryPoint>> {
    let mut out = Vec::new();
    for &m in meshes {
        let LoadedMesh { label, mesh, fix } = m.load()?;
        let fix_text = fix
            .iter()
            .map(ToString::to_string)
            .collect::<Vec<_>>()
            .join(",");
        for &encoding in encodings {
            let flags = encoding.flags();
            let options =
                BuildOptions::precomputed(material, fix.clone(), Solver::Cholesky, Precision::F32)
                    .with_compression(encoding.compression());
            let built = build(&mesh, &MeshReport::default(), &options)
                .with_context(|| format!("memory chart, {label}: {flags}"))?;
            let info = info_json(&TableFile::from_bytes(&built.bytes))
                .map_err(|e| anyhow::anyhow!("memory chart, {label}: {flags}: {e}"))?;
            let measured = |key: &str| {
                info["measured"][key]
                    .as_f64()
                    .with_context(|| format!("memory chart, {label}: {flags}: no measured {key}"))
            };
            out.push(MemoryPoint {
                mesh: label.clone(),
                vertices: mesh.positions.len(),
                tets: mesh.tets.len(),
                touchable: built.touchable_count,
                fix: fix_text.clone(),
                family: encoding.family(),
                parameter: encoding.parameter(),
                flags: flags.clone(),
                bytes: built.bytes.len(),
                force_error: measured("force_error")?,
                touchable_displacement_error: measured("touchable_displacement_error")?,
                displacement_error: measured("displacement_error")?,
            });
            tick(&format!("memory {label} {flags}"));
        }
    }
    Ok(out)
}
