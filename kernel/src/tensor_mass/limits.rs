//! Divergence bounds ([`Limits`]) and the check an integrator's last pass
//! over the vertices accumulates against them ([`Watch`]; MODELS.md §6:
//! divergence is detected before it reaches the output).

use super::force::vec3;
use super::state::Fault;
use crate::Real;

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

/// The divergence check of MODELS.md §6, accumulated vertex by vertex inside
/// an integrator's last pass over the vertices (no separate pass): the first
/// non-finite or out-of-bound vertex, and the kinetic energy.
pub(crate) struct Watch<T> {
    max_displacement2_m2: T,
    max_kinetic_energy_j: T,
    twice_kinetic_j: T,
    fault: Option<Fault>,
}

impl<T: Real> Watch<T> {
    pub(crate) fn new(limits: &Limits<T>) -> Self {
        Self {
            max_displacement2_m2: limits.max_displacement_m * limits.max_displacement_m,
            max_kinetic_energy_j: limits.max_kinetic_energy_j,
            twice_kinetic_j: T::zero(),
            fault: None,
        }
    }

    /// Checks vertex `vertex` with displacement `u` (m), velocity `v` (m/s)
    /// and mass `m` (kg) after the update.
    #[inline(always)]
    pub(crate) fn visit(&mut self, vertex: usize, u: &[T; 3], v: &[T; 3], m: T) {
        let (u2, v2) = (vec3(u).norm_squared(), vec3(v).norm_squared());
        if self.fault.is_none() {
            let vertex = vertex as u32;
            if !(u2.finite() && v2.finite()) {
                self.fault = Some(Fault::NonFinite { vertex });
            } else if u2 > self.max_displacement2_m2 {
                self.fault = Some(Fault::DisplacementBound { vertex });
            }
        }
        self.twice_kinetic_j += m * v2;
    }

    /// The kinetic energy `½ Σ m |v|²` (J), or the first fault seen.
    pub(crate) fn finish(self) -> Result<T, Fault> {
        if let Some(fault) = self.fault {
            return Err(fault);
        }
        let kinetic = self.twice_kinetic_j / T::of_f64(2.0);
        if !kinetic.finite() || kinetic > self.max_kinetic_energy_j {
            return Err(Fault::KineticEnergyBound);
        }
        Ok(kinetic)
    }
}
