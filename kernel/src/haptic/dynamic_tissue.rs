//! The dynamic tensor-mass model as a tissue for the haptic loop
//! (RR-3510 §5; Cotin 1999 §4; MODELS.md §6).
//!
//! Coupling (imposed displacement, Cotin 1999 §4: "the barycentric
//! coordinates of the intersection point distribute the displacement to the
//! vertices of the intersected triangle"): at each physics update, every
//! contact's triangle vertices are held ([`TensorMassModel::impose`]) so that
//! the contact point moves by `gap · n` onto the tool sphere; the
//! minimum-norm distribution is `Δu_i = w_i / Σ_k w_k² · gap · n` over the
//! triangle's free vertices. The model is then stepped, the force on the
//! hand is the elastic force the held vertices resist, `F = Σ_i f_i`, and
//! the surface is re-binned ([`DeformingSurface::rebin`]). Vertices no
//! longer under a contact are released at the next update.
//!
//! Force between physics updates (extrapolation from the local contact
//! stiffness and the tool's motion, Cotin 1999 §6): each tick sends
//! `F = F_update − α K_c n · gap`, where `gap` is the tool's normal motion
//! since the last update (measured against that update's surface, zero
//! right after it) and `K_c = Σ_{i,j ∈ triangle} K_ij w_j / Σw²` comes from
//! the model's current vertex and edge tensors (RR-3510 §5.1). With the
//! rest of the mesh frozen, moving the held vertices by
//! `Δu_j = w_j / Σw² · gap · n` changes the force by exactly
//! `−K_c n · gap`, so `α = 1` ([`Extrapolation::Instantaneous`]) is the
//! model's own force until the next step (exact for the linear law; for St
//! Venant-Kirchhoff `K` is the rest tangent). But the free vertices then
//! relax during the step, so the instantaneous stiffness overshoots and the
//! force drops at every update (a saw-tooth at the physics rate).
//! [`Extrapolation::Secant`] (the default) scales it by the ratio the
//! tissue showed over the last period, `α = ΔF·n / (−gap · n·K_c n)`
//! clamped to `[0, 1]` (kept when the tool moved less than
//! [`SECANT_MIN_MOTION_M`]; 1 on a new contact), so the force follows the
//! stiffness the tissue actually responds with and an update changes it
//! only by the period's prediction error.

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

/// The stiffness the force is extrapolated with between physics updates
/// (module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Extrapolation {
    /// `K_c`: the model's force with the rest of the mesh frozen.
    Instantaneous,
    /// `α K_c`, `α` the secant ratio of the last period.
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

    /// `Σ w_k²` over the target's movable vertices (0 when none is).
    fn weight_norm2(&self, t: &ContactTarget<T>) -> T {
        t.vertices
            .iter()
            .zip(&t.contact.weights)
            .filter(|(v, _)| self.movable(**v))
            .fold(T::zero(), |s, (_, &w)| s + w * w)
    }

    /// `K_c n` (N/m) of a target: the change of force on the hand per metre
    /// of imposed normal displacement of its contact point (module docs).
    /// Cost: 9 tensor products and 6 edge look-ups.
    fn stiffness_along_normal(&self, t: &ContactTarget<T>) -> Vector3<T> {
        let s = self.weight_norm2(t);
        if s <= T::zero() {
            return Vector3::zeros();
        }
        let table = self.model.table();
        let mut kn = Vector3::zeros();
        for &i in t.vertices.iter().filter(|&&v| self.movable(v)) {
            for (&j, &wj) in t.vertices.iter().zip(&t.contact.weights) {
                if !self.movable(j) {
                    continue;
                }
                let du = t.normal * (wj / s);
                kn += if i == j {
                    self.model
                        .vertex_tensors()
                        .get(i as usize)
                        .map_or(Vector3::zeros(), |k| product(k, &du, false))
                } else {
                    // The stored edge tensor is K_{lo,hi}; K_{hi,lo} is its transpose.
                    table
                        .edge_index(i, j)
                        .and_then(|e| self.model.edge_tensors().get(e as usize))
                        .map_or(Vector3::zeros(), |k| product(k, &du, i > j))
                };
            }
        }
        kn
    }

    /// The extrapolation ratio after an update that moved target `t` by
    /// `gap` and changed its force from `before`'s to `force_n`.
    fn secant_scale(
        &self,
        before: Option<Held<T>>,
        t: &ContactTarget<T>,
        force_n: &Vector3<T>,
    ) -> T {
        let Some(before) = before else {
            return T::one();
        };
        if self.physics.extrapolation == Extrapolation::Instantaneous
            || t.gap_m.abs() < T::of_f64(SECANT_MIN_MOTION_M)
        {
            return before.scale;
        }
        let predicted = -self.stiffness_along_normal(t).dot(&t.normal) * t.gap_m;
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
        // Impose: move each contact point by gap · n (minimum norm).
        for t in set {
            let s = self.weight_norm2(t);
            let shift = t.normal * t.gap_m;
            for (&v, &w) in t.vertices.iter().zip(&t.contact.weights) {
                if !self.movable(v) || s <= T::zero() {
                    continue;
                }
                let u = self
                    .model
                    .displacements_m()
                    .map_err(|f| PhysicsError::Step(StepError::Faulted(f)))?
                    .get(v as usize)
                    .map_or(Vector3::zeros(), |u| Vector3::new(u[0], u[1], u[2]));
                self.model
                    .impose(v, u + shift * (w / s))
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
            let scale = self.secant_scale(carried(&previous, t), t, &force_n);
            if let Some(slot) = self.held.get_mut(t.tool) {
                *slot = Some(Held {
                    vertices: t.vertices,
                    force_n,
                    scale,
                });
            }
        }
        let u = self
            .model
            .displacements_m()
            .map_err(|f| PhysicsError::Step(StepError::Faulted(f)))?;
        self.surface.rebin(u).map_err(PhysicsError::Surface)?;
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

    /// `F_q = F_update − α K_c n · gap` per target (module docs); the force of
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
            let (before, scale) = carried(&self.held, t)
                .map_or((Vector3::zeros(), T::one()), |h| (h.force_n, h.scale));
            let force_n = before - self.stiffness_along_normal(t) * (scale * t.gap_m);
            solved.device_force_n += force_n;
            *g = -force_n;
        }
        Ok(solved)
    }

    fn forget(&mut self) {}

    /// Back to rest: the model's reset, nothing held, the surface at rest.
    fn reset(&mut self) {
        self.model.reset();
        self.held = [None; P];
        self.fault = None;
        // Rest positions come from a validated table: finite.
        let _ = self.surface.rebin(&[]);
    }
}
