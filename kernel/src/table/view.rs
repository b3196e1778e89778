//! The validated, zero-copy view of a pre-computed table.

use nalgebra::Matrix3;

use super::LoadError;
use super::format::{
    self, CRC_LEN, FIXED_SLOT, HEADER_LEN, RawHeader, SECTION_ALIGN, SECTION_ENTRY_LEN,
    SectionEntry, SectionKind,
};
use crate::Real;

/// A pre-computed table that passed every load-time check; the step path
/// takes only this type.
///
/// Invariants established by [`PrecomputedTable::load`]:
/// - `vertex_slot` and `free_vertex` are inverse maps between the `N` vertices
///   and the `F` free indices; free indices `0..S` are the touchable vertices;
/// - every surface triangle's vertices are `< N`;
/// - every float is finite and every diagonal block `C_kk` is symmetric
///   positive definite;
/// - section lengths match the header's counts exactly.
#[derive(Clone, Copy, Debug)]
pub struct PrecomputedTable<'a, T: Real> {
    header: RawHeader,
    vertex_slot: &'a [u32],
    free_vertex: &'a [u32],
    rest_positions: &'a [[T; 3]],
    triangles: &'a [[u32; 3]],
    surface: &'a [[T; 9]],
    interior: &'a [[T; 9]],
}

/// The sections of a table, located but not yet checked for content.
struct Located<'a> {
    by_kind: [Option<&'a [u8]>; SectionKind::ALL.len()],
}

impl<'a, T: Real> PrecomputedTable<'a, T> {
    /// Validates `bytes` once and returns the view (format in
    /// [`super::format`]). Checks, in order: length, magic, version, declared
    /// length, CRC-32, scalar width, header counts, material, section
    /// directory (kinds, sizes, bounds, alignment), vertex maps, triangle
    /// indices, finite floats, SPD diagonal compliance blocks.
    ///
    /// Cost: linear in the table size. Not for the step path.
    pub fn load(bytes: &'a [u8]) -> Result<Self, LoadError> {
        let header = read_header(bytes)?;
        check_header::<T>(&header, bytes)?;
        let located = locate_sections::<T>(&header, bytes)?;
        let table = Self {
            header,
            vertex_slot: cast(&located, SectionKind::VertexSlot)?,
            free_vertex: cast(&located, SectionKind::FreeVertex)?,
            rest_positions: cast(&located, SectionKind::RestPositions)?,
            triangles: cast(&located, SectionKind::SurfaceTriangles)?,
            surface: cast(&located, SectionKind::ComplianceSurface)?,
            interior: cast(&located, SectionKind::ComplianceInterior)?,
        };
        table.check_vertex_maps()?;
        table.check_triangles()?;
        check_finite(SectionKind::RestPositions, table.rest_positions)?;
        check_finite(SectionKind::ComplianceSurface, table.surface)?;
        check_finite(SectionKind::ComplianceInterior, table.interior)?;
        table.check_diagonal_blocks()?;
        log::debug!(
            "table loaded: {} vertices, {} free, {} touchable, {}-byte floats",
            table.vertex_count(),
            table.free_count(),
            table.touchable_count(),
            T::BYTES
        );
        Ok(table)
    }

    /// The header as stored.
    pub fn header(&self) -> &RawHeader {
        &self.header
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

    /// Young's modulus the table was built with, Pa.
    pub fn young_pa(&self) -> f64 {
        self.header.young_pa
    }

    /// Poisson ratio the table was built with.
    pub fn poisson(&self) -> f64 {
        self.header.poisson
    }

    /// Free index of `vertex`: `Some(Some(i))` free, `Some(None)` fixed,
    /// `None` out of range.
    pub fn free_index(&self, vertex: u32) -> Option<Option<u32>> {
        let slot = *self.vertex_slot.get(vertex as usize)?;
        Some((slot != FIXED_SLOT).then_some(slot))
    }

    /// `true` if `vertex` is fixed (zero displacement). Out of range: `false`.
    pub fn is_fixed(&self, vertex: u32) -> bool {
        matches!(self.free_index(vertex), Some(None))
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

    /// Packed touchable–touchable compliance blocks, m/N (layout in [`super::format`]).
    pub fn surface_blocks(&self) -> &'a [[T; 9]] {
        self.surface
    }

    /// Interior–touchable compliance blocks, m/N (layout in [`super::format`]).
    pub fn interior_blocks(&self) -> &'a [[T; 9]] {
        self.interior
    }

