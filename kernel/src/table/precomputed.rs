//! The validated, zero-copy view of a pre-computed table.

use nalgebra::Matrix3;

use super::LoadError;
use super::collision::{SurfaceIndex, SurfaceSections};
use super::compressed::{ComplianceBlocks, load_parts};
use super::container::{Container, check_finite, check_tet_materials};
use super::format::{
    self, CompressionRecord, FIXED_SLOT, RawHeader, SectionKind, TET_MATERIAL_LEN, TableKind,
};
use super::index::{FreeIndex, VertexIndex, VertexSlot};
use crate::Real;
use crate::math::ldlt::positive_definite3;

/// A pre-computed table that passed every load-time check; the step path
/// takes only this type.
///
/// Invariants established by [`PrecomputedTable::load`]:
/// - `vertex_slot` and `free_vertex` are inverse maps between the `N` vertices
///   and the `F` free indices; free indices `0..S` are the touchable vertices;
/// - every surface triangle's vertices are `< N`;
/// - every float is finite and every diagonal block `C_kk` is stored and
///   symmetric positive definite;
/// - a compressed compliance part (format docs, "Compressed compliance") has
///   finite positive scales, finite codes and a consistent kept-block index;
/// - every tet's Lamé coefficients have `μ > 0` and `λ > −2μ/3`;
/// - section lengths match the header's counts exactly.
#[derive(Clone, Copy, Debug)]
pub struct PrecomputedTable<'a, T: Real> {
    header: RawHeader,
    checksum: u32,
    vertex_slot: &'a [u32],
    free_vertex: &'a [u32],
    rest_positions: &'a [[T; 3]],
    triangles: &'a [[u32; 3]],
    compression: Option<CompressionRecord>,
    surface: ComplianceBlocks<'a, T>,
    interior: ComplianceBlocks<'a, T>,
    surface_index: SurfaceIndex<'a, T>,
    tet_materials: &'a [[T; TET_MATERIAL_LEN]],
}

impl<'a, T: Real> PrecomputedTable<'a, T> {
    /// Validates `bytes` once and returns the view (format in
    /// [`super::format`]): the container checks (length, magic, version,
    /// declared length, CRC-32, table kind, scalar width, header counts,
    /// material, section directory), then vertex maps, triangle indices,
    /// finite floats, the compliance encoding (dense, or coded with its
    /// scales, codes and kept blocks) and SPD diagonal compliance blocks.
    ///
    /// Cost: linear in the table size. Not for the step path.
    pub fn load(bytes: &'a [u8]) -> Result<Self, LoadError> {
        let c = Container::parse::<T>(bytes, TableKind::Precomputed)?;
        let rest_positions: &'a [[T; 3]] = c.section(SectionKind::RestPositions)?;
        let triangles: &'a [[u32; 3]] = c.section(SectionKind::SurfaceTriangles)?;
        let vertex_slot: &'a [u32] = c.section(SectionKind::VertexSlot)?;
        check_triangles(triangles, vertex_slot.len())?;
        check_finite(SectionKind::RestPositions, rest_positions)?;
        let sections = SurfaceSections {
            grid: c.section(SectionKind::SurfaceGrid)?,
            dims: c.section(SectionKind::GridDims)?,
            cell_start: c.section(SectionKind::GridCellStart)?,
            grid_vertex: c.section(SectionKind::GridVertex)?,
            vertex_triangle_start: c.section(SectionKind::VertexTriangleStart)?,
            vertex_triangle: c.section(SectionKind::VertexTriangle)?,
            planes: c.section(SectionKind::SurfacePlane)?,
            cell_triangle_start: c.section(SectionKind::CellTriangleStart)?,
            cell_triangle: c.section(SectionKind::CellTriangle)?,
        };
        let parts = load_parts(&c)?;
        let table = Self {
            header: c.header,
            checksum: c.checksum,
            vertex_slot,
            free_vertex: c.section(SectionKind::FreeVertex)?,
            rest_positions,
            triangles,
            compression: parts.record,
            surface: parts.surface,
            interior: parts.interior,
            surface_index: SurfaceIndex::new(&sections, rest_positions, triangles)?,
            tet_materials: c.section(SectionKind::TetMaterial)?,
        };
        table.check_vertex_maps()?;
        table.check_diagonal_blocks()?;
        check_tet_materials(table.tet_materials)?;
        log::debug!(
            "table loaded: {} vertices, {} free, {} touchable, {}-byte floats",
            table.vertex_count(),
            table.free_count(),
            table.touchable_count(),
            T::BYTES
        );
        Ok(table)
    }

