//! The St Venant-Kirchhoff force computed tet by tet from the deformation
//! gradient (MODELS.md §4; Picinbono 2001 §3, eq. 10–11), and the
//! incompressibility penalty of Picinbono 2001 §3.2.
//!
//! With the rest shape-function gradients `a_j` (1/m) and rest volume `V`
//! (m³) of a tet and the displacements `u_j` (m) of its corners:
//! `∇U = Σ_j u_j a_jᵀ`, `F = I + ∇U`, Green strain `E = ½(FᵀF − I)`,
//! second Piola-Kirchhoff stress `S = λ tr(E) I + 2μE`, energy
//! `W = V (λ/2 (tr E)² + μ tr E²)` and force on corner `j`
//! `f_j = −∂W/∂u_j = −V F S a_j`.

use nalgebra::{Matrix3, Vector3};

use super::force::vec3;
use crate::Real;
use crate::table::TensorMassTable;
use crate::table::format::tet_face_vertices;

/// What the per-tet passes read: the table (tets, rest shapes and
/// positions) and which tets are alive.
pub(crate) struct TetPass<'b, 'a, T: Real> {
    pub(crate) table: &'b TensorMassTable<'a, T>,
    pub(crate) tet_alive: &'b [bool],
}

/// `∇U` of a tet from its corner displacements, `Σ_j u_j a_jᵀ`; with
/// `a_0 = −(a_1 + a_2 + a_3)` this is `Σ_{j≥1} (u_j − u_0) a_jᵀ`.
#[inline(always)]
fn displacement_gradient<T: Real>(u: &[Vector3<T>; 4], a: &[Vector3<T>; 4]) -> Matrix3<T> {
    let [u0, u1, u2, u3] = u;
    let [_, a1, a2, a3] = a;
    (u1 - u0) * a1.transpose() + (u2 - u0) * a2.transpose() + (u3 - u0) * a3.transpose()
}

/// `F` and `S` of a tet with displacement gradient `g` (see the module docs).
#[inline(always)]
fn deformation_and_stress<T: Real>(g: &Matrix3<T>, lambda: T, mu: T) -> (Matrix3<T>, Matrix3<T>) {
    let f = Matrix3::identity() + g;
    let half = T::of_f64(0.5);
    let e = (f.transpose() * f - Matrix3::identity()) * half;
    let s = Matrix3::from_diagonal_element(lambda * e.trace()) + e * (mu + mu);
    (f, s)
}

impl<T: Real> TetPass<'_, '_, T> {
    /// Calls `visit(t, tet, a, volume, u)` for every live tet `t` with its
    /// corners, rest gradients (1/m), rest volume (m³) and corner
    /// displacements (m). Bounded by the tet count; a tet whose references
    /// fall outside `u` is skipped (validated at load, never expected).
    #[inline(always)]
    fn for_each_live_tet(
        &self,
        u: &[[T; 3]],
        mut visit: impl FnMut([u32; 4], &[Vector3<T>; 4], T, [Vector3<T>; 4]),
    ) {
        let tets = self.table.tets().iter().zip(self.tet_alive);
        for (t, (&tet, &alive)) in tets.enumerate() {
            if !alive {
                continue;
            }
            let (Some((a, volume)), Some(u0), Some(u1), Some(u2), Some(u3)) = (
                self.table.tet_shape(t),
                u.get(tet[0] as usize),
                u.get(tet[1] as usize),
                u.get(tet[2] as usize),
                u.get(tet[3] as usize),
            ) else {
                continue;
            };
            visit(tet, &a, volume, [vec3(u0), vec3(u1), vec3(u2), vec3(u3)]);
        }
    }

    /// Overwrites `f` with the St Venant-Kirchhoff forces `f_j = −V F S a_j`
    /// (N) of displacements `u` (m), Lamé coefficients `lambda`, `mu` (Pa).
    pub(crate) fn stvk_forces(&self, lambda: T, mu: T, u: &[[T; 3]], f: &mut [[T; 3]]) {
        f.fill([T::zero(); 3]);
        self.for_each_live_tet(u, |tet, a, volume, corners| {
            let g = displacement_gradient(&corners, a);
            let (def, s) = deformation_and_stress(&g, lambda, mu);
            let p = def * s * volume;
            let [_, a1, a2, a3] = a;
            let (f1, f2, f3) = (p * a1, p * a2, p * a3);
            let f0 = -(f1 + f2 + f3);
            // f_j = −V P a_j: subtract each corner's `V P a_j`.
            for (&v, fj) in tet.iter().zip([f0, f1, f2, f3]) {
                if let Some(out) = f.get_mut(v as usize) {
                    *out = [out[0] - fj.x, out[1] - fj.y, out[2] - fj.z];
                }
            }
        });
    }

    /// The St Venant-Kirchhoff energy `Σ V (λ/2 (tr E)² + μ tr E²)` (J) of
    /// displacements `u` (m).
    pub(crate) fn stvk_energy_j(&self, lambda: T, mu: T, u: &[[T; 3]]) -> T {
        let mut energy = T::zero();
        self.for_each_live_tet(u, |_, a, volume, corners| {
            let g = displacement_gradient(&corners, a);
            let f = Matrix3::identity() + g;
            let e = (f.transpose() * f - Matrix3::identity()) * T::of_f64(0.5);
            let trace = e.trace();
            energy += volume * (lambda / T::of_f64(2.0) * trace * trace + mu * e.norm_squared());
        });
        energy
    }

    /// Adds the incompressibility penalty of Picinbono 2001 §3.2 to `f` (N):
    /// on each corner `p` of each live tet, a force along the unit normal of
    /// the face opposite `p`, of magnitude `γ ((V − V₀)/V₀)²` (`gamma_n`, N),
    /// pushing the corner towards that face when the tet has grown and away
    /// from it when it has shrunk, so the rest volume is restored.
    pub(crate) fn add_incompressibility(&self, gamma_n: T, u: &[[T; 3]], f: &mut [[T; 3]]) {
        let rest = self.table.rest_positions();
        self.for_each_live_tet(u, |tet, _, rest_volume, corners| {
            let mut x = [Vector3::zeros(); 4];
            for ((xj, &v), uj) in x.iter_mut().zip(&tet).zip(&corners) {
                if let Some(p) = rest.get(v as usize) {
                    *xj = vec3(p) + uj;
                }
            }
            let [x0, x1, x2, x3] = &x;
            let volume = (x1 - x0).dot(&(x2 - x0).cross(&(x3 - x0))) / T::of_f64(6.0);
            let change = (volume - rest_volume) / rest_volume;
            // sign(ΔV) (ΔV/V₀)², restoring: against ∂V/∂x_p when ΔV > 0.
            // A non-finite change propagates into `f`, and from there into
            // the state, where the step's divergence check faults on it.
            let magnitude = gamma_n * change * change.abs();
            for (face, &v) in tet_face_vertices([0, 1, 2, 3]).iter().zip(&tet) {
                let (Some(b), Some(c), Some(d)) = (
                    x.get(face[0] as usize),
                    x.get(face[1] as usize),
                    x.get(face[2] as usize),
                ) else {
                    continue;
                };
                // Outward normal of the face opposite p: −∂V/∂x_p direction.
                let outward = (c - b).cross(&(d - b));
                let length = outward.norm();
                let (Some(out), true) = (f.get_mut(v as usize), length > T::zero()) else {
                    continue;
                };
                let push = outward * (magnitude / length);
                *out = [out[0] + push.x, out[1] + push.y, out[2] + push.z];
            }
        });
    }
}
