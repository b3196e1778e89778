//! The container every table shares: header, section directory, CRC-32.
//! Checked once, independent of the table kind; the kind-specific views
//! ([`super::PrecomputedTable`]) check their contents on top.

use super::LoadError;
use super::format::{
    self, CRC_LEN, HEADER_LEN, RawHeader, SECTION_ALIGN, SECTION_ENTRY_LEN, SectionEntry,
    SectionKind, TableKind,
};
use crate::Real;

/// The slot in [`Container`]'s sections of each [`SectionKind`], by its
/// value: its index in [`SectionKind::ALL`] (a table, so that looking a
/// section up is one load, not a search). Evaluated at compile time: an
/// index out of range here is a compile error, never a run-time panic.
#[allow(clippy::indexing_slicing)]
const SLOT_OF_KIND: [u8; 72] = {
    let mut slots = [u8::MAX; 72];
    let mut i = 0;
    while i < SectionKind::ALL.len() {
        slots[SectionKind::ALL[i] as usize] = i as u8;
        i += 1;
    }
    slots
};

impl RawHeader {
    /// The checks that come before any other, on the header alone: the
    /// magic and the format version. The loader starts with them, and a
    /// reader that has only the header so far (the host reading a file
    /// header first) calls them before reading on.
    pub fn check_identity(&self) -> Result<(), LoadError> {
        if self.magic != format::MAGIC {
            return Err(LoadError::BadMagic);
        }
        if self.format_version != format::FORMAT_VERSION {
            return Err(LoadError::UnsupportedVersion {
                found: self.format_version,
            });
        }
        Ok(())
    }
}

/// A table whose header, directory and checksum are valid, with every section
/// located (bounds and alignment checked) but not yet viewed.
pub(crate) struct Container<'a> {
    pub(crate) header: RawHeader,
    /// The CRC-32 trailer (checked): what identifies the table's contents.
    pub(crate) checksum: u32,
    sections: [Option<&'a [u8]>; SectionKind::ALL.len()],
}

impl<'a> Container<'a> {
    /// Checks, in order: length, magic, version, declared length, CRC-32,
    /// table kind, scalar width, header counts, material, and the section
    /// directory (known kinds, no duplicates, sizes implied by the header,
    /// bounds, alignment), and that every section `kind` requires is present
    /// (but for the compliance sections an encoding may replace,
    /// [`SectionKind::encodable`]: the pre-computed view checks those).
    pub(crate) fn parse<T: Real>(bytes: &'a [u8], kind: TableKind) -> Result<Self, LoadError> {
        let header = read_header(bytes)?;
        let checksum = check_header::<T>(&header, bytes, kind)?;
        let mut container = locate_sections::<T>(header, bytes)?;
        container.checksum = checksum;
        for &required in kind.sections() {
            if !required.encodable() && !container.has(required) {
                return Err(LoadError::MissingSection { kind: required });
            }
        }
        Ok(container)
    }

    fn raw(&self, kind: SectionKind) -> Option<&'a [u8]> {
        let slot = *SLOT_OF_KIND.get(kind as usize)?;
        self.sections.get(usize::from(slot)).copied().flatten()
    }

    /// `true` if the section `kind` is present.
    pub(crate) fn has(&self, kind: SectionKind) -> bool {
        self.raw(kind).is_some()
    }

    /// The section `kind` viewed in place as elements `E`, `None` if absent.
    pub(crate) fn optional_section<E: bytemuck::Pod>(
        &self,
        kind: SectionKind,
    ) -> Result<Option<&'a [E]>, LoadError> {
        if self.has(kind) {
            self.section(kind).map(Some)
        } else {
            Ok(None)
        }
    }

    /// The section `kind` viewed in place as elements `E`.
    pub(crate) fn section<E: bytemuck::Pod>(
        &self,
        kind: SectionKind,
    ) -> Result<&'a [E], LoadError> {
        let bytes = self.raw(kind).ok_or(LoadError::MissingSection { kind })?;
        bytemuck::try_cast_slice(bytes).map_err(|_| LoadError::Misaligned { kind })
    }
}

