//! What the host's Newton static solver ([`super::newton`]) needs of a
//! hyperelastic tetrahedron of `N` nodes ([`HyperelasticTet`]: energy,
//! forces, tangent, admissibility; P1 `N = 4`, P2 `N = 10`) and the
//! kinematics every such element shares at one quadrature point
//! ([`RestTet`]): `F = Σ_j x_j a_jᵀ` (`a_j = ∇N_j` at rest at the point),
//! the force on node `j` from the first Piola-Kirchhoff stress `P`,
//! `f_j = −∂W/∂x_j = −w P a_j` (`w` the point's weight, a volume), and
//! the tangent stiffness `K_jk = −∂f_j/∂x_k` from the stress's
//! differential: for `dx_k = e_c`, `dF = e_c a_kᵀ`, column `c` of `K_jk`
//! is `w dP(dF) a_j`. The P1 tet is one point of weight `V₀` with the
//! constant gradients `∇Λ_j`; an element of several points sums them.

use nalgebra::{Matrix3, Vector3};

use super::element::shape_gradients;
use super::material::Material;

/// `N`×`N` blocks of 3×3, N/m: `K[j][k][a][c] = −∂f_{j,a}/∂x_{k,c}`.
pub type TetTangent<const N: usize = 4> = [[[[f64; 3]; 3]; N]; N];

/// A hyperelastic tetrahedron of `N` nodes for the Newton solver.
/// Positions `x` are the current nodes, m.
pub trait HyperelasticTet<const N: usize = 4> {
    /// The tet with rest nodes `rest` (m, positively oriented corners) of
    /// `material`.
    fn at_rest(rest: &[[f64; 3]; N], material: &Material) -> Self;
    /// Elastic energy `W` at `x`, J; `+∞` where the law is not defined
    /// (not [`HyperelasticTet::admissible`]).
    fn energy_j(&self, x: &[[f64; 3]; N]) -> f64;
    /// The elastic force on each node at `x`, N (admissible `x` only).
    fn forces_n(&self, x: &[[f64; 3]; N]) -> [Vector3<f64>; N];
    /// The tangent stiffness at `x` (symmetric; admissible `x` only).
    fn tangent(&self, x: &[[f64; 3]; N]) -> TetTangent<N>;
    /// Whether the law is defined at `x` (default: everywhere).
    fn admissible(&self, _x: &[[f64; 3]; N]) -> bool {
        true
    }
}

/// A tet's rest shape at one quadrature point of an `N`-node element:
/// the shape-function gradients there and the point's weight (the P1 tet:
/// its constant gradients and rest volume, [`RestTet::new`]).
#[derive(Clone, Copy, Debug)]
pub struct RestTet<const N: usize = 4> {
    /// `a_j = ∇N_j` at rest at the point, 1/m.
    gradients: [Vector3<f64>; N],
    /// The point's weight, m³ (the P1 tet: its rest volume `V₀`).
    volume_m3: f64,
}

impl RestTet {
    /// The rest shape of the P1 tet with corners `rest` (m).
    pub fn new(rest: &[[f64; 3]; 4]) -> Self {
        let (a, volume) = shape_gradients(rest);
        Self {
            gradients: a.map(Vector3::from),
            volume_m3: volume.abs(),
        }
    }
}

impl<const N: usize> RestTet<N> {
    /// The quadrature point with rest gradients `gradients` (1/m) and
    /// weight `volume_m3` (m³).
    pub fn at_point(gradients: [Vector3<f64>; N], volume_m3: f64) -> Self {
        Self {
            gradients,
            volume_m3,
        }
    }

    /// The point's weight (the P1 tet: rest volume `V₀`), m³.
    pub fn volume_m3(&self) -> f64 {
        self.volume_m3
    }

    /// `F = Σ_j x_j a_jᵀ` at current positions `x` (m).
    pub fn deformation_gradient(&self, x: &[[f64; 3]; N]) -> Matrix3<f64> {
        x.iter()
            .zip(&self.gradients)
            .map(|(xj, aj)| Vector3::from(*xj) * aj.transpose())
            .sum()
    }

    /// The node forces `f_j = −w P a_j` of the first Piola-Kirchhoff
    /// stress `p` (Pa), N.
    pub fn forces_n(&self, p: &Matrix3<f64>) -> [Vector3<f64>; N] {
        self.gradients.map(|a| -(p * a) * self.volume_m3)
    }

    /// The tangent stiffness of the stress differential `dp` (`dF ↦ dP`,
    /// Pa): column `c` of block `K_jk` is `w dP(e_c a_kᵀ) a_j`.
    pub fn tangent(&self, dp: impl Fn(&Matrix3<f64>) -> Matrix3<f64>) -> TetTangent<N> {
        let mut k = [[[[0.0; 3]; 3]; N]; N];
        self.add_tangent(dp, &mut k);
        k
    }

    /// Adds [`Self::tangent`] of `dp` to `k` (the points of one element
    /// summed).
    pub fn add_tangent(&self, dp: impl Fn(&Matrix3<f64>) -> Matrix3<f64>, k: &mut TetTangent<N>) {
        for (kk, ak) in self.gradients.iter().enumerate() {
            for c in 0..3 {
                let dp = dp(&(Vector3::ith(c, 1.0) * ak.transpose()));
                for (row, aj) in k.iter_mut().zip(&self.gradients) {
                    let column = dp * aj * self.volume_m3;
                    for (entry, value) in row[kk].iter_mut().zip(column.iter()) {
                        entry[c] += *value;
                    }
                }
            }
        }
    }
}
