//! The study's body: the generated cylinder or a user's mesh, its supports,
//! its loaded vertices and the geometry of its loads ([`Load`]), and the
//! displacement the study measures of it ([`tip_m`]).

use anyhow::Context;
use nalgebra::Vector3;
use serde::Serialize;

use super::face::{integrate, loaded_faces, nodal_loads, p1_shape};
use crate::fem::material::{Material, TetMaterials};
use crate::fem::newton::StaticProblem;
use crate::fem::static_solve::solve_loaded;
use crate::fix::{FixPredicate, fixed_vertices};
use crate::mesh::generate::cylinder_mesh;
use crate::mesh::{MeshReport, TetMesh};

/// Cylinder height, m.
pub const HEIGHT_M: f64 = 0.1;

/// The press's lateral imperfection: every loaded vertex's share of the
/// axial force carries this fraction of it along [`Body::lateral`] (the
/// bend's direction), for every model and the reference alike, so beyond
/// the buckling load every model solves the same problem with one bend
/// direction (the symmetric mesh and load leave it undecided: without it
/// the relaxations stay on the unstable straight state). Small enough
/// that the press-1 % reference's tip moves by 5e-5 (relative; 3×15:
/// 1.01620 → 1.01625 mm) and its figures in the report not at all.
pub const PRESS_IMPERFECTION: f64 = 1e-3;

/// The hybrid's tensor-mass region: this fraction of the body's length at
/// its loaded end ([`Body::hybrid_dynamic_tets`]).
pub const HYBRID_DYNAMIC_FRACTION: f64 = 1.0 / 3.0;

/// Which loads.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Load {
    /// Axial compression of the top face.
    Press,
    /// Lateral dead load on the top face.
    Bend,
    /// Torque as tangential loads on the top face.
    Twist,
}

impl Load {
    /// Every load.
    pub const ALL: [Load; 3] = [Load::Press, Load::Bend, Load::Twist];

    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            Load::Press => "press",
            Load::Bend => "bend",
            Load::Twist => "twist",
        }
    }
}

/// A user's mesh for the study (`palpate chart --mesh`): run at its own
/// resolution only (no refinement series).
#[derive(Clone, Debug)]
pub struct GivenMesh {
    /// The file name, the mesh's label in the study.
    pub label: String,
    /// The rest mesh, m.
    pub mesh: TetMesh,
    /// Its reader report.
    pub report: MeshReport,
    /// The supports.
    pub fix: Vec<FixPredicate>,
    /// The loaded vertices (any predicate matching); empty: the face
    /// farthest from the supports ([`GivenMesh::loaded_vertices`]).
    pub load_on: Vec<FixPredicate>,
    /// Material.
    pub material: Material,
}

/// Of the extent along the axis, the depth of the face loaded by default.
pub const LOADED_FACE_DEPTH: f64 = 1e-3;

impl GivenMesh {
    /// The loaded vertices: those matching [`GivenMesh::load_on`], or by
    /// default the face farthest from the supports: the vertices within
    /// [`LOADED_FACE_DEPTH`] of the mesh's extent of the farthest one along
    /// the direction from the supports' centroid to the mesh's vertex
    /// centroid. Fixed and unreferenced vertices are never loaded.
    pub fn loaded_vertices(&self) -> anyhow::Result<Vec<u32>> {
        let positions = &self.mesh.positions;
        let (fixed, _) = fixed_vertices(positions, &self.fix, &self.report.unreferenced_vertices);
        let candidates = (0..positions.len() as u32).filter(|&v| !fixed[v as usize]);
        if !self.load_on.is_empty() {
            let p = |v: u32| positions[v as usize];
            let loaded: Vec<u32> = candidates
                .filter(|&v| self.load_on.iter().any(|f| f.matches(&p(v))))
                .collect();
            anyhow::ensure!(!loaded.is_empty(), "--load-on matches no free vertex");
            return Ok(loaded);
        }
        let supports = centroid(positions, (0..positions.len()).filter(|&v| fixed[v]))
            .context("no vertex matches the supports (--fix)")?;
        let all = centroid(positions, 0..positions.len()).context("an empty mesh")?;
        let direction = (all - supports)
            .try_normalize(1e-12)
            .context("the supports are centred on the mesh: give the loaded face with --load-on")?;
        let along = |v: u32| (Vector3::from(positions[v as usize]) - supports).dot(&direction);
        let (lo, hi) = (0..positions.len() as u32)
            .map(along)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                (lo.min(x), hi.max(x))
            });
        let depth = LOADED_FACE_DEPTH * (hi - lo);
        Ok(candidates.filter(|&v| along(v) >= hi - depth).collect())
    }

    /// The study's body.
    pub fn body(&self) -> anyhow::Result<Body> {
        Body::with_loaded_vertices(
            self.label.clone(),
            self.mesh.clone(),
            self.report.clone(),
            self.fix.clone(),
            self.loaded_vertices()?,
            self.material,
        )
    }
}

