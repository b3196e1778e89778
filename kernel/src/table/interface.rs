//! The validated, zero-copy view of an interface table: the pre-computed
//! region of a hybrid model condensed onto its connection nodes (RR-3510
//! §6.2, MODELS.md §2 for the linear elasticity it condenses).

use super::LoadError;
use super::container::{Container, check_finite};
use super::format::{FIXED_SLOT, RawHeader, SectionKind, TableKind};
use crate::Real;

/// An interface table that passed every load-time check.
///
/// Invariants established by [`InterfaceTable::load`]:
/// - `c ≥ 1` connection nodes; their mesh vertices are `< N` and strictly
///   ascending, connection node `j` is tensor-mass vertex `j`, and that is
///   the `dynamic-vertex` entry of its mesh vertex;
/// - every float is finite, and every diagonal entry of the condensed
///   stiffness is positive (a Schur complement of a positive definite
///   stiffness is positive definite);
/// - section lengths match the header's counts: the `3c × 3c` condensed
///   stiffness and `3F × 3c` response, `F` load displacements and `c` load
///   forces, `N` dynamic-vertex entries.
///
/// That the table belongs with a given pre-computed and tensor-mass table
/// is checked where the three meet ([`crate::hybrid::HybridModel::new`]).
#[derive(Clone, Copy, Debug)]
pub struct InterfaceTable<'a, T: Real> {
    header: RawHeader,
    checksum: u32,
    connections: &'a [[u32; 2]],
    condensed: &'a [[T; 3]],
    response: &'a [[T; 3]],
    load_displacement: &'a [[T; 3]],
    load_force: &'a [[T; 3]],
    dynamic_vertex: &'a [u32],
    region_checksums: [u32; 2],
}

impl<'a, T: Real> InterfaceTable<'a, T> {
    /// Validates `bytes` once and returns the view (format in
    /// [`super::format`]). Cost: linear in the table size. Not for the step
    /// path.
    pub fn load(bytes: &'a [u8]) -> Result<Self, LoadError> {
        let c = Container::parse::<T>(bytes, TableKind::Interface)?;
        let table = Self {
            header: c.header,
            checksum: c.checksum,
            connections: c.section(SectionKind::ConnectionVertex)?,
            condensed: c.section(SectionKind::CondensedStiffness)?,
            response: c.section(SectionKind::ConnectionResponse)?,
            load_displacement: c.section(SectionKind::LoadDisplacement)?,
            load_force: c.section(SectionKind::LoadForce)?,
            dynamic_vertex: c.section(SectionKind::DynamicVertex)?,
            region_checksums: c
                .section::<[u32; 2]>(SectionKind::RegionChecksums)?
                .first()
                .copied()
                .ok_or(LoadError::SectionSize {
                    kind: SectionKind::RegionChecksums,
                })?,
        };
        check_finite(SectionKind::CondensedStiffness, table.condensed)?;
        check_finite(SectionKind::ConnectionResponse, table.response)?;
        check_finite(SectionKind::LoadDisplacement, table.load_displacement)?;
        check_finite(SectionKind::LoadForce, table.load_force)?;
        let mut previous: Option<u32> = None;
        for (j, &[vertex, dynamic]) in table.connections.iter().enumerate() {
            let ascending = previous.is_none_or(|p| vertex > p);
            let mapped = table.dynamic_vertex.get(vertex as usize) == Some(&dynamic);
            let diagonal = (0..3).all(|a| {
                table
                    .condensed_row(3 * j + a)
                    .get(j)
                    .and_then(|s| s.get(a))
                    .is_some_and(|&d| d > T::zero())
            });
            if !(ascending && mapped && dynamic == j as u32 && diagonal) {
                return Err(LoadError::BadConnection {
                    connection: j as u32,
                });
            }
            previous = Some(vertex);
        }
        Ok(table)
    }

    /// The header as stored.
    pub fn header(&self) -> &RawHeader {
        &self.header
    }

    /// The table's CRC-32 trailer (checked at load): what identifies its
    /// contents, so a hybrid's interface can name the region tables it was
    /// built with.
    pub fn checksum(&self) -> u32 {
        self.checksum
    }

    /// Vertices of the whole mesh (`N`).
    pub fn vertex_count(&self) -> usize {
        self.dynamic_vertex.len()
    }

    /// Connection nodes (`c`).
    pub fn connection_count(&self) -> usize {
        self.connections.len()
    }

    /// Free vertices of the pre-computed region's table (`F`), the rows of
    /// the response.
    pub fn free_count(&self) -> usize {
        self.load_displacement.len()
    }

    /// Each connection node as `[mesh vertex, tensor-mass vertex]`.
    pub fn connections(&self) -> &'a [[u32; 2]] {
        self.connections
    }

    /// Row `r = 3j + a` of the `3c × 3c` condensed stiffness (N/m), as `c`
    /// triples (columns `3k..3k+3` in triple `k`); empty out of range.
    pub fn condensed_row(&self, r: usize) -> &'a [[T; 3]] {
        let c = self.connection_count();
        self.condensed.get(r * c..(r + 1) * c).unwrap_or(&[])
    }

    /// Row `r = 3n + a` (free index `n` of the pre-computed table, component
    /// `a`) of the `3F × 3c` response (m/m), as `c` triples; empty out of
    /// range.
    pub fn response_row(&self, r: usize) -> &'a [[T; 3]] {
        let c = self.connection_count();
        self.response.get(r * c..(r + 1) * c).unwrap_or(&[])
    }

    /// The built-in load's displacement of each free vertex of the
    /// pre-computed region with the connection nodes at rest, m.
    pub fn load_displacement_m(&self) -> &'a [[T; 3]] {
        self.load_displacement
    }

    /// The force the built-in load passes to each connection node, N.
    pub fn load_force_n(&self) -> &'a [[T; 3]] {
        self.load_force
    }

    /// The tensor-mass vertex of mesh vertex `vertex`; `None` for a vertex of
    /// the pre-computed region only, or out of range.
    pub fn dynamic_vertex(&self, vertex: u32) -> Option<u32> {
        self.dynamic_vertex
            .get(vertex as usize)
            .copied()
            .filter(|&d| d != FIXED_SLOT)
    }

    /// The CRC-32 trailers of the pre-computed and the tensor-mass region
    /// tables this interface was built with.
    pub fn region_checksums(&self) -> [u32; 2] {
        self.region_checksums
    }

    /// The `dynamic-vertex` section as stored ([`FIXED_SLOT`] for a vertex
    /// of the pre-computed region only).
    pub fn dynamic_vertices(&self) -> &'a [u32] {
        self.dynamic_vertex
    }
}
