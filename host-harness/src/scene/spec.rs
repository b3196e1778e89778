//! A validated scene ([`Scene`]): what a haptic session simulates. The file format is
//! [`super::file`]'s; the checks are [`super::validate`]'s.

use palpate_kernel::haptic::SafetyLimits;
use palpate_kernel::tensor_mass::Extrapolation;
use palpate_kernel::tensor_mass::{ElasticLaw, Integrator};

use super::error::SceneError;
use super::materials::{MaterialSpec, RegionSpec, tet_materials};
use super::mesh::MeshSource;
use super::tables::TablesSpec;
use super::tool::ToolSpec;
use super::zones::{PartitionSpec, Zone};
use crate::fem::material::TetMaterials;
use crate::fix::FixPredicate;
use crate::mesh::{MeshError, MeshReport, TetMesh};

/// Largest number of dynamic-model steps per physics update (`physics period / dt_s`): the
/// kernel's bound on a physics update's loop.
pub const MAX_SUBSTEPS: u32 = palpate_kernel::tensor_mass::MAX_SUBSTEPS;

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
    /// `"stvk-incompressible"` → [`ElasticLaw::StVenantKirchhoff`] in the given `form`,
    /// `"corotational"` → [`ElasticLaw::Corotational`], `"neo-hookean"` →
    /// [`ElasticLaw::NeoHookean`].
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
    /// Haptic (tick) rate, Hz, finite, > 0 and at most `MAX_HAPTIC_HZ`.
    pub haptic_hz: f64,
    /// A physics update every this many ticks, ≥ 1 (force extrapolated in between).
    pub physics_every: u32,
}

/// Default haptic rate, Hz.
pub const DEFAULT_HAPTIC_HZ: f64 = 1000.0;
/// Default physics update interval, ticks.
pub const DEFAULT_PHYSICS_EVERY: u32 = 1;
/// Default number of tets one physics update cuts or tears at most.
pub const DEFAULT_CAPACITY_TETS: u32 = 8;
/// Largest number of tets one physics update may cut or tear (`[cutting]` and `[tearing]`
/// `capacity_tets`), so an update's removal work stays bounded.
pub const MAX_CAPACITY_TETS: u32 = 64;
/// Default device force clamp, N (desktop haptic devices peak at 3–8 N).
pub const DEFAULT_MAX_FORCE_N: f64 = 4.0;
/// Default slew limit, N/s (full force in 2 ms).
pub const DEFAULT_MAX_SLEW_N_PER_S: f64 = 2000.0;

/// A validated scene.
///
/// Invariants (checked by [`Scene::validate`], which every constructor runs): the ranges stated
/// on each field's type; a pre-computed scene has at least one `fix` predicate (a free body has
/// no compliance) and no tearing; a dynamic scene's physics period is a whole number
/// (1..=[`MAX_SUBSTEPS`]) of `dt_s`; the tool has one kind per trajectory tool point and needs
/// at most `MAX_TOOL_POINTS` kernel tool points. Fields are public for reading and for tests; after changing one, call
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
    /// the loop takes them in f32 ((`crate::session::setup::loop_config`)).
    pub safety: SafetyLimits<f64>,
    /// Where the tissue must be dynamic (`[[zone]]`, [`crate::scene::zones`]).
    pub zones: Vec<Zone>,
    /// How the zones become tets (`[partition]`).
    pub partition: PartitionSpec,
    /// How a pre-computed scene's compliance table is stored (`[tables]`).
    pub tables: TablesSpec,
}

impl Scene {
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

    /// The material of every tet of `mesh` (read with `report`), by `[material]` and
    /// `[[region]]` ([`tet_materials`]).
    pub fn tet_materials(
        &self,
        mesh: &TetMesh,
        report: &MeshReport,
    ) -> Result<TetMaterials, SceneError> {
        tet_materials(&self.source, &self.material, &self.regions, mesh, report)
    }

    /// Load (or generate) the mesh ([`MeshSource::load`]).
    pub fn load_mesh(&self) -> Result<(TetMesh, MeshReport), MeshError> {
        self.mesh.load()
    }
}

/// Whole steps of `dt_s` in `period_s`, if `period_s / dt_s` is within 1e-9 (relative) of an
/// integer in `1..=MAX_SUBSTEPS`.
pub(crate) fn substeps(period_s: f64, dt_s: f64) -> Option<u32> {
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
