//! The dynamic tensor-mass model as a tissue for the haptic loop
//! (RR-3510 §5; Cotin 1999 §4; MODELS.md §6).
//!
//! Coupling (imposed displacement, Cotin 1999 §4: "the vertices of the
//! intersected triangle receive the displacement of the intersection
//! point"): at each physics update, the contact triangle's movable vertices
//! are held ([`TensorMassModel::impose`]) and translated by `gap · n`, so the
//! triangle keeps its orientation and the contact point (any barycentric
//! weights) lands on the tool sphere. The model is then stepped and the
//! surface re-binned ([`DeformingSurface::rebin`]). The tool is frictionless:
//! the force on the hand is the normal part of the elastic force the held
//! vertices resist, `F = (n · Σ_i f_i) n`. Vertices no longer under a
//! contact are released at the next update.
//!
//! Force between physics updates (extrapolation from the local contact
//! stiffness and the tool's motion, Cotin 1999 §6): each tick sends
//! `F = (n · F_update − α k · gap) n`, where `gap` is the tool's normal
//! motion since the last update (measured against that update's surface,
//! zero right after it) and `k = n · K_c n`, `K_c = Σ_{i,j} K_ij` over the
//! triangle's movable vertices, from the model's current vertex and edge
//! tensors (RR-3510 §5.1). With the rest of the mesh frozen, translating
//! the held vertices by `gap · n` changes the force by exactly
//! `−K_c n · gap`, so `α = 1` ([`Extrapolation::Instantaneous`]) is the
//! model's own force until the next step (exact for the linear law; for St
//! Venant-Kirchhoff `K` is the rest tangent). But the free vertices then
//! relax during the step, so the instantaneous stiffness overshoots and the
//! force drops at every update (a saw-tooth at the physics rate).
//! [`Extrapolation::Secant`] (the default) scales it by the ratio the
//! tissue showed over the last period, `α = n · ΔF / (−k · gap)` clamped to
//! `[0, 1]` (kept when the tool moved less than [`SECANT_MIN_MOTION_M`]; a
//! new contact starts from zero force at `α = 1`), and spreads what an
//! update corrects over the next period: the difference between the force
//! sent on the last tick before the update and the update's force decays
//! linearly to zero over as many ticks as the last period had (`1 − j/k`
//! of it at the `j`-th of `k` ticks). The force
//! the device receives is then continuous across updates by construction;
//! the price is that a correction arrives over one physics period instead
//! of at once.

use core::fmt;

use nalgebra::Vector3;

use super::contact::{Supports, SurfaceGeometry};
use super::deforming::{DeformingSurface, NonFinitePosition, SurfaceBufferError, SurfaceBuffers};
use super::tissue::{ContactTarget, Refusal, Solved, Tissue};
use crate::Real;
use crate::tensor_mass::{Integrator, StepError, StepReport, TensorMassModel};

/// Least normal tool motion over a physics period, m, for a new secant
/// stiffness ratio (below it the ratio is noise: kept from before).
pub const SECANT_MIN_MOTION_M: f64 = 1e-6;

/// How the force is extrapolated between physics updates (module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Extrapolation {
    /// `K_c`: the model's force with the rest of the mesh frozen.
    Instantaneous,
    /// `α K_c`, `α` the secant ratio of the last period, and each update's
    /// correction spread over the next period.
    #[default]
    Secant,
}

/// How the dynamic model is stepped at each physics update.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhysicsConfig<T> {
    /// The force between updates.
    pub extrapolation: Extrapolation,
    /// The explicit integrator.
    pub integrator: Integrator,
    /// Step, s (finite, > 0; below the integrator's critical step).
    pub dt_s: T,
    /// Steps per physics update (≥ 1; the physics period is
    /// `substeps · dt_s`).
    pub substeps: u32,
}

/// Why a dynamic tissue was not built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DynamicTissueError {
    /// A surface buffer has the wrong length.
    Surface(SurfaceBufferError),
    /// The force scratch buffer is not one entry per vertex.
    ForceBuffer {
        /// Vertices of the table.
        expected: usize,
        /// Entries given.
        found: usize,
    },
    /// `dt_s` not finite and positive, or `substeps` zero.
    BadPhysics,
}

