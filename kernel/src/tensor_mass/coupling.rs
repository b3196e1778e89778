//! The force a pre-computed region passes to the connection nodes of a
//! tensor-mass region it is coupled with (the hybrid model, RR-3510 §6.2):
//! the condensed stiffness acting on the connection displacements, plus the
//! constant forces of the region's load and contacts.

use crate::Real;
use crate::math::dense::dot;
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
    /// `f_j += p_j − Σ_k S_jk u_k` for every connection node `j` (tensor-mass
    /// vertex `j`, passed force `p_j`): the force of the pre-computed region,
    /// held at the connection displacements with its interior at
    /// equilibrium (static condensation, `S = K_cc − K_ci K_ii⁻¹ K_ic`).
    /// `S u` dense or hierarchical, as the interface stores it
    /// ([`InterfaceTable::add_condensed_product`]).
    pub(crate) fn add_forces(&self, u: &[[T; 3]], f: &mut [[T; 3]]) {
        let c = self.interface.connection_count();
        if u.len() < c {
            return;
        }
        let Some(fc) = f.get_mut(..c) else {
            return;
        };
        for (fr, &p) in fc
            .as_flattened_mut()
            .iter_mut()
            .zip(self.passed_force_n.as_flattened())
        {
            *fr += p;
        }
        self.interface.add_condensed_product(u, -T::one(), fc);
    }

    /// `½ u_cᵀ S u_c − pᵀ u_c` (J): the condensed region's energy at the
    /// connection displacements, less the work of the passed forces (so
    /// that [`Self::add_forces`] is minus its gradient).
    pub(crate) fn energy_j(&self, u: &[[T; 3]]) -> T {
        let c = self.interface.connection_count();
        let uc = u.get(..c).unwrap_or(&[]).as_flattened();
        let work = dot(uc, self.passed_force_n.as_flattened());
        T::of_f64(0.5) * self.interface.condensed_quadratic(u) - work
    }
}
