//! What the three haptic loops share (MODELS.md §6): the loop's
//! configuration, the tool points in, the force and status out, and the
//! tensor-mass physics settings of the dynamic and hybrid loops.
//!
//! A loop has `tool_points` tool points (1 to `PALPATE_TOOL_POINTS`, fixed
//! at creation). The kernel's loop is built for `PALPATE_TOOL_POINTS`; the
//! points beyond `tool_points` are parked at `PARKED_M` (1e30 m), outside every
//! mesh's collision grid, from creation on, so they never touch (the
//! detection of a point outside the grid's reach visits no triangle), and
//! one build of the loop serves devices with one to four points.

use nalgebra::Vector3;
use palpate_kernel::contact::Tissue;
use palpate_kernel::haptic::{
    ForceOutput, HapticLoop, LoopConfig as KernelLoopConfig, OutputStatus as KernelStatus,
    PhysicsTissue, SafetyFault, SafetyLimits, ToolAction as KernelAction, ToolInput,
};
use palpate_kernel::tensor_mass::{
    DynamicParams, ElasticLaw, Extrapolation as KernelExtrapolation,
    Integrator as KernelIntegrator, PhysicsConfig as KernelPhysics, StvkForm, TearThresholds,
    Tearing,
};

use crate::error::Detail;
use crate::handle;
use crate::status::Status;
use crate::{M, P, PALPATE_TOOL_POINTS};

/// Where tool points beyond a loop's `tool_points` stand, m (each
/// component): outside any mesh's collision grid.
pub(crate) const PARKED_M: f32 = 1.0e30;

/// A haptic loop's settings (`palpate_loop_config_default` gives the
/// host's defaults).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LoopConfig {
    /// Tool points, 1 to `PALPATE_TOOL_POINTS`: `palpate_*_loop_tick` takes
    /// this many.
    pub tool_points: u32,
    /// Radius of each tool point's sphere, m (finite, > 0).
    pub radius_m: f32,
    /// Haptic period, s (finite, > 0; 1 kHz: 0.001).
    pub dt_s: f32,
    /// Largest force magnitude sent to the device, N (finite, > 0).
    pub max_force_n: f32,
    /// Largest change of the force vector per second, N/s (finite, > 0).
    pub max_slew_n_per_s: f32,
}

/// The host's defaults (`palpate session run` scenes): one tool point of
/// radius 2 mm, 1 kHz, 4 N, 2000 N/s (full force in 2 ms).
#[unsafe(no_mangle)]
pub extern "C" fn palpate_loop_config_default() -> LoopConfig {
    LoopConfig {
        tool_points: 1,
        radius_m: 0.002,
        dt_s: 0.001,
        max_force_n: 4.0,
        max_slew_n_per_s: 2000.0,
    }
}

impl LoopConfig {
    /// The kernel's configuration, and the tool point count.
    pub(crate) fn kernel(&self) -> Result<(KernelLoopConfig<f32>, usize), Status> {
        if !(1..=PALPATE_TOOL_POINTS).contains(&self.tool_points) {
            return Err(Status::BadArgument);
        }
        let config = KernelLoopConfig {
            radius_m: self.radius_m,
            dt_s: self.dt_s,
            limits: SafetyLimits {
                max_force_n: self.max_force_n,
                max_slew_n_per_s: self.max_slew_n_per_s,
            },
        };
        Ok((config, self.tool_points as usize))
    }
}

/// What a tool point does in a tick (`palpate_tool::action`).
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ToolAction {
    /// A probe: touches, slides without friction, lets go when it would
    /// pull.
    Touch = 0,
    /// A closed grasper jaw: the contact it has when the grip closes is
    /// held (it follows the jaw and may pull) until the action changes.
    Grip = 1,
    /// An enabled blade from the point along `blade_m`: cuts the
    /// tensor-mass model at each physics update; a probe on the
    /// pre-computed model (`cut_refused` says so).
    Cut = 2,
}

/// A tool point's input for one tick.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tool {
    /// The tool sphere's centre, m (a non-finite value latches
    /// `PALPATE_OUTPUT_STATUS_FAULT_NON_FINITE_INPUT`).
    pub position_m: [f32; 3],
    /// A `palpate_tool_action` value.
    pub action: u32,
    /// A blade's extent from the point, m (`PALPATE_TOOL_ACTION_CUT` only).
    pub blade_m: [f32; 3],
}

