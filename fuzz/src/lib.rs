//! Helpers shared by the fuzz targets: the invariants every successfully read mesh must
//! satisfy, and the byte handling of the table targets (16-byte alignment, container repair).

use std::collections::HashSet;

use palpate::mesh::{MeshReport, TetMesh, boundary_surface};
use palpate_kernel::table::format::{CRC_LEN, CRC32, HEADER_LEN, RawHeader};

/// Asserts the [`TetMesh`] invariants and the report's consistency on a mesh a reader
/// accepted, and that the derived data (boundary surface, content hash) computes.
pub fn check_mesh(mesh: &TetMesh, report: &MeshReport) {
    let n = mesh.positions.len();
    assert!(!mesh.tets.is_empty(), "a mesh has at least one tet");
    assert!(
        mesh.positions.iter().flatten().all(|x| x.is_finite()),
        "non-finite coordinate accepted"
    );
    let mut seen = HashSet::with_capacity(mesh.tets.len());
    for (t, tet) in mesh.tets.iter().enumerate() {
        assert!(
            tet.iter().all(|&v| (v as usize) < n),
            "tet {t}: {tet:?} out of range"
        );
        let mut sorted = *tet;
        sorted.sort_unstable();
        assert!(
            sorted.windows(2).all(|w| w[0] != w[1]),
            "tet {t}: repeated vertex {tet:?}"
        );
        assert!(seen.insert(sorted), "tet {t}: duplicate of an earlier tet");
        let volume = mesh.tet_volume(t);
        assert!(volume > 0.0, "tet {t}: volume {volume} not positive");
    }
    let unreferenced: Vec<u32> = mesh
        .referenced()
        .iter()
        .enumerate()
        .filter(|(_, used)| !**used)
        .map(|(v, _)| v as u32)
        .collect();
    assert_eq!(report.unreferenced_vertices, unreferenced);
    let surface = boundary_surface(mesh);
    assert!(
        surface
            .triangles
            .iter()
            .flatten()
            .all(|&v| (v as usize) < n)
    );
    assert!(surface.vertices.windows(2).all(|w| w[0] < w[1]));
    let _ = mesh.content_hash();
}

/// A copy of some bytes at a chosen offset from a 16-byte boundary (tables are viewed in
/// place: [`palpate_kernel::PrecomputedTable::load`] needs 16-byte-aligned bytes).
pub struct AlignedCopy {
    words: Vec<u128>,
    offset: usize,
    len: usize,
}

impl AlignedCopy {
    /// `data` copied to `offset` bytes past a 16-byte boundary (`offset = 0`: aligned).
    pub fn new(data: &[u8], offset: usize) -> Self {
        let mut words = vec![0u128; (offset + data.len()).div_ceil(16)];
        bytemuck::cast_slice_mut::<u128, u8>(&mut words)[offset..offset + data.len()]
            .copy_from_slice(data);
        Self {
            words,
            offset,
            len: data.len(),
        }
    }

    /// The copied bytes.
    pub fn bytes(&self) -> &[u8] {
        &bytemuck::cast_slice::<u128, u8>(&self.words)[self.offset..self.offset + self.len]
    }
}

/// `data` with the header's declared length and the CRC-32 trailer made to match, so
/// that a mutated table gets past the container's length and checksum checks and reaches
/// the directory and content checks. `None` if `data` is too short to hold a header.
pub fn repair_container(data: &[u8]) -> Option<Vec<u8>> {
    if data.len() < HEADER_LEN + CRC_LEN {
        return None;
    }
    let mut bytes = data.to_vec();
    let at = core::mem::offset_of!(RawHeader, file_len);
    let len = bytes.len() as u64;
    bytes[at..at + 8].copy_from_slice(&len.to_le_bytes());
    let body = bytes.len() - CRC_LEN;
    let crc = crc::Crc::<u32>::new(&CRC32).checksum(&bytes[..body]);
    bytes[body..].copy_from_slice(&crc.to_le_bytes());
    Some(bytes)
}

/// Calls `load` on `data` as given (16-byte aligned), then, when its
/// container can be repaired, on the repaired copy aligned and 4 bytes past
/// a 16-byte boundary: the three layouts every table target fuzzes.
pub fn table_layouts(data: &[u8], mut load: impl FnMut(&[u8])) {
    load(AlignedCopy::new(data, 0).bytes());
    if let Some(repaired) = repair_container(data) {
        load(AlignedCopy::new(&repaired, 0).bytes());
        load(AlignedCopy::new(&repaired, 4).bytes());
    }
}
