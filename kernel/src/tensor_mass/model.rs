//! [`TensorMassModel`]: the table, the caller's state buffers and the step.

use core::fmt;

use nalgebra::Vector3;

use super::coupling::Coupling;
use super::edges::{EdgeGroup, EdgeTensors, lay_out};
use super::force::{InternalForces, Stiffness, vec3};
use super::integrator::{Integrator, Loads};
use super::law::{ElasticLaw, StvkForm};
use super::limits::{Limits, Watch};
use super::split::SplitBuffers;
use super::state::{Fault, StateBuffers, StateError, VertexMode};
use super::stvk::TetPass;
use super::stvk_terms::{NonLinearTerms, TermArraysMut};
use crate::Real;
use crate::math::{Dispatch, Portable};
use crate::table::{InterfaceTable, TensorMassTable};

/// Parameters of the dynamics that are not in the table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DynamicParams<T> {
    /// The elastic force: linear or St Venant-Kirchhoff.
    pub law: ElasticLaw,
    /// Incompressibility penalty `γ` (N) of Picinbono 2001 §3.2, `None`
    /// when off: on each tet corner, `γ ((V − V₀)/V₀)²` along the normal of
    /// the opposite face, restoring the rest volume.
    pub incompressibility_n: Option<T>,
    /// Mass-proportional damping `c` (1/s): `γ_i = c m_i` in
    /// `m_i p̈_i = −γ_i ṗ_i + f_i + f_ext,i` (MODELS.md §3).
    pub damping_per_s: T,
    /// Gravity acting on every free vertex, m/s².
    pub gravity_m_s2: Vector3<T>,
    /// Divergence bounds.
    pub limits: Limits<T>,
}

impl<T: Real> DynamicParams<T> {
    /// The linear law without the penalty or gravity, with mass-proportional
    /// damping `damping_per_s` (1/s) and a displacement bound
    /// `max_displacement_m` (m); the kinetic-energy bound is off. Other
    /// settings by the `with_*` methods:
    /// `DynamicParams::linear(c, d).with_law(law).with_gravity(g)`.
    pub fn linear(damping_per_s: T, max_displacement_m: T) -> Self {
        Self {
            law: ElasticLaw::Linear,
            incompressibility_n: None,
            damping_per_s,
            gravity_m_s2: Vector3::zeros(),
            limits: Limits {
                max_displacement_m,
                max_kinetic_energy_j: T::of_f64(f64::INFINITY),
            },
        }
    }

    /// The same with the elastic force `law`.
    #[must_use]
    pub fn with_law(self, law: ElasticLaw) -> Self {
        Self { law, ..self }
    }

    /// The same with the incompressibility penalty `γ` (N), `None` for off.
    #[must_use]
    pub fn with_incompressibility(self, incompressibility_n: Option<T>) -> Self {
        Self {
            incompressibility_n,
            ..self
        }
    }

    /// The same with gravity `gravity_m_s2` (m/s²) on every free vertex.
    #[must_use]
    pub fn with_gravity(self, gravity_m_s2: Vector3<T>) -> Self {
        Self {
            gravity_m_s2,
            ..self
        }
    }