impl Tool {
    /// The kernel's tool input.
    fn kernel(&self) -> Result<ToolInput<f32>, Status> {
        let action = match self.action {
            a if a == ToolAction::Touch as u32 => KernelAction::Touch,
            a if a == ToolAction::Grip as u32 => KernelAction::Grip,
            a if a == ToolAction::Cut as u32 => KernelAction::Cut {
                blade_m: self.blade_m.into(),
            },
            _ => return Err(Status::BadArgument),
        };
        Ok(ToolInput {
            position_m: self.position_m.into(),
            action,
        })
    }
}

/// The supervisor's verdict on a tick's force.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutputStatus {
    /// The force is the model's.
    Ok = 0,
    /// The force was reduced by the magnitude clamp or the slew limit.
    Clamped = 1,
    /// Latched fault, zero force until reset: a non-finite tool position.
    FaultNonFiniteInput = 2,
    /// Latched fault, zero force until reset: a non-finite model force.
    FaultNonFiniteForce = 3,
    /// Latched fault, zero force until reset: the model refused the
    /// contact set or diverged.
    FaultModel = 4,
    /// Not latched: a tool point's centre is inside the body with no
    /// contact (it got deeper than the contact test looks without crossing
    /// the surface where the test saw it: a first position inside, a jump,
    /// a contact let go inside). It adds no force: the force is the other
    /// contacts', slew-limited (with none, it ramps to zero).
    ToolInside = 5,
}

/// What the device receives each tick.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Force {
    /// Force on the hand, N (after the supervisor).
    pub force_n: [f32; 3],
    /// Ok, clamped, the latched fault, or a tool point inside the body.
    pub status: OutputStatus,
    /// Tool points in contact.
    pub contacts: u8,
    /// Tool points whose new contact was refused this tick (capacity
    /// reached, or a contact the model refused).
    pub refused: u8,
    /// A blade touches a tissue that cannot be cut (the pre-computed model).
    pub cut_refused: bool,
}

impl From<&ForceOutput<f32>> for Force {
    fn from(out: &ForceOutput<f32>) -> Self {
        Self {
            force_n: out.force_n.into(),
            status: match out.status {
                KernelStatus::Ok => OutputStatus::Ok,
                KernelStatus::Clamped => OutputStatus::Clamped,
                KernelStatus::Faulted(SafetyFault::NonFiniteInput) => {
                    OutputStatus::FaultNonFiniteInput
                }
                KernelStatus::Faulted(SafetyFault::NonFiniteForce) => {
                    OutputStatus::FaultNonFiniteForce
                }
                KernelStatus::Faulted(SafetyFault::ModelFault) => OutputStatus::FaultModel,
                KernelStatus::ToolInside => OutputStatus::ToolInside,
            },
            contacts: out.contacts,
            refused: out.refused,
            cut_refused: out.cut_refused,
        }
    }
}

/// A live loop: the kernel's loop over tissue `B` and its tool point count.
pub(crate) struct Live<B> {
    /// The kernel's loop.
    pub(crate) haptic: HapticLoop<f32, B, P, M>,
    /// Tool points the caller drives (the rest are parked).
    pub(crate) tool_points: usize,
}

impl<B: Tissue<f32, M>> Live<B> {
    /// The loop over `tissue` with the caller's `config`.
    pub(crate) fn new(tissue: B, config: &LoopConfig) -> Result<Self, Detail> {
        let (kernel, tool_points) = config.kernel()?;
        Ok(Self {
            haptic: HapticLoop::new(tissue, kernel)?,
            tool_points,
        })
    }

    /// One tick with `count` tools at `tools`, the force to `force`.
    ///
    /// # Safety
    ///
    /// `tools` is `NULL` or points to `count` readable `palpate_tool`;
    /// `force` is `NULL` or points to a writable `palpate_force`.
    pub(crate) unsafe fn tick(
        &mut self,
        tools: *const Tool,
        count: usize,
        force: *mut Force,
    ) -> Result<(), Status> {
        if count != self.tool_points {
            return Err(Status::BadArgument);
        }
        // SAFETY: the contract.
        let tools = unsafe { handle::slice(tools, count) }?;
        handle::check(force)?;
        let parked = ToolInput::touch(Vector3::from([PARKED_M; 3]));
        let mut inputs = [parked; P];
        for (input, tool) in inputs.iter_mut().zip(tools) {
            *input = tool.kernel()?;
        }
        let out = self.haptic.tick_tools(&inputs);
        // SAFETY: the contract (checked non-null and aligned above).
        unsafe { handle::out(force, Force::from(&out)) }
    }
}

