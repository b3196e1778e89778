//! Scene files: what a haptic session simulates, in TOML simple enough to write by hand.
//!
//! ```toml
//! mesh = "block.msh"           # relative to the scene file's folder; or instead:
//! # [generated]
//! # box_m = [0.12, 0.12, 0.06] # a box [0, x] × [0, y] × [0, z], m (`box` is accepted too)
//! # cells = [12, 12, 6]        # cells per axis, 6 tets each (mesh::generate::box_mesh)
//! fix = ["z<0.001"]            # fixed-vertex predicates, the CLI's --fix syntax, mesh units
//!
//! [material]
//! young_pa = 3000.0            # required
//! poisson = 0.45               # required, 0 <= nu <= 0.4999 (fem::material::MAX_POISSON)
//! density_kg_m3 = 1000.0       # default 1000 (used by the dynamic model)
//!
//! [model]                      # default: kind = "precomputed"
//! kind = "dynamic"             # "precomputed" or "dynamic"; the keys below are dynamic-only
//! law = "stvk"                 # "linear" (default), "stvk" or "stvk-incompressible"
//! form = "per-tet"             # St Venant-Kirchhoff form: "per-tet" (default) or "tensors"
//! integrator = "symplectic"    # "euler", "symplectic" (default), "rk4" or "central"
//! dt_s = 0.0005                # default: the physics period (physics_every / haptic_hz)
//! damping_per_s = 2.0          # required for kind = "dynamic"
//! incompressibility_n = 0.5    # required for, and only for, law = "stvk-incompressible"
//! extrapolation = "secant"     # force between physics updates: "secant" (default) or
//!                              # "instantaneous" (palpate_kernel::tensor_mass::tissue)
//!
//! [tool]
//! points = 1                   # trajectory tool points: default 1, in 1..=4 (MAX_TOOL_POINTS)
//! radius_m = 0.002             # default 0.002
//! kind = "probe"               # "probe" (default), "grasper" or "cutter" for every trajectory
//!                              # tool point, or one per point: kind = ["grasper", "cutter"]
//!                              # (as many as `points`); a grasper is 2 kernel tool points (its
//!                              # jaws), a probe or cutter 1, at most 4 in all (MAX_TOOL_POINTS)
//! jaw_axis = [1.0, 0.0, 0.0]   # grasper: direction from jaw 0 to jaw 1, finite, non-zero;
//!                              # stored normalized; default x
//! grip_opening_m = 0.005       # grasper: jaw opening (m) at or below which the jaws hold what
//!                              # they touch; finite, > 0; default 2.5 * radius_m
//! blade_m = [0.0, 0.0, -0.01]  # cutter: blade (m) from the tool point (the blade's upper end)
//!                              # to its tip; finite, length in (0, 0.1]; default [0, 0, -0.01]
//!
//! [cutting]                    # optional; only meaningful for the dynamic model
//! capacity_tets = 8            # tets one physics update removes at most (the rest on the next
//!                              # updates); 1..=64, default 8
//! force_n = 0.2                # the blade sphere's push, N, at which the tissue ahead of it
//!                              # gives way (its tet is cut); finite, > 0; default 0.2
//!
//! [tearing]                    # optional, dynamic model only; absent: no tearing
//! volume_change = 0.5          # tear a tet past |V - V0|/V0 ...
//! mean_elongation = 0.4        # ... or past this mean relative elongation of its 6 edges ...
//! max_elongation = 0.6         # ... or past this one of any edge (each optional, absent = off,
//!                              # finite and > 0; at least one; TearThresholds in the kernel)
//! capacity_tets = 8            # tets one physics update tears at most; 1..=64, default 8
//!
//! [rates]
//! haptic_hz = 1000.0           # default 1000, at most 10000 (crate::limits::MAX_HAPTIC_HZ)
//! physics_every = 1            # default 1: a physics update every this many ticks
//!
//! [safety]
//! max_force_n = 4.0            # default 4
//! max_slew_n_per_s = 2000.0    # default 2000
//!
//! [[region]]                   # optional, any number: per-region materials (super::materials)
//! id = 2                       # the mesh's region id; tets of other regions take [material]
//! young_pa = 30000.0
//! poisson = 0.45
//! # [[zone]] and [partition]: where the hybrid model must be dynamic (crate::scene::zones)
//! ```
//!
//! Unknown keys are refused, so a typo is an error, not a silently ignored setting. TOML integers
//! are accepted where a real is expected (`young_pa = 3000`). Every error names the file and, for
//! a syntax or type error, the line; for a value out of range, the key. The grasper and cutter
//! keys are checked even when no tool point is of that kind (and then unused), as is `[cutting]`
//! on the pre-computed model, which cannot be cut.
//!
//! Whether `dt_s` is stable on the scene's mesh needs the mesh: [`crate::session::stability`]
//! checks it once the mesh is loaded.

use std::path::{Path, PathBuf};

use palpate_kernel::MAX_CONTACTS;
use palpate_kernel::haptic::SafetyLimits;
use palpate_kernel::tensor_mass::Extrapolation;
use palpate_kernel::tensor_mass::{ElasticLaw, Integrator, StvkForm};
use serde::Deserialize;

use super::materials::{RegionSpec, check_regions};
use super::zones::{PartitionFile, PartitionSpec, Zone, ZoneFile, ZoneKind, ZoneShape, zones_spec};
use crate::fem::material::{Material, MaterialError, POISSON_RANGE};
use crate::fix::FixPredicate;
use crate::limits::{MAX_HAPTIC_HZ, MAX_SCENE_FILE_BYTES, read_bounded};
use crate::mesh::generate::{ORGAN_CUBE_M, box_mesh, organ_mesh};
use crate::mesh::{MeshError, MeshReport, TetMesh, read_mesh, top_height};
use crate::output::number::shown;

/// Largest number of tool points of a scene, both the trajectory's tool points (`[tool] points`)
/// and the kernel tool points their kinds need ([`ToolSpec::kernel_points`]: a grasper's two jaws
/// count two): the kernel's contact capacity ([`palpate_kernel::MAX_CONTACTS`]), one contact per
/// kernel tool point.
pub const MAX_TOOL_POINTS: usize = MAX_CONTACTS;

/// Largest vertex count of a `[generated]` box, so a typo cannot ask for a mesh that does not
/// fit in memory (the table build is quadratic in the surface size long before this).
pub const MAX_GENERATED_VERTICES: usize = 10_000_000;

/// Largest number of dynamic-model steps per physics update (`physics period / dt_s`): the
/// kernel's bound on a physics update's loop.
pub const MAX_SUBSTEPS: u32 = palpate_kernel::tensor_mass::MAX_SUBSTEPS;

/// Why a scene could not be read. Every message starts with the file (or the source name given
/// to [`Scene::from_toml_str_named`]).
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read from disk.
    #[error("{file}: cannot read scene: {err}")]
    Io {
        /// The scene file as given.
        file: String,
        /// Underlying I/O error.
        err: std::io::Error,
    },
    /// Not valid TOML, an unknown key, a missing required key or a value of the wrong type.
    #[error("{file}: {}{msg}", line_prefix(.line))]
    Syntax {
        /// The scene file.
        file: String,
        /// 1-based line of the offending text, where the parser located it.
        line: Option<usize>,
        /// The parser's message (one line).
        msg: String,
    },
    /// A well-formed value that is out of range or inconsistent with another.
    #[error("{file}: {key}: {msg}")]
    Invalid {
        /// The scene file.
        file: String,
        /// The key, as `[table] key = value` (or `key = value` at the top level).
        key: String,
        /// What is wrong and what is expected.
        msg: String,
    },
}

/// `line 3: ` or empty.
fn line_prefix(line: &Option<usize>) -> String {
    match line {
        Some(line) => format!("line {line}: "),
        None => String::new(),
    }
}

