//! The elastic force of the tensor-mass model (MODELS.md §1):
//! `f_i = −(K_ii u_i + Σ_j K_ij u_j)`, one pass over the vertices and one over
//! the edges (each edge stored once, `K_ji = K_ijᵀ`).

use nalgebra::Vector3;

use super::coupling::CouplingForces;
use super::law::{ElasticLaw, StvkForm};
use super::stvk::TetPass;
use super::stvk_terms::NonLinearTerms;
use crate::Real;
use crate::math::Dispatch;
use crate::table::span;

/// Everything the internal-force pass of a step reads, for the configured
/// [`ElasticLaw`] and optional incompressibility penalty.
pub(crate) struct InternalForces<'b, 'a, T: Real> {
    pub(crate) stiffness: Stiffness<'b, T>,
    pub(crate) tets: TetPass<'b, 'a, T>,
    /// The current split terms (empty slices when not provided; the model
    /// refuses [`StvkForm::Tensors`] then).
    pub(crate) terms: NonLinearTerms<'b, T>,
    pub(crate) law: ElasticLaw,
    /// Penalty `γ` (N) of Picinbono 2001 §3.2, `None` when off.
    pub(crate) incompressibility_n: Option<T>,
    /// The pre-computed region of a hybrid model, `None` for a model alone.
    pub(crate) coupling: Option<CouplingForces<'b, 'a, T>>,
}

impl<T: Real> InternalForces<'_, '_, T> {
    /// Overwrites `f` with the internal forces (N) of displacements `u` (m):
    /// the elastic force of the law, plus the incompressibility penalty, plus
    /// the coupled pre-computed region's force on the connection nodes. Each
    /// pass over the mesh runs through `dispatch` ([`Dispatch`]).
    pub(crate) fn forces(&self, dispatch: impl Dispatch, u: &[[T; 3]], f: &mut [[T; 3]]) {
        match self.law {
            ElasticLaw::StVenantKirchhoff(StvkForm::PerTet) => {
                f.fill([T::zero(); 3]);
                dispatch.run(
                    #[inline(always)]
                    || self.tets.add_stvk_forces(u, f),
                );
            }
            // One call site of the (always inlined) linear pass for both
            // laws that read the tensors: one copy of it in the firmware.
            law => {
                dispatch.run(
                    #[inline(always)]
                    || {
                        self.stiffness.elastic_forces(u, f);
                        if law == ElasticLaw::StVenantKirchhoff(StvkForm::Tensors) {
                            self.terms.add_forces(u, f);
                        }
                    },
                );
            }
        }
        if let Some(gamma_n) = self.incompressibility_n {
            dispatch.run(
                #[inline(always)]
                || self.tets.add_incompressibility(gamma_n, u, f),
            );
        }
        if let Some(coupling) = &self.coupling {
            coupling.add_forces(u, f);
        }
    }

    /// The elastic energy (J) of displacements `u` (m) under the law, plus
    /// a coupled pre-computed region's ([`CouplingForces::energy_j`]); the
    /// incompressibility penalty has no energy (its force is not a gradient)
    /// and is not included. `scratch` (N entries) receives the linear
    /// forces where the law needs them.
    pub(crate) fn energy_j(&self, u: &[[T; 3]], scratch: &mut [[T; 3]]) -> T {
        // ½ uᵀ K u = −½ Σ u·f with f = −K u.
        let mut quadratic = || {
            self.stiffness.elastic_forces(u, scratch);
            let twice: T = u
                .iter()
                .zip(&*scratch)
                .map(|(ui, fi)| vec3(ui).dot(&vec3(fi)))
                .fold(T::zero(), |sum, x| sum + x);
            -twice / T::of_f64(2.0)
        };
        let coupled = self.coupling.map_or(T::zero(), |c| c.energy_j(u));
        coupled
            + match self.law {
                ElasticLaw::Linear => quadratic(),
                ElasticLaw::StVenantKirchhoff(StvkForm::PerTet) => self.tets.stvk_energy_j(u),
                ElasticLaw::StVenantKirchhoff(StvkForm::Tensors) => {
                    quadratic() + self.terms.energy_j(u)
                }
            }
    }
}

/// The stiffness the force pass reads: current tensors and the CSR edge list.
pub(crate) struct Stiffness<'t, T> {
    pub(crate) vertex_tensors: &'t [[T; 9]],
    pub(crate) edge_tensors: &'t [[T; 9]],
    pub(crate) row_start: &'t [u32],
    pub(crate) column: &'t [u32],
}

/// `[T; 3]` as a vector.
pub(crate) fn vec3<T: Real>(v: &[T; 3]) -> Vector3<T> {
    Vector3::new(v[0], v[1], v[2])
}

/// `K x` for a row-major 3×3 `K`.
#[inline(always)]
fn mul<T: Real>(k: &[T; 9], x: &[T; 3]) -> [T; 3] {
    [
        k[0] * x[0] + k[1] * x[1] + k[2] * x[2],
        k[3] * x[0] + k[4] * x[1] + k[5] * x[2],
        k[6] * x[0] + k[7] * x[1] + k[8] * x[2],
    ]
}

/// `Kᵀ x` for a row-major 3×3 `K`.
#[inline(always)]
fn mul_transposed<T: Real>(k: &[T; 9], x: &[T; 3]) -> [T; 3] {
    [
        k[0] * x[0] + k[3] * x[1] + k[6] * x[2],
        k[1] * x[0] + k[4] * x[1] + k[7] * x[2],
        k[2] * x[0] + k[5] * x[1] + k[8] * x[2],
    ]
}

impl<T: Real> Stiffness<'_, T> {
    /// Overwrites `f` with the elastic forces (N) of displacements `u` (m).
    /// Loops: `N` vertices, then `E` edges (lengths validated at load and at
    /// state construction; an out-of-range access is skipped, never a panic).
    /// Always inlined, so that a [`Dispatch`] compiles it where it runs.
    #[inline(always)]
    pub(crate) fn elastic_forces(&self, u: &[[T; 3]], f: &mut [[T; 3]]) {
        for ((fi, ui), k) in f.iter_mut().zip(u).zip(self.vertex_tensors) {
            let ku = mul(k, ui);
            *fi = [-ku[0], -ku[1], -ku[2]];
        }
        for (i, pair) in self.row_start.windows(2).enumerate() {
            let (Some(&[start, end]), Some(ui)) = (pair.first_chunk::<2>(), u.get(i)) else {
                continue;
            };
            let range = span(start, end);
            let (Some(columns), Some(tensors)) =
                (self.column.get(range.clone()), self.edge_tensors.get(range))
            else {
                continue;
            };
            // A copy: `f`'s writes below cannot change it (without the copy,
            // the compiler reloads `u_i` at every edge).
            let ui = *ui;
            let mut fi = [T::zero(); 3];
            for (&j, k) in columns.iter().zip(tensors) {
                let (Some(uj), Some(fj)) = (u.get(j as usize), f.get_mut(j as usize)) else {
                    continue;
                };
                let a = mul(k, uj);
                let b = mul_transposed(k, &ui);
                fi = [fi[0] - a[0], fi[1] - a[1], fi[2] - a[2]];
                *fj = [fj[0] - b[0], fj[1] - b[1], fj[2] - b[2]];
            }
            if let Some(f) = f.get_mut(i) {
                *f = [f[0] + fi[0], f[1] + fi[1], f[2] + fi[2]];
            }
        }
    }
}
