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
use super::tool::{DEFAULT_TOOL_POINTS, DEFAULT_TOOL_RADIUS_M, ToolKind, ToolSpec};
use super::zones::{PartitionSpec, Zone, ZoneKind, ZoneShape};
use crate::fem::material::Material;
use crate::fix::FixPredicate;
use crate::mesh::generate::{ORGAN_CUBE_M, organ_mesh};
use crate::mesh::top_height;

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
                elastic: Material {
                    young_pa: 5000.0,
                    poisson: 0.4,
                },
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
}