impl fmt::Display for DynamicTissueError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Surface(e) => e.fmt(f),
            Self::ForceBuffer { expected, found } => {
                write!(f, "force buffer: length {found}, expected {expected}")
            }
            Self::BadPhysics => f.write_str("physics dt_s must be finite and > 0, substeps >= 1"),
        }
    }
}

impl core::error::Error for DynamicTissueError {}

/// Why a physics update failed: the tissue is faulted until reset (the
/// loop's next tick latches a model fault, zero force).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PhysicsError {
    /// The step failed or diverged.
    Step(StepError),
    /// The surface could not be re-binned.
    Surface(NonFinitePosition),
    /// An imposed displacement was not finite.
    NonFiniteContact {
        /// The tool point.
        tool: usize,
    },
}

impl fmt::Display for PhysicsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Step(e) => write!(f, "step: {e}"),
            Self::Surface(e) => write!(f, "surface: {e}"),
            Self::NonFiniteContact { tool } => {
                write!(f, "tool point {tool}: non-finite contact displacement")
            }
        }
    }
}

impl core::error::Error for PhysicsError {}

/// What a tool point's contact held at the last physics update.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Held<T> {
    vertices: [u32; 3],
    /// Force on the hand from these vertices after the update, N.
    force_n: Vector3<T>,
    /// Extrapolation stiffness ratio `α`, in `[0, 1]`.
    scale: T,
    /// Normal force sent just before the update minus the update's, N
    /// (decays to zero over the next period; zero when instantaneous).
    offset_n: T,
}

/// The dynamic model, its deforming surface and what each of the `P` tool
/// points holds.
pub struct DynamicTissue<'a, 's, T: Real, const P: usize> {
    model: TensorMassModel<'a, 's, T>,
    surface: DeformingSurface<'a, 's, T>,
    forces_n: &'s mut [[T; 3]],
    physics: PhysicsConfig<T>,
    held: [Option<Held<T>>; P],
    fault: Option<PhysicsError>,
    /// Ticks since the last update, and in the period before it (≥ 1).
    ticks_since_update: u32,
    period_ticks: u32,
}

impl<'a, 's, T: Real, const P: usize> DynamicTissue<'a, 's, T, P> {
    /// The tissue of `model` (its current state), with the surface buffers
    /// and a force scratch buffer of one entry per vertex.
    pub fn new(
        model: TensorMassModel<'a, 's, T>,
        surface: SurfaceBuffers<'s, T>,
        forces_n: &'s mut [[T; 3]],
        physics: PhysicsConfig<T>,
    ) -> Result<Self, DynamicTissueError> {
        let n = model.table().vertex_count();
        if forces_n.len() != n {
            return Err(DynamicTissueError::ForceBuffer {
                expected: n,
                found: forces_n.len(),
            });
        }
        if !(physics.dt_s.finite() && physics.dt_s > T::zero() && physics.substeps >= 1) {
            return Err(DynamicTissueError::BadPhysics);
        }
        let surface =
            DeformingSurface::new(&model, surface).map_err(DynamicTissueError::Surface)?;
        Ok(Self {
            model,
            surface,
            forces_n,
            physics,
            held: [None; P],
            fault: None,
            ticks_since_update: 0,
            period_ticks: 1,
        })
    }

    /// The model.
    pub fn model(&self) -> &TensorMassModel<'a, 's, T> {
        &self.model
    }

    /// The deforming surface.
    pub fn surface(&self) -> &DeformingSurface<'a, 's, T> {
        &self.surface
    }

    /// The fault of the last physics update, if any (cleared by reset).
    pub fn fault(&self) -> Option<PhysicsError> {
        self.fault
    }

    /// `true` for a vertex the tool can move (not fixed by the table).
    fn movable(&self, v: u32) -> bool {
        !self.model.table().is_fixed(v)
    }

