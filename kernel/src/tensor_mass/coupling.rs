//! The force a pre-computed region passes to the connection nodes of a
//! tensor-mass region it is coupled with (the hybrid model, RR-3510 §6.2):
//! the condensed stiffness acting on the connection displacements, plus the
//! constant forces of the region's load and contacts.

use nalgebra::{Matrix3, Vector3};

use super::force::vec3;
use crate::Real;
use crate::table::InterfaceTable;

/// A tensor-mass model's coupling to a pre-computed region: the interface
/// table and the force (N) each connection node receives besides the
/// condensed stiffness (`Hᵀ f` of the region's load and contacts), which the
/// hybrid model sets between steps.
pub(crate) struct Coupling<'a, 's, T: Real> {
    pub(crate) interface: InterfaceTable<'a, T>,
    pub(crate) passed_force_n: &'s mut [[T; 3]],
}

/// What the force pass reads of a [`Coupling`].
#[derive(Clone, Copy)]
pub(crate) struct CouplingForces<'b, 'a, T: Real> {
    pub(crate) interface: &'b InterfaceTable<'a, T>,
    pub(crate) passed_force_n: &'b [[T; 3]],
}

impl<'a, 's, T: Real> Coupling<'a, 's, T> {
    /// The view the force pass reads.
    pub(crate) fn forces(&self) -> CouplingForces<'_, 'a, T> {
        CouplingForces {
            interface: &self.interface,
            passed_force_n: self.passed_force_n,
        }
    }
}

impl<T: Real> CouplingForces<'_, '_, T> {
    /// `f_{d_j} += p_j − Σ_k S_jk u_{d_k}` for every connection node `j` (mesh
    /// vertex of tensor-mass number `d_j`, passed force `p_j`): the force of
    /// the pre-computed region, held at the connection displacements with
    /// its interior at equilibrium (static condensation,
    /// `S = K_cc − K_ci K_ii⁻¹ K_ic`). `9c²` multiply-adds.
    pub(crate) fn add_forces(&self, u: &[[T; 3]], f: &mut [[T; 3]]) {
        let connections = self.interface.connections();
        for (j, (&[_, dj], passed)) in connections.iter().zip(self.passed_force_n).enumerate() {
            let mut acc = vec3(passed);
            for (s, &[_, dk]) in self.interface.condensed_row(j).iter().zip(connections) {
                if let Some(uk) = u.get(dk as usize) {
                    acc -= Matrix3::from_row_slice(s) * vec3(uk);
                }
            }
            if let Some(fj) = f.get_mut(dj as usize) {
                *fj = (vec3(fj) + acc).into();
            }
        }
    }

    /// `½ u_cᵀ S u_c − pᵀ u_c` (J): the condensed region's energy at the
    /// connection displacements, less the work of the passed forces (so
    /// that [`Self::add_forces`] is minus its gradient).
    pub(crate) fn energy_j(&self, u: &[[T; 3]]) -> T {
        let connections = self.interface.connections();
        let at = |d: u32| u.get(d as usize).map_or(Vector3::zeros(), vec3);
        let mut energy = T::zero();
        for (j, (&[_, dj], passed)) in connections.iter().zip(self.passed_force_n).enumerate() {
            let uj = at(dj);
            let mut su = Vector3::zeros();
            for (s, &[_, dk]) in self.interface.condensed_row(j).iter().zip(connections) {
                su += Matrix3::from_row_slice(s) * at(dk);
            }
            energy += uj.dot(&su) / T::of_f64(2.0) - uj.dot(&vec3(passed));
        }
        energy
    }
}
