//! The compressible neo-Hookean law ([`super::neo_hookean`]) on the
//! quadratic (P2, 10-node) tetrahedron: the converged truth of the
//! speed/accuracy study, where the P1 tet locks in bending on the study's
//! meshes. Nodes: the four corners, then the mid-edge nodes of the edges
//! [`EDGES`] (a mesh's P2 nodes: [`P2Mesh`]). Shape functions in the
//! barycentric coordinates `Λ`: corner `N_i = Λ_i (2Λ_i − 1)`, mid-edge
//! `N_ij = 4 Λ_i Λ_j`, gradients `∇N_i = (4Λ_i − 1) a_i`,
//! `∇N_ij = 4 (Λ_j a_i + Λ_i a_j)` (`a_i = ∇Λ_i`, the rest tet's, edges
//! straight with their nodes at the midpoints: the map is affine).
//!
//! Quadrature: the 4-point rule of degree 2 (`Λ = (α, β, β, β)` and its
//! permutations, `α = (5 + 3√5)/20`, `β = (5 − √5)/20`, weights `V₀/4`).
//! It integrates `∇N_j·∇N_k` (degree 2) exactly, so the element's small-
//! strain tangent is the exact linear-elastic P2 stiffness; the nonlinear
//! energy is integrated approximately, an error of the same order as the
//! P2 interpolation's (`O(h²)` in the energy), and the rule's stiffness has
//! no zero-energy modes (4 points × 6 strains = 24 = 30 DOFs − 6 rigid). The energy,
//! forces and tangent are the sums over the points ([`RestTet`]), so the
//! forces are exactly `−∂W/∂x` of the integrated energy.
//!
//! Folds: the quadrature points do not see an element folded over between
//! them. Under a strong press of the chart's 2×10 cylinder the Newton solve
//! settled, with `J > 0` at every point, in a state whose upper column had
//! passed through its own base by folding one layer of elements (`J =
//! −0.04` at a node): an equilibrium of the quadrature, not of the body.
//! [`NeoHookeanP2Tet::keeps_orientation`] also checks `J` at the ten nodes,
//! and [`super::newton::solve_neo_hookean_p2`] refuses an equilibrium that
//! fails it. `J` is a cubic in `Λ`, so these 14 samples reject such folds
//! without proving `J > 0` everywhere.

use nalgebra::{Matrix3, Vector3};

use super::element::shape_gradients;
use super::hyperelastic::{HyperelasticTet, RestTet, TetTangent};
use super::material::Material;
use super::neo_hookean::NeoHookeanLaw;

/// The corner pairs of the mid-edge nodes 4..10, in node order.
pub const EDGES: [[usize; 2]; 6] = [[0, 1], [1, 2], [0, 2], [0, 3], [1, 3], [2, 3]];

/// The 4-point rule's barycentric coordinates: `α` at one corner, `β` at
/// the others.
const ALPHA: f64 = 0.585_410_196_624_968_5;
const BETA: f64 = 0.138_196_601_125_010_5;

/// One P2 tet: its rest shape at the four quadrature points and its law.
#[derive(Clone, Copy, Debug)]
pub struct NeoHookeanP2Tet {
    /// The rest shape at each quadrature point (weight `V₀/4`).
    points: [RestTet<10>; 4],
    /// The law.
    law: NeoHookeanLaw,
}

impl NeoHookeanP2Tet {
    /// `F` at each quadrature point for nodes `x`.
    fn deformation_gradients(&self, x: &[[f64; 3]; 10]) -> [Matrix3<f64>; 4] {
        self.points.map(|p| p.deformation_gradient(x))
    }

    /// Whether `J > 0` at the four quadrature points and at the ten nodes of
    /// the element at `x` (module documentation: a fold between the points
    /// fails it). The map is quadratic, so `F` is affine in `Λ`:
    /// `F(Λ) = Σ Λ_i F_i` (`F_i` at corner `i`); the points' `F` sum to
    /// `Σ F_i` (`α + 3β = 1`), so `F_i = (F(point i) − β Σ F(points))/(α − β)`,
    /// and a mid-edge node's is the mean of its corners'.
    pub fn keeps_orientation(&self, x: &[[f64; 3]; 10]) -> bool {
        let at_points = self.deformation_gradients(x);
        let positive = |f: &Matrix3<f64>| NeoHookeanLaw::invert(f).is_some();
        if !at_points.iter().all(positive) {
            return false;
        }
        let sum: Matrix3<f64> = at_points.iter().sum();
        let corners = at_points.map(|f| (f - sum * BETA) / (ALPHA - BETA));
        corners.iter().all(positive)
            && EDGES
                .iter()
                .all(|&[i, j]| positive(&((corners[i] + corners[j]) * 0.5)))
    }
}

/// The P2 shape-function gradients at barycentric coordinates `l` of the
/// tet with P1 gradients `a`, 1/m.
fn p2_gradients(a: &[Vector3<f64>; 4], l: [f64; 4]) -> [Vector3<f64>; 10] {
    core::array::from_fn(|n| {
        if n < 4 {
            a[n] * (4.0 * l[n] - 1.0)
        } else {
            let [i, j] = EDGES[n - 4];
            (a[i] * l[j] + a[j] * l[i]) * 4.0
        }
    })
}