/// The mean rest position of `vertices`, m; `None` for none.
fn centroid(positions: &[[f64; 3]], vertices: impl Iterator<Item = usize>) -> Option<Vector3<f64>> {
    let (mut sum, mut count) = (Vector3::zeros(), 0usize);
    for v in vertices {
        sum += Vector3::from(positions[v]);
        count += 1;
    }
    (count > 0).then(|| sum / count as f64)
}

/// A mesh of the study with its boundary sets and load geometry.
pub struct Body {
    /// `"RxH"` for a cylinder, the file name for a given mesh.
    pub label: String,
    /// The rest mesh.
    pub mesh: TetMesh,
    /// The mesh's reader report (the hybrid's tables are built from it).
    pub report: MeshReport,
    /// The support predicates ([`Body::fixed`] is what they match).
    pub fix: Vec<FixPredicate>,
    /// Fixed vertices.
    pub fixed: Vec<bool>,
    /// The loaded vertices (the cylinder's top face).
    pub top: Vec<u32>,
    /// The loaded face: the boundary triangles whose vertices are all
    /// loaded (`chart::face::loaded_faces`); empty when the loaded vertices form no
    /// face (then each gets an equal share of the load).
    pub faces: Vec<[u32; 3]>,
    /// Material.
    pub material: Material,
    /// Unit vector from the supports to the loaded end (the press pushes
    /// along `−axis`, the twist turns about it).
    pub axis: Vector3<f64>,
    /// Unit vector orthogonal to `axis`: the bend's direction.
    pub lateral: Vector3<f64>,
    /// Centroid of the loaded vertices, m (the twist's axis passes through it).
    pub centre: Vector3<f64>,
    /// Extent of the mesh along `axis`, m: the length the levels are
    /// fractions of.
    pub length_m: f64,
    /// Largest distance of a loaded vertex from the axis through
    /// [`Body::centre`], m: the remap sample's radius.
    pub radius_m: f64,
}

impl Body {
    /// The cylinder of `(radial, height)` cells, of `material`.
    pub fn cylinder((radial, height): (usize, usize), material: Material) -> Self {
        let mesh = cylinder_mesh(HEIGHT_M, radial, height);
        let label = format!("{radial}x{height}");
        let fix = vec!["z<=0".parse().expect("a valid predicate")];
        let top = (0..mesh.positions.len() as u32)
            .filter(|&v| mesh.positions[v as usize][2] == HEIGHT_M)
            .collect();
        let report = MeshReport {
            source: format!("generated cylinder {label}"),
            ..MeshReport::default()
        };
        let body = Self::with_loaded_vertices(label, mesh, report, fix, top, material)
            .expect("the cylinder is fixed at its base and loaded on its top");
        // The exact axes (the centroids agree with them to rounding).
        Self {
            axis: Vector3::z(),
            lateral: Vector3::x(),
            centre: Vector3::new(0.0, 0.0, HEIGHT_M),
            radius_m: HEIGHT_M / 5.0,
            ..body
        }
    }

