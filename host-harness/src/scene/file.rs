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
//! law = "stvk"                 # "linear" (default), "stvk", "stvk-incompressible",
//!                              # "corotational" or "neo-hookean"
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
//! # [tables]: how a pre-computed scene's compliance is stored (crate::scene::tables)
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

use palpate_kernel::haptic::SafetyLimits;
use palpate_kernel::tensor_mass::{ElasticLaw, Extrapolation, Integrator, StvkForm};
use serde::Deserialize;

use super::error::SceneError;
use super::exact;
use super::materials::{DEFAULT_DENSITY_KG_M3, MaterialSpec, RegionSpec};
use super::mesh::MeshSource;
use super::spec::{
    CuttingSpec, DEFAULT_CAPACITY_TETS, DEFAULT_CUT_FORCE_N, DEFAULT_HAPTIC_HZ,
    DEFAULT_MAX_FORCE_N, DEFAULT_MAX_SLEW_N_PER_S, DEFAULT_PHYSICS_EVERY, DynamicSpec, ModelSpec,
    Rates, Scene, TearingSpec,
};
use super::tables::{TablesFile, TablesSpec};
use super::tool::{
    DEFAULT_BLADE_M, DEFAULT_GRIP_OPENING_RADII, DEFAULT_JAW_AXIS, DEFAULT_TOOL_POINTS,
    DEFAULT_TOOL_RADIUS_M, MAX_TOOL_POINTS, ToolKind, ToolSpec, normalized,
};
use super::zones::{PartitionFile, ZoneFile, zones_spec};
use crate::fem::material::Material;
use crate::fix::FixPredicate;
use crate::limits::{MAX_SCENE_FILE_BYTES, read_bounded};

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
    region: Vec<RegionFile>,
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
    #[serde(default)]
    tables: TablesFile,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct GeneratedFile {
    #[serde(alias = "box", deserialize_with = "exact::three")]
    box_m: [f64; 3],
    #[serde(deserialize_with = "exact::three")]
    cells: [usize; 3],
}

/// A `[[region]]` table as written ([`RegionSpec`]).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RegionFile {
    id: u32,
    young_pa: f64,
    poisson: f64,
    density_kg_m3: Option<f64>,
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
    Corotational,
    NeoHookean,
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
        let tables = TablesSpec::new(&raw.tables).map_err(|(key, msg)| invalid(&key, msg))?;
        let (zones, partition) =
            zones_spec(&raw.zone, raw.partition.as_ref(), base_dir, raw.tool.points)
                .map_err(|(key, msg)| invalid(&key, msg))?;
        let scene = Scene {
            source: source.to_owned(),
            mesh,
            fix,
            // Checked by `validate` below, with the key that names them.
            material: MaterialSpec {
                elastic: Material {
                    young_pa: raw.material.young_pa,
                    poisson: raw.material.poisson,
                },
                density_kg_m3: raw.material.density_kg_m3,
            },
            regions: raw
                .region
                .iter()
                .map(|r| RegionSpec {
                    id: r.id,
                    elastic: Material {
                        young_pa: r.young_pa,
                        poisson: r.poisson,
                    },
                    density_kg_m3: r.density_kg_m3,
                })
                .collect(),
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
            tables,
        };
        scene.validate()?;
        Ok(scene)
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
    let per_tet_only = matches!(
        law_name,
        LawName::Linear | LawName::Corotational | LawName::NeoHookean
    );
    if per_tet_only && raw.form.is_some() {
        return Err((
            "[model] form".into(),
            "applies to law = \"stvk\" or \"stvk-incompressible\" only".into(),
        ));
    }
    let (law, incompressibility_n) = match (law_name, raw.incompressibility_n) {
        (LawName::Linear, None) => (ElasticLaw::Linear, None),
        (LawName::Stvk, None) => (ElasticLaw::StVenantKirchhoff(form), None),
        (LawName::Corotational, None) => (ElasticLaw::Corotational, None),
        (LawName::NeoHookean, None) => (ElasticLaw::NeoHookean, None),
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
