//! Caller-provided mutable state, its validation, and the fault state.

use core::fmt;

use super::edges::{EdgeGroup, edge_group_capacity};
use super::stvk_terms::TermArraysMut;
use crate::Real;
use crate::table::TensorMassTable;

/// How a vertex moves.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum VertexMode {
    /// Integrated from the forces.
    #[default]
    Free,
    /// Fixed by the table: zero displacement, never released.
    Fixed,
    /// Held at a displacement the caller imposes (tool contact, coupling).
    Imposed,
}

/// Storage for the mutable state of a [`super::TensorMassModel`], provided by
/// the caller (static arrays on firmware, vectors on the host). Lengths are
/// checked once by [`super::TensorMassModel::new`]: `N` = vertices, `E` =
/// edges, `M` = tets of the table, `G` = [`Self::edge_group_count`].
pub struct StateBuffers<'s, T> {
    /// `N`: current vertex tensors `K_ii`, N/m (change when tets are removed).
    pub vertex_tensors: &'s mut [[T; 9]],
    /// `G`: current edge tensors `K_ij`, N/m, in groups of 4 edges of one
    /// row (`super::edges`; written from the table by the model).
    pub edge_groups: &'s mut [EdgeGroup<T>],
    /// `N + 1`: the first of each row's [`Self::edge_groups`], and their
    /// end.
    pub edge_group_starts: &'s mut [u32],
    /// `N`: current lumped masses, kg.
    pub masses_kg: &'s mut [T],
    /// `M`: `false` once a tet is removed.
    pub tet_alive: &'s mut [bool],
    /// `N`: live tets around each vertex (a vertex left with none is
    /// detached: zero mass and stiffness, it keeps still).
    pub live_tets: &'s mut [u32],
    /// `N`: how each vertex moves.
    pub modes: &'s mut [VertexMode],
    /// `N`: displacement from rest `u = p − p_rest`, m.
    pub displacement_m: &'s mut [[T; 3]],
    /// `N`: velocity, m/s.
    pub velocity_m_s: &'s mut [[T; 3]],
    /// `N`: displacement one step earlier, m (central-difference scheme).
    pub previous_displacement_m: &'s mut [[T; 3]],
    /// `N`: external force per vertex, N.
    pub external_force_n: &'s mut [[T; 3]],
    /// `N`: force scratch, N.
    pub force_n: &'s mut [[T; 3]],
    /// `4N` for RK4 (stage displacement, stage velocity, and the two weighted
    /// sums), or empty when RK4 is not needed (saves `48N` bytes in f32).
    pub rk4_scratch: &'s mut [[T; 3]],
    /// Current St Venant-Kirchhoff split terms (Picinbono table 1) for
    /// [`super::StvkForm::Tensors`]: one entry per vertex, edge, mesh
    /// triangle and tet of the table, or all four empty when that form is
    /// not used (saves `4·(4N + 16E + 15T + 3M)` bytes in f32).
    pub stvk_terms: TermArraysMut<'s, T>,
}

/// A [`StateBuffers`] field has the wrong length for the table, or a
/// parameter is out of range.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StateError {
    /// A buffer's length differs from what the table needs.
    BufferLength {
        /// The [`StateBuffers`] field.
        buffer: &'static str,
        /// Entries the table needs.
        expected: usize,
        /// Entries given.
        found: usize,
    },
    /// A [`super::DynamicParams`] value is non-finite or negative.
    BadParameter {
        /// Which parameter.
        name: &'static str,
    },
    /// [`super::StvkForm::Tensors`] was asked for without
    /// [`StateBuffers::stvk_terms`].
    NoTermBuffers,
}

impl fmt::Display for StateError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BufferLength {
                buffer,
                expected,
                found,
            } => write!(
                f,
                "state buffer {buffer} holds {found} entries, the table needs {expected}"
            ),
            Self::BadParameter { name } => write!(f, "parameter {name} must be finite and >= 0"),
            Self::NoTermBuffers => {
                f.write_str("the tensors form of St Venant-Kirchhoff needs the stvk_terms buffers")
            }
        }
    }
}

