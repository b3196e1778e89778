//! The built-in scenes (`built-in`, `built-in-dynamic`, `built-in-tools`, `built-in-hybrid`),
//! the hybrid one's sites on the organ, and the scene a command line names.

use std::path::Path;

use palpate_kernel::haptic::SafetyLimits;
use palpate_kernel::tensor_mass::{ElasticLaw, Extrapolation, Integrator};

use super::error::SceneError;
use super::materials::{DEFAULT_DENSITY_KG_M3, MaterialSpec};
use super::mesh::MeshSource;
use super::spec::{
    CuttingSpec, DEFAULT_CAPACITY_TETS, DEFAULT_CUT_FORCE_N, DEFAULT_HAPTIC_HZ,
    DEFAULT_MAX_FORCE_N, DEFAULT_MAX_SLEW_N_PER_S, DEFAULT_PHYSICS_EVERY, DynamicSpec, ModelSpec,
    Rates, Scene, TearingSpec,
};
use super::tables::TablesSpec;
use super::tool::{DEFAULT_TOOL_POINTS, DEFAULT_TOOL_RADIUS_M, ToolKind, ToolSpec};
use super::zones::{PartitionSpec, Zone, ZoneKind, ZoneShape};
use crate::fem::material::Material;
use crate::fix::FixPredicate;
use crate::mesh::organ::{ORGAN_FLOOR_Z_M, organ};
use crate::mesh::top_height;

/// How far the built-in hybrid scene's cut zone reaches past its cut line into the organ, m:
/// the blade's sphere (2 mm) and two of the left lobe's 5 mm tets. It is the zone's margin: the
/// scene adds no element rings (`[partition] margin_rings = 0`; the default 4 rings would make
/// three quarters of the organ tensor-mass).
pub const HEPATECTOMY_ZONE_PAST_CUT_M: f64 = 0.012;

/// The built-in hybrid scene's cutter blade, m: 2 cm straight down from the tool point, longer
/// than the left lobe is thick where it is cut (1.3 cm), so the cut goes through.
pub const HEPATECTOMY_BLADE_M: [f64; 3] = [0.0, 0.0, -0.02];

/// The built-in hybrid scene's time step, s: 40 steps per physics update. The organ's
/// 5 mm tets make symplectic Euler's largest stable step 0.449 ms (`palpate` checks it when a
/// session starts); 0.25 ms keeps well below it as the cut removes tets.
pub const HEPATECTOMY_DT_S: f64 = 0.00025;

/// Where the built-in hybrid scene's tools work on the organ's rest surface (m): the grasper on
/// the top of the right lobe's dome, the cutter across the left lobe, 4.5 cm from its tip.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HepatectomySites {
    /// The surface point between the grasper's jaws.
    pub grasp_m: [f64; 3],
    /// Where the cut starts (along +y, front to back): 3 mm inside the left lobe's front rim,
    /// at the height of the lobe's top on its mid-line (`y = 0`), where the blade tip enters.
    pub cut_from_m: [f64; 3],
    /// Where the cut ends: 4 mm past the lobe's back rim, at the same height.
    pub cut_to_m: [f64; 3],
    /// Height of the organ's flat underside (its lowest vertices).
    pub floor_m: f64,
}

impl HepatectomySites {
    /// The sites on the built-in [`organ`]: the grasp at `(0.04, 0)` (the right lobe's dome,
    /// 4 cm high), the cut along `x = −0.04` from `y = −0.034` to `0.042` (the lobe spans
    /// `y` from −0.037 to 0.038 m there, and `z` from −0.006 to 0.008 m), each at the height
    /// of the rest surface at its `x` on `y = 0`.
    pub fn on_the_organ() -> Self {
        // The embedded organ reads (tests::host::mesh reads it).
        let (mesh, _) = organ().expect("the built-in organ");
        let surface = crate::mesh::boundary_surface(&mesh);
        let top = |x: f64, y: f64| {
            // The sites are over the organ (a fixed mesh).
            top_height(&mesh.positions, &surface.triangles, x, y).unwrap_or(0.0)
        };
        let (x, z) = (-0.04, top(-0.04, 0.0));
        Self {
            grasp_m: [0.04, 0.0, top(0.04, 0.0)],
            cut_from_m: [x, -0.034, z],
            cut_to_m: [x, 0.042, z],
            floor_m: ORGAN_FLOOR_Z_M,
        }
    }
}

impl Scene {
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
                elastic: Material {
                    young_pa: 3000.0,
                    poisson: 0.45,
                },
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
            tables: TablesSpec::default(),
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
    /// ([`MeshSource::BuiltInOrgan`], E = 5 kPa, ν = 0.4, 1000 kg/m³, its flat underside
    /// fixed), a grasper (trajectory tool 0) holding the right lobe on its dome and a cutter
    /// (tool 1, blade [`HEPATECTOMY_BLADE_M`]) cutting the left lobe through, across its width
    /// ([`HepatectomySites`]), so its tip comes off; the one `[[zone]]`, a cut box holding the
    /// left lobe from its tip to [`HEPATECTOMY_ZONE_PAST_CUT_M`] past the cut line, with no
    /// margin rings (the 12 mm are the margin), makes the tensor-mass region (linear: no large-deformation zone), the
    /// rest of the organ is pre-computed, so the grasper holds pre-computed tissue and the
    /// blade cuts tensor-mass tissue, and the tip it cuts off is all tensor-mass. Symplectic
    /// Euler in [`HEPATECTOMY_DT_S`] steps, damping 30/s, physics every 10 ticks, tearing past
    /// 100 % edge elongation. `session generate hepatectomy` writes its trajectory.
    pub fn built_in_hybrid() -> Scene {
        let sites = HepatectomySites::on_the_organ();
        let mut scene = Self::built_in_tools();
        scene.tool.blade_m = HEPATECTOMY_BLADE_M;
        if let ModelSpec::Dynamic(dynamic) = &mut scene.model {
            dynamic.dt_s = HEPATECTOMY_DT_S;
        }
        Scene {
            source: "built-in hybrid scene".into(),
            mesh: MeshSource::BuiltInOrgan,
            // Parses (a number formatted by Rust).
            fix: format!("z<{}", sites.floor_m + 1e-6)
                .parse::<FixPredicate>()
                .into_iter()
                .collect(),
            material: MaterialSpec {
                elastic: Material {
                    young_pa: 5000.0,
                    poisson: 0.4,
                },
                density_kg_m3: DEFAULT_DENSITY_KG_M3,
            },
            partition: PartitionSpec { margin_rings: 0 },
            // The organ lies within 0.1 m of the origin.
            zones: vec![Zone {
                kind: ZoneKind::Cut,
                shape: ZoneShape::Box {
                    min_m: [-0.2, -0.2, -0.2],
                    max_m: [sites.cut_from_m[0] + HEPATECTOMY_ZONE_PAST_CUT_M, 0.2, 0.2],
                },
            }],
            ..scene
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
}
