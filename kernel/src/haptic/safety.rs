//! The safety supervisor on the force output (MODELS.md §6: a haptic device
//! must never receive a spike): magnitude clamp, slew-rate limit, and a
//! latched fault with zero force on any non-finite value or model fault,
//! cleared only by an explicit [`Supervisor::reset`].

use core::fmt;

use nalgebra::Vector3;

use crate::Real;

/// Output limits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SafetyLimits<T> {
    /// Largest force magnitude sent to the device, N.
    pub max_force_n: T,
    /// Largest change of the force vector per second, N/s.
    pub max_slew_n_per_s: T,
}

/// Why the supervisor latched its fault.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SafetyFault {
    /// A tool position was NaN or infinite.
    NonFiniteInput,
    /// The model produced a non-finite force.
    NonFiniteForce,
    /// The model refused the contact set or diverged.
    ModelFault,
}

impl fmt::Display for SafetyFault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::NonFiniteInput => "non-finite tool position",
            Self::NonFiniteForce => "non-finite force",
            Self::ModelFault => "model fault",
        })
    }
}

impl core::error::Error for SafetyFault {}

/// What the device receives with the force.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutputStatus {
    /// The force is the model's.
    Ok,
    /// The force was reduced by the magnitude clamp or the slew limit.
    Clamped,
    /// A tool point's centre lies inside the body and it has no contact
    /// (not latched; the haptic loop says so, the supervisor never does):
    /// it went deeper than the penetration test looks without the sweep
    /// seeing it cross the surface (the first sample inside, a jump of more
    /// than a grid cell, a contact let go or refused while inside). It adds
    /// no force (it is not pushed out: from deep inside, the nearest face is
    /// not necessarily the one it entered by, and a push through the wrong
    /// one is the pop-through a device must never give), so the force is
    /// the other contacts', slew-limited as always: with no other contact
    /// it ramps down to zero. The point is found again as usual once it
    /// reaches within the penetration test's depth of the surface, and the
    /// status clears once it is found or outside.
    ToolInside,
    /// Latched fault: the force is zero until [`Supervisor::reset`].
    Faulted(SafetyFault),
}

/// Limits out of range: non-finite or not positive.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BadLimits;

impl fmt::Display for BadLimits {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("safety limits must be finite and > 0")
    }
}

impl core::error::Error for BadLimits {}

/// The supervisor: the last force sent and the latched fault.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Supervisor<T> {
    limits: SafetyLimits<T>,
    last_n: Vector3<T>,
    fault: Option<SafetyFault>,
}

impl<T: Real> Supervisor<T> {
    /// A supervisor starting from zero force.
    pub fn new(limits: SafetyLimits<T>) -> Result<Self, BadLimits> {
        let ok = |x: T| x.finite() && x > T::zero();
        if !(ok(limits.max_force_n) && ok(limits.max_slew_n_per_s)) {
            return Err(BadLimits);
        }
        Ok(Self {
            limits,
            last_n: Vector3::zeros(),
            fault: None,
        })
    }

    /// The latched fault, if any.
    pub fn fault(&self) -> Option<SafetyFault> {
        self.fault
    }

    /// Clears the fault; the force restarts from zero (and ramps at the
    /// slew limit).
    pub fn reset(&mut self) {
        self.fault = None;
        self.last_n = Vector3::zeros();
    }

    /// The force to send this tick, `dt_s` after the previous one, for the
    /// model's `requested` force (N) or its fault. A fault (or a non-finite
    /// force) latches: zero force from this tick on, without slew limiting
    /// (zero is the safe state). Otherwise the magnitude is clamped to
    /// `max_force_n`, then the change from the last force to
    /// `max_slew_n_per_s · dt_s`.
    pub fn output(
        &mut self,
        requested: Result<Vector3<T>, SafetyFault>,
        dt_s: T,
    ) -> (Vector3<T>, OutputStatus) {
        if self.fault.is_none() {
            match requested {
                Err(fault) => self.fault = Some(fault),
                Ok(f) if !f.iter().all(|x| x.finite()) => {
                    self.fault = Some(SafetyFault::NonFiniteForce);
                }
                Ok(_) => {}
            }
        }
        if let Some(fault) = self.fault {
            self.last_n = Vector3::zeros();
            return (Vector3::zeros(), OutputStatus::Faulted(fault));
        }
        let mut f = requested.unwrap_or_else(|_| Vector3::zeros());
        let mut clamped = false;
        let norm = f.norm();
        if norm > self.limits.max_force_n {
            f *= self.limits.max_force_n / norm;
            clamped = true;
        }
        let step = f - self.last_n;
        let max_step = self.limits.max_slew_n_per_s * dt_s;
        let step_norm = step.norm();
        if step_norm > max_step {
            f = self.last_n + step * (max_step / step_norm);
            clamped = true;
        }
        self.last_n = f;
        let status = if clamped {
            OutputStatus::Clamped
        } else {
            OutputStatus::Ok
        };
        (f, status)
    }
}
