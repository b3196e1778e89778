//! [`TensorMassModel`]: the table, the caller's state buffers and the step.

use core::fmt;

use nalgebra::Vector3;

use super::force::{Stiffness, vec3};
use super::integrator::{Integrator, Loads};
use super::state::{Fault, StateBuffers, StateError, VertexMode};
use crate::Real;
use crate::table::TensorMassTable;

/// Divergence bounds checked inside every step (MODELS.md §6: divergence is
/// detected before it reaches the output). `+∞` switches a bound off;
/// non-finite state is always a fault.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits<T> {
    /// Largest allowed displacement norm of any vertex, m.
    pub max_displacement_m: T,
    /// Largest allowed total kinetic energy, J.
    pub max_kinetic_energy_j: T,
}

/// Parameters of the dynamics that are not in the table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DynamicParams<T> {
    /// Mass-proportional damping `c` (1/s): `γ_i = c m_i` in
    /// `m_i p̈_i = −γ_i ṗ_i + f_i + f_ext,i` (MODELS.md §3).
    pub damping_per_s: T,
    /// Gravity acting on every free vertex, m/s².
    pub gravity_m_s2: Vector3<T>,
    /// Divergence bounds.
    pub limits: Limits<T>,
}

/// What a step did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepReport<T> {
    /// Kinetic energy after the step, `½ Σ m_i |v_i|²`, J.
    pub kinetic_energy_j: T,
    /// Force evaluations (passes over vertices and edges) the step took.
    pub force_evaluations: u32,
}

/// Why a step did not run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StepError {
    /// The model is in a fault state (this step's or an earlier one).
    Faulted(Fault),
    /// `dt` is not finite and positive.
    BadTimeStep,
    /// RK4 was asked for but the state has no RK4 scratch.
    NoRk4Scratch,
}

impl fmt::Display for StepError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Faulted(fault) => write!(f, "model faulted: {fault}"),
            Self::BadTimeStep => f.write_str("time step must be finite and > 0 s"),
            Self::NoRk4Scratch => f.write_str("RK4 needs rk4_scratch of 4N entries"),
        }
    }
}

impl core::error::Error for StepError {}

/// Why a per-vertex input was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InputError {
    /// No such vertex.
    VertexOutOfRange {
        /// The vertex index given.
        vertex: u32,
    },
    /// The vertex is fixed by the table.
    FixedVertex {
        /// The vertex index given.
        vertex: u32,
    },
    /// A non-finite value.
    NonFinite {
        /// The vertex index given.
        vertex: u32,
    },
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::VertexOutOfRange { vertex } => write!(f, "vertex {vertex} does not exist"),
            Self::FixedVertex { vertex } => write!(f, "vertex {vertex} is fixed"),
            Self::NonFinite { vertex } => write!(f, "vertex {vertex}: non-finite input"),
        }
    }
}

impl core::error::Error for InputError {}

/// The dynamic tensor-mass model: a validated table, the caller's state
/// buffers, and the parameters (RR-3510 §5, MODELS.md §3).
pub struct TensorMassModel<'a, 's, T: Real> {
    pub(super) table: TensorMassTable<'a, T>,
    pub(super) state: StateBuffers<'s, T>,
    params: DynamicParams<T>,
    previous_valid: bool,
    fault: Option<Fault>,
}

impl<'a, 's, T: Real> TensorMassModel<'a, 's, T> {
    /// Checks the buffer lengths and parameters, then [`Self::reset`]s the
    /// state to rest.
    pub fn new(
        table: TensorMassTable<'a, T>,
        state: StateBuffers<'s, T>,
        params: DynamicParams<T>,
    ) -> Result<Self, StateError> {
        state.check(&table)?;
        let non_negative = |x: T| x >= T::zero(); // false for NaN
        let checks = [
            (
                "damping_per_s",
                non_negative(params.damping_per_s) && params.damping_per_s.finite(),
            ),
            (
                "gravity_m_s2",
                params.gravity_m_s2.iter().all(|g| g.finite()),
            ),
            (
                "max_displacement_m",
                non_negative(params.limits.max_displacement_m),
            ),
            (
                "max_kinetic_energy_j",
                non_negative(params.limits.max_kinetic_energy_j),
            ),
        ];
        if let Some((name, _)) = checks.iter().find(|(_, ok)| !ok) {
            return Err(StateError::BadParameter { name });
        }
        let mut model = Self {
            table,
            state,
            params,
            previous_valid: false,
            fault: None,
        };
        model.reset();
        Ok(model)
    }