impl HyperelasticTet<10> for NeoHookeanP2Tet {
    /// Uses the corners `rest[..4]` (the mid-edge nodes are at the
    /// midpoints: [`P2Mesh`]).
    fn at_rest(rest: &[[f64; 3]; 10], material: &Material) -> Self {
        let (a, volume) = shape_gradients(&[rest[0], rest[1], rest[2], rest[3]]);
        let a = a.map(Vector3::from);
        let points = core::array::from_fn(|q| {
            let l = core::array::from_fn(|i| if i == q { ALPHA } else { BETA });
            RestTet::at_point(p2_gradients(&a, l), volume.abs() / 4.0)
        });
        Self {
            points,
            law: NeoHookeanLaw::new(material),
        }
    }

    fn energy_j(&self, x: &[[f64; 3]; 10]) -> f64 {
        self.points
            .iter()
            .zip(self.deformation_gradients(x))
            .map(|(p, f)| p.volume_m3() * self.law.density_pa(&f))
            .sum()
    }

    /// Non-finite where `J ≤ 0` at a point.
    fn forces_n(&self, x: &[[f64; 3]; 10]) -> [Vector3<f64>; 10] {
        let mut forces = [Vector3::zeros(); 10];
        for (p, f) in self.points.iter().zip(self.deformation_gradients(x)) {
            for (sum, fj) in forces.iter_mut().zip(p.forces_n(&self.law.pk1(&f))) {
                *sum += fj;
            }
        }
        forces
    }

    /// Non-finite where `J ≤ 0` at a point.
    fn tangent(&self, x: &[[f64; 3]; 10]) -> TetTangent<10> {
        let mut k = [[[[0.0; 3]; 3]; 10]; 10];
        for (p, f) in self.points.iter().zip(self.deformation_gradients(x)) {
            let Some((j, f_inv_t)) = NeoHookeanLaw::invert(&f) else {
                return [[[[f64::NAN; 3]; 3]; 10]; 10];
            };
            p.add_tangent(self.law.differential(j, f_inv_t), &mut k);
        }
        k
    }

    /// `J > 0` at every quadrature point.
    fn admissible(&self, x: &[[f64; 3]; 10]) -> bool {
        self.deformation_gradients(x)
            .iter()
            .all(|f| NeoHookeanLaw::invert(f).is_some())
    }
}

/// A P1 tet mesh raised to P2: the P1 vertices keep their indices, each
/// edge gets one mid-edge node (shared by the tets around it) after them.
#[derive(Clone, Debug)]
pub struct P2Mesh {
    /// Node positions (P1 vertices, then mid-edge nodes), m.
    pub positions: Vec<[f64; 3]>,
    /// 10-node tets: the P1 corners, then the nodes of [`EDGES`].
    pub tets: Vec<[u32; 10]>,
    /// The P1 vertices of each mid-edge node, node `vertex_count + e`.
    pub edges: Vec<[u32; 2]>,
}

impl P2Mesh {
    /// Raises the P1 mesh `positions`, `tets`.
    pub fn new(positions: &[[f64; 3]], tets: &[[u32; 4]]) -> Self {
        let n = positions.len();
        let mut index = std::collections::HashMap::new();
        let mut edges: Vec<[u32; 2]> = Vec::new();
        let tets = tets
            .iter()
            .map(|t| {
                let mut nodes = [0u32; 10];
                nodes[..4].copy_from_slice(t);
                for (node, [i, j]) in nodes[4..].iter_mut().zip(EDGES) {
                    let key = [t[i].min(t[j]), t[i].max(t[j])];
                    *node = *index.entry(key).or_insert_with(|| {
                        edges.push(key);
                        (n + edges.len() - 1) as u32
                    });
                }
                nodes
            })
            .collect();
        let mut all = positions.to_vec();
        all.extend(edges.iter().map(|e| {
            let [p, q] = e.map(|v| Vector3::from(positions[v as usize]));
            <[f64; 3]>::from((p + q) * 0.5)
        }));
        Self {
            positions: all,
            tets,
            edges,
        }
    }

    /// Per-node flags from per-vertex `flags`: a mid-edge node is flagged
    /// where both its vertices are (the fixed nodes of a fixed face: every
    /// edge of a face whose corners are fixed).
    pub fn node_flags(&self, flags: &[bool]) -> Vec<bool> {
        let mut all = flags.to_vec();
        all.extend(
            self.edges
                .iter()
                .map(|e| flags[e[0] as usize] && flags[e[1] as usize]),
        );
        all
    }

    /// Per-node dead loads from per-vertex loads `loads_n` (N): on the
    /// vertices as given, none on the mid-edge nodes (empty stays empty).
    pub fn node_loads(&self, loads_n: &[[f64; 3]]) -> Vec<[f64; 3]> {
        if loads_n.is_empty() {
            return Vec::new();
        }
        let mut all = loads_n.to_vec();
        all.resize(self.positions.len(), [0.0; 3]);
        all
    }
}
