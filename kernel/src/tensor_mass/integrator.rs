//! The explicit integrators of the tensor-mass model (MODELS.md §3) and the
//! per-vertex acceleration they share.

use nalgebra::Vector3;

use super::force::{InternalForces, vec3};
use super::split::SplitBuffers;
use super::state::VertexMode;
use crate::Real;
use crate::math::Dispatch;

/// An explicit time integrator. All four are conditionally stable: the
/// largest stable step is measured by `palpate dynamic critical-dt`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Integrator {
    /// Forward Euler: `u' = u + Δt v`, `v' = v + Δt a(u, v)`. One force
    /// evaluation; unstable for undamped oscillators at any step size
    /// (amplification `sqrt(1 + (ωΔt)²) > 1`), stable only with damping.
    ExplicitEuler,
    /// Semi-implicit (symplectic) Euler: `v' = v + Δt a(u, v)`,
    /// `u' = u + Δt v'`. One force evaluation; stable for `Δt < 2/ω_max`
    /// undamped, no energy drift.
    SymplecticEuler,
    /// Classical fourth-order Runge-Kutta on `(u, v)`: four force evaluations
    /// (RR-3510 §5 reports about 10× larger stable steps than Euler).
    Rk4,
    /// The central-difference scheme of Picinbono 2001 eq. (19), written with
    /// MODELS.md's damping sign (`m p̈ = −γ ṗ + f`, `γ = c·m`):
    /// `(1 + cΔt/2) u⁺ = Δt² (f + f_ext)/m + Δt² g + 2u − (1 − cΔt/2) u⁻`.
    /// One force evaluation; stable for `Δt < 2/ω_max`.
    CentralDifference,
}

impl Integrator {
    /// Every integrator, in documentation order.
    pub const ALL: [Integrator; 4] = [
        Integrator::ExplicitEuler,
        Integrator::SymplecticEuler,
        Integrator::Rk4,
        Integrator::CentralDifference,
    ];

    /// The CLI name: `euler`, `symplectic`, `rk4`, `central`.
    pub const fn name(self) -> &'static str {
        match self {
            Integrator::ExplicitEuler => "euler",
            Integrator::SymplecticEuler => "symplectic",
            Integrator::Rk4 => "rk4",
            Integrator::CentralDifference => "central",
        }
    }

    /// Force evaluations per step.
    pub const fn force_evaluations(self) -> u32 {
        match self {
            Integrator::Rk4 => 4,
            _ => 1,
        }
    }
}

/// Per-vertex data the acceleration needs besides the stiffness.
pub(crate) struct Loads<'t, T: Real> {
    pub(crate) masses_kg: &'t [T],
    pub(crate) modes: &'t [VertexMode],
    pub(crate) external_force_n: &'t [[T; 3]],
    pub(crate) gravity_m_s2: Vector3<T>,
}

impl<T: Real> Loads<'_, T> {
    /// Overwrites `a` with the accelerations (m/s²) at state `(u, v)`:
    /// `a_i = (f_i + f_ext,i)/m_i + g − c v_i` for a free vertex with positive
    /// mass (MODELS.md §3 with `γ_i = c m_i`, `c = damping_per_s`), zero for
    /// fixed, imposed and massless vertices (a vertex left without tets by a
    /// cut keeps still).
    #[expect(
        clippy::too_many_arguments,
        reason = "the state (u, v), its output, the damping and the force pass with its split scratch"
    )]
    pub(crate) fn accelerations(
        &self,
        dispatch: impl Dispatch,
        forces: &InternalForces<'_, '_, T>,
        split: Option<&mut SplitBuffers<'_, T>>,
        damping_per_s: T,
        u: &[[T; 3]],
        v: &[[T; 3]],
        a: &mut [[T; 3]],
    ) {
        forces.forces(dispatch, split, u, a);
        dispatch.run(
            #[inline(always)]
            || {
                let per_vertex = a
                    .iter_mut()
                    .zip(v)
                    .zip(self.masses_kg)
                    .zip(self.modes)
                    .zip(self.external_force_n);
                for ((((ai, vi), &m), &mode), fext) in per_vertex {
                    *ai = self
                        .acceleration(ai, vi, m, mode, fext, damping_per_s)
                        .into();
                }
            },
        );
    }

    /// One vertex's acceleration (m/s²) from its elastic force `f` (N),
    /// velocity `v` (m/s), mass `m` (kg), mode and external force `fext` (N):
    /// `(f + f_ext)/m + g − c v` for a free vertex with positive mass, zero
    /// otherwise.
    #[inline(always)]
    pub(crate) fn acceleration(
        &self,
        f: &[T; 3],
        v: &[T; 3],
        m: T,
        mode: VertexMode,
        fext: &[T; 3],
        damping_per_s: T,
    ) -> Vector3<T> {
        if mode == VertexMode::Free && m > T::zero() {
            (vec3(f) + vec3(fext)) * (T::one() / m) + self.gravity_m_s2 - vec3(v) * damping_per_s
        } else {
            Vector3::zeros()
        }
    }
}