    /// Back to rest: the table's tensors and masses, every tet alive, zero
    /// displacement, velocity and external force, table-fixed vertices fixed
    /// and all others free, fault cleared.
    pub fn reset(&mut self) {
        let s = &mut self.state;
        s.vertex_tensors
            .copy_from_slice_checked(self.table.vertex_tensors());
        s.edge_tensors
            .copy_from_slice_checked(self.table.edge_tensors());
        s.masses_kg.copy_from_slice_checked(self.table.masses_kg());
        s.tet_alive.fill(true);
        s.live_tets.fill(0);
        for tet in self.table.tets() {
            for &v in tet {
                if let Some(count) = s.live_tets.get_mut(v as usize) {
                    *count += 1;
                }
            }
        }
        for (v, mode) in s.modes.iter_mut().enumerate() {
            *mode = if self.table.is_fixed(v as u32) {
                VertexMode::Fixed
            } else {
                VertexMode::Free
            };
        }
        for buffer in [
            &mut *s.displacement_m,
            &mut *s.velocity_m_s,
            &mut *s.previous_displacement_m,
            &mut *s.external_force_n,
        ] {
            buffer.fill([T::zero(); 3]);
        }
        self.previous_valid = false;
        self.fault = None;
    }

    /// The table.
    pub fn table(&self) -> &TensorMassTable<'a, T> {
        &self.table
    }

    /// The parameters.
    pub fn params(&self) -> &DynamicParams<T> {
        &self.params
    }

    /// The fault, if the model is in the fault state.
    pub fn fault(&self) -> Option<Fault> {
        self.fault
    }

    /// Displacements from rest, m, vertex order; refused in the fault state.
    pub fn displacements_m(&self) -> Result<&[[T; 3]], Fault> {
        self.fault.map_or(Ok(&*self.state.displacement_m), Err)
    }

    /// Velocities, m/s, vertex order; refused in the fault state.
    pub fn velocities_m_s(&self) -> Result<&[[T; 3]], Fault> {
        self.fault.map_or(Ok(&*self.state.velocity_m_s), Err)
    }

    /// Current lumped masses, kg.
    pub fn masses_kg(&self) -> &[T] {
        self.state.masses_kg
    }

    /// `false` for every removed tet.
    pub fn tet_alive(&self) -> &[bool] {
        self.state.tet_alive
    }

    /// How each vertex moves.
    pub fn modes(&self) -> &[VertexMode] {
        self.state.modes
    }

    /// Current vertex tensors `K_ii` (row-major, N/m).
    pub fn vertex_tensors(&self) -> &[[T; 9]] {
        self.state.vertex_tensors
    }

    /// Current edge tensors `K_ij`, `i < j` (row-major, N/m).
    pub fn edge_tensors(&self) -> &[[T; 9]] {
        self.state.edge_tensors
    }

    fn vertex_index(&self, vertex: u32) -> Result<usize, InputError> {
        let v = vertex as usize;
        if v >= self.state.modes.len() {
            return Err(InputError::VertexOutOfRange { vertex });
        }
        if self.state.modes.get(v) == Some(&VertexMode::Fixed) {
            return Err(InputError::FixedVertex { vertex });
        }
        Ok(v)
    }

    /// The index of a free or imposed `vertex` taking the finite input `value`.
    fn input_vertex(&self, vertex: u32, value: &Vector3<T>) -> Result<usize, InputError> {
        if !value.iter().all(|x| x.finite()) {
            return Err(InputError::NonFinite { vertex });
        }
        self.vertex_index(vertex)
    }

    /// Sets the external force on `vertex`, N (replaces the previous one).
    pub fn set_external_force(
        &mut self,
        vertex: u32,
        force_n: Vector3<T>,
    ) -> Result<(), InputError> {
        let v = self.input_vertex(vertex, &force_n)?;
        if let Some(f) = self.state.external_force_n.get_mut(v) {
            *f = force_n.into();
        }
        Ok(())
    }

    /// Sets the velocity of a free `vertex`, m/s (initial conditions).
    pub fn set_velocity(
        &mut self,
        vertex: u32,
        velocity_m_s: Vector3<T>,
    ) -> Result<(), InputError> {
        let v = self.input_vertex(vertex, &velocity_m_s)?;
        if let Some(vel) = self.state.velocity_m_s.get_mut(v) {
            *vel = velocity_m_s.into();
        }
        Ok(())
    }

    /// Zeroes every external force.
    pub fn clear_external_forces(&mut self) {
        self.state.external_force_n.fill([T::zero(); 3]);
    }

    /// Holds `vertex` at displacement `displacement_m` (m) with zero velocity
    /// from now on (tool contact, coupling), until [`Self::release`].
    pub fn impose(&mut self, vertex: u32, displacement_m: Vector3<T>) -> Result<(), InputError> {
        let v = self.input_vertex(vertex, &displacement_m)?;
        let s = &mut self.state;
        if let (Some(mode), Some(u), Some(p), Some(vel)) = (
            s.modes.get_mut(v),
            s.displacement_m.get_mut(v),
            s.previous_displacement_m.get_mut(v),
            s.velocity_m_s.get_mut(v),
        ) {
            *mode = VertexMode::Imposed;
            *u = displacement_m.into();
            *p = *u;
            *vel = [T::zero(); 3];
        }
        Ok(())
    }

    /// Lets an imposed vertex move freely again (from rest velocity).
    pub fn release(&mut self, vertex: u32) -> Result<(), InputError> {
        let v = self.vertex_index(vertex)?;
        if let Some(mode) = self.state.modes.get_mut(v) {
            *mode = VertexMode::Free;
        }
        Ok(())
    }

    /// Writes the elastic forces of the current state into `out` (N, one per
    /// vertex; a shorter `out` gets the first vertices only). The force an
    /// imposed vertex's holder applies is the negative of its entry.
    pub fn elastic_forces_n(&self, out: &mut [[T; 3]]) {
        self.elastic_forces_of(self.state.displacement_m, out);
    }

    /// The elastic forces `−K u` (N) of any displacement field `u` (m) with
    /// the current stiffness (energy and eigenvalue estimates).
    pub fn elastic_forces_of(&self, u: &[[T; 3]], out: &mut [[T; 3]]) {
        self.stiffness().elastic_forces(u, out);
    }

    fn stiffness(&self) -> Stiffness<'_, T> {
        Stiffness {
            vertex_tensors: self.state.vertex_tensors,
            edge_tensors: self.state.edge_tensors,
            row_start: self.table.edge_row_starts(),
            column: self.table.edge_columns(),
        }
    }

    /// Advances the state by `dt_s` seconds with `integrator`, then checks
    /// for divergence: a non-finite state or a bound exceeded puts the model
    /// in the fault state (returned as [`StepError::Faulted`]); the diverged
    /// state can then not be read.
    pub fn step(&mut self, integrator: Integrator, dt_s: T) -> Result<StepReport<T>, StepError> {
        if let Some(fault) = self.fault {
            return Err(StepError::Faulted(fault));
        }
        if !(dt_s.finite() && dt_s > T::zero()) {
            return Err(StepError::BadTimeStep);
        }
        match integrator {
            Integrator::ExplicitEuler | Integrator::SymplecticEuler => {
                self.step_euler(dt_s, integrator == Integrator::SymplecticEuler)
            }
            Integrator::Rk4 => self.step_rk4(dt_s)?,
            Integrator::CentralDifference => self.step_central(dt_s),
        }
        self.previous_valid = integrator == Integrator::CentralDifference;
        match self.check() {
            Ok(kinetic_energy_j) => Ok(StepReport {
                kinetic_energy_j,
                force_evaluations: integrator.force_evaluations(),
            }),
            Err(fault) => {
                self.fault = Some(fault);
                Err(StepError::Faulted(fault))
            }
        }
    }

    /// Forward (`symplectic == false`) or semi-implicit Euler.
    fn step_euler(&mut self, dt: T, symplectic: bool) {
        let (stiffness, loads, s) = split(&self.table, &mut self.state, &self.params);
        let (u, v, a) = (s.displacement_m, s.velocity_m_s, s.force_n);
        loads.accelerations(&stiffness, self.params.damping_per_s, u, v, a);
        for (((ui, vi), ai), mode) in u.iter_mut().zip(v.iter_mut()).zip(&*a).zip(loads.modes) {
            if *mode != VertexMode::Free {
                continue;
            }
            let v_old = vec3(vi);
            let v_new = v_old + vec3(ai) * dt;
            let step = if symplectic { v_new } else { v_old };
            *ui = (vec3(ui) + step * dt).into();
            *vi = v_new.into();
        }
    }

    /// Classical RK4 on `y = (u, v)`, `ẏ = (v, a(u, v))`.
    fn step_rk4(&mut self, dt: T) -> Result<(), StepError> {
        let n = self.state.displacement_m.len();
        let (stiffness, loads, s) = split(&self.table, &mut self.state, &self.params);
        let mut chunks = s.rk4_scratch.chunks_exact_mut(n.max(1));
        let (Some(su), Some(sv), Some(du), Some(dv)) =
            (chunks.next(), chunks.next(), chunks.next(), chunks.next())
        else {
            return Err(StepError::NoRk4Scratch);
        };
        let (u, v, a) = (s.displacement_m, s.velocity_m_s, s.force_n);
        su.copy_from_slice_checked(u);
        sv.copy_from_slice_checked(v);
        du.fill([T::zero(); 3]);
        dv.fill([T::zero(); 3]);
        let half = dt / T::of_f64(2.0);
        let stages = [
            (T::one(), half),
            (T::of_f64(2.0), half),
            (T::of_f64(2.0), dt),
            (T::one(), T::zero()),
        ];
        for (weight, next) in stages {
            loads.accelerations(&stiffness, self.params.damping_per_s, su, sv, a);
            let rows = su
                .iter_mut()
                .zip(sv.iter_mut())
                .zip(du.iter_mut())
                .zip(dv.iter_mut());
            for ((((sui, svi), dui), dvi), ((ui, vi), ai)) in
                rows.zip(u.iter().zip(v.iter()).zip(&*a))
            {
                let (ku, kv) = (vec3(svi), vec3(ai));
                *dui = (vec3(dui) + ku * weight).into();
                *dvi = (vec3(dvi) + kv * weight).into();
                *sui = (vec3(ui) + ku * next).into();
                *svi = (vec3(vi) + kv * next).into();
            }
        }
        let sixth = dt / T::of_f64(6.0);
        for ((((ui, vi), dui), dvi), mode) in u
            .iter_mut()
            .zip(v.iter_mut())
            .zip(&*du)
            .zip(&*dv)
            .zip(loads.modes)
        {
            if *mode == VertexMode::Free {
                *ui = (vec3(ui) + vec3(dui) * sixth).into();
                *vi = (vec3(vi) + vec3(dvi) * sixth).into();
            }
        }
        Ok(())
    }

    /// Picinbono 2001 eq. (19), MODELS.md damping sign (see [`Integrator::CentralDifference`]).
    fn step_central(&mut self, dt: T) {
        let first = !self.previous_valid;
        let (stiffness, loads, s) = split(&self.table, &mut self.state, &self.params);
        let (u, v, prev, a) = (
            s.displacement_m,
            s.velocity_m_s,
            s.previous_displacement_m,
            s.force_n,
        );
        // Damping enters through the scheme's coefficients, not the acceleration.
        loads.accelerations(&stiffness, T::zero(), u, v, a);
        let c_half = self.params.damping_per_s * dt / T::of_f64(2.0);
        let two = T::of_f64(2.0);
        let rows = u
            .iter_mut()
            .zip(v.iter_mut())
            .zip(prev.iter_mut())
            .zip(&*a)
            .zip(loads.modes);
        for ((((ui, vi), pi), ai), mode) in rows {
            if *mode != VertexMode::Free {
                continue;
            }
            let u_now = vec3(ui);
            // Start-up: u⁻ = u − Δt v (first step, or after another integrator).
            let u_prev = if first {
                u_now - vec3(vi) * dt
            } else {
                vec3(pi)
            };
            let u_next = (vec3(ai) * (dt * dt) + u_now * two - u_prev * (T::one() - c_half))
                / (T::one() + c_half);
            *vi = ((u_next - u_prev) / (two * dt)).into();
            *pi = u_now.into();
            *ui = u_next.into();
        }
    }

    /// Kinetic energy, or the first divergence found (MODELS.md §6).
    fn check(&self) -> Result<T, Fault> {
        let limits = &self.params.limits;
        let max_u2 = limits.max_displacement_m * limits.max_displacement_m;
        let mut twice_kinetic = T::zero();
        let s = &self.state;
        let rows = s
            .displacement_m
            .iter()
            .zip(&*s.velocity_m_s)
            .zip(&*s.masses_kg);
        for (vertex, ((u, v), &m)) in rows.enumerate() {
            let vertex = vertex as u32;
            let (u, v) = (vec3(u), vec3(v));
            let (u2, v2) = (u.norm_squared(), v.norm_squared());
            if !(u2.finite() && v2.finite()) {
                return Err(Fault::NonFinite { vertex });
            }
            if u2 > max_u2 {
                return Err(Fault::DisplacementBound { vertex });
            }
            twice_kinetic += m * v2;
        }
        let kinetic = twice_kinetic / T::of_f64(2.0);
        if !kinetic.finite() || kinetic > limits.max_kinetic_energy_j {
            return Err(Fault::KineticEnergyBound);
        }
        Ok(kinetic)
    }
}