    /// `C_nk` for two touchable free indices `n`, `k` (either order; the
    /// transpose is taken for `n > k`), m/N. `None` if either is not touchable.
    pub fn touchable_block(&self, n: u32, k: u32) -> Option<Matrix3<T>> {
        let (lo, hi) = if n <= k { (n, k) } else { (k, n) };
        if hi as usize >= self.touchable_count() {
            return None;
        }
        let raw = self
            .surface
            .get(format::surface_block_index(lo as usize, hi as usize))?;
        let block = Matrix3::from_row_slice(raw);
        Some(if n <= k { block } else { block.transpose() })
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
        // Touchable vertices come first, in ascending order (format contract).
        let touchable = self.free_vertex.get(..self.touchable_count());
        let touchable = touchable.ok_or(LoadError::InconsistentHeader)?;
        for pair in touchable.windows(2) {
            if let [a, b] = *pair {
                if a >= b {
                    return Err(LoadError::BadVertexMap { vertex: b });
                }
            }
        }
        Ok(())
    }

    fn check_triangles(&self) -> Result<(), LoadError> {
        let n = self.vertex_count();
        for (t, tri) in self.triangles.iter().enumerate() {
            if tri.iter().any(|&v| v as usize >= n) {
                return Err(LoadError::BadTriangle { triangle: t as u32 });
            }
        }
        Ok(())
    }

    /// Every `C_kk` must be symmetric (to 1e-4 relative, well above f32
    /// rounding) and positive definite (a 3×3 Cholesky with positive pivots):
    /// a compliance of an elastic body with fixed vertices is SPD.
    fn check_diagonal_blocks(&self) -> Result<(), LoadError> {
        for k in 0..self.touchable_count() {
            let touchable = k as u32;
            let bad = LoadError::NotPositiveDefinite { touchable };
            let c = self.touchable_block(touchable, touchable).ok_or(bad)?;
            let scale = c.abs().max();
            let sym_tol = T::of_f64(1e-4) * scale;
            let asym = (c - c.transpose()).abs().max();
            if asym > sym_tol
                || !asym.finite()
                || crate::precomputed::cholesky3(&c, T::zero()).is_none()
            {
                return Err(bad);
            }
        }
        Ok(())
    }
}

fn read_header(bytes: &[u8]) -> Result<RawHeader, LoadError> {
    let too_short = LoadError::TooShort { len: bytes.len() };
    if bytes.len() < HEADER_LEN + CRC_LEN {
        return Err(too_short);
    }
    let raw = bytes.get(..HEADER_LEN).ok_or(too_short)?;
    Ok(bytemuck::pod_read_unaligned(raw))
}