    /// The collision index: surface vertices in a grid, triangles around
    /// each vertex (validated at load).
    pub fn surface_index(&self) -> &SurfaceIndex<'a, T> {
        &self.surface_index
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

    /// Vertices of the source mesh (`N`).
    pub fn vertex_count(&self) -> usize {
        self.vertex_slot.len()
    }

    /// Free (not fixed) vertices (`F`).
    pub fn free_count(&self) -> usize {
        self.free_vertex.len()
    }

    /// Touchable vertices: free vertices on the boundary surface (`S`).
    pub fn touchable_count(&self) -> usize {
        self.header.touchable_count as usize
    }

    /// Young's modulus of the default material (the scene's `[material]`),
    /// Pa; each tet's own is in [`Self::tet_materials`].
    pub fn young_pa(&self) -> f64 {
        self.header.young_pa
    }

    /// Poisson ratio of the default material.
    pub fn poisson(&self) -> f64 {
        self.header.poisson
    }

    /// The Lamé coefficients `[λ, μ]` (Pa) each tet of the source mesh had
    /// when the compliance was computed, in tet order (the model itself
    /// reads only the compliance).
    pub fn tet_materials(&self) -> &'a [[T; TET_MATERIAL_LEN]] {
        self.tet_materials
    }

    /// `vertex` as a checked index of this table's vertices; `None` out of
    /// range.
    pub fn vertex(&self, vertex: u32) -> Option<VertexIndex> {
        VertexIndex::new(vertex, self.vertex_count())
    }

    /// Where `vertex` stands: free (with its free index) or fixed; `None`
    /// out of range.
    pub fn slot(&self, vertex: u32) -> Option<VertexSlot> {
        // The section's own bound is the range check (one comparison on the
        // force path, not two).
        let entry = self.vertex_slot.get(usize::try_from(vertex).ok()?)?;
        Some(VertexSlot::of_entry(*entry))
    }

    /// Where the checked `vertex` stands ([`Self::slot`] without the range
    /// check; `None` only for an index of a larger table).
    pub fn vertex_slot_of(&self, vertex: VertexIndex) -> Option<VertexSlot> {
        self.vertex_slot
            .get(vertex.get())
            .map(|&entry| VertexSlot::of_entry(entry))
    }

    /// `true` if `vertex` is fixed (zero displacement). Out of range: `false`.
    pub fn is_fixed(&self, vertex: u32) -> bool {
        self.slot(vertex).is_some_and(VertexSlot::is_fixed)
    }

    /// `true` if the checked `vertex` is fixed ([`Self::is_fixed`] without
    /// the range check).
    pub fn is_fixed_vertex(&self, vertex: VertexIndex) -> bool {
        self.vertex_slot_of(vertex)
            .is_some_and(VertexSlot::is_fixed)
    }

    /// Vertex of each free index; the first [`Self::touchable_count`] are the
    /// touchable vertices in ascending order.
    pub fn free_vertices(&self) -> &'a [u32] {
        self.free_vertex
    }

    /// Rest positions of all vertices, m (mesh units).
    pub fn rest_positions(&self) -> &'a [[T; 3]] {
        self.rest_positions
    }

    /// Boundary surface triangles, outward right-hand normals.
    pub fn surface_triangles(&self) -> &'a [[u32; 3]] {
        self.triangles
    }

    /// Packed touchable–touchable compliance blocks, m/N (layout in
    /// [`super::format`]), dense or coded.
    pub fn surface_blocks(&self) -> ComplianceBlocks<'a, T> {
        self.surface
    }

    /// Interior–touchable compliance blocks, m/N (layout in
    /// [`super::format`]), dense or coded.
    pub fn interior_blocks(&self) -> ComplianceBlocks<'a, T> {
        self.interior
    }

    /// How the compliance is stored and the error measured at build time
    /// (format docs, "Compressed compliance"); `None` for a table whose
    /// compliance is all in the table scalar without a record.
    pub fn compression(&self) -> Option<&CompressionRecord> {
        self.compression.as_ref()
    }

    /// `C_nk` for two touchable free indices `n`, `k` (either order; the
    /// transpose is taken for `n > k`), m/N. `None` if either is not touchable.
    pub fn touchable_block(&self, n: u32, k: u32) -> Option<Matrix3<T>> {
        let s = self.touchable_count();
        self.touchable_block_of(FreeIndex::new(n, s)?, FreeIndex::new(k, s)?)
    }

    /// `C_nk` for two free indices `n`, `k` ([`Self::touchable_block`] on
    /// checked indices), m/N. `None` if either is not touchable.
    pub fn touchable_block_of(&self, n: FreeIndex, k: FreeIndex) -> Option<Matrix3<T>> {
        let (index, column, transposed) = self.stored_touchable_index(n, k)?;
        let block = Matrix3::from_row_slice(&self.surface.block(index, column)?);
        Some(if transposed { block.transpose() } else { block })
    }

    /// Where the block `C_nk` of two touchable free indices `n`, `k` (either
    /// order) is stored: the index of the stored block `C_lo,hi` in the
    /// surface part ([`Self::surface_blocks`]: read it there, decoded if
    /// coded), its column `hi`, and whether `C_nk` is its transpose
    /// (`n > k`). `None` if either is not touchable.
    pub fn stored_touchable_index(
        &self,
        n: FreeIndex,
        k: FreeIndex,
    ) -> Option<(usize, usize, bool)> {
        (n.get().max(k.get()) < self.touchable_count()).then(|| Self::stored_block_index(n, k))
    }

    /// [`Self::stored_touchable_index`] of indices known to be touchable
    /// (a resolved contact point's, [`crate::precomputed`]): the haptic
    /// path's form, without the check. For touchable indices the index lies
    /// within the surface part, whose block count the load checked; for
    /// others it names another block or none. No block is copied or
    /// decoded here.
    #[inline(always)]
    pub(crate) fn stored_block_index(n: FreeIndex, k: FreeIndex) -> (usize, usize, bool) {
        let (lo, hi) = if n <= k { (n, k) } else { (k, n) };
        (
            format::surface_block_index(lo.get(), hi.get()),
            hi.get(),
            n > k,
        )
    }

    fn check_vertex_maps(&self) -> Result<(), LoadError> {
        let mut free_seen = 0usize;
        for (v, &slot) in self.vertex_slot.iter().enumerate() {
            let vertex = v as u32;
            if slot == FIXED_SLOT {
                continue;
            }
            free_seen += 1;
            if self.free_vertex.get(slot as usize) != Some(&vertex) {
                return Err(LoadError::BadVertexMap { vertex });
            }
        }
        if free_seen != self.free_vertex.len() {
            return Err(LoadError::InconsistentHeader);
        }
        // Touchable vertices come first, in ascending order (format
        // contract), but for a hierarchical surface part, whose touchable
        // indices follow its cluster tree's leaves (`format::hierarchy`).
        let touchable = self.free_vertex.get(..self.touchable_count());
        let touchable = touchable.ok_or(LoadError::InconsistentHeader)?;
        let ascending = !self.surface.encoding().is_hierarchical();
        for pair in touchable.windows(2).filter(|_| ascending) {
            if let [a, b] = *pair
                && a >= b
            {
                return Err(LoadError::BadVertexMap { vertex: b });
            }
        }
        Ok(())
    }

    /// Every `C_kk` must be stored, symmetric (to 1e-4 relative, well above
    /// f32 rounding and the 16-bit codes' rounding, which the writer applies
    /// to a symmetrized block) and positive definite (an LDLᵀ with
    /// positive pivots): a compliance of an elastic body with fixed vertices
    /// is SPD.
    fn check_diagonal_blocks(&self) -> Result<(), LoadError> {
        for k in 0..self.touchable_count() {
            let touchable = k as u32;
            if !self.surface.is_stored(format::surface_block_index(k, k)) {
                return Err(LoadError::DroppedDiagonal { touchable });
            }
            let bad = LoadError::NotPositiveDefinite { touchable };
            let c = self.touchable_block(touchable, touchable).ok_or(bad)?;
            let scale = c.abs().max();
            let sym_tol = T::of_f64(1e-4) * scale;
            let asym = (c - c.transpose()).abs().max();
            // The rows of `c`: the columns of its (column-major) transpose.
            let definite = positive_definite3(&c.transpose().data.0);
            if asym > sym_tol || !asym.finite() || !definite {
                return Err(bad);
            }
        }
        Ok(())
    }
}

/// Every surface triangle's vertices are `< n`.
fn check_triangles(triangles: &[[u32; 3]], n: usize) -> Result<(), LoadError> {
    for (t, tri) in triangles.iter().enumerate() {
        if tri.iter().any(|&v| VertexIndex::new(v, n).is_none()) {
            return Err(LoadError::BadTriangle { triangle: t as u32 });
        }
    }
    Ok(())
}