    /// A given mesh with its supports `fix`, its loaded vertices `top`
    /// (not all fixed) and `material`. The axis runs from the fixed
    /// vertices' centroid to the loaded ones'; the bend is along the
    /// coordinate axis most orthogonal to it, made orthogonal.
    pub fn with_loaded_vertices(
        label: String,
        mesh: TetMesh,
        report: MeshReport,
        fix: Vec<FixPredicate>,
        top: Vec<u32>,
        material: Material,
    ) -> anyhow::Result<Self> {
        let (fixed, _) = fixed_vertices(&mesh.positions, &fix, &report.unreferenced_vertices);
        let supports = centroid(&mesh.positions, (0..fixed.len()).filter(|&v| fixed[v]))
            .context("no vertex matches the supports (--fix)")?;
        let loaded: Vec<u32> = top.into_iter().filter(|&v| !fixed[v as usize]).collect();
        let centre = centroid(&mesh.positions, loaded.iter().map(|&v| v as usize))
            .context("no free vertex to load")?;
        let axis = (centre - supports)
            .try_normalize(1e-12)
            .context("the loaded vertices' centroid is the supports' centroid: no axis")?;
        let least = (0..3)
            .min_by(|&a, &b| axis[a].abs().total_cmp(&axis[b].abs()))
            .unwrap_or(0);
        let lateral = (Vector3::ith(least, 1.0) - axis * axis[least]).normalize();
        let along = mesh.positions.iter().map(|p| Vector3::from(*p).dot(&axis));
        let (lo, hi) = along.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
            (lo.min(x), hi.max(x))
        });
        let radius_m = loaded
            .iter()
            .map(|&v| {
                let r = Vector3::from(mesh.positions[v as usize]) - centre;
                (r - axis * r.dot(&axis)).norm()
            })
            .fold(0.0, f64::max);
        let mut is_loaded = vec![false; mesh.positions.len()];
        for &v in &loaded {
            is_loaded[v as usize] = true;
        }
        let faces = loaded_faces(&mesh.tets, &is_loaded);
        Ok(Self {
            radius_m,
            faces,
            label,
            mesh,
            report,
            fix,
            fixed,
            top: loaded,
            material,
            axis,
            lateral,
            centre,
            length_m: hi - lo,
        })
    }

    /// Nodal loads of `load` with total force (press, bend) or torque
    /// (twist) `magnitude`, N or N·m: the consistent loads of its traction
    /// over [`Body::faces`] ([`Body::face_loads`]), or equal shares per
    /// loaded vertex when they form no face.
    pub fn loads(&self, load: Load, magnitude: f64) -> Vec<[f64; 3]> {
        if !self.faces.is_empty() {
            return self.face_loads(&self.mesh.positions, &self.faces, p1_shape, load, magnitude);
        }
        let mut f = vec![[0.0; 3]; self.mesh.positions.len()];
        let share = magnitude / self.top.len() as f64;
        let polar: f64 = self
            .top
            .iter()
            .map(|&v| self.arm(&self.position(v)).norm_squared())
            .sum();
        for &v in &self.top {
            f[v as usize] = match load {
                Load::Press => (share * (PRESS_IMPERFECTION * self.lateral - self.axis)).into(),
                Load::Bend => (share * self.lateral).into(),
                Load::Twist => {
                    (self.axis.cross(&self.arm(&self.position(v))) * (magnitude / polar)).into()
                }
            };
        }
        f
    }

    /// The consistent nodal loads (N, `chart::face::nodal_loads`) of
    /// `load` over `faces` of the nodes `positions` (this body's loaded
    /// face, or a refinement of it, with the shape functions `shape`): the
    /// press a uniform traction `F (ε lateral − axis)/A` (`ε` the
    /// [`PRESS_IMPERFECTION`]), the bend `F lateral/A`, the twist
    /// `T (axis × r)/∫|r|² dA` (`r` the distance vector from the axis
    /// through [`Body::centre`]); `A` and `∫|r|² dA` over `faces` by the
    /// same quadrature, so the total force or torque is `magnitude`.
    pub fn face_loads<const K: usize>(
        &self,
        positions: &[[f64; 3]],
        faces: &[[u32; K]],
        shape: fn([f64; 3]) -> [f64; K],
        load: Load,
        magnitude: f64,
    ) -> Vec<[f64; 3]> {
        let (mut area, mut polar) = (0.0, 0.0);
        integrate(positions, faces, |_, x, _, w| {
            area += w;
            polar += w * self.arm(x).norm_squared();
        });
        let traction = |x: &Vector3<f64>| match load {
            Load::Press => (PRESS_IMPERFECTION * self.lateral - self.axis) * (magnitude / area),
            Load::Bend => self.lateral * (magnitude / area),
            Load::Twist => self.axis.cross(&self.arm(x)) * (magnitude / polar),
        };
        nodal_loads(positions, faces, shape, traction)
    }

    /// Rest position of vertex `v`, m.
    fn position(&self, v: u32) -> Vector3<f64> {
        Vector3::from(self.mesh.positions[v as usize])
    }

    /// The distance vector of `x` from the axis through [`Body::centre`], m.
    fn arm(&self, x: &Vector3<f64>) -> Vector3<f64> {
        let r = x - self.centre;
        r - self.axis * r.dot(&self.axis)
    }

    /// The hybrid's tensor-mass region: the tets whose centroid lies in the
    /// [`HYBRID_DYNAMIC_FRACTION`] of the length nearest the loaded end,
    /// and every tet with a loaded vertex (so the load acts on the
    /// tensor-mass region). That is where the rotations of the bend and the
    /// twist are largest (they grow from the supports to the loaded end)
    /// and where a tool would touch and cut.
    pub fn hybrid_dynamic_tets(&self) -> Vec<bool> {
        let end = self.centre.dot(&self.axis);
        let from = end - HYBRID_DYNAMIC_FRACTION * self.length_m;
        let mut loaded = vec![false; self.mesh.positions.len()];
        for &v in &self.top {
            loaded[v as usize] = true;
        }
        self.mesh
            .tets
            .iter()
            .map(|tet| {
                let centroid: Vector3<f64> = tet
                    .iter()
                    .map(|&v| Vector3::from(self.mesh.positions[v as usize]))
                    .sum::<Vector3<f64>>()
                    / 4.0;
                centroid.dot(&self.axis) >= from || tet.iter().any(|&v| loaded[v as usize])
            })
            .collect()
    }

    /// Every tet's material (the body is homogeneous).
    pub fn materials(&self) -> TetMaterials {
        TetMaterials::uniform(self.material, self.mesh.tets.len())
    }

    /// The linear FEM tip displacement ([`tip_m`]) per newton of `load`,
    /// m/N: what scales a load level to its magnitude.
    pub fn tip_per_newton_m(&self, load: Load) -> anyhow::Result<f64> {
        let unit = self.loads(load, 1.0);
        let (u_unit, _) = solve_loaded(
            &self.mesh.positions,
            &self.mesh.tets,
            &self.materials(),
            &self.fixed,
            &[],
            &unit,
        )?;
        Ok(tip_m(&unit, &u_unit))
    }

    /// The static problem of the body under `loads_n` (N per vertex).
    pub fn static_problem<'b>(
        &'b self,
        materials: &'b TetMaterials,
        loads_n: &'b [[f64; 3]],
    ) -> StaticProblem<'b> {
        StaticProblem {
            positions: &self.mesh.positions,
            tets: &self.mesh.tets,
            materials,
            fixed: &self.fixed,
            prescribed: &[],
            loads_n,
        }
    }
}

/// The top-face displacement measured for a load: the work-conjugate mean
/// `Σ f_v·u_v / Σ |f_v|` over the loaded vertices (m): the mean axial
/// shortening under press, the mean lateral deflection under bend, the
/// force-weighted mean tangential displacement under twist.
pub fn tip_m(loads: &[[f64; 3]], u: &[[f64; 3]]) -> f64 {
    let (mut work, mut total) = (0.0, 0.0);
    for (f, d) in loads.iter().zip(u) {
        let f = Vector3::from(*f);
        work += f.dot(&Vector3::from(*d));
        total += f.norm();
    }
    if total > 0.0 { work / total } else { 0.0 }
}