/// The elastic law of the tensor-mass model (`palpate_physics_config::law`).
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Law {
    /// Linear elasticity on vertex and edge tensors (RR-3510 §5).
    Linear = 0,
    /// St Venant-Kirchhoff, per tet (Picinbono 2001; the fast form).
    Stvk = 1,
    /// St Venant-Kirchhoff by the split terms on vertices, edges,
    /// triangles and tets (Picinbono 2001 eq. 13-15; more memory).
    StvkTensors = 2,
    /// Co-rotational linear, per tet (Muller & Gross 2004).
    Corotational = 3,
    /// Compressible neo-Hookean, per tet (Bonet & Wood).
    NeoHookean = 4,
}

/// The explicit integrator (`palpate_physics_config::integrator`).
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Integrator {
    /// Explicit Euler.
    ExplicitEuler = 0,
    /// Symplectic Euler (stable up to `2/ω_max`).
    SymplecticEuler = 1,
    /// Fourth-order Runge-Kutta (needs `4N` more vectors of memory).
    Rk4 = 2,
    /// The central difference of Picinbono eq. 19.
    CentralDifference = 3,
}

/// How the force is extrapolated between physics updates
/// (`palpate_physics_config::extrapolation`).
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Extrapolation {
    /// The secant ratio of the last period, each update's correction
    /// spread over the next period (the default).
    Secant = 0,
    /// The contact stiffness with the rest of the mesh frozen.
    Instantaneous = 1,
}

/// The tensor-mass model's physics (the dynamic loop's tissue, the hybrid's
/// tensor-mass region). The caller calls `palpate_*_loop_physics_update`
/// every few ticks; each runs `substeps` steps of `dt_s`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhysicsConfig {
    /// A `palpate_law` value.
    pub law: u32,
    /// Incompressibility penalty `γ`, N (Picinbono 2001 §3.2), 0 for none.
    pub incompressibility_n: f32,
    /// Mass-proportional damping `c`, 1/s (finite, ≥ 0).
    pub damping_per_s: f32,
    /// Gravity on every free vertex, m/s².
    pub gravity_m_s2: [f32; 3],
    /// Divergence bound: largest displacement of any vertex, m (≥ 0).
    pub max_displacement_m: f32,
    /// Divergence bound: largest kinetic energy, J (≥ 0; `INFINITY` for
    /// none).
    pub max_kinetic_energy_j: f32,
    /// A `palpate_integrator` value.
    pub integrator: u32,
    /// A `palpate_extrapolation` value.
    pub extrapolation: u32,
    /// Step, s (finite, > 0, below the integrator's critical step:
    /// `palpate dynamic critical-dt`).
    pub dt_s: f32,
    /// Steps per physics update, 1 to 10000.
    pub substeps: u32,
    /// Most tets the blades remove per update, 1 to 64.
    pub cut_capacity_tets: u32,
    /// The push of a blade's sphere at which the tet ahead gives way, N
    /// (finite, > 0; the host's default is 0.2).
    pub cut_force_n: f32,
    /// Most tets tearing removes per update, 1 to 64; 0 for no tearing.
    pub tear_capacity_tets: u32,
    /// Tearing: largest `|V − V₀| / V₀` of a tet, 0 for no limit.
    pub tear_volume_change: f32,
    /// Tearing: largest mean edge elongation of a tet, 0 for no limit.
    pub tear_mean_elongation: f32,
    /// Tearing: largest single edge elongation, 0 for no limit.
    pub tear_max_elongation: f32,
}

impl PhysicsConfig {
    /// The kernel's elastic law.
    pub(crate) fn law(&self) -> Result<ElasticLaw, Status> {
        match self.law {
            l if l == Law::Linear as u32 => Ok(ElasticLaw::Linear),
            l if l == Law::Stvk as u32 => Ok(ElasticLaw::StVenantKirchhoff(StvkForm::PerTet)),
            l if l == Law::StvkTensors as u32 => {
                Ok(ElasticLaw::StVenantKirchhoff(StvkForm::Tensors))
            }
            l if l == Law::Corotational as u32 => Ok(ElasticLaw::Corotational),
            l if l == Law::NeoHookean as u32 => Ok(ElasticLaw::NeoHookean),
            _ => Err(Status::BadArgument),
        }
    }

    /// The kernel's integrator.
    pub(crate) fn integrator(&self) -> Result<KernelIntegrator, Status> {
        match self.integrator {
            i if i == Integrator::ExplicitEuler as u32 => Ok(KernelIntegrator::ExplicitEuler),
            i if i == Integrator::SymplecticEuler as u32 => Ok(KernelIntegrator::SymplecticEuler),
            i if i == Integrator::Rk4 as u32 => Ok(KernelIntegrator::Rk4),
            i if i == Integrator::CentralDifference as u32 => {
                Ok(KernelIntegrator::CentralDifference)
            }
            _ => Err(Status::BadArgument),
        }
    }