/// The state's fields split into what the force pass reads and what the
/// integrator writes (disjoint borrows).
struct Writable<'b, T> {
    displacement_m: &'b mut [[T; 3]],
    velocity_m_s: &'b mut [[T; 3]],
    previous_displacement_m: &'b mut [[T; 3]],
    force_n: &'b mut [[T; 3]],
    rk4_scratch: &'b mut [[T; 3]],
}

fn split<'b, T: Real>(
    table: &'b TensorMassTable<'_, T>,
    state: &'b mut StateBuffers<'_, T>,
    params: &DynamicParams<T>,
) -> (Stiffness<'b, T>, Loads<'b, T>, Writable<'b, T>) {
    let stiffness = Stiffness {
        vertex_tensors: state.vertex_tensors,
        edge_tensors: state.edge_tensors,
        row_start: table.edge_row_starts(),
        column: table.edge_columns(),
    };
    let loads = Loads {
        masses_kg: state.masses_kg,
        modes: state.modes,
        external_force_n: state.external_force_n,
        gravity_m_s2: params.gravity_m_s2,
    };
    let writable = Writable {
        displacement_m: state.displacement_m,
        velocity_m_s: state.velocity_m_s,
        previous_displacement_m: state.previous_displacement_m,
        force_n: state.force_n,
        rk4_scratch: state.rk4_scratch,
    };
    (stiffness, loads, writable)
}

/// `copy_from_slice` without its length panic: copies the common prefix
/// (lengths are equal by construction, checked in [`StateBuffers::check`]).
trait CopyChecked<E> {
    fn copy_from_slice_checked(&mut self, src: &[E]);
}

impl<E: Copy> CopyChecked<E> for [E] {
    fn copy_from_slice_checked(&mut self, src: &[E]) {
        for (d, s) in self.iter_mut().zip(src) {
            *d = *s;
        }
    }
}