impl core::error::Error for StateError {}

impl<T: Real> StateBuffers<'_, T> {
    /// `G`, the length of [`Self::edge_groups`] for `table`: at most
    /// `⌈(E + 3 k) / 4⌉` groups of 4 edges, `k` the vertices with at most 2
    /// table edges to higher vertices (on `palpate bench`'s 6144-tet cylinder, 2083
    /// groups for 8160 edges, of which the layout fills 2051). Cost: one
    /// pass over the `N` rows.
    pub fn edge_group_count(table: &TensorMassTable<'_, T>) -> usize {
        edge_group_capacity(table)
    }

    /// `true` if the split-term buffers are provided (non-empty vertex terms).
    pub(crate) fn has_stvk_terms(&self) -> bool {
        !self.stvk_terms.vertex.is_empty()
    }

    /// Checks every length against `table`.
    pub(crate) fn check(&self, table: &TensorMassTable<'_, T>) -> Result<(), StateError> {
        let n = table.vertex_count();
        let rk4 = if self.rk4_scratch.is_empty() {
            0
        } else {
            4 * n
        };
        let terms = &self.stvk_terms;
        let has_terms = usize::from(self.has_stvk_terms());
        let lengths = [
            ("vertex_tensors", self.vertex_tensors.len(), n),
            (
                "edge_groups",
                self.edge_groups.len(),
                Self::edge_group_count(table),
            ),
            ("edge_group_starts", self.edge_group_starts.len(), n + 1),
            ("masses_kg", self.masses_kg.len(), n),
            ("tet_alive", self.tet_alive.len(), table.tet_count()),
            ("live_tets", self.live_tets.len(), n),
            ("modes", self.modes.len(), n),
            ("displacement_m", self.displacement_m.len(), n),
            ("velocity_m_s", self.velocity_m_s.len(), n),
            (
                "previous_displacement_m",
                self.previous_displacement_m.len(),
                n,
            ),
            ("external_force_n", self.external_force_n.len(), n),
            ("force_n", self.force_n.len(), n),
            ("rk4_scratch", self.rk4_scratch.len(), rk4),
            ("stvk_terms.vertex", terms.vertex.len(), n * has_terms),
            (
                "stvk_terms.edge",
                terms.edge.len(),
                table.edge_count() * has_terms,
            ),
            (
                "stvk_terms.triangle",
                terms.triangle.len(),
                table.mesh_triangles().len() * has_terms,
            ),
            (
                "stvk_terms.tet",
                terms.tet.len(),
                table.tet_count() * has_terms,
            ),
        ];
        match lengths
            .iter()
            .find(|(_, found, expected)| found != expected)
        {
            Some(&(buffer, found, expected)) => Err(StateError::BufferLength {
                buffer,
                expected,
                found,
            }),
            None => Ok(()),
        }
    }
}

/// Why the model stopped producing numbers. Detected inside the step, before
/// the new state can be read; cleared only by
/// [`super::TensorMassModel::reset`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fault {
    /// A displacement or velocity became NaN or infinite at this vertex.
    NonFinite {
        /// Vertex index.
        vertex: u32,
    },
    /// A displacement exceeded [`super::Limits::max_displacement_m`].
    DisplacementBound {
        /// Vertex index.
        vertex: u32,
    },
    /// The kinetic energy exceeded [`super::Limits::max_kinetic_energy_j`].
    KineticEnergyBound,
}

impl fmt::Display for Fault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NonFinite { vertex } => write!(f, "vertex {vertex}: non-finite state"),
            Self::DisplacementBound { vertex } => {
                write!(f, "vertex {vertex}: displacement beyond the bound")
            }
            Self::KineticEnergyBound => f.write_str("kinetic energy beyond the bound"),
        }
    }
}

impl core::error::Error for Fault {}
