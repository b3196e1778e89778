//! [`CondensedRegion`]: the pre-computed region of a hybrid model condensed
//! onto its connection nodes, coupled to a tensor-mass model: its
//! contacts, the forces it passes to the connection nodes, its field.

use core::fmt;

use nalgebra::Vector3;

use crate::Real;
use crate::math::dense::{axpy, dot};
use crate::precomputed::{
    AsConstraint, Constraint, ContactError, ContactPoint, ContactSolution, DisplacementError,
    PrecomputedModel,
};
use crate::table::{InterfaceTable, PrecomputedTable, VertexSlot};
use crate::tensor_mass::{Fault, TensorMassModel, VertexMode};

/// The hybrid model's own buffers (static arrays on firmware).
pub struct HybridBuffers<'s, T> {
    /// One per connection node (`c`): the force the pre-computed region's
    /// load and contacts pass to it, N.
    pub passed_force_n: &'s mut [[T; 3]],
    /// One per free vertex of the pre-computed table (`F`, its free index
    /// order): the displacement the connection nodes and the load give it,
    /// m ([`CondensedRegion::update_background`]).
    pub background_m: &'s mut [[T; 3]],
}

/// The three tables or the buffers of a hybrid model do not belong together.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HybridError {
    /// A buffer has the wrong length.
    Buffer {
        /// Which buffer.
        name: &'static str,
        /// Entries the tables require.
        expected: usize,
        /// Entries given.
        found: usize,
    },
    /// The tables disagree: what, and at which mesh vertex if at one.
    Mismatch {
        /// What disagrees.
        what: &'static str,
        /// The mesh vertex, `None` for a count or the whole table.
        vertex: Option<u32>,
    },
}

impl fmt::Display for HybridError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            HybridError::Buffer {
                name,
                expected,
                found,
            } => write!(
                f,
                "buffer {name} holds {found} entries, the tables need {expected}"
            ),
            HybridError::Mismatch { what, vertex } => {
                write!(
                    f,
                    "the interface table does not belong with the region tables: {what}"
                )?;
                match vertex {
                    Some(v) => write!(f, " (vertex {v})"),
                    None => Ok(()),
                }
            }
        }
    }
}

impl core::error::Error for HybridError {}

/// Why [`CondensedRegion::displacements`] wrote nothing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FieldError {
    /// The output buffer does not hold one entry per mesh vertex.
    Length(DisplacementError),
    /// The tensor-mass region is faulted: its state cannot be read.
    Faulted(Fault),
}

impl fmt::Display for FieldError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FieldError::Length(e) => e.fmt(f),
            FieldError::Faulted(fault) => write!(f, "dynamic region faulted: {fault}"),
        }
    }
}

impl core::error::Error for FieldError {}

/// The pre-computed region of a hybrid model over its validated table (the
/// connection nodes fixed in it, numbered as the whole mesh) and the
/// interface that condenses it onto the connection nodes, coupled to the
/// tensor-mass model of the other region (module docs: [`crate::hybrid`]).
/// Its methods take that model: it holds no copy of its state.
///
/// Costs: per force evaluation of the tensor-mass model, `9c²`
/// multiply-adds (the coupling term). Per physics update, for contacts on
/// this region: [`Self::update_background`] over the touchable rows
/// (`9·S·c`) and [`Self::pass_contact_forces`] (`27·c` per contact). Per
/// tick: [`Self::contact_forces`], the pre-computed solve (`O(m³)`).
pub struct CondensedRegion<'a, 's, T: Real> {
    precomputed: PrecomputedModel<'a, T>,
    interface: InterfaceTable<'a, T>,
    background_m: &'s mut [[T; 3]],
}

