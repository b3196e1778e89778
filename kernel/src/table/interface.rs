//! The validated, zero-copy view of an interface table: the pre-computed
//! region of a hybrid model condensed onto its connection nodes (RR-3510
//! §6.2, MODELS.md §2 for the linear elasticity it condenses).

use super::LoadError;
use super::container::{Container, check_finite};
use super::format::{FIXED_SLOT, RawHeader, SectionKind, TableKind};
use super::hierarchical::HierarchicalBlocks;
use crate::Real;
use crate::math::dense::dot;

/// How an interface table stores its condensed stiffness `S` (N/m).
#[derive(Clone, Copy, Debug)]
pub enum CondensedStiffness<'a, T: Real> {
    /// The dense `3c × 3c` matrix ([`SectionKind::CondensedStiffness`]),
    /// row `r = 3j + a` the `c` triples at `r·c .. (r + 1)·c`.
    Dense(&'a [[T; 3]]),
    /// A hierarchical matrix over a cluster tree of the connection nodes
    /// (the hierarchy sections, [`super::format::hierarchy`], with the
    /// touchable vertices read as the connection nodes in leaf order) and
    /// the order that maps it to the connection nodes
    /// ([`SectionKind::HierarchyOrder`]).
    Hierarchical {
        /// The blocks of `S` in hierarchy order.
        blocks: HierarchicalBlocks<'a, T>,
        /// Per hierarchy index `i`: `[connection node at i, hierarchy index
        /// of connection node i]`.
        order: &'a [[u32; 2]],
    },
}