    /// `k = n · K_c n` (N/m): the change of the normal force on the hand
    /// per metre of normal translation of the target's movable vertices
    /// (module docs). Cost: 9 tensor products and 6 edge look-ups.
    fn normal_stiffness(&self, t: &ContactTarget<T>) -> T {
        let table = self.model.table();
        let n = &t.normal;
        let mut k = T::zero();
        for &i in t.vertices.iter().filter(|&&v| self.movable(v)) {
            for &j in t.vertices.iter().filter(|&&v| self.movable(v)) {
                k += if i == j {
                    self.model
                        .vertex_tensors()
                        .get(i as usize)
                        .map_or(T::zero(), |kij| n.dot(&product(kij, n, false)))
                } else {
                    // The stored edge tensor is K_{lo,hi}; K_{hi,lo} is its transpose.
                    table
                        .edge_index(i, j)
                        .and_then(|e| self.model.edge_tensors().get(e as usize))
                        .map_or(T::zero(), |kij| n.dot(&product(kij, n, i > j)))
                };
            }
        }
        k
    }

    /// The normal force (N, along `t.normal`, positive pushing the tool
    /// out) sent for target `t` at this tick (module docs).
    fn normal_force(&self, t: &ContactTarget<T>) -> T {
        let Some(h) = carried(&self.held, t) else {
            return -self.normal_stiffness(t) * t.gap_m;
        };
        // 1 − j/period at the j-th tick after the update: zero by the next
        // one, so corrections never accumulate.
        let ticks = T::of_f64(f64::from(self.ticks_since_update));
        let period = T::of_f64(f64::from(self.period_ticks));
        let remaining = T::one() - ticks / period;
        let blend = if remaining > T::zero() {
            remaining
        } else {
            T::zero()
        };
        h.force_n.dot(&t.normal) - h.scale * self.normal_stiffness(t) * t.gap_m + blend * h.offset_n
    }

    /// The extrapolation ratio after an update that moved target `t` by
    /// `gap` and changed its force from `before`'s to `force_n` (a new
    /// contact's `before` is zero force at `α = 1`).
    fn secant_scale(&self, before: &Held<T>, t: &ContactTarget<T>, force_n: &Vector3<T>) -> T {
        if self.physics.extrapolation == Extrapolation::Instantaneous
            || t.gap_m.abs() < T::of_f64(SECANT_MIN_MOTION_M)
        {
            return before.scale;
        }
        let predicted = -self.normal_stiffness(t) * t.gap_m;
        let measured = (force_n - before.force_n).dot(&t.normal);
        let ratio = measured / predicted;
        if !ratio.finite() {
            before.scale
        } else if ratio < T::zero() {
            T::zero()
        } else if ratio > T::one() {
            T::one()
        } else {
            ratio
        }
    }

    /// The physics update for contact set `set` (the loop's current
    /// contacts at the current tool position): release, impose, step
    /// `substeps` times, read the held forces, re-bin. Bounded by the
    /// model's step and the re-bin. On failure the tissue is faulted.
    pub fn update(&mut self, set: &[ContactTarget<T>]) -> Result<StepReport<T>, PhysicsError> {
        let result = self.try_update(set);
        if let Err(e) = result {
            self.fault = Some(e);
            self.held = [None; P];
        }
        result
    }