/// Where the tissue mesh comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum MeshSource {
    /// A mesh file (any format [`read_mesh`] reads), already resolved against the scene file's
    /// folder.
    File(PathBuf),
    /// A generated box ([`box_mesh`]): `[0, size_m[0]] × [0, size_m[1]] × [0, size_m[2]]` in m,
    /// `cells[i] ≥ 1` cells per axis.
    GeneratedBox {
        /// Box size, m, each finite and > 0.
        size_m: [f64; 3],
        /// Cells per axis, each ≥ 1 (6 tets per cell).
        cells: [usize; 3],
    },
    /// The generated liver-like organ ([`organ_mesh`] at [`ORGAN_CUBE_M`]: 1386 vertices,
    /// 5868 tets, its flat underside the lowest vertices); the built-in hybrid scene's.
    GeneratedOrgan,
}

/// The tissue material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaterialSpec {
    /// Young's modulus `E`, Pa, finite and > 0.
    pub young_pa: f64,
    /// Poisson ratio `ν`, `0 ≤ ν < 0.5`.
    pub poisson: f64,
    /// Mass density, kg/m³, finite and > 0 (the dynamic model's lumped masses).
    pub density_kg_m3: f64,
}

/// Which soft-tissue model the session runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ModelSpec {
    /// The pre-computed quasi-static linear model (RR-3510 §4): a compliance table.
    Precomputed,
    /// The dynamic tensor-mass model (RR-3510 §5, Picinbono 2001).
    Dynamic(DynamicSpec),
}

/// Parameters of the dynamic model (`kind = "dynamic"`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DynamicSpec {
    /// The elastic law: `law = "linear"` → [`ElasticLaw::Linear`], `"stvk"` and
    /// `"stvk-incompressible"` → [`ElasticLaw::StVenantKirchhoff`] in the given `form`.
    pub law: ElasticLaw,
    /// Incompressibility penalty `γ`, N (Picinbono 2001 §3.2): `Some` exactly for
    /// `law = "stvk-incompressible"`, finite and ≥ 0.
    pub incompressibility_n: Option<f64>,
    /// The explicit integrator.
    pub integrator: Integrator,
    /// Time step, s, finite and > 0; the physics period is a whole number of steps
    /// ([`Scene::dynamic_substeps`]).
    pub dt_s: f64,
    /// Mass-proportional damping `c`, 1/s, finite and ≥ 0 (damping force `−c·m_i·v_i`).
    pub damping_per_s: f64,
    /// The stiffness the force is extrapolated with between physics updates.
    pub extrapolation: Extrapolation,
}

/// What a trajectory tool point is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ToolKind {
    /// A probe tip: one sphere that pushes (one kernel tool point).
    Probe,
    /// A grasper: two jaws along [`ToolSpec::jaw_axis`] (two kernel tool points) that hold what
    /// they touch once closed to [`ToolSpec::grip_opening_m`].
    Grasper,
    /// A cutter: a blade [`ToolSpec::blade_m`] from the tool point that removes the tets it
    /// touches (one kernel tool point).
    Cutter,
}

impl ToolKind {
    /// Every kind, in documentation order.
    pub const ALL: [ToolKind; 3] = [ToolKind::Probe, ToolKind::Grasper, ToolKind::Cutter];

    /// The scene file's name: `probe`, `grasper` or `cutter`.
    pub fn name(self) -> &'static str {
        match self {
            ToolKind::Probe => "probe",
            ToolKind::Grasper => "grasper",
            ToolKind::Cutter => "cutter",
        }
    }

    /// Kernel tool points (contact spheres) of one such trajectory tool point: a grasper's two
    /// jaws, one otherwise.
    pub fn kernel_points(self) -> usize {
        match self {
            ToolKind::Grasper => 2,
            ToolKind::Probe | ToolKind::Cutter => 1,
        }
    }

    /// The kind a scene file names, if any.
    fn from_name(name: &str) -> Option<ToolKind> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }
}

/// The tool: a few trajectory tool points, each of a [`ToolKind`], with a radius.
#[derive(Clone, Debug, PartialEq)]
pub struct ToolSpec {
    /// Number of trajectory tool points (the trajectory's tool columns), in
    /// `1..=MAX_TOOL_POINTS`.
    pub points: usize,
    /// Radius of every kernel tool point (probe tip, jaw, blade), m, finite and > 0.
    pub radius_m: f64,
    /// The kind of each trajectory tool point: `points` of them, needing at most
    /// [`MAX_TOOL_POINTS`] kernel tool points in all ([`Self::kernel_points`]).
    pub kinds: Vec<ToolKind>,
    /// Grasper: unit direction from jaw 0 to jaw 1 (finite; the file's value is normalized).
    pub jaw_axis: [f64; 3],
    /// Grasper: jaw opening, m, at or below which the jaws hold what they touch; finite and > 0.
    pub grip_opening_m: f64,
    /// Cutter: the blade, m, from the tool point (its upper end) to its tip; finite, length in
    /// `(0, MAX_BLADE_M]`.
    pub blade_m: [f64; 3],
}

impl ToolSpec {
    /// `points` probes of radius `radius_m`, the grasper and cutter settings at their defaults
    /// ([`DEFAULT_JAW_AXIS`], [`DEFAULT_GRIP_OPENING_RADII`] × `radius_m`, [`DEFAULT_BLADE_M`]).
    pub fn probes(points: usize, radius_m: f64) -> ToolSpec {
        ToolSpec {
            points,
            radius_m,
            kinds: vec![ToolKind::Probe; points.min(MAX_TOOL_POINTS)],
            jaw_axis: DEFAULT_JAW_AXIS,
            grip_opening_m: DEFAULT_GRIP_OPENING_RADII * radius_m,
            blade_m: DEFAULT_BLADE_M,
        }
    }

    /// Kernel tool points the kinds need: the sum of [`ToolKind::kernel_points`] (a grasper is
    /// two jaws).
    pub fn kernel_points(&self) -> usize {
        self.kinds.iter().map(|k| k.kernel_points()).sum()
    }
}

/// Cutting by the scene's cutters (`[cutting]`; only the dynamic model can be cut).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CuttingSpec {
    /// Tets one physics update removes at most (the rest on the next updates), in
    /// `1..=MAX_CAPACITY_TETS`.
    pub capacity_tets: u32,
    /// The push of a blade's sphere, N, at which the tet it presses into is cut (the resistance
    /// the hand feels ahead of the blade); finite, > 0 and fits f32.
    pub force_n: f64,
}

/// Default [`CuttingSpec::force_n`], N: about what a scalpel needs through soft parenchyma,
/// and under the 0.3 N of the built-in press on the 3 kPa block.
pub const DEFAULT_CUT_FORCE_N: f64 = 0.2;

/// Tearing by thresholds (`[tearing]`, dynamic model only): the kernel's
/// [`palpate_kernel::tensor_mass::TearThresholds`] and a per-update capacity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TearingSpec {
    /// Tear a tet whose `|V − V₀| / V₀` exceeds this (`None`: criterion off); finite and > 0.
    pub volume_change: Option<f64>,
    /// Tear a tet whose mean relative edge elongation `(l − l₀)/l₀` over its 6 edges exceeds
    /// this (`None`: off); finite and > 0.
    pub mean_elongation: Option<f64>,
    /// Tear a tet one of whose edges' relative elongation exceeds this (`None`: off); finite
    /// and > 0.
    pub max_elongation: Option<f64>,
    /// Tets one physics update tears at most, in `1..=MAX_CAPACITY_TETS`.
    pub capacity_tets: u32,
}

/// Loop rates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rates {
    /// Haptic (tick) rate, Hz, finite, > 0 and at most [`MAX_HAPTIC_HZ`].
    pub haptic_hz: f64,
    /// A physics update every this many ticks, ≥ 1 (force extrapolated in between).
    pub physics_every: u32,
}