/// An interface table that passed every load-time check.
///
/// Invariants established by [`InterfaceTable::load`]:
/// - `c ≥ 1` connection nodes; their mesh vertices are `< N` and strictly
///   ascending, connection node `j` is tensor-mass vertex `j`, and that is
///   the `dynamic-vertex` entry of its mesh vertex;
/// - every float is finite, and every diagonal entry of the condensed
///   stiffness is positive (a Schur complement of a positive definite
///   stiffness is positive definite);
/// - the condensed stiffness is either dense (the `3c × 3c` matrix) or
///   hierarchical (the hierarchy sections over `c` connection nodes, their
///   invariants [`HierarchicalBlocks`]'s, and a hierarchy order that is a
///   permutation of `0..c` stored with its inverse), never both;
/// - section lengths match the header's counts: the response over every
///   free vertex (`3F × 3c`, [`SectionKind::ConnectionResponse`]) or over
///   the touchable ones only (`3S × 3c`, [`SectionKind::TouchableResponse`],
///   one of the two, never both), `F` load displacements and `c` load
///   forces, `N` dynamic-vertex entries.
///
/// That the table belongs with a given pre-computed and tensor-mass table
/// is checked where the three meet ([`crate::hybrid::HybridModel::new`]).
#[derive(Clone, Copy, Debug)]
pub struct InterfaceTable<'a, T: Real> {
    header: RawHeader,
    checksum: u32,
    connections: &'a [[u32; 2]],
    condensed: CondensedStiffness<'a, T>,
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
        let (response, response_rows) = connection_response(&c)?;
        // The handle a C caller holds a table in has a fixed size: the row
        // count is the response's length over `3c`, not a field of its own.
        let table = Self {
            header: c.header,
            checksum: c.checksum,
            connections: c.section(SectionKind::ConnectionVertex)?,
            condensed: condensed_stiffness(&c)?,
            response,
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
        if let CondensedStiffness::Dense(dense) = table.condensed {
            check_finite(SectionKind::CondensedStiffness, dense)?;
        }
        let response_kind = if response_rows == table.free_count() {
            SectionKind::ConnectionResponse
        } else {
            SectionKind::TouchableResponse
        };
        check_finite(response_kind, table.response)?;
        check_finite(SectionKind::LoadDisplacement, table.load_displacement)?;
        check_finite(SectionKind::LoadForce, table.load_force)?;
        let mut previous: Option<u32> = None;
        for (j, &[vertex, dynamic]) in table.connections.iter().enumerate() {
            let ascending = previous.is_none_or(|p| vertex > p);
            let mapped = table.dynamic_vertex.get(vertex as usize) == Some(&dynamic);
            let diagonal = table
                .condensed_block(j, j)
                .is_some_and(|d| [d[0], d[4], d[8]].iter().all(|&x| x > T::zero()));
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

    /// The condensed stiffness as stored.
    pub fn condensed(&self) -> &CondensedStiffness<'a, T> {
        &self.condensed
    }

    /// The block `S_jk` (N/m, row-major 3×3: element `3a + b` is
    /// `S[(j, a), (k, b)]`) of connection nodes `j` and `k`; `None` out of
    /// range. Not for the step path (a hierarchical table finds it by two
    /// binary searches; the product is [`Self::add_condensed_product`]).
    pub fn condensed_block(&self, j: usize, k: usize) -> Option<[T; 9]> {
        let c = self.connection_count();
        match self.condensed {
            CondensedStiffness::Dense(dense) => {
                let mut out = [T::zero(); 9];
                for (a, row) in out.chunks_exact_mut(3).enumerate() {
                    let at = (3 * j + a).checked_mul(c)?.checked_add(k)?;
                    row.copy_from_slice(dense.get(at).filter(|_| j < c && k < c)?);
                }
                Some(out)
            }
            CondensedStiffness::Hierarchical { blocks, order } => {
                let position = |n: usize| order.get(n).map(|&[_, p]| p as usize);
                blocks.block(position(j)?, position(k)?)
            }
        }
    }

    /// `out += scale · S u` over the connection nodes (`u` and `out` hold at
    /// least `c` triples, tensor-mass vertex `j` being connection node `j`;
    /// nothing is done with fewer): `9c²` multiply-adds over contiguous rows
    /// dense, one pass over the blocks hierarchical
    /// ([`HierarchicalBlocks::products`]). No allocation, no panic.
    #[inline]
    pub fn add_condensed_product(&self, u: &[[T; 3]], scale: T, out: &mut [[T; 3]]) {
        let c = self.connection_count();
        let (Some(uc), Some(oc)) = (u.get(..c), out.get_mut(..c)) else {
            return;
        };
        match self.condensed {
            CondensedStiffness::Dense(dense) => {
                let flat = uc.as_flattened();
                let rows = dense.chunks_exact(c.max(1));
                for (o, row) in oc.as_flattened_mut().iter_mut().zip(rows) {
                    *o += scale * dot(row.as_flattened(), flat);
                }
            }
            CondensedStiffness::Hierarchical { blocks, order } => {
                let at = |i: usize| order.get(i).map(|&[node, _]| node as usize);
                blocks.products(at, uc, |slot, v| {
                    if let Some(o) = oc.get_mut(slot) {
                        for (x, &y) in o.iter_mut().zip(&v) {
                            *x += scale * y;
                        }
                    }
                });
            }
        }
    }

    /// `uᵀ S u` over the connection nodes (J for `u` in m), with the same
    /// cost and conventions as [`Self::add_condensed_product`] (`0` with
    /// fewer than `c` triples).
    #[inline]
    pub fn condensed_quadratic(&self, u: &[[T; 3]]) -> T {
        let c = self.connection_count();
        let Some(uc) = u.get(..c) else {
            return T::zero();
        };
        let mut sum = T::zero();
        match self.condensed {
            CondensedStiffness::Dense(dense) => {
                let flat = uc.as_flattened();
                for (&x, row) in flat.iter().zip(dense.chunks_exact(c.max(1))) {
                    sum += x * dot(row.as_flattened(), flat);
                }
            }
            CondensedStiffness::Hierarchical { blocks, order } => {
                let at = |i: usize| order.get(i).map(|&[node, _]| node as usize);
                blocks.products(at, uc, |slot, v| {
                    if let Some(x) = uc.get(slot) {
                        sum += x[0] * v[0] + x[1] * v[1] + x[2] * v[2];
                    }
                });
            }
        }
        sum
    }

    /// Free vertices of the pre-computed region whose response rows are
    /// stored (free indices `0..rows`): `F`, or the touchable `S` of an
    /// interface whose region is hierarchical
    /// ([`SectionKind::TouchableResponse`]).
    pub fn response_rows(&self) -> usize {
        self.response.len() / (3 * self.connection_count()).max(1)
    }

    /// Row `r = 3n + a` (free index `n` of the pre-computed table, component
    /// `a`) of the response (m/m), as `c` triples; empty out of range (`n`
    /// at or beyond [`Self::response_rows`]).
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

/// The response of the interface in `c` and the free vertices it has rows
/// for: the `3F × 3c` section or the touchable `3S × 3c` one (their lengths
/// checked against the header's counts by the container), exactly one.
fn connection_response<'a, T: Real>(c: &Container<'a>) -> Result<(&'a [[T; 3]], usize), LoadError> {
    let all = c.optional_section(SectionKind::ConnectionResponse)?;
    let touchable = c.optional_section(SectionKind::TouchableResponse)?;
    match (all, touchable) {
        (Some(all), None) => Ok((all, c.header.free_count as usize)),
        (None, Some(touchable)) => Ok((touchable, c.header.touchable_count as usize)),
        (None, None) => Err(LoadError::MissingSection {
            kind: SectionKind::ConnectionResponse,
        }),
        (Some(_), Some(_)) => Err(LoadError::BadHierarchy {
            kind: SectionKind::TouchableResponse,
            index: 0,
            what: "an interface stores the response of every free vertex or of the touchable \
                   ones, not both",
        }),
    }
}