    fn try_update(&mut self, set: &[ContactTarget<T>]) -> Result<StepReport<T>, PhysicsError> {
        if let Some(fault) = self.fault {
            return Err(fault);
        }
        let previous = self.held;
        // What the last tick sent, per target (the corrections' reference).
        let mut sent = [T::zero(); P];
        for t in set {
            if let Some(x) = sent.get_mut(t.tool) {
                *x = self.normal_force(t);
            }
        }
        // Release what no current contact holds.
        for held in previous.iter().flatten() {
            for &v in &held.vertices {
                if !set.iter().any(|t| t.vertices.contains(&v)) {
                    // A fixed vertex was never imposed: nothing to release.
                    let _ = self.model.release(v);
                }
            }
        }
        self.held = [None; P];
        // Impose: translate each contact triangle by gap · n.
        for t in set {
            let shift = t.normal * t.gap_m;
            for &v in &t.vertices {
                if !self.movable(v) {
                    continue;
                }
                let u = self
                    .model
                    .displacements_m()
                    .map_err(|f| PhysicsError::Step(StepError::Faulted(f)))?
                    .get(v as usize)
                    .map_or(Vector3::zeros(), |u| Vector3::new(u[0], u[1], u[2]));
                self.model
                    .impose(v, u + shift)
                    .map_err(|_| PhysicsError::NonFiniteContact { tool: t.tool })?;
            }
        }
        let mut report = None;
        for _ in 0..self.physics.substeps {
            report = Some(
                self.model
                    .step(self.physics.integrator, self.physics.dt_s)
                    .map_err(PhysicsError::Step)?,
            );
        }
        // The force each contact's held vertices resist.
        self.model.elastic_forces_n(self.forces_n);
        for t in set {
            let mut force_n = Vector3::zeros();
            for &v in t.vertices.iter().filter(|&&v| self.movable(v)) {
                if let Some(f) = self.forces_n.get(v as usize) {
                    force_n += Vector3::new(f[0], f[1], f[2]);
                }
            }
            // A new contact started from the surface at rest: zero force, α = 1.
            let before = carried(&previous, t).unwrap_or(Held {
                vertices: t.vertices,
                force_n: Vector3::zeros(),
                scale: T::one(),
                offset_n: T::zero(),
            });
            let scale = self.secant_scale(&before, t, &force_n);
            let offset_n = match self.physics.extrapolation {
                Extrapolation::Instantaneous => T::zero(),
                Extrapolation::Secant => {
                    sent.get(t.tool).copied().unwrap_or(T::zero()) - force_n.dot(&t.normal)
                }
            };
            if let Some(slot) = self.held.get_mut(t.tool) {
                *slot = Some(Held {
                    vertices: t.vertices,
                    force_n,
                    scale,
                    offset_n,
                });
            }
        }
        let u = self
            .model
            .displacements_m()
            .map_err(|f| PhysicsError::Step(StepError::Faulted(f)))?;
        self.surface.rebin(u).map_err(PhysicsError::Surface)?;
        self.period_ticks = self.ticks_since_update.max(1);
        self.ticks_since_update = 0;
        report.ok_or(PhysicsError::Step(StepError::BadTimeStep))
    }
}

/// What tool point `t.tool` held at the last update, if its contact is
/// still on or next to that triangle (they share a vertex).
fn carried<T: Real, const P: usize>(
    held: &[Option<Held<T>>; P],
    t: &ContactTarget<T>,
) -> Option<Held<T>> {
    held.get(t.tool)
        .copied()
        .flatten()
        .filter(|h| h.vertices.iter().any(|v| t.vertices.contains(v)))
}

/// `K x`, or `Kᵀ x` when `transposed`, for a row-major 3×3 `K`.
fn product<T: Real>(k: &[T; 9], x: &Vector3<T>, transposed: bool) -> Vector3<T> {
    let m = nalgebra::Matrix3::from_row_slice(k);
    if transposed { m.transpose() * x } else { m * x }
}

impl<T: Real, const P: usize, const M: usize> Tissue<T, M> for DynamicTissue<'_, '_, T, P> {
    fn geometry(&self) -> SurfaceGeometry<'_, T> {
        self.surface
            .geometry(Supports::TensorMass(self.model.table()))
    }

    /// The surface follows a held contact, so the gap says nothing about
    /// leaving: a contact stays until its force would pull (the solve).
    fn keeps(&self, _gap_m: T) -> bool {
        true
    }

    /// `F_q = (n · F_update − α k · gap + blend · offset) n` per target
    /// (module docs); the force of
    /// the last update carries over while the contact stays on or next to
    /// the triangle it held (they share a vertex).
    fn solve(&mut self, set: &[ContactTarget<T>]) -> Result<Solved<T, M>, Refusal> {
        if self.fault.is_some() || self.model.fault().is_some() {
            return Err(Refusal::Fault);
        }
        let mut solved = Solved {
            device_force_n: Vector3::zeros(),
            tissue_forces_n: [Vector3::zeros(); M],
        };
        for (t, g) in set.iter().zip(solved.tissue_forces_n.iter_mut()) {
            let force_n = t.normal * self.normal_force(t);
            solved.device_force_n += force_n;
            *g = -force_n;
        }
        Ok(solved)
    }

    fn begin_tick(&mut self) {
        self.ticks_since_update = self.ticks_since_update.saturating_add(1);
    }

    fn forget(&mut self) {}

    /// Back to rest: the model's reset, nothing held, the surface at rest.
    fn reset(&mut self) {
        self.model.reset();
        self.held = [None; P];
        self.fault = None;
        self.ticks_since_update = 0;
        self.period_ticks = 1;
        // Rest positions come from a validated table: finite.
        let _ = self.surface.rebin(&[]);
    }
}