    /// The same with the kinetic-energy bound `max_kinetic_energy_j` (J;
    /// `+∞` is off).
    #[must_use]
    pub fn with_max_kinetic_energy(self, max_kinetic_energy_j: T) -> Self {
        Self {
            limits: Limits {
                max_kinetic_energy_j,
                ..self.limits
            },
            ..self
        }
    }
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
    coupling: Option<Coupling<'a, 's, T>>,
    /// The split per-tet pass's storage ([`Self::with_split`]), `None`: never split.
    pub(super) split: Option<SplitBuffers<'s, T>>,
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
            (
                "incompressibility_n",
                params
                    .incompressibility_n
                    .is_none_or(|g| non_negative(g) && g.finite()),
            ),
        ];
        if let Some((name, _)) = checks.iter().find(|(_, ok)| !ok) {
            return Err(StateError::BadParameter { name });
        }
        if params.law == ElasticLaw::StVenantKirchhoff(StvkForm::Tensors) && !state.has_stvk_terms()
        {
            return Err(StateError::NoTermBuffers);
        }
        let mut model = Self {
            table,
            state,
            params,
            previous_valid: false,
            fault: None,
            coupling: None,
            split: None,
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
        lay_out(&self.table, s.edge_group_starts, s.edge_groups);
        s.masses_kg.copy_from_slice_checked(self.table.masses_kg());
        let terms = &mut s.stvk_terms;
        terms
            .vertex
            .copy_from_slice_checked(self.table.vertex_terms());
        terms.edge.copy_from_slice_checked(self.table.edge_terms());
        terms
            .triangle
            .copy_from_slice_checked(self.table.triangle_terms());
        terms.tet.copy_from_slice_checked(self.table.tet_terms());
        s.tet_alive.fill(true);
        s.live_tets.fill(0);
        for t in self.table.tet_indices() {
            for v in self.table.tet_vertices(t).into_iter().flatten() {
                if let Some(count) = s.live_tets.get_mut(v.get()) {
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

    /// The current edge tensor `K_ij` (row `i`, column `j`, row-major, N/m;
    /// `K_ji = K_ijᵀ`) of the edge between vertices `i` and `j`, `None` if
    /// there is none. Cost: a scan of the two rows' edge groups.
    pub fn edge_tensor(&self, i: u32, j: u32) -> Option<[T; 9]> {
        self.edge_tensors().block(i, j)
    }

    /// The current edge tensors as the force pass reads them: groups of 4
    /// edges of one row (`EdgeGroup`: the entries by lane, the other ends,
    /// padding lanes with a zero block and the row itself), row `i`'s
    /// groups `starts[i]..starts[i+1]`; returned as `(starts, groups)`. The
    /// groups past `starts[N]` are unused (zero).
    pub fn edge_groups(&self) -> (&[u32], &[EdgeGroup<T>]) {
        (self.state.edge_group_starts, self.state.edge_groups)
    }

    fn edge_tensors(&self) -> EdgeTensors<'_, T> {
        EdgeTensors {
            starts: self.state.edge_group_starts,
            groups: self.state.edge_groups,
        }
    }

    fn vertex_index(&self, vertex: u32) -> Result<usize, InputError> {
        let v = self
            .table
            .vertex(vertex)
            .ok_or(InputError::VertexOutOfRange { vertex })?;
        if self.state.modes.get(v.get()) == Some(&VertexMode::Fixed) {
            return Err(InputError::FixedVertex { vertex });
        }
        Ok(v.get())
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

    /// The internal forces (N) of any displacement field `u` (m) with the
    /// current stiffness and the configured law and penalty (energy and
    /// eigenvalue estimates, finite-difference checks).
    pub fn elastic_forces_of(&self, u: &[[T; 3]], out: &mut [[T; 3]]) {
        self.internal_forces().forces(Portable, None, u, out);
    }

    /// The elastic energy (J) of any displacement field `u` (m) under the
    /// configured law (the incompressibility penalty has none); `scratch`
    /// must hold one entry per vertex.
    pub fn elastic_energy_of(&self, u: &[[T; 3]], scratch: &mut [[T; 3]]) -> T {
        self.internal_forces().energy_j(u, scratch)
    }

    /// Couples the model to the pre-computed region that `interface`
    /// condenses (the hybrid model, RR-3510 §6.2): from now on every force
    /// evaluation adds that region's force on the connection nodes, the
    /// condensed stiffness on their displacements plus `passed_force_n` (one
    /// entry per connection node, N, which the caller updates between
    /// steps). The caller has checked that `interface` belongs to this
    /// model's table and that `passed_force_n` has `c` entries.
    pub(crate) fn couple(
        &mut self,
        interface: InterfaceTable<'a, T>,
        passed_force_n: &'s mut [[T; 3]],
    ) {
        self.coupling = Some(Coupling {
            interface,
            passed_force_n,
        });
    }

    /// The forces passed to the connection nodes by a coupled region (N),
    /// `None` for a model alone.
    pub(crate) fn passed_force_mut(&mut self) -> Option<&mut [[T; 3]]> {
        self.coupling.as_mut().map(|c| &mut *c.passed_force_n)
    }

    fn internal_forces(&self) -> InternalForces<'_, 'a, T> {
        let s = &self.state;
        internal_forces(
            &self.table,
            s.vertex_tensors,
            self.edge_tensors(),
            s.tet_alive,
            &s.stvk_terms,
            &self.params,
            self.coupling.as_ref(),
        )
    }

    /// Advances the state by `dt_s` seconds with `integrator`, then checks
    /// for divergence: a non-finite state or a bound exceeded puts the model
    /// in the fault state (returned as [`StepError::Faulted`]); the diverged
    /// state can then not be read.
    pub fn step(&mut self, integrator: Integrator, dt_s: T) -> Result<StepReport<T>, StepError> {
        self.step_with(Portable, integrator, dt_s)
    }

    /// [`Self::step`] with its passes over the mesh (force passes and the
    /// integrator's vertex updates) run through `dispatch`: a host's
    /// run-time CPU-feature dispatch ([`crate::math::dispatch`]). Same
    /// results as [`Self::step`].
    pub fn step_with(
        &mut self,
        dispatch: impl Dispatch,
        integrator: Integrator,
        dt_s: T,
    ) -> Result<StepReport<T>, StepError> {
        if let Some(fault) = self.fault {
            return Err(StepError::Faulted(fault));
        }
        if !(dt_s.finite() && dt_s > T::zero()) {
            return Err(StepError::BadTimeStep);
        }
        let outcome = match integrator {
            Integrator::ExplicitEuler | Integrator::SymplecticEuler => {
                let symplectic = integrator == Integrator::SymplecticEuler;
                self.step_euler(dispatch, dt_s, symplectic)
            }
            Integrator::Rk4 => self
                .step_rk4(dispatch, dt_s)
                .ok_or(StepError::NoRk4Scratch)?,
            Integrator::CentralDifference => self.step_central(dispatch, dt_s),
        };
        self.previous_valid = integrator == Integrator::CentralDifference;
        match outcome {
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

    /// Forward (`symplectic == false`) or semi-implicit Euler: one force
    /// pass, then one pass over the vertices that updates and checks each.
    fn step_euler(&mut self, dispatch: impl Dispatch, dt: T, symplectic: bool) -> Result<T, Fault> {
        let (forces, loads, s) = split(
            &self.table,
            &mut self.state,
            &self.params,
            self.coupling.as_ref(),
        );
        let (u, v, f) = (s.displacement_m, s.velocity_m_s, s.force_n);
        forces.forces(dispatch, self.split.as_mut(), u, f);
        let c = self.params.damping_per_s;
        let limits = &self.params.limits;
        // `move`: the scalars and `loads` live in the pass's registers, not
        // reloaded through the closure at every vertex.
        dispatch.run(
            #[inline(always)]
            move || {
                let mut watch = Watch::new(limits);
                let rows = u
                    .iter_mut()
                    .zip(v.iter_mut())
                    .zip(&*f)
                    .zip(loads.masses_kg)
                    .zip(loads.modes)
                    .zip(loads.external_force_n);
                for (vertex, (((((ui, vi), fi), &m), &mode), fext)) in rows.enumerate() {
                    if mode == VertexMode::Free {
                        let v_old = vec3(vi);
                        let v_new = v_old + loads.acceleration(fi, vi, m, mode, fext, c) * dt;
                        let step = if symplectic { v_new } else { v_old };
                        *ui = (vec3(ui) + step * dt).into();
                        *vi = v_new.into();
                    }
                    watch.visit(vertex, ui, vi, m);
                }
                watch.finish()
            },
        )
    }

    /// Classical RK4 on `y = (u, v)`, `ẏ = (v, a(u, v))`; `None` without
    /// RK4 scratch.
    fn step_rk4(&mut self, dispatch: impl Dispatch, dt: T) -> Option<Result<T, Fault>> {
        let n = self.state.displacement_m.len();
        let (forces, loads, s) = split(
            &self.table,
            &mut self.state,
            &self.params,
            self.coupling.as_ref(),
        );
        let mut chunks = s.rk4_scratch.chunks_exact_mut(n.max(1));
        let (Some(su), Some(sv), Some(du), Some(dv)) =
            (chunks.next(), chunks.next(), chunks.next(), chunks.next())
        else {
            return None;
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
            let c = self.params.damping_per_s;
            let split = self.split.as_mut();
            loads.accelerations(dispatch, &forces, split, c, su, sv, a);
            dispatch.run(
                #[inline(always)]
                || {
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
                },
            );
        }
        let sixth = dt / T::of_f64(6.0);
        let limits = &self.params.limits;
        Some(dispatch.run(
            #[inline(always)]
            || {
                let mut watch = Watch::new(limits);
                let rows = u
                    .iter_mut()
                    .zip(v.iter_mut())
                    .zip(&*du)
                    .zip(&*dv)
                    .zip(loads.modes)
                    .zip(loads.masses_kg);
                for (vertex, (((((ui, vi), dui), dvi), mode), &m)) in rows.enumerate() {
                    if *mode == VertexMode::Free {
                        *ui = (vec3(ui) + vec3(dui) * sixth).into();
                        *vi = (vec3(vi) + vec3(dvi) * sixth).into();
                    }
                    watch.visit(vertex, ui, vi, m);
                }
                watch.finish()
            },
        ))
    }

    /// Picinbono 2001 eq. (19), MODELS.md damping sign (see [`Integrator::CentralDifference`]).
    fn step_central(&mut self, dispatch: impl Dispatch, dt: T) -> Result<T, Fault> {
        let first = !self.previous_valid;
        let (forces, loads, s) = split(
            &self.table,
            &mut self.state,
            &self.params,
            self.coupling.as_ref(),
        );
        let (u, v, prev, f) = (
            s.displacement_m,
            s.velocity_m_s,
            s.previous_displacement_m,
            s.force_n,
        );
        forces.forces(dispatch, self.split.as_mut(), u, f);
        let c_half = self.params.damping_per_s * dt / T::of_f64(2.0);
        let two = T::of_f64(2.0);
        let limits = &self.params.limits;
        dispatch.run(
            #[inline(always)]
            || {
                let mut watch = Watch::new(limits);
                let rows = u
                    .iter_mut()
                    .zip(v.iter_mut())
                    .zip(prev.iter_mut())
                    .zip(&*f)
                    .zip(loads.modes)
                    .zip(loads.masses_kg)
                    .zip(loads.external_force_n);
                for (vertex, ((((((ui, vi), pi), fi), &mode), &m), fext)) in rows.enumerate() {
                    if mode == VertexMode::Free {
                        // Damping enters through the scheme's coefficients, not the acceleration.
                        let a = loads.acceleration(fi, vi, m, mode, fext, T::zero());
                        let u_now = vec3(ui);
                        // Start-up: u⁻ = u − Δt v (first step, or after another integrator).
                        let u_prev = if first {
                            u_now - vec3(vi) * dt
                        } else {
                            vec3(pi)
                        };
                        let u_next = (a * (dt * dt) + u_now * two - u_prev * (T::one() - c_half))
                            / (T::one() + c_half);
                        *vi = ((u_next - u_prev) / (two * dt)).into();
                        *pi = u_now.into();
                        *ui = u_next.into();
                    }
                    watch.visit(vertex, ui, vi, m);
                }
                watch.finish()
            },
        )
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

fn split<'b, 'a, T: Real>(
    table: &'b TensorMassTable<'a, T>,
    state: &'b mut StateBuffers<'_, T>,
    params: &DynamicParams<T>,
    coupling: Option<&'b Coupling<'a, '_, T>>,
) -> (InternalForces<'b, 'a, T>, Loads<'b, T>, Writable<'b, T>) {
    let forces = internal_forces(
        table,
        state.vertex_tensors,
        EdgeTensors {
            starts: state.edge_group_starts,
            groups: state.edge_groups,
        },
        state.tet_alive,
        &state.stvk_terms,
        params,
        coupling,
    );
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
    (forces, loads, writable)
}

/// The internal-force pass over the current tensors and live tets.
fn internal_forces<'b, 'a, T: Real>(
    table: &'b TensorMassTable<'a, T>,
    vertex_tensors: &'b [[T; 9]],
    edges: EdgeTensors<'b, T>,
    tet_alive: &'b [bool],
    terms: &'b TermArraysMut<'_, T>,
    params: &DynamicParams<T>,
    coupling: Option<&'b Coupling<'a, '_, T>>,
) -> InternalForces<'b, 'a, T> {
    let terms = NonLinearTerms {
        vertex_terms: terms.vertex,
        edge_row_start: table.edge_row_starts(),
        edge_column: table.edge_columns(),
        edge_terms: terms.edge,
        triangles: table.mesh_triangles(),
        triangle_terms: terms.triangle,
        tets: table.tets(),
        tet_terms: terms.tet,
        tet_alive,
    };
    InternalForces {
        stiffness: Stiffness {
            vertex_tensors,
            edges,
        },
        tets: TetPass { table, tet_alive },
        terms,
        law: params.law,
        incompressibility_n: params.incompressibility_n,
        coupling: coupling.map(Coupling::forces),
    }
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