fn check_header<T: Real>(h: &RawHeader, bytes: &[u8]) -> Result<(), LoadError> {
    if h.magic != format::MAGIC {
        return Err(LoadError::BadMagic);
    }
    if h.format_version != format::FORMAT_VERSION {
        return Err(LoadError::UnsupportedVersion {
            found: h.format_version,
        });
    }
    if h.file_len != bytes.len() as u64 {
        return Err(LoadError::LengthMismatch {
            declared: h.file_len,
            actual: bytes.len(),
        });
    }
    let body_len = bytes.len() - CRC_LEN;
    let (body, trailer) = bytes.split_at(body_len);
    let stored = u32::from_le_bytes(
        trailer
            .try_into()
            .map_err(|_| LoadError::TooShort { len: bytes.len() })?,
    );
    let computed = crc::Crc::<u32>::new(&format::CRC32).checksum(body);
    if stored != computed {
        return Err(LoadError::ChecksumMismatch { stored, computed });
    }
    if h.scalar_bytes != T::BYTES {
        return Err(LoadError::ScalarMismatch {
            table: h.scalar_bytes,
            requested: T::BYTES,
        });
    }
    let directory_len = (h.section_count as usize).checked_mul(SECTION_ENTRY_LEN);
    let header_len = directory_len.and_then(|d| d.checked_add(HEADER_LEN));
    if header_len != Some(h.header_len as usize)
        || h.header_len as usize > body_len
        || h.free_count > h.vertex_count
        || h.touchable_count > h.free_count
        || h.reserved != 0
    {
        return Err(LoadError::InconsistentHeader);
    }
    let material_ok = h.young_pa.is_finite()
        && h.young_pa > 0.0
        && h.poisson.is_finite()
        && (0.0..0.5).contains(&h.poisson);
    if !material_ok {
        return Err(LoadError::BadMaterial);
    }
    Ok(())
}

fn locate_sections<'a, T: Real>(h: &RawHeader, bytes: &'a [u8]) -> Result<Located<'a>, LoadError> {
    let body_len = bytes.len() - CRC_LEN;
    let directory = bytes
        .get(HEADER_LEN..h.header_len as usize)
        .ok_or(LoadError::InconsistentHeader)?;
    let mut located = Located {
        by_kind: [None; SectionKind::ALL.len()],
    };
    for raw in directory.chunks_exact(SECTION_ENTRY_LEN) {
        let entry: SectionEntry = bytemuck::pod_read_unaligned(raw);
        let (slot, kind) = SectionKind::ALL
            .iter()
            .enumerate()
            .find(|(_, k)| **k as u32 == entry.kind)
            .ok_or(LoadError::UnknownSection { kind: entry.kind })?;
        let expected = kind.expected_count(h);
        if entry.elem_bytes != kind.elem_bytes(T::BYTES) || expected != Some(entry.count) {
            return Err(LoadError::SectionSize { kind: *kind });
        }
        let bounds = LoadError::SectionBounds { kind: *kind };
        let len = entry
            .count
            .checked_mul(u64::from(entry.elem_bytes))
            .ok_or(bounds)?;
        let end = entry.offset.checked_add(len).ok_or(bounds)?;
        if entry.offset < u64::from(h.header_len)
            || end > body_len as u64
            || entry.offset % SECTION_ALIGN as u64 != 0
        {
            return Err(bounds);
        }
        let section = bytes
            .get(entry.offset as usize..end as usize)
            .ok_or(bounds)?;
        let target = located.by_kind.get_mut(slot).ok_or(bounds)?;
        if target.is_some() {
            return Err(LoadError::DuplicateSection { kind: *kind });
        }
        *target = Some(section);
    }
    Ok(located)
}

fn cast<'a, E: bytemuck::Pod>(
    located: &Located<'a>,
    kind: SectionKind,
) -> Result<&'a [E], LoadError> {
    let slot = SectionKind::ALL.iter().position(|k| *k == kind);
    let bytes = slot
        .and_then(|s| located.by_kind.get(s).copied().flatten())
        .ok_or(LoadError::MissingSection { kind })?;
    bytemuck::try_cast_slice(bytes).map_err(|_| LoadError::Misaligned { kind })
}

fn check_finite<T: Real, const L: usize>(
    kind: SectionKind,
    items: &[[T; L]],
) -> Result<(), LoadError> {
    match items
        .iter()
        .position(|item| !item.iter().all(|x| x.finite()))
    {
        Some(index) => Err(LoadError::NonFinite {
            kind,
            index: index as u64,
        }),
        None => Ok(()),
    }
}