    /// The model's parameters.
    pub(crate) fn params(&self) -> Result<DynamicParams<f32>, Status> {
        let penalty = (self.incompressibility_n != 0.0).then_some(self.incompressibility_n);
        Ok(
            DynamicParams::linear(self.damping_per_s, self.max_displacement_m)
                .with_law(self.law()?)
                .with_incompressibility(penalty)
                .with_gravity(self.gravity_m_s2.into())
                .with_max_kinetic_energy(self.max_kinetic_energy_j),
        )
    }

    /// The physics update's configuration.
    pub(crate) fn physics(&self) -> Result<KernelPhysics<f32>, Status> {
        let extrapolation = match self.extrapolation {
            e if e == Extrapolation::Secant as u32 => KernelExtrapolation::Secant,
            e if e == Extrapolation::Instantaneous as u32 => KernelExtrapolation::Instantaneous,
            _ => return Err(Status::BadArgument),
        };
        let threshold = |x: f32| {
            if x == 0.0 {
                Ok(None)
            } else if x.is_finite() && x > 0.0 {
                Ok(Some(x))
            } else {
                Err(Status::BadArgument)
            }
        };
        let thresholds = TearThresholds {
            volume_change: threshold(self.tear_volume_change)?,
            mean_elongation: threshold(self.tear_mean_elongation)?,
            max_elongation: threshold(self.tear_max_elongation)?,
        };
        Ok(KernelPhysics {
            extrapolation,
            cut_capacity_tets: self.cut_capacity_tets,
            cut_force_n: self.cut_force_n,
            tearing: (self.tear_capacity_tets != 0).then_some(Tearing {
                thresholds,
                capacity_tets: self.tear_capacity_tets,
            }),
            ..KernelPhysics::new(self.integrator()?, self.dt_s, self.substeps)
        })
    }

    /// Whether the state needs the RK4 scratch vectors.
    pub(crate) fn needs_rk4(&self) -> bool {
        self.integrator == Integrator::Rk4 as u32
    }

    /// Whether the state needs the split St Venant-Kirchhoff terms.
    pub(crate) fn needs_terms(&self) -> bool {
        self.law == Law::StvkTensors as u32
    }
}

/// What a physics update did.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhysicsReport {
    /// Kinetic energy of the tensor-mass model after the update, J.
    pub kinetic_energy_j: f32,
    /// Force evaluations (passes over vertices and edges) of the last step.
    pub force_evaluations: u32,
    /// Tets the update removed (blades, then tearing):
    /// `palpate_*_loop_removed_tets` lists them.
    pub removed_tets: u32,
}

impl<B: PhysicsTissue<f32, M>> Live<B> {
    /// One physics update; its report to `report` (when not null).
    ///
    /// # Safety
    ///
    /// `report` is `NULL` or points to a writable `palpate_physics_report`.
    pub(crate) unsafe fn physics_update(
        &mut self,
        report: *mut PhysicsReport,
        removed: impl Fn(&B) -> usize,
    ) -> Result<(), Detail> {
        let step = self.haptic.physics_update()?;
        let value = PhysicsReport {
            kinetic_energy_j: step.kinetic_energy_j,
            force_evaluations: step.force_evaluations,
            removed_tets: u32::try_from(removed(self.haptic.tissue())).unwrap_or(u32::MAX),
        };
        if !report.is_null() {
            // SAFETY: the contract.
            unsafe { handle::out(report, value) }?;
        }
        Ok(())
    }
}

/// Copies the tets the last physics update removed (`removed`) to `tets`
/// (`capacity` entries, may be `NULL` when 0) and their number to `count`.
/// `Err(BadArgument)` when they do not fit (`count` says how many there are).
///
/// # Safety
///
/// `tets` is `NULL` or points to `capacity` writable `uint32_t`; `count` is
/// `NULL` or points to a writable `size_t`.
pub(crate) unsafe fn copy_removed(
    removed: &[u32],
    tets: *mut u32,
    capacity: usize,
    count: *mut usize,
) -> Result<(), Status> {
    // SAFETY: the contract.
    unsafe { handle::out(count, removed.len()) }?;
    if removed.is_empty() {
        return Ok(());
    }
    if removed.len() > capacity {
        return Err(Status::BadArgument);
    }
    // SAFETY: the contract: `capacity ≥ removed.len()` entries.
    let out = unsafe { handle::slice_mut(tets, removed.len()) }?;
    for (o, &t) in out.iter_mut().zip(removed) {
        *o = t;
    }
    Ok(())
}