impl<'a, 's, T: Real> CondensedRegion<'a, 's, T> {
    /// Couples `dynamic` to the pre-computed region of `precomputed` through
    /// `interface`, after checking that the three belong together: the
    /// region tables are the ones the interface was built with (their
    /// CRC-32 trailers, recorded in it: same mesh, partition and
    /// materials), one vertex numbering (the interface's and the pre-computed table's vertex
    /// counts, free counts and touchable counts agree), every vertex of the
    /// tensor-mass table mapped from exactly one mesh vertex at the same
    /// rest position and fixed in the pre-computed table, every connection
    /// node free in the tensor-mass model, a response over the touchable
    /// rows only with a hierarchical region table, and the buffers' lengths. The
    /// background starts at the load's displacement with the connection
    /// nodes at rest.
    ///
    /// Cost: linear in the tables' vertices. Not for the step path.
    pub fn couple(
        dynamic: &mut TensorMassModel<'a, 's, T>,
        precomputed: PrecomputedTable<'a, T>,
        interface: InterfaceTable<'a, T>,
        buffers: HybridBuffers<'s, T>,
    ) -> Result<Self, HybridError> {
        let mismatch = |what, vertex| HybridError::Mismatch { what, vertex };
        if interface.region_checksums() != [precomputed.checksum(), dynamic.table().checksum()] {
            return Err(mismatch(
                "the region tables are not the ones it was built with (checksums differ)",
                None,
            ));
        }
        let n = precomputed.vertex_count();
        if interface.vertex_count() != n {
            return Err(mismatch("vertex count", None));
        }
        if interface.free_count() != precomputed.free_count()
            || interface.header().touchable_count as usize != precomputed.touchable_count()
        {
            return Err(mismatch(
                "free or touchable count of the pre-computed region",
                None,
            ));
        }
        // A response over the touchable rows only leaves the interior
        // vertices without a background: only a region that does not move
        // them either (a hierarchical table, its interior part dropped)
        // goes with it, so that the field never mixes the two.
        let touchable_rows = interface.response_rows() < interface.free_count();
        if touchable_rows && !precomputed.surface_blocks().encoding().is_hierarchical() {
            return Err(mismatch(
                "a response over the touchable rows only needs a hierarchical pre-computed region",
                None,
            ));
        }
        let dynamic_table = *dynamic.table();
        let mut mapped = 0usize;
        for (v, p) in precomputed.rest_positions().iter().enumerate() {
            let vertex = v as u32;
            let Some(d) = interface.dynamic_vertex(vertex) else {
                continue;
            };
            mapped += 1;
            let same_place = dynamic_table.rest_positions().get(d as usize) == Some(p);
            if !same_place {
                return Err(mismatch("rest position of a dynamic vertex", Some(vertex)));
            }
            if !matches!(precomputed.slot(vertex), Some(VertexSlot::Fixed)) {
                return Err(mismatch(
                    "dynamic vertex free in the pre-computed region",
                    Some(vertex),
                ));
            }
        }
        if mapped != dynamic_table.vertex_count() {
            return Err(mismatch("dynamic vertex count", None));
        }
        for &[vertex, d] in interface.connections() {
            if dynamic.modes().get(d as usize) != Some(&VertexMode::Free) {
                return Err(mismatch(
                    "connection node not free in the dynamic region",
                    Some(vertex),
                ));
            }
        }
        let c = interface.connection_count();
        let check = |name, expected: usize, found: usize| {
            (expected == found)
                .then_some(())
                .ok_or(HybridError::Buffer {
                    name,
                    expected,
                    found,
                })
        };
        check("passed_force_n", c, buffers.passed_force_n.len())?;
        check(
            "background_m",
            interface.free_count(),
            buffers.background_m.len(),
        )?;
        copy(buffers.passed_force_n, interface.load_force_n());
        copy(buffers.background_m, interface.load_displacement_m());
        dynamic.couple(interface, buffers.passed_force_n);
        Ok(Self {
            precomputed: PrecomputedModel::new(precomputed),
            interface,
            background_m: buffers.background_m,
        })
    }

