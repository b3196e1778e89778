//! The elastic force of the tensor-mass model (MODELS.md §1):
//! `f_i = −(K_ii u_i + Σ_j K_ij u_j)`, one pass over the vertices and one over
//! the edges (each edge stored once, `K_ji = K_ijᵀ`, in the groups of
//! [`super::edges`]).

use nalgebra::Vector3;

use super::coupling::CouplingForces;
use super::edges::{EdgeTensors, add_edge_forces};
use super::law::{ElasticLaw, StvkForm};
use super::split::SplitBuffers;
use super::stvk::{Block, TetPass, TetTerms};
use super::stvk_terms::NonLinearTerms;
use crate::Real;
use crate::math::Dispatch;
use crate::math::block::mul;

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
    /// pass over the mesh runs through `dispatch` ([`Dispatch`]); with
    /// `split` and `dispatch.parts() > 1` the per-tet pass is cut into
    /// parts ([`super::split`]: the same bits).
    pub(crate) fn forces(
        &self,
        dispatch: impl Dispatch,
        split: Option<&mut SplitBuffers<'_, T>>,
        u: &[[T; 3]],
        f: &mut [[T; 3]],
    ) {
        match self.law {
            // The law closures are always inlined, so that they are
            // compiled inside the dispatched pass, for its CPU features.
            ElasticLaw::StVenantKirchhoff(StvkForm::PerTet) => {
                self.per_tet_forces(dispatch, split, u, f, |b| b.elastic());
            }
            ElasticLaw::NeoHookean => {
                self.per_tet_forces(dispatch, split, u, f, |b| b.neo_hookean());
            }
            ElasticLaw::Corotational => {
                self.per_tet_forces(
                    dispatch,
                    split,
                    u,
                    f,
                    #[inline(always)]
                    |b| b.corotational(),
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

    /// Overwrites `f` with the forces (N) of a per-tet `law` at
    /// displacements `u` (m), the pass run through `dispatch`, split into
    /// its parts with `split` when `dispatch` has more than one.
    #[inline(always)]
    fn per_tet_forces(
        &self,
        dispatch: impl Dispatch,
        split: Option<&mut SplitBuffers<'_, T>>,
        u: &[[T; 3]],
        f: &mut [[T; 3]],
        law: impl Fn(&Block<'_, T>) -> TetTerms<T> + Sync,
    ) {
        match split {
            Some(split) if dispatch.parts() > 1 => {
                split.tet_forces(dispatch, &self.tets, u, f, &law);
            }
            _ => {
                f.fill([T::zero(); 3]);
                dispatch.run(
                    #[inline(always)]
                    || self.tets.add_tet_forces(u, f, law),
                );
            }
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
                ElasticLaw::StVenantKirchhoff(StvkForm::PerTet) => {
                    self.tets.tet_energy_j(u, |b| b.elastic())
                }
                ElasticLaw::NeoHookean => self.tets.tet_energy_j(u, |b| b.neo_hookean()),
                ElasticLaw::Corotational => self.tets.tet_energy_j(u, |b| b.corotational()),
                ElasticLaw::StVenantKirchhoff(StvkForm::Tensors) => {
                    quadratic() + self.terms.energy_j(u)
                }
            }
    }
}

/// The stiffness the force pass reads: the current vertex and edge tensors.
pub(crate) struct Stiffness<'t, T> {
    pub(crate) vertex_tensors: &'t [[T; 9]],
    pub(crate) edges: EdgeTensors<'t, T>,
}

/// `[T; 3]` as a vector.
pub(crate) fn vec3<T: Real>(v: &[T; 3]) -> Vector3<T> {
    Vector3::new(v[0], v[1], v[2])
}

impl<T: Real> Stiffness<'_, T> {
    /// Overwrites `f` with the elastic forces (N) of displacements `u` (m).
    /// Loops: `N` vertices, then the edge groups ([`add_edge_forces`];
    /// lengths validated at load and at state construction; an out-of-range
    /// access is skipped, never a panic).
    /// Always inlined, so that a [`Dispatch`] compiles it where it runs.
    #[inline(always)]
    pub(crate) fn elastic_forces(&self, u: &[[T; 3]], f: &mut [[T; 3]]) {
        for ((fi, ui), k) in f.iter_mut().zip(u).zip(self.vertex_tensors) {
            let ku = mul(k, ui);
            *fi = [-ku[0], -ku[1], -ku[2]];
        }
        add_edge_forces(&self.edges, u, f);
    }
}