/// `Err(NonFinite)` naming the first element with a NaN or infinity.
pub(crate) fn check_finite<T: Real, const L: usize>(
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

/// The [`SectionKind::TetMaterial`] check: every `(λ, μ)` finite, `μ > 0`
/// and `λ + 2μ/3 > 0` (a positive shear and bulk modulus, MODELS.md §1).
pub(crate) fn check_tet_materials<T: Real>(lame: &[[T; 2]]) -> Result<(), LoadError> {
    check_finite(SectionKind::TetMaterial, lame)?;
    let two_thirds = T::of_f64(2.0 / 3.0);
    match lame
        .iter()
        .position(|&[lambda, mu]| !(mu > T::zero() && lambda + two_thirds * mu > T::zero()))
    {
        Some(tet) => Err(LoadError::BadTetMaterial { tet: tet as u32 }),
        None => Ok(()),
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

/// The header checks of [`Container::parse`]; returns the (checked) CRC-32.
fn check_header<T: Real>(h: &RawHeader, bytes: &[u8], kind: TableKind) -> Result<u32, LoadError> {
    h.check_identity()?;
    if h.file_len != bytes.len() as u64 {
        return Err(LoadError::LengthMismatch {
            declared: h.file_len,
            actual: bytes.len(),
        });
    }
    // Checked, not `split_at`: the length check is in `read_header`, which
    // the optimiser may not see, and a C caller's bytes are opaque (the C
    // ABI's link-time no-panic proof, `tools/ffi-check.sh`).
    let (body, trailer) = bytes
        .split_last_chunk::<CRC_LEN>()
        .ok_or(LoadError::TooShort { len: bytes.len() })?;
    let body_len = body.len();
    let stored = u32::from_le_bytes(*trailer);
    let computed = crc::Crc::<u32>::new(&format::CRC32).checksum(body);
    if stored != computed {
        return Err(LoadError::ChecksumMismatch { stored, computed });
    }
    if h.table_kind != kind as u32 {
        return Err(LoadError::WrongTableKind {
            found: h.table_kind,
        });
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
        || header_len.is_some_and(|len| len > body_len)
        || h.free_count > h.vertex_count
        || h.touchable_count > h.free_count
        || (h.connection_count != 0) != (kind == TableKind::Interface)
    {
        return Err(LoadError::InconsistentHeader);
    }
    let material_ok = h.young_pa.is_finite()
        && h.young_pa > 0.0
        && h.poisson.is_finite()
        && (0.0..0.5).contains(&h.poisson)
        && h.density_kg_m3.is_finite()
        && h.density_kg_m3 >= 0.0;
    if !material_ok {
        return Err(LoadError::BadMaterial);
    }
    Ok(stored)
}

fn locate_sections<T: Real>(h: RawHeader, bytes: &[u8]) -> Result<Container<'_>, LoadError> {
    let body_len = bytes.len() - CRC_LEN;
    let directory = bytes
        .get(HEADER_LEN..h.header_len as usize)
        .ok_or(LoadError::InconsistentHeader)?;
    let mut located = Container {
        header: h,
        checksum: 0,
        sections: [None; SectionKind::ALL.len()],
    };
    for raw in directory.chunks_exact(SECTION_ENTRY_LEN) {
        let entry: SectionEntry = bytemuck::pod_read_unaligned(raw);
        let (slot, kind) = SectionKind::ALL
            .iter()
            .enumerate()
            .find(|(_, k)| **k as u32 == entry.kind)
            .ok_or(LoadError::UnknownSection { kind: entry.kind })?;
        let expected = kind.expected_count(&h);
        let count_ok = if kind.count_is_declared() {
            expected.is_some_and(|most| entry.count <= most)
        } else {
            expected == Some(entry.count)
        };
        if entry.elem_bytes != kind.elem_bytes(T::BYTES) || !count_ok {
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
            || !entry.offset.is_multiple_of(SECTION_ALIGN as u64)
        {
            return Err(bounds);
        }
        let section = bytes
            .get(entry.offset as usize..end as usize)
            .ok_or(bounds)?;
        let target = located.sections.get_mut(slot).ok_or(bounds)?;
        if target.is_some() {
            return Err(LoadError::DuplicateSection { kind: *kind });
        }
        *target = Some(section);
    }
    Ok(located)
}