/// A validated scene.
///
/// Invariants (checked by [`Scene::validate`], which every constructor runs): the ranges stated
/// on each field's type; a pre-computed scene has at least one `fix` predicate (a free body has
/// no compliance) and no tearing; a dynamic scene's physics period is a whole number
/// (1..=[`MAX_SUBSTEPS`]) of `dt_s`; the tool has one kind per trajectory tool point and needs
/// at most [`MAX_TOOL_POINTS`] kernel tool points. Fields are public for reading and for tests; after changing one, call
/// [`Scene::validate`] again.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// Names the scene in messages: the file as given, or `built-in scene`.
    pub source: String,
    /// The tissue mesh.
    pub mesh: MeshSource,
    /// Fixed-vertex predicates (mesh units); a vertex matching any is fixed.
    pub fix: Vec<FixPredicate>,
    /// The material (of every tet without a `[[region]]`).
    pub material: MaterialSpec,
    /// Per-region materials (`[[region]]`, heterogeneous tissue; [`Scene::tet_materials`]).
    pub regions: Vec<RegionSpec>,
    /// The model.
    pub model: ModelSpec,
    /// The tool.
    pub tool: ToolSpec,
    /// Cutting (used by the dynamic model's cutters).
    pub cutting: CuttingSpec,
    /// Tearing (`None`: off); only with the dynamic model.
    pub tearing: Option<TearingSpec>,
    /// Loop rates.
    pub rates: Rates,
    /// Limits of the safety supervisor on the device force (N, N/s), each finite and > 0;
    /// the loop takes them in f32 ([`crate::session::run::loop_config`]).
    pub safety: SafetyLimits<f64>,
    /// Where the tissue must be dynamic (`[[zone]]`, [`crate::scene::zones`]).
    pub zones: Vec<Zone>,
    /// How the zones become tets (`[partition]`).
    pub partition: PartitionSpec,
}