    /// The pre-computed region's model (connection nodes fixed in it).
    pub fn precomputed(&self) -> &PrecomputedModel<'a, T> {
        &self.precomputed
    }

    /// The interface table.
    pub fn interface(&self) -> &InterfaceTable<'a, T> {
        &self.interface
    }

    /// Back to rest with `dynamic` (reset by the caller): no contact force
    /// passed, the background at the load's displacement.
    pub fn reset(&mut self, dynamic: &mut TensorMassModel<'a, 's, T>) {
        self.pass_contact_forces::<1>(dynamic, None);
        copy(self.background_m, self.interface.load_displacement_m());
    }

    /// Recomputes the background of the pre-computed free rows `0..rows`
    /// (all of them for `rows ≥ F`; the touchable ones, which contacts
    /// read, for `rows = S`): `b_n = K_ii⁻¹ f_n + Σ_j H_nj u_j`, m, from the
    /// connection displacements of `dynamic`. `9c` multiply-adds per row.
    /// Only the rows the interface stores are recomputed
    /// ([`InterfaceTable::response_rows`]: the touchable ones of a
    /// hierarchical region, whose interior rows keep the load's
    /// displacement). A faulted model leaves the background as it was.
    pub fn update_background(
        &mut self,
        dynamic: &TensorMassModel<'_, '_, T>,
        rows: usize,
    ) -> Result<(), Fault> {
        let u = dynamic.displacements_m()?;
        let interface = &self.interface;
        let backgrounds = self
            .background_m
            .iter_mut()
            .zip(interface.load_displacement_m())
            .enumerate()
            .take(rows.min(interface.response_rows()));
        for (n, (b, load)) in backgrounds {
            *b = (Vector3::from(*load) + response(interface, n, u)).into();
        }
        Ok(())
    }

    /// The background of each pre-computed free vertex (see
    /// [`Self::update_background`]), m, by free index.
    pub fn background_m(&self) -> &[[T; 3]] {
        self.background_m
    }

    /// Sets the force this region passes to the connection nodes of
    /// `dynamic` to that of its load plus the contacts of `solution`
    /// (`None`: no contact): `p_j = Hᵀ f_load + Σ_q Σ_a β_a H_{a j}ᵀ g_q`
    /// (N). Takes effect at the next force evaluation. `27c` multiply-adds
    /// per contact.
    pub fn pass_contact_forces<const M: usize>(
        &self,
        dynamic: &mut TensorMassModel<'_, '_, T>,
        solution: Option<&ContactSolution<T, M>>,
    ) {
        let interface = &self.interface;
        let Some(passed) = dynamic.passed_force_mut() else {
            return;
        };
        copy(passed, interface.load_force_n());
        let Some(solution) = solution else {
            return;
        };
        let passed = passed.as_flattened_mut();
        for (point, g) in solution.resolved() {
            for (k, beta) in point.terms() {
                // p += H_kᵀ (β g): row 3k + a of H scaled by β g_a.
                for (a, &ga) in g.iter().enumerate() {
                    let row = interface.response_row(3 * k.get() + a);
                    axpy(ga * beta, row.as_flattened(), passed);
                }
            }
        }
    }

    /// Contact forces for contacts on this region (MODELS.md §2 with the
    /// connection nodes held): each contact's imposed displacement less the
    /// background at its point (the displacement the connection nodes of
    /// `dynamic` and the load give it) is solved with the compliance `C⁰`.
    /// Reads the background of the touchable rows: call
    /// [`Self::update_background`] with at least `S` rows after each
    /// physics update. Bounded: `O(M³)` like [`PrecomputedModel::contact_forces`].
    pub fn contact_forces<const M: usize>(
        &self,
        dynamic: &TensorMassModel<'_, '_, T>,
        contacts: &[impl AsConstraint<T>],
    ) -> Result<ContactSolution<T, M>, ContactError> {
        if contacts.len() > M {
            return Err(ContactError::TooManyContacts {
                given: contacts.len(),
                capacity: M,
            });
        }
        let u = dynamic.displacements_m().unwrap_or(&[]);
        let mut relative = [Constraint::at_vertex(0, Vector3::zeros()); M];
        for (r, contact) in relative.iter_mut().zip(contacts) {
            let point = contact.point();
            *r = Constraint {
                point,
                displacement_m: contact.displacement_m() - self.background_at(u, point),
            };
        }
        let relative = relative.get(..contacts.len()).unwrap_or(&[]);
        self.precomputed.contact_forces::<M>(relative)
    }

    /// The displacement of every mesh vertex (m, mesh vertex order): the
    /// tensor-mass region's own (from `dynamic`), and in this region the
    /// background plus the response to the contacts of `solution` (`None`:
    /// no contact). A hierarchical region's interior vertices (free
    /// indices at or beyond [`InterfaceTable::response_rows`]) report zero,
    /// as a hierarchical pre-computed table's do: neither their compliance
    /// nor their response to the connection nodes is stored. `9c`
    /// multiply-adds per pre-computed free vertex with a stored response
    /// row, plus [`PrecomputedModel::displacements`]. Not needed by the
    /// haptic path.
    pub fn displacements<const M: usize>(
        &self,
        dynamic: &TensorMassModel<'_, '_, T>,
        solution: Option<&ContactSolution<T, M>>,
        out: &mut [[T; 3]],
    ) -> Result<(), FieldError> {
        let u = dynamic.displacements_m().map_err(FieldError::Faulted)?;
        match solution {
            Some(s) => self.precomputed.displacements(s, out),
            None => {
                let expected = self.interface.vertex_count();
                if out.len() == expected {
                    out.fill([T::zero(); 3]);
                    Ok(())
                } else {
                    Err(DisplacementError {
                        expected,
                        found: out.len(),
                    })
                }
            }
        }
        .map_err(FieldError::Length)?;
        let table = self.precomputed.table();
        for (n, (&v, load)) in table
            .free_vertices()
            .iter()
            .zip(self.interface.load_displacement_m())
            .enumerate()
            .take(self.interface.response_rows())
        {
            if let Some(o) = out.get_mut(v as usize) {
                let b = Vector3::from(*load) + response(&self.interface, n, u);
                *o = (Vector3::from(*o) + b).into();
            }
        }
        for (o, &d) in out.iter_mut().zip(self.interface.dynamic_vertices()) {
            if let Some(ud) = u.get(d as usize) {
                *o = *ud;
            }
        }
        Ok(())
    }

    /// The displacement of mesh vertex `v` as the surface sees it (m): a
    /// tensor-mass vertex's from `u` (the model's displacements), a free
    /// vertex's background as last refreshed (the touchable rows, which
    /// the surface's triangles use, at every physics update; an interior
    /// row since its last full refresh, which no triangle uses), `None`
    /// (zero) for a fixed vertex.
    pub fn surface_displacement<'u>(&'u self, u: &'u [[T; 3]], v: u32) -> Option<&'u [T; 3]> {
        match (
            self.interface.dynamic_vertex(v),
            self.precomputed.table().slot(v),
        ) {
            (Some(d), _) => u.get(d as usize),
            (None, Some(VertexSlot::Free(n))) => self.background_m.get(n.get()),
            _ => None,
        }
    }

    /// The background at a contact point: `Σ_a β_a b(v_a)` over
    /// [`Self::surface_displacement`] (with `u` empty, a faulted model's,
    /// the tensor-mass vertices count zero; the caller's solve refuses a
    /// faulted tissue's contacts).
    fn background_at(&self, u: &[[T; 3]], point: ContactPoint<T>) -> Vector3<T> {
        let (vertices, weights) = match point {
            ContactPoint::Vertex(v) => ([v, v, v], [T::one(), T::zero(), T::zero()]),
            ContactPoint::Triangle { vertices, weights } => (vertices, weights),
        };
        let mut sum = Vector3::zeros();
        for (&v, &w) in vertices.iter().zip(&weights) {
            if let Some(b) = self.surface_displacement(u, v) {
                sum += Vector3::from(*b) * w;
            }
        }
        sum
    }
}

/// `Σ_j H_nj u_j` (m): row `n` of the response applied to the connection
/// displacements (the first `c` of the tensor-mass displacements `u`).
fn response<T: Real>(interface: &InterfaceTable<'_, T>, n: usize, u: &[[T; 3]]) -> Vector3<T> {
    let uc = u
        .get(..interface.connection_count())
        .unwrap_or(&[])
        .as_flattened();
    let row = |a: usize| dot(interface.response_row(3 * n + a).as_flattened(), uc);
    Vector3::new(row(0), row(1), row(2))
}

/// Copies the common prefix of `src` into `dst`.
fn copy<E: Copy>(dst: &mut [E], src: &[E]) {
    for (d, s) in dst.iter_mut().zip(src) {
        *d = *s;
    }
}
