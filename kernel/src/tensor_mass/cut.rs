//! Local removal of tetrahedra (RR-3510 §5; Picinbono 2001 §3.1, MODELS.md
//! §1 and §3): a removed tet's 4 vertex blocks, 6 edge blocks and 4 mass
//! shares are subtracted from the current state, recomputed from the rest
//! shape the table keeps for it, so the tensors equal those built from the
//! mesh without the tet, to rounding.

use core::fmt;

use super::model::TensorMassModel;
use crate::Real;
use crate::element::stiffness_block;
use crate::table::format::{NO_NEIGHBOUR, TET_EDGE_PAIRS, tet_face_vertices};

/// Why a tet was not removed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RemoveError {
    /// No such tet.
    TetOutOfRange {
        /// The tet index given.
        tet: u32,
    },
    /// The tet was removed before.
    AlreadyRemoved {
        /// The tet index given.
        tet: u32,
    },
}

impl fmt::Display for RemoveError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::TetOutOfRange { tet } => write!(f, "tet {tet} does not exist"),
            Self::AlreadyRemoved { tet } => write!(f, "tet {tet} is already removed"),
        }
    }
}

impl core::error::Error for RemoveError {}

impl<T: Real> TensorMassModel<'_, '_, T> {
    /// Removes `tet`, then every face neighbour it leaves with no live face
    /// neighbour (held to the rest by an edge or a vertex only), so the mesh
    /// stays conformal. Returns how many tets were removed (1 to 5).
    ///
    /// Bounded: a hanging tet has no live face neighbour, so removing it
    /// cannot leave another tet hanging; at most 4 follow the first.
    pub fn remove_tet(&mut self, tet: u32) -> Result<u32, RemoveError> {
        let t = tet as usize;
        match self.state.tet_alive.get(t) {
            None => return Err(RemoveError::TetOutOfRange { tet }),
            Some(false) => return Err(RemoveError::AlreadyRemoved { tet }),
            Some(true) => {}
        }
        self.subtract(t);
        let mut removed = 1;
        let neighbours = self.table.tet_neighbours().get(t).copied();
        for other in neighbours.unwrap_or([NO_NEIGHBOUR; 4]) {
            if self.is_alive(other) && self.live_face_neighbours(other) == 0 {
                self.subtract(other as usize);
                removed += 1;
            }
        }
        Ok(removed)
    }

    fn is_alive(&self, tet: u32) -> bool {
        self.state.tet_alive.get(tet as usize) == Some(&true)
    }

    fn live_face_neighbours(&self, tet: u32) -> usize {
        let neighbours = self.table.tet_neighbours().get(tet as usize);
        neighbours.map_or(0, |n| n.iter().filter(|&&o| self.is_alive(o)).count())
    }

    /// The current boundary surface: every face of a live tet whose
    /// neighbour across it is absent or removed, outward right-hand normal.
    /// Bounded by `4 × tet_count`.
    pub fn surface_triangles(&self) -> impl Iterator<Item = [u32; 3]> + '_ {
        let tets = self.table.tets().iter().zip(self.table.tet_neighbours());
        tets.zip(self.state.tet_alive.iter())
            .filter(|(_, alive)| **alive)
            .flat_map(move |((tet, neighbours), _)| {
                tet_face_vertices(*tet)
                    .into_iter()
                    .zip(*neighbours)
                    .filter(move |(_, other)| !self.is_alive(*other))
                    .map(|(face, _)| face)
            })
    }

    /// Subtracts tet `t`'s blocks and mass shares and marks it removed. A
    /// vertex left without live tets is detached: mass, vertex tensor and
    /// velocity set to exactly zero (it keeps still).
    fn subtract(&mut self, t: usize) {
        let (Some(&tet), Some(edges), Some((a, volume))) = (
            self.table.tets().get(t),
            self.table.tet_edges().get(t),
            self.table.tet_shape(t),
        ) else {
            return;
        };
        let (lambda, mu) = self.table.lame();
        let share = T::of_f64(self.table.density_kg_m3()) * volume / T::of_f64(4.0);
        let s = &mut self.state;
        for (&v, aj) in tet.iter().zip(&a) {
            let v = v as usize;
            let block = stiffness_block(aj, aj, volume, lambda, mu);
            let (Some(k), Some(m), Some(count), Some(vel)) = (
                s.vertex_tensors.get_mut(v),
                s.masses_kg.get_mut(v),
                s.live_tets.get_mut(v),
                s.velocity_m_s.get_mut(v),
            ) else {
                continue;
            };
            *count = count.saturating_sub(1);
            if *count == 0 {
                *k = [T::zero(); 9];
                *m = T::zero();
                *vel = [T::zero(); 3];
            } else {
                subtract_block(k, &block);
                *m -= share;
            }
        }
        for ([j, l], &e) in TET_EDGE_PAIRS.into_iter().zip(edges) {
            // The stored edge tensor couples its lower vertex (row) to its higher.
            let (Some(&vj), Some(&vl)) = (tet.get(j), tet.get(l)) else {
                continue;
            };
            let (row, col) = if vj < vl { (j, l) } else { (l, j) };
            if let (Some(ar), Some(ac), Some(k)) =
                (a.get(row), a.get(col), s.edge_tensors.get_mut(e as usize))
            {
                subtract_block(k, &stiffness_block(ar, ac, volume, lambda, mu));
            }
        }
        if let Some(alive) = s.tet_alive.get_mut(t) {
            *alive = false;
        }
    }
}

/// `k −= block` for a row-major stored 3×3 tensor.
fn subtract_block<T: Real>(k: &mut [T; 9], block: &nalgebra::Matrix3<T>) {
    for (e, x) in k.iter_mut().enumerate() {
        if let Some(b) = block.get((e / 3, e % 3)) {
            *x -= *b;
        }
    }
}
