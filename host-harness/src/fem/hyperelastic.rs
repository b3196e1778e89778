//! What the host's Newton static solver ([`super::newton`]) needs of a
//! hyperelastic P1 tetrahedron ([`HyperelasticTet`]: energy, forces,
//! tangent, admissibility) and the kinematics every such element shares
//! ([`RestTet`]): `F = Σ_j x_j a_jᵀ` (`a_j = ∇Λ_j` at rest), the force on
//! vertex `j` from the first Piola-Kirchhoff stress `P`,
//! `f_j = −∂W/∂x_j = −V₀ P a_j`, and the tangent stiffness
//! `K_jk = −∂f_j/∂x_k` from the stress's differential: for `dx_k = e_c`,
//! `dF = e_c a_kᵀ`, column `c` of `K_jk` is `V₀ dP(dF) a_j`.

use nalgebra::{Matrix3, Vector3};

use super::element::shape_gradients;
use super::material::Material;

/// 4×4 blocks of 3×3, N/m: `K[j][k][a][c] = −∂f_{j,a}/∂x_{k,c}`.
pub type TetTangent = [[[[f64; 3]; 3]; 4]; 4];

/// A hyperelastic tetrahedron of the Newton solver. Positions `x` are the
/// current corners, m.
pub trait HyperelasticTet {
    /// The tet with rest corners `rest` (m, positively oriented) of
    /// `material`.
    fn at_rest(rest: &[[f64; 3]; 4], material: &Material) -> Self;
    /// Elastic energy `W` at `x`, J; `+∞` where the law is not defined
    /// (not [`HyperelasticTet::admissible`]).
    fn energy_j(&self, x: &[[f64; 3]; 4]) -> f64;
    /// The elastic force on each vertex at `x`, N (admissible `x` only).
    fn forces_n(&self, x: &[[f64; 3]; 4]) -> [Vector3<f64>; 4];
    /// The tangent stiffness at `x` (symmetric; admissible `x` only).
    fn tangent(&self, x: &[[f64; 3]; 4]) -> TetTangent;
    /// Whether the law is defined at `x` (default: everywhere).
    fn admissible(&self, _x: &[[f64; 3]; 4]) -> bool {
        true
    }
}

/// A tet's rest shape: shape-function gradients and rest volume.
#[derive(Clone, Copy, Debug)]
pub struct RestTet {
    /// `a_j = ∇Λ_j` at rest, 1/m.
    gradients: [Vector3<f64>; 4],
    /// Rest volume `V₀`, m³.
    volume_m3: f64,
}

impl RestTet {
    /// The rest shape of the corners `rest` (m).
    pub fn new(rest: &[[f64; 3]; 4]) -> Self {
        let (a, volume) = shape_gradients(rest);
        Self {
            gradients: a.map(Vector3::from),
            volume_m3: volume.abs(),
        }
    }

    /// Rest volume `V₀`, m³.
    pub fn volume_m3(&self) -> f64 {
        self.volume_m3
    }

    /// `F = Σ_j x_j a_jᵀ` at current positions `x` (m).
    pub fn deformation_gradient(&self, x: &[[f64; 3]; 4]) -> Matrix3<f64> {
        x.iter()
            .zip(&self.gradients)
            .map(|(xj, aj)| Vector3::from(*xj) * aj.transpose())
            .sum()
    }

    /// The vertex forces `f_j = −V₀ P a_j` of the first Piola-Kirchhoff
    /// stress `p` (Pa), N.
    pub fn forces_n(&self, p: &Matrix3<f64>) -> [Vector3<f64>; 4] {
        self.gradients.map(|a| -(p * a) * self.volume_m3)
    }

    /// The tangent stiffness of the stress differential `dp` (`dF ↦ dP`,
    /// Pa): column `c` of block `K_jk` is `V₀ dP(e_c a_kᵀ) a_j`.
    pub fn tangent(&self, dp: impl Fn(&Matrix3<f64>) -> Matrix3<f64>) -> TetTangent {
        let mut k = [[[[0.0; 3]; 3]; 4]; 4];
        for (kk, ak) in self.gradients.iter().enumerate() {
            for c in 0..3 {
                let dp = dp(&(Vector3::ith(c, 1.0) * ak.transpose()));
                for (row, aj) in k.iter_mut().zip(&self.gradients) {
                    let column = dp * aj * self.volume_m3;
                    for (entry, value) in row[kk].iter_mut().zip(column.iter()) {
                        entry[c] = *value;
                    }
                }
            }
        }
        k
    }
}