/// The condensed stiffness of the interface in `c`: the dense section, or
/// the hierarchy sections and order (checked: [`HierarchicalBlocks`]'s
/// invariants over `c` connection nodes, the order a permutation stored
/// with its inverse); one of the two, not both.
fn condensed_stiffness<'a, T: Real>(
    c: &Container<'a>,
) -> Result<CondensedStiffness<'a, T>, LoadError> {
    let dense = c.has(SectionKind::CondensedStiffness);
    let hierarchical = c.has(SectionKind::HierarchyRecord);
    let bad = |kind, index: usize, what| LoadError::BadHierarchy {
        kind,
        index: index as u64,
        what,
    };
    match (dense, hierarchical) {
        (true, false) => Ok(CondensedStiffness::Dense(
            c.section(SectionKind::CondensedStiffness)?,
        )),
        (false, false) => Err(LoadError::MissingSection {
            kind: SectionKind::CondensedStiffness,
        }),
        (true, true) => Err(bad(
            SectionKind::CondensedStiffness,
            0,
            "an interface stores its condensed stiffness dense or hierarchical, not both",
        )),
        (false, true) => {
            let n = c.header.connection_count as usize;
            let blocks = HierarchicalBlocks::load(c, n, false)?;
            let order: &'a [[u32; 2]] = c.section(SectionKind::HierarchyOrder)?;
            // `inverse(node(i)) = i` for every `i`: `node` is injective on
            // `0..c` into `0..c`, a permutation, and `inverse` its inverse.
            let node = |i: usize| order.get(i).map(|&[node, _]| node as usize);
            let inverse = |j: usize| order.get(j).map(|&[_, p]| p as usize);
            if let Some(i) = (0..n).find(|&i| node(i).and_then(inverse) != Some(i)) {
                return Err(bad(
                    SectionKind::HierarchyOrder,
                    i,
                    "not a permutation of the connection nodes stored with its inverse",
                ));
            }
            Ok(CondensedStiffness::Hierarchical { blocks, order })
        }
    }
}