// ---- The file as written (serde), before validation. ----

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    mesh: Option<PathBuf>,
    generated: Option<GeneratedFile>,
    #[serde(default)]
    fix: Vec<String>,
    material: MaterialFile,
    #[serde(default)]
    region: Vec<RegionSpec>,
    #[serde(default)]
    model: ModelFile,
    #[serde(default)]
    tool: ToolFile,
    #[serde(default)]
    cutting: CuttingFile,
    tearing: Option<TearingFile>,
    #[serde(default)]
    rates: RatesFile,
    #[serde(default)]
    safety: SafetyFile,
    #[serde(default)]
    zone: Vec<ZoneFile>,
    partition: Option<PartitionFile>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct GeneratedFile {
    #[serde(alias = "box", deserialize_with = "exact::three")]
    box_m: [f64; 3],
    #[serde(deserialize_with = "exact::three")]
    cells: [usize; 3],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MaterialFile {
    young_pa: f64,
    poisson: f64,
    #[serde(default = "default_density")]
    density_kg_m3: f64,
}

#[derive(Clone, Copy, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
enum KindName {
    #[default]
    Precomputed,
    Dynamic,
}

#[derive(Clone, Copy, Deserialize)]
#[serde(rename_all = "kebab-case")]
enum LawName {
    Linear,
    Stvk,
    StvkIncompressible,
}

#[derive(Clone, Copy, Deserialize)]
#[serde(rename_all = "kebab-case")]
enum FormName {
    PerTet,
    Tensors,
}

#[derive(Clone, Copy, Deserialize)]
#[serde(rename_all = "kebab-case")]
enum IntegratorName {
    Euler,
    Symplectic,
    Rk4,
    Central,
}

#[derive(Clone, Copy, Deserialize)]
#[serde(rename_all = "kebab-case")]
enum ExtrapolationName {
    Secant,
    Instantaneous,
}

#[derive(Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct ModelFile {
    #[serde(default)]
    kind: KindName,
    law: Option<LawName>,
    form: Option<FormName>,
    integrator: Option<IntegratorName>,
    dt_s: Option<f64>,
    damping_per_s: Option<f64>,
    incompressibility_n: Option<f64>,
    extrapolation: Option<ExtrapolationName>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ToolFile {
    #[serde(default = "default_points")]
    points: usize,
    #[serde(default = "default_radius")]
    radius_m: f64,
    kind: Option<KindsFile>,
    #[serde(default, deserialize_with = "exact::three_opt")]
    jaw_axis: Option<[f64; 3]>,
    grip_opening_m: Option<f64>,
    #[serde(default, deserialize_with = "exact::three_opt")]
    blade_m: Option<[f64; 3]>,
}

/// `[tool] kind`: one name for every tool point, or one per tool point. Names are checked after
/// parsing, so that a bad one is an error naming the key.
enum KindsFile {
    One(String),
    Many(Vec<String>),
}

impl<'de> Deserialize<'de> for KindsFile {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Kinds;
        impl<'de> serde::de::Visitor<'de> for Kinds {
            type Value = KindsFile;
            fn expecting(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
                f.write_str(
                    "a tool kind (\"probe\", \"grasper\" or \"cutter\") or an array of them",
                )
            }
            fn visit_str<E: serde::de::Error>(self, name: &str) -> Result<KindsFile, E> {
                Ok(KindsFile::One(name.to_owned()))
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> Result<KindsFile, A::Error> {
                let mut names = Vec::new();
                while let Some(name) = seq.next_element::<String>()? {
                    names.push(name);
                }
                Ok(KindsFile::Many(names))
            }
        }
        deserializer.deserialize_any(Kinds)
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CuttingFile {
    #[serde(default = "default_capacity_tets")]
    capacity_tets: u32,
    #[serde(default = "default_cut_force")]
    force_n: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TearingFile {
    volume_change: Option<f64>,
    mean_elongation: Option<f64>,
    max_elongation: Option<f64>,
    #[serde(default = "default_capacity_tets")]
    capacity_tets: u32,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RatesFile {
    #[serde(default = "default_haptic_hz")]
    haptic_hz: f64,
    #[serde(default = "default_physics_every")]
    physics_every: u32,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SafetyFile {
    #[serde(default = "default_max_force")]
    max_force_n: f64,
    #[serde(default = "default_max_slew")]
    max_slew_n_per_s: f64,
}

/// Radius of the built-in hybrid scene's cut zone around its cut line, m: the blade's 1 cm
/// and the sphere below it, and a few millimetres.
pub const HEPATECTOMY_CUT_RADIUS_M: f64 = 0.012;

/// Where the built-in hybrid scene's tools work on the organ's rest surface (m): the right
/// lobe's upper terrace, flat in the voxel surface (the benches' sites).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HepatectomySites {
    /// The surface point between the grasper's jaws.
    pub grasp_m: [f64; 3],
    /// The cut line on the surface, from and to (along +x).
    pub cut_from_m: [f64; 3],
    /// See `cut_from_m`.
    pub cut_to_m: [f64; 3],
    /// Height of the organ's flat underside (its lowest vertices).
    pub floor_m: f64,
}

impl HepatectomySites {
    /// The sites on [`organ_mesh`] at [`ORGAN_CUBE_M`]: the grasp at `(0.030, −0.028)`, the
    /// cut along `y = 2c + 1 mm` (1 mm off a row of vertices) from `x = 0.006` to `0.053`,
    /// each at the height of the rest surface there.
    pub fn on_the_organ() -> Self {
        let mesh = organ_mesh(ORGAN_CUBE_M);
        let surface = crate::mesh::boundary_surface(&mesh);
        let on_top = |x: f64, y: f64| {
            // The sites are on the organ (a fixed, generated mesh).
            let z = top_height(&mesh.positions, &surface.triangles, x, y).unwrap_or(0.0);
            [x, y, z]
        };
        let y = 2.0 * ORGAN_CUBE_M + 0.001;
        Self {
            grasp_m: on_top(0.030, -0.028),
            cut_from_m: on_top(0.006, y),
            cut_to_m: on_top(0.053, y),
            floor_m: mesh
                .positions
                .iter()
                .map(|p| p[2])
                .fold(f64::INFINITY, f64::min),
        }
    }
}

/// Default density, kg/m³ (water; soft tissue is 1000–1100).
pub const DEFAULT_DENSITY_KG_M3: f64 = 1000.0;
/// Default tool point count.
pub const DEFAULT_TOOL_POINTS: usize = 1;
/// Default tool point radius, m (a 4 mm probe tip).
pub const DEFAULT_TOOL_RADIUS_M: f64 = 0.002;
/// Default haptic rate, Hz.
pub const DEFAULT_HAPTIC_HZ: f64 = 1000.0;
/// Default physics update interval, ticks.
pub const DEFAULT_PHYSICS_EVERY: u32 = 1;
/// Default grasper jaw axis (from jaw 0 to jaw 1): +x.
pub const DEFAULT_JAW_AXIS: [f64; 3] = [1.0, 0.0, 0.0];
/// Default grasper grip opening, in tool radii: `grip_opening_m = 2.5 × radius_m`.
pub const DEFAULT_GRIP_OPENING_RADII: f64 = 2.5;
/// Largest tool radius, as a fraction of the mesh's largest bounding-box extent: 0.5, a tool
/// sphere as wide as the body. A larger one (`radius_m = 1.0` on a 12 cm block) covers the
/// whole body from any side: the contact search faulted every tick. Checked once the mesh is
/// loaded ([`Scene::check_on_mesh`]).
pub const MAX_TOOL_RADIUS_FRACTION: f64 = 0.5;

/// Default cutter blade, m: 1 cm straight down from the tool point.
pub const DEFAULT_BLADE_M: [f64; 3] = [0.0, 0.0, -0.01];
/// Longest cutter blade, m.
pub const MAX_BLADE_M: f64 = 0.1;
/// Default number of tets one physics update cuts or tears at most.
pub const DEFAULT_CAPACITY_TETS: u32 = 8;
/// Largest number of tets one physics update may cut or tear (`[cutting]` and `[tearing]`
/// `capacity_tets`), so an update's removal work stays bounded.
pub const MAX_CAPACITY_TETS: u32 = 64;
/// Default device force clamp, N (desktop haptic devices peak at 3–8 N).
pub const DEFAULT_MAX_FORCE_N: f64 = 4.0;
/// Default slew limit, N/s (full force in 2 ms).
pub const DEFAULT_MAX_SLEW_N_PER_S: f64 = 2000.0;

fn default_density() -> f64 {
    DEFAULT_DENSITY_KG_M3
}
fn default_points() -> usize {
    DEFAULT_TOOL_POINTS
}
fn default_radius() -> f64 {
    DEFAULT_TOOL_RADIUS_M
}
fn default_cut_force() -> f64 {
    DEFAULT_CUT_FORCE_N
}
fn default_capacity_tets() -> u32 {
    DEFAULT_CAPACITY_TETS
}
fn default_haptic_hz() -> f64 {
    DEFAULT_HAPTIC_HZ
}
fn default_physics_every() -> u32 {
    DEFAULT_PHYSICS_EVERY
}
fn default_max_force() -> f64 {
    DEFAULT_MAX_FORCE_N
}
fn default_max_slew() -> f64 {
    DEFAULT_MAX_SLEW_N_PER_S
}

impl Default for ToolFile {
    fn default() -> Self {
        Self {
            points: DEFAULT_TOOL_POINTS,
            radius_m: DEFAULT_TOOL_RADIUS_M,
            kind: None,
            jaw_axis: None,
            grip_opening_m: None,
            blade_m: None,
        }
    }
}

impl Default for CuttingFile {
    fn default() -> Self {
        Self {
            capacity_tets: DEFAULT_CAPACITY_TETS,
            force_n: DEFAULT_CUT_FORCE_N,
        }
    }
}

impl Default for RatesFile {
    fn default() -> Self {
        Self {
            haptic_hz: DEFAULT_HAPTIC_HZ,
            physics_every: DEFAULT_PHYSICS_EVERY,
        }
    }
}

impl Default for SafetyFile {
    fn default() -> Self {
        Self {
            max_force_n: DEFAULT_MAX_FORCE_N,
            max_slew_n_per_s: DEFAULT_MAX_SLEW_N_PER_S,
        }
    }
}

impl Scene {
    /// The checks of the scene that need its loaded `mesh`: `[tool] radius_m` at most
    /// [`MAX_TOOL_RADIUS_FRACTION`] of the mesh's largest bounding-box extent.
    pub fn check_on_mesh(&self, mesh: &TetMesh) -> Result<(), SceneError> {
        let (lo, hi) = mesh.positions.iter().fold(
            ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
            |(lo, hi), p| {
                (
                    [0, 1, 2].map(|i| lo[i].min(p[i])),
                    [0, 1, 2].map(|i| hi[i].max(p[i])),
                )
            },
        );
        let extent = (0..3).map(|i| hi[i] - lo[i]).fold(0.0, f64::max);
        let most = MAX_TOOL_RADIUS_FRACTION * extent;
        if self.tool.radius_m > most {
            return Err(SceneError::Invalid {
                file: self.source.clone(),
                key: format!("[tool] radius_m = {}", self.tool.radius_m),
                msg: format!(
                    "above {MAX_TOOL_RADIUS_FRACTION} of the mesh's largest extent ({extent} m): \
                     at most {most} m (MAX_TOOL_RADIUS_FRACTION); a tool wider than the body \
                     touches all of it"
                ),
            });
        }
        Ok(())
    }

    /// The scene of `palpate demo`: a 12 × 12 × 6 cm generated block (12 × 12 × 6 cells: 1183
    /// vertices, 5184 tets), E = 3000 Pa, ν = 0.45, density 1000 kg/m³, base fixed (`z<0.0001`),
    /// the pre-computed model, 1 tool point of radius 2 mm, 1 kHz haptic rate with a physics
    /// update every tick, force clamp 4 N, slew limit 2000 N/s.
    pub fn built_in() -> Scene {
        Scene {
            source: "built-in scene".into(),
            mesh: MeshSource::GeneratedBox {
                size_m: [0.12, 0.12, 0.06],
                cells: [12, 12, 6],
            },
            // Parses (a fixed literal); the base is the face z = 0 of the generated box.
            fix: "z<0.0001".parse::<FixPredicate>().into_iter().collect(),
            material: MaterialSpec {
                young_pa: 3000.0,
                poisson: 0.45,
                density_kg_m3: DEFAULT_DENSITY_KG_M3,
            },
            regions: Vec::new(),
            model: ModelSpec::Precomputed,
            tool: ToolSpec::probes(DEFAULT_TOOL_POINTS, DEFAULT_TOOL_RADIUS_M),
            cutting: CuttingSpec {
                capacity_tets: DEFAULT_CAPACITY_TETS,
                force_n: DEFAULT_CUT_FORCE_N,
            },
            tearing: None,
            rates: Rates {
                haptic_hz: DEFAULT_HAPTIC_HZ,
                physics_every: DEFAULT_PHYSICS_EVERY,
            },
            safety: SafetyLimits {
                max_force_n: DEFAULT_MAX_FORCE_N,
                max_slew_n_per_s: DEFAULT_MAX_SLEW_N_PER_S,
            },
            zones: Vec::new(),
            partition: PartitionSpec::default(),
        }
    }

    /// The built-in block on the dynamic model: linear tensor-mass, symplectic Euler in 0.5 ms
    /// steps, damping 30/s, physics at 100 Hz (every 10 ticks, the display rate; the force is
    /// extrapolated in between with the secant stiffness).
    pub fn built_in_dynamic() -> Scene {
        Scene {
            source: "built-in dynamic scene".into(),
            model: ModelSpec::Dynamic(DynamicSpec {
                law: ElasticLaw::Linear,
                incompressibility_n: None,
                integrator: Integrator::SymplecticEuler,
                dt_s: 0.0005,
                damping_per_s: 30.0,
                extrapolation: Extrapolation::Secant,
            }),
            rates: Rates {
                haptic_hz: DEFAULT_HAPTIC_HZ,
                physics_every: 10,
            },
            ..Self::built_in()
        }
    }

    /// The built-in surgical scene: the dynamic block of [`Self::built_in_dynamic`] with two
    /// tools, a grasper (trajectory tool 0, jaws along x, holding at 5 mm) and a cutter (tool
    /// 1, the default blade 1 cm up from its tip), cutting at most 8 tets per physics update,
    /// and tearing where an edge stretches by more than 100 % (8 tets per update).
    pub fn built_in_tools() -> Scene {
        let mut tool = ToolSpec::probes(2, DEFAULT_TOOL_RADIUS_M);
        tool.kinds = vec![ToolKind::Grasper, ToolKind::Cutter];
        Scene {
            source: "built-in tools scene".into(),
            tool,
            tearing: Some(TearingSpec {
                volume_change: None,
                mean_elongation: None,
                max_elongation: Some(1.0),
                capacity_tets: DEFAULT_CAPACITY_TETS,
            }),
            ..Self::built_in_dynamic()
        }
    }

    /// The built-in hepatectomy-style scene on the hybrid model (RR-3510 §6.2): the organ
    /// ([`MeshSource::GeneratedOrgan`], E = 5 kPa, ν = 0.4, 1000 kg/m³, its flat underside
    /// fixed), a grasper (trajectory tool 0) holding the right lobe on its upper terrace and a
    /// cutter (tool 1) cutting a segment off along a 4.7 cm line of the same terrace
    /// ([`HepatectomySites`]); the one `[[zone]]`, a cut capsule of radius
    /// [`HEPATECTOMY_CUT_RADIUS_M`] around the cut line, with the default margin, makes the
    /// tensor-mass region (linear: no large-deformation zone), the rest of the organ is
    /// pre-computed, so the grasper holds pre-computed tissue and the blade cuts tensor-mass
    /// tissue. Symplectic Euler in 0.5 ms steps, damping 30/s, physics every 10 ticks, tearing
    /// past 100 % edge elongation. `session generate hepatectomy` writes its trajectory.
    pub fn built_in_hybrid() -> Scene {
        let sites = HepatectomySites::on_the_organ();
        let (a, b) = (sites.cut_from_m, sites.cut_to_m);
        Scene {
            source: "built-in hybrid scene".into(),
            mesh: MeshSource::GeneratedOrgan,
            // Parses (a number formatted by Rust).
            fix: format!("z<{}", sites.floor_m + 1e-6)
                .parse::<FixPredicate>()
                .into_iter()
                .collect(),
            material: MaterialSpec {
                young_pa: 5000.0,
                poisson: 0.4,
                density_kg_m3: DEFAULT_DENSITY_KG_M3,
            },
            zones: vec![Zone {
                kind: ZoneKind::Cut,
                shape: ZoneShape::Capsule {
                    a_m: a,
                    b_m: b,
                    radius_m: HEPATECTOMY_CUT_RADIUS_M,
                },
            }],
            ..Self::built_in_tools()
        }
    }

    /// The built-in scene names [`Self::named`] knows.
    pub const BUILT_IN: [&'static str; 4] = [
        "built-in",
        "built-in-dynamic",
        "built-in-tools",
        "built-in-hybrid",
    ];

    /// The scene a command line names: `built-in` ([`Self::built_in`]), `built-in-dynamic`
    /// ([`Self::built_in_dynamic`]), `built-in-tools` ([`Self::built_in_tools`]),
    /// `built-in-hybrid` ([`Self::built_in_hybrid`]), or a scene file ([`Self::read`]).
    pub fn named(name: &str) -> Result<Scene, SceneError> {
        match name {
            "built-in" => Ok(Self::built_in()),
            "built-in-dynamic" => Ok(Self::built_in_dynamic()),
            "built-in-tools" => Ok(Self::built_in_tools()),
            "built-in-hybrid" => Ok(Self::built_in_hybrid()),
            path => Self::read(Path::new(path)),
        }
    }

    /// Read and validate a scene file (at most [`MAX_SCENE_FILE_BYTES`], UTF-8). A relative
    /// `mesh` path is resolved against the file's folder. Messages name the file as `path`
    /// displays.
    pub fn read(path: &Path) -> Result<Scene, SceneError> {
        let file = path.display().to_string();
        let text = read_bounded(
            path,
            MAX_SCENE_FILE_BYTES,
            "a scene file (MAX_SCENE_FILE_BYTES)",
        )
        .and_then(|bytes| {
            String::from_utf8(bytes)
                .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, e))
        })
        .map_err(|err| SceneError::Io {
            file: file.clone(),
            err,
        })?;
        let base_dir = path.parent().unwrap_or(Path::new(""));
        Self::from_toml_str_named(&text, &file, base_dir)
    }

    /// Parse and validate a scene from TOML text; a relative `mesh` path is resolved against
    /// `base_dir`. Messages name the source `inline scene`.
    pub fn from_toml_str(text: &str, base_dir: &Path) -> Result<Scene, SceneError> {
        Self::from_toml_str_named(text, "inline scene", base_dir)
    }

    /// [`Scene::from_toml_str`], naming the source `source` in messages and in [`Scene::source`].
    pub fn from_toml_str_named(
        text: &str,
        source: &str,
        base_dir: &Path,
    ) -> Result<Scene, SceneError> {
        let raw: SceneFile = toml::from_str(text).map_err(|err| SceneError::Syntax {
            file: source.to_owned(),
            // A missing top-level key is located at the document's start: no line then.
            line: err
                .span()
                .filter(|span| span.start > 0 || !err.message().starts_with("missing field"))
                .and_then(|span| text.get(..span.start))
                .map(|before| before.matches('\n').count() + 1),
            msg: with_array_key(text, &err),
        })?;
        let invalid = |key: &str, msg: String| SceneError::Invalid {
            file: source.to_owned(),
            key: key.to_owned(),
            msg,
        };
        let mesh = match (raw.mesh, raw.generated) {
            (Some(path), None) => MeshSource::File(base_dir.join(path)),
            (None, Some(g)) => MeshSource::GeneratedBox {
                size_m: g.box_m,
                cells: g.cells,
            },
            (Some(_), Some(_)) => {
                return Err(invalid(
                    "mesh",
                    "give either `mesh = \"<file>\"` or a [generated] table, not both".into(),
                ));
            }
            (None, None) => {
                return Err(invalid(
                    "mesh",
                    "missing: give `mesh = \"<file>\"` or a [generated] table with box_m and cells"
                        .into(),
                ));
            }
        };
        let fix = raw
            .fix
            .iter()
            .enumerate()
            .map(|(i, text)| {
                text.parse::<FixPredicate>().map_err(|_| {
                    invalid(
                        &format!("fix[{i}] = {text:?}"),
                        "expected x|y|z, then <, <=, > or >=, then a finite number, e.g. \"z<0.001\""
                            .into(),
                    )
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let model = model_spec(&raw.model, raw.rates.haptic_hz, raw.rates.physics_every)
            .map_err(|(key, msg)| invalid(&key, msg))?;
        let tool = tool_spec(&raw.tool).map_err(|(key, msg)| invalid(&key, msg))?;
        let (zones, partition) =
            zones_spec(&raw.zone, raw.partition.as_ref(), base_dir, raw.tool.points)
                .map_err(|(key, msg)| invalid(&key, msg))?;
        let scene = Scene {
            source: source.to_owned(),
            mesh,
            fix,
            material: MaterialSpec {
                young_pa: raw.material.young_pa,
                poisson: raw.material.poisson,
                density_kg_m3: raw.material.density_kg_m3,
            },
            regions: raw.region,
            model,
            tool,
            cutting: CuttingSpec {
                capacity_tets: raw.cutting.capacity_tets,
                force_n: raw.cutting.force_n,
            },
            tearing: raw.tearing.map(|t| TearingSpec {
                volume_change: t.volume_change,
                mean_elongation: t.mean_elongation,
                max_elongation: t.max_elongation,
                capacity_tets: t.capacity_tets,
            }),
            rates: Rates {
                haptic_hz: raw.rates.haptic_hz,
                physics_every: raw.rates.physics_every,
            },
            safety: SafetyLimits {
                max_force_n: raw.safety.max_force_n,
                max_slew_n_per_s: raw.safety.max_slew_n_per_s,
            },
            zones,
            partition,
        };
        scene.validate()?;
        Ok(scene)
    }

    /// Check every invariant of [`Scene`]; the error names [`Scene::source`] and the key.
    pub fn validate(&self) -> Result<(), SceneError> {
        let invalid = |key: String, msg: &str| {
            Err(SceneError::Invalid {
                file: self.source.clone(),
                key,
                msg: msg.to_owned(),
            })
        };
        let positive = |x: f64| x.is_finite() && x > 0.0;
        if let MeshSource::GeneratedBox { size_m, cells } = self.mesh {
            if !size_m.iter().all(|&s| positive(s)) {
                return invalid(
                    format!("[generated] box_m = {size_m:?}"),
                    "every size must be finite and > 0 m",
                );
            }
            let vertices = cells.iter().try_fold(1usize, |n, &c| {
                if c == 0 {
                    None
                } else {
                    n.checked_mul(c.checked_add(1)?)
                }
            });
            match vertices {
                None if cells.contains(&0) => {
                    return invalid(
                        format!("[generated] cells = {cells:?}"),
                        "every cell count must be >= 1",
                    );
                }
                Some(n) if n <= MAX_GENERATED_VERTICES => {}
                _ => {
                    return invalid(
                        format!("[generated] cells = {cells:?}"),
                        &format!("too many vertices: at most {MAX_GENERATED_VERTICES}"),
                    );
                }
            }
        }
        if self.fix.is_empty() && self.model == ModelSpec::Precomputed {
            return invalid(
                "fix = []".into(),
                "the pre-computed model needs at least one fixed-vertex predicate (a free body has no compliance)",
            );
        }
        let m = &self.material;
        if let Err(err) = Material::new(m.young_pa, m.poisson) {
            return match err {
                MaterialError::YoungModulus(e) => invalid(
                    format!("[material] young_pa = {}", shown(e)),
                    "must be finite and > 0 Pa",
                ),
                MaterialError::PoissonRatio(nu) => invalid(
                    format!("[material] poisson = {}", shown(nu)),
                    &format!("must satisfy {POISSON_RANGE}"),
                ),
            };
        }
        if !positive(m.density_kg_m3) {
            return invalid(
                format!("[material] density_kg_m3 = {}", shown(m.density_kg_m3)),
                "must be finite and > 0 kg/m3",
            );
        }
        if !(1..=MAX_TOOL_POINTS).contains(&self.tool.points) {
            return invalid(
                format!("[tool] points = {}", self.tool.points),
                &format!("must be in 1..={MAX_TOOL_POINTS} (the kernel's contact capacity)"),
            );
        }
        if !positive(self.tool.radius_m) {
            return invalid(
                format!("[tool] radius_m = {}", shown(self.tool.radius_m)),
                "must be finite and > 0 m",
            );
        }
        let in_file = |(key, msg): (String, String)| SceneError::Invalid {
            file: self.source.clone(),
            key,
            msg,
        };
        check_regions(&self.regions, m.young_pa, m.density_kg_m3).map_err(in_file)?;
        check_tool(&self.tool).map_err(in_file)?;
        check_removal(&self.cutting, self.tearing.as_ref(), &self.model).map_err(in_file)?;
        if !positive(self.rates.haptic_hz) {
            return invalid(
                format!("[rates] haptic_hz = {}", shown(self.rates.haptic_hz)),
                "must be finite and > 0 Hz",
            );
        }
        if self.rates.haptic_hz > MAX_HAPTIC_HZ {
            return invalid(
                format!("[rates] haptic_hz = {}", shown(self.rates.haptic_hz)),
                &format!(
                    "above {MAX_HAPTIC_HZ} Hz (MAX_HAPTIC_HZ): haptic devices servo at 1 to 10 kHz"
                ),
            );
        }
        if self.rates.physics_every == 0 {
            return invalid(
                "[rates] physics_every = 0".into(),
                "must be >= 1 (a physics update every this many ticks)",
            );
        }
        if !(positive(self.tick_s()) && positive(self.physics_period_s())) {
            return invalid(
                format!("[rates] haptic_hz = {}", shown(self.rates.haptic_hz)),
                "too small: 1/haptic_hz and physics_every/haptic_hz must be finite seconds",
            );
        }
        if !positive(self.safety.max_force_n) {
            return invalid(
                format!("[safety] max_force_n = {}", shown(self.safety.max_force_n)),
                "must be finite and > 0 N",
            );
        }
        if !positive(self.safety.max_slew_n_per_s) {
            return invalid(
                format!(
                    "[safety] max_slew_n_per_s = {}",
                    shown(self.safety.max_slew_n_per_s)
                ),
                "must be finite and > 0 N/s",
            );
        }
        // The loop runs in f32 (`session::run::loop_config`): a value beyond
        // its range would reach the kernel as infinity or zero.
        let in_f32 = |x: f64| {
            let y = x as f32;
            y.is_finite() && y > 0.0
        };
        let f32_range = format!("between {:e} and {:e}", f32::MIN_POSITIVE, f32::MAX);
        for (key, value, unit) in [
            ("[safety] max_force_n", self.safety.max_force_n, "N"),
            (
                "[safety] max_slew_n_per_s",
                self.safety.max_slew_n_per_s,
                "N/s",
            ),
            ("[tool] radius_m", self.tool.radius_m, "m"),
            ("[tool] grip_opening_m", self.tool.grip_opening_m, "m"),
        ] {
            if !in_f32(value) {
                return invalid(
                    format!("{key} = {value:e}"),
                    &format!("out of range of the loop's f32: must lie {f32_range} {unit}"),
                );
            }
        }
        if !in_f32(self.tick_s()) {
            return invalid(
                format!("[rates] haptic_hz = {:e}", self.rates.haptic_hz),
                &format!("out of range of the loop's f32: 1/haptic_hz must lie {f32_range} s"),
            );
        }
        if !in_f32(length(self.tool.blade_m)) {
            return invalid(
                format!("[tool] blade_m = {:?}", self.tool.blade_m),
                &format!("out of range of the loop's f32: its length must lie {f32_range} m"),
            );
        }
        if let ModelSpec::Dynamic(d) = &self.model {
            check_dynamic(d, self.physics_period_s()).map_err(in_file)?;
        }
        Ok(())
    }

    /// The validated elastic material (E, ν) for the table builders.
    pub fn elastic_material(&self) -> Result<Material, MaterialError> {
        Material::new(self.material.young_pa, self.material.poisson)
    }

    /// The tick period, s: `1 / haptic_hz`.
    pub fn tick_s(&self) -> f64 {
        1.0 / self.rates.haptic_hz
    }

    /// The physics period, s: `physics_every / haptic_hz`.
    pub fn physics_period_s(&self) -> f64 {
        f64::from(self.rates.physics_every) / self.rates.haptic_hz
    }

    /// For a dynamic scene, how many steps of `dt_s` make one physics period (≥ 1); `None` for
    /// the pre-computed model.
    pub fn dynamic_substeps(&self) -> Option<u32> {
        match &self.model {
            ModelSpec::Precomputed => None,
            ModelSpec::Dynamic(d) => substeps(self.physics_period_s(), d.dt_s),
        }
    }

    /// Load (or generate) the mesh. A generated box is built by [`box_mesh`] and satisfies the
    /// [`TetMesh`] invariants by construction; its report names it (`generated box ...`) and is
    /// otherwise empty. A file's errors name the file (see [`read_mesh`]).
    pub fn load_mesh(&self) -> Result<(TetMesh, MeshReport), MeshError> {
        match &self.mesh {
            MeshSource::File(path) => read_mesh(path),
            MeshSource::GeneratedBox { size_m, cells } => {
                let mesh = box_mesh(*cells, *size_m);
                let report = MeshReport {
                    source: format!(
                        "generated box {} x {} x {} m, {} x {} x {} cells",
                        size_m[0], size_m[1], size_m[2], cells[0], cells[1], cells[2]
                    ),
                    ..MeshReport::default()
                };
                Ok((mesh, report))
            }
            MeshSource::GeneratedOrgan => Ok((
                organ_mesh(ORGAN_CUBE_M),
                MeshReport {
                    source: format!("generated organ, {ORGAN_CUBE_M} m cubes"),
                    ..MeshReport::default()
                },
            )),
        }
    }
}

/// Whole steps of `dt_s` in `period_s`, if `period_s / dt_s` is within 1e-9 (relative) of an
/// integer in `1..=MAX_SUBSTEPS`.
fn substeps(period_s: f64, dt_s: f64) -> Option<u32> {
    let ratio = period_s / dt_s;
    let n = ratio.round();
    if ratio.is_finite()
        && n >= 1.0
        && n <= f64::from(MAX_SUBSTEPS)
        && (ratio - n).abs() <= 1e-9 * n
    {
        // In 1..=MAX_SUBSTEPS, so the conversion is exact.
        Some(n as u32)
    } else {
        None
    }
}

/// The model of the `[model]` table; errors are `(key, message)`.
fn model_spec(
    raw: &ModelFile,
    haptic_hz: f64,
    physics_every: u32,
) -> Result<ModelSpec, (String, String)> {
    if raw.kind == KindName::Precomputed {
        let dynamic_only = [
            ("law", raw.law.is_some()),
            ("form", raw.form.is_some()),
            ("integrator", raw.integrator.is_some()),
            ("dt_s", raw.dt_s.is_some()),
            ("damping_per_s", raw.damping_per_s.is_some()),
            ("incompressibility_n", raw.incompressibility_n.is_some()),
            ("extrapolation", raw.extrapolation.is_some()),
        ];
        if let Some((key, _)) = dynamic_only.iter().find(|(_, given)| *given) {
            return Err((
                format!("[model] {key}"),
                "applies to kind = \"dynamic\" only (this scene is \"precomputed\")".into(),
            ));
        }
        return Ok(ModelSpec::Precomputed);
    }
    let form = match raw.form {
        None | Some(FormName::PerTet) => StvkForm::PerTet,
        Some(FormName::Tensors) => StvkForm::Tensors,
    };
    let law_name = raw.law.unwrap_or(LawName::Linear);
    if matches!(law_name, LawName::Linear) && raw.form.is_some() {
        return Err((
            "[model] form".into(),
            "applies to law = \"stvk\" or \"stvk-incompressible\" only".into(),
        ));
    }
    let (law, incompressibility_n) = match (law_name, raw.incompressibility_n) {
        (LawName::Linear, None) => (ElasticLaw::Linear, None),
        (LawName::Stvk, None) => (ElasticLaw::StVenantKirchhoff(form), None),
        (LawName::StvkIncompressible, Some(gamma)) => {
            (ElasticLaw::StVenantKirchhoff(form), Some(gamma))
        }
        (LawName::StvkIncompressible, None) => {
            return Err((
                "[model] incompressibility_n".into(),
                "missing: law = \"stvk-incompressible\" needs the penalty gamma (N)".into(),
            ));
        }
        (_, Some(_)) => {
            return Err((
                "[model] incompressibility_n".into(),
                "applies to law = \"stvk-incompressible\" only".into(),
            ));
        }
    };
    let integrator = match raw.integrator.unwrap_or(IntegratorName::Symplectic) {
        IntegratorName::Euler => Integrator::ExplicitEuler,
        IntegratorName::Symplectic => Integrator::SymplecticEuler,
        IntegratorName::Rk4 => Integrator::Rk4,
        IntegratorName::Central => Integrator::CentralDifference,
    };
    let Some(damping_per_s) = raw.damping_per_s else {
        return Err((
            "[model] damping_per_s".into(),
            "missing: kind = \"dynamic\" needs the mass-proportional damping (1/s)".into(),
        ));
    };
    Ok(ModelSpec::Dynamic(DynamicSpec {
        law,
        incompressibility_n,
        integrator,
        dt_s: raw.dt_s.unwrap_or(f64::from(physics_every) / haptic_hz),
        damping_per_s,
        extrapolation: match raw.extrapolation {
            None | Some(ExtrapolationName::Secant) => Extrapolation::Secant,
            Some(ExtrapolationName::Instantaneous) => Extrapolation::Instantaneous,
        },
    }))
}

/// The tool of the `[tool]` table; errors are `(key, message)`. Kinds are expanded to one per
/// tool point (at most [`MAX_TOOL_POINTS`], so a huge `points` allocates nothing before
/// [`Scene::validate`] refuses it); a finite, non-zero `jaw_axis` is normalized. The ranges are
/// [`Scene::validate`]'s.
fn tool_spec(raw: &ToolFile) -> Result<ToolSpec, (String, String)> {
    let kind = |name: &str, key: String| {
        ToolKind::from_name(name).ok_or_else(|| {
            (
                key,
                "expected \"probe\", \"grasper\" or \"cutter\"".to_owned(),
            )
        })
    };
    let kinds = match &raw.kind {
        None => vec![ToolKind::Probe; raw.points.min(MAX_TOOL_POINTS)],
        Some(KindsFile::One(name)) => {
            let k = kind(name, format!("[tool] kind = {name:?}"))?;
            vec![k; raw.points.min(MAX_TOOL_POINTS)]
        }
        Some(KindsFile::Many(names)) => names
            .iter()
            .enumerate()
            .map(|(i, name)| kind(name, format!("[tool] kind[{i}] = {name:?}")))
            .collect::<Result<_, _>>()?,
    };
    Ok(ToolSpec {
        points: raw.points,
        radius_m: raw.radius_m,
        kinds,
        jaw_axis: raw.jaw_axis.map_or(DEFAULT_JAW_AXIS, normalized),
        grip_opening_m: raw
            .grip_opening_m
            .unwrap_or(DEFAULT_GRIP_OPENING_RADII * raw.radius_m),
        blade_m: raw.blade_m.unwrap_or(DEFAULT_BLADE_M),
    })
}

/// `a / |a|` computed without overflow or underflow (scaled by the largest component first), to
/// within a few ulps of unit length; `a` itself if it is not finite or is zero.
fn normalized(a: [f64; 3]) -> [f64; 3] {
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if !(a.iter().all(|x| x.is_finite()) && scale > 0.0) {
        return a;
    }
    let b = a.map(|x| x / scale);
    let length = b.iter().map(|x| x * x).sum::<f64>().sqrt();
    b.map(|x| x / length)
}

/// Euclidean length of `a` (overflows to infinity only past `f64::MAX`; NaN if a component is).
fn length(a: [f64; 3]) -> f64 {
    if a.iter().any(|x| x.is_nan()) {
        return f64::NAN;
    }
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if !(scale.is_finite() && scale > 0.0) {
        return scale;
    }
    scale
        * a.map(|x| x / scale)
            .iter()
            .map(|x| x * x)
            .sum::<f64>()
            .sqrt()
}

/// The ranges of a [`ToolSpec`] (after `points` and `radius_m`); errors are `(key, message)`.
fn check_tool(tool: &ToolSpec) -> Result<(), (String, String)> {
    let names = || {
        let names: Vec<&str> = tool.kinds.iter().map(|k| k.name()).collect();
        format!("[tool] kind = {names:?}")
    };
    if tool.kinds.len() != tool.points {
        return Err((
            names(),
            format!(
                "{} given for points = {}: give one kind per trajectory tool point, or a single kind for all",
                tool.kinds.len(),
                tool.points
            ),
        ));
    }
    let needed = tool.kernel_points();
    if needed > MAX_TOOL_POINTS {
        return Err((
            names(),
            format!(
                "needs {needed} kernel tool points (a grasper is 2 jaws, a probe or cutter 1): at most {MAX_TOOL_POINTS} (MAX_TOOL_POINTS, the kernel's contact capacity)"
            ),
        ));
    }
    let axis = tool.jaw_axis;
    if !axis.iter().all(|x| x.is_finite()) || axis.iter().all(|&x| x == 0.0) {
        return Err((
            format!("[tool] jaw_axis = {axis:?}"),
            "must be finite and non-zero (the direction from jaw 0 to jaw 1)".into(),
        ));
    }
    if (length(axis) - 1.0).abs() > 1e-12 {
        return Err((
            format!("[tool] jaw_axis = {axis:?}"),
            "must have unit length (a scene file's jaw_axis is normalized when read)".into(),
        ));
    }
    let grip = tool.grip_opening_m;
    if !(grip.is_finite() && grip > 0.0) {
        return Err((
            format!("[tool] grip_opening_m = {grip}"),
            "must be finite and > 0 m".into(),
        ));
    }
    let blade = tool.blade_m;
    let blade_length = length(blade);
    if !(blade.iter().all(|x| x.is_finite()) && blade_length > 0.0 && blade_length <= MAX_BLADE_M) {
        return Err((
            format!("[tool] blade_m = {blade:?}"),
            format!(
                "must be finite, with a length > 0 and at most {MAX_BLADE_M} m (MAX_BLADE_M), from the tool point to the blade's tip"
            ),
        ));
    }
    Ok(())
}

/// The ranges of `[cutting]` and `[tearing]`; errors are `(key, message)`.
fn check_removal(
    cutting: &CuttingSpec,
    tearing: Option<&TearingSpec>,
    model: &ModelSpec,
) -> Result<(), (String, String)> {
    let capacity = |table: &str, capacity: u32| {
        if (1..=MAX_CAPACITY_TETS).contains(&capacity) {
            Ok(())
        } else {
            Err((
                format!("[{table}] capacity_tets = {capacity}"),
                format!(
                    "must be in 1..={MAX_CAPACITY_TETS} (MAX_CAPACITY_TETS: tets one physics update removes at most)"
                ),
            ))
        }
    };
    capacity("cutting", cutting.capacity_tets)?;
    let force = cutting.force_n;
    if !(force.is_finite() && force > 0.0 && force <= f64::from(f32::MAX)) {
        return Err((
            format!("[cutting] force_n = {force}"),
            "must be finite, > 0 N and fit f32".into(),
        ));
    }
    let Some(tearing) = tearing else {
        return Ok(());
    };
    if *model == ModelSpec::Precomputed {
        return Err((
            "[tearing]".into(),
            "applies to kind = \"dynamic\" only (this scene is \"precomputed\", which cannot tear)"
                .into(),
        ));
    }
    let criteria = [
        ("volume_change", tearing.volume_change),
        ("mean_elongation", tearing.mean_elongation),
        ("max_elongation", tearing.max_elongation),
    ];
    if criteria.iter().all(|(_, value)| value.is_none()) {
        return Err((
            "[tearing]".into(),
            "no criterion: give at least one of volume_change, mean_elongation and max_elongation (or remove the table: no tearing)".into(),
        ));
    }
    for (key, value) in criteria {
        if let Some(x) = value
            && !(x.is_finite() && x > 0.0)
        {
            return Err((
                format!("[tearing] {key} = {x}"),
                "must be finite and > 0".into(),
            ));
        }
    }
    capacity("tearing", tearing.capacity_tets)
}

/// The ranges of a [`DynamicSpec`]; errors are `(key, message)`.
fn check_dynamic(d: &DynamicSpec, physics_period_s: f64) -> Result<(), (String, String)> {
    if let Some(gamma) = d.incompressibility_n
        && !(gamma.is_finite() && gamma >= 0.0)
    {
        return Err((
            format!("[model] incompressibility_n = {gamma}"),
            "must be finite and >= 0 N".into(),
        ));
    }
    if !(d.damping_per_s.is_finite() && d.damping_per_s >= 0.0) {
        return Err((
            format!("[model] damping_per_s = {}", shown(d.damping_per_s)),
            "must be finite and >= 0 1/s".into(),
        ));
    }
    if !(d.dt_s.is_finite() && d.dt_s > 0.0) {
        return Err((
            format!("[model] dt_s = {}", shown(d.dt_s)),
            "must be finite and > 0 s".into(),
        ));
    }
    if substeps(physics_period_s, d.dt_s).is_none() {
        return Err((
            format!("[model] dt_s = {}", shown(d.dt_s)),
            format!(
                "the physics period ({physics_period_s} s = physics_every / haptic_hz) must be a whole number of steps, 1 to {MAX_SUBSTEPS}"
            ),
        ));
    }
    Ok(())
}

/// Arrays of exactly three numbers in a scene file: `[x, y, z]` with a fourth (or a second
/// missing) is an error naming the key (the parser's message shows its line), never truncated.
pub(crate) mod exact {
    use serde::de::{Deserialize, Deserializer, Error};

    /// A `[a, b, c]` array: three elements, no more, no fewer.
    pub(crate) fn three<'de, D, T>(deserializer: D) -> Result<[T; 3], D::Error>
    where
        D: Deserializer<'de>,
        T: Deserialize<'de>,
    {
        let items = Vec::<T>::deserialize(deserializer)?;
        let len = items.len();
        <[T; 3]>::try_from(items)
            .map_err(|_| D::Error::invalid_length(len, &"exactly 3 numbers, [x, y, z]"))
    }

    /// [`three`] of an optional key (with `#[serde(default)]`).
    pub(crate) fn three_opt<'de, D, T>(deserializer: D) -> Result<Option<[T; 3]>, D::Error>
    where
        D: Deserializer<'de>,
        T: Deserialize<'de>,
    {
        three(deserializer).map(Some)
    }
}

/// The parser's message of `err` on one line; for an array of the wrong length
/// ([`exact::three`]), preceded by its key as written on its line (`min_m: invalid length 4,
/// ...`).
fn with_array_key(text: &str, err: &toml::de::Error) -> String {
    let msg = err.message().trim().replace('\n', "; ");
    let key = err
        .span()
        .filter(|_| msg.starts_with("invalid length"))
        .and_then(|span| {
            let start = text.get(..span.start)?.rfind('\n').map_or(0, |i| i + 1);
            let line = text.get(start..)?.lines().next()?;
            let key = line.split_once('=')?.0.trim();
            (!key.is_empty()).then(|| key.to_owned())
        });
    match key {
        Some(key) => format!("{key}: {msg}"),
        None => msg,
    }
}
