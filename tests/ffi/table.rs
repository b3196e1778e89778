//! Tables through the C ABI (`ffi/src/table.rs`): a load gives the code of
//! exactly the error the kernel's own load gives for the same bytes
//! (truncated, padded, bit-flipped with and without the CRC repaired,
//! another version, kind or scalar width, misaligned), and the counts of a
//! valid table; the helpers the other `ffi` tests load their tables with.

use palpate_ffi::error::Error;
use palpate_ffi::status::Status;
use palpate_ffi::table::{
    Table, TableInfo, TableKind, palpate_interface_table_load, palpate_precomputed_table_load,
    palpate_table_get_info, palpate_tensor_mass_table_load,
};
use palpate_kernel::PrecomputedTable;
use palpate_kernel::table::format::{CRC_LEN, CRC32};
use palpate_kernel::table::{InterfaceTable, TensorMassTable};
use palpate_tests::firmware_box_tables;

/// The loader of each kind.
type Load = unsafe extern "C" fn(*mut Table, *const u8, usize, *mut Error) -> Status;

/// Loads `bytes` with `load` into a fresh handle.
pub fn load_with(load: Load, bytes: &[u8]) -> (Status, Box<Table>) {
    let mut table = Box::<Table>::default();
    // SAFETY: a live handle; `bytes` readable for its length and kept alive
    // by the caller while the handle is used.
    let status = unsafe {
        load(
            &mut *table,
            bytes.as_ptr(),
            bytes.len(),
            core::ptr::null_mut(),
        )
    };
    (status, table)
}

/// A loaded handle of each kind over the firmware box's tables, or a panic.
pub fn loaded(load: Load, bytes: &[u8]) -> Box<Table> {
    let (status, table) = load_with(load, bytes);
    assert_eq!(status, Status::Ok);
    table
}

/// The pre-computed box table's handle.
pub fn precomputed() -> Box<Table> {
    loaded(
        palpate_precomputed_table_load,
        firmware_box_tables().precomputed.bytes(),
    )
}

/// The tensor-mass box table's handle.
pub fn tensor_mass() -> Box<Table> {
    loaded(
        palpate_tensor_mass_table_load,
        firmware_box_tables().tensor_mass.bytes(),
    )
}

fn info(table: &Table) -> TableInfo {
    let mut info = TableInfo {
        kind: TableKind::Interface,
        vertex_count: 0,
        free_count: 0,
        touchable_count: 0,
        tet_count: 0,
        edge_count: 0,
        connection_count: 0,
    };
    // SAFETY: a live handle and a writable info.
    assert_eq!(
        unsafe { palpate_table_get_info(table, &mut info) },
        Status::Ok
    );
    info
}

/// `bytes` in a 16-byte-aligned buffer, `skew` bytes in.
fn aligned(bytes: &[u8], skew: usize) -> (Vec<u128>, usize) {
    let mut buffer = vec![0u128; (bytes.len() + skew).div_ceil(16)];
    // SAFETY: a u128 buffer viewed as bytes (any bit pattern is valid).
    let view = unsafe {
        core::slice::from_raw_parts_mut(buffer.as_mut_ptr().cast::<u8>(), buffer.len() * 16)
    };
    view[skew..skew + bytes.len()].copy_from_slice(bytes);
    (buffer, skew)
}

fn view(buffer: &[u128], skew: usize, len: usize) -> &[u8] {
    // SAFETY: as in `aligned`.
    let bytes =
        unsafe { core::slice::from_raw_parts(buffer.as_ptr().cast::<u8>(), buffer.len() * 16) };
    &bytes[skew..skew + len]
}

/// `bytes` with its CRC-32 trailer recomputed (so a mutation reaches the
/// checks behind the checksum).
fn repaired(mut bytes: Vec<u8>) -> Vec<u8> {
    let body = bytes.len() - CRC_LEN;
    let crc = crc::Crc::<u32>::new(&CRC32).checksum(&bytes[..body]);
    bytes[body..].copy_from_slice(&crc.to_le_bytes());
    bytes
}

#[test]
fn load_codes_are_the_kernels_load_errors() {
    let tables = firmware_box_tables();
    let original = tables.precomputed.bytes().to_vec();
    let mut variants: Vec<(String, Vec<u8>)> = vec![
        ("valid".into(), original.clone()),
        ("empty".into(), Vec::new()),
        ("10 bytes".into(), original[..10].to_vec()),
        ("truncated".into(), original[..original.len() - 5].to_vec()),
        ("padded".into(), [original.as_slice(), &[0; 16]].concat()),
    ];
    // Header fields with the CRC repaired (`RawHeader` offsets): magic,
    // version, scalar width, kind.
    for (what, at, value) in [
        ("magic", 0usize, 0x51u8),
        ("version", 8, 2),
        ("scalar", 16, 8),
        ("kind", 24, 2),
    ] {
        let mut bytes = original.clone();
        bytes[at] = value;
        variants.push((format!("{what} (CRC repaired)"), repaired(bytes)));
    }
    // A NaN in the rest positions (the first float of the section), CRC
    // repaired.
    let at = {
        let bytes = tables.precomputed.bytes();
        let view = PrecomputedTable::<f32>::load(bytes).unwrap();
        view.rest_positions().as_ptr() as usize - bytes.as_ptr() as usize
    };
    let mut nan = original.clone();
    nan[at..at + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    variants.push(("a NaN rest position (CRC repaired)".into(), repaired(nan)));
    // Single bytes flipped through the whole table, CRC stale and repaired.
    for at in (0..original.len() - CRC_LEN).step_by(97) {
        let mut bytes = original.clone();
        bytes[at] ^= 0x5A;
        variants.push((format!("byte {at} flipped"), bytes.clone()));
        variants.push((format!("byte {at} flipped (CRC repaired)"), repaired(bytes)));
    }
    let mut seen = std::collections::BTreeSet::new();
    for (what, bytes) in &variants {
        for skew in [0, 1, 4] {
            let (buffer, skew) = aligned(bytes, skew);
            let bytes = view(&buffer, skew, bytes.len());
            let kernel = PrecomputedTable::<f32>::load(bytes);
            let (status, table) = load_with(palpate_precomputed_table_load, bytes);
            let expected = kernel.map_or_else(Status::from, |_| Status::Ok);
            assert_eq!(status, expected, "{what}, skew {skew}: {kernel:?}");
            if status == Status::Ok {
                assert_eq!(info(&table).vertex_count, 64);
            }
            seen.insert(status as u32);
        }
    }
    // The mutations reach well behind the checksum: at least these codes.
    for s in [
        Status::Ok,
        Status::TableTooShort,
        Status::TableBadMagic,
        Status::TableUnsupportedVersion,
        Status::TableLengthMismatch,
        Status::TableChecksumMismatch,
        Status::TableScalarMismatch,
        Status::TableWrongKind,
        Status::TableMisaligned,
        Status::TableNonFinite,
    ] {
        assert!(seen.contains(&(s as u32)), "{s:?} never produced");
    }
    assert!(seen.len() >= 14, "codes produced: {seen:?}");
}

#[test]
fn each_kind_loads_and_counts_as_the_kernel() {
    let tables = firmware_box_tables();
    let pre = PrecomputedTable::<f32>::load(tables.precomputed.bytes()).unwrap();
    let i = info(&precomputed());
    assert_eq!(i.kind, TableKind::Precomputed);
    assert_eq!(
        (i.vertex_count, i.free_count, i.touchable_count),
        (64, 48, 40)
    );
    assert_eq!(i.free_count as usize, pre.free_count());

    let tm = TensorMassTable::<f32>::load(tables.tensor_mass.bytes()).unwrap();
    let i = info(&tensor_mass());
    assert_eq!(i.kind, TableKind::TensorMass);
    assert_eq!(
        (i.vertex_count, i.tet_count, i.edge_count as usize),
        (64, 162, tm.edge_count())
    );

    let interface = tables.hybrid.interface.bytes();
    let kernel = InterfaceTable::<f32>::load(interface).unwrap();
    let i = info(&loaded(palpate_interface_table_load, interface));
    assert_eq!(i.kind, TableKind::Interface);
    assert_eq!(
        (i.connection_count as usize, i.free_count as usize),
        (kernel.connection_count(), kernel.free_count())
    );
    // Each loader refuses the other kinds.
    let (status, _) = load_with(palpate_tensor_mass_table_load, tables.precomputed.bytes());
    assert_eq!(status, Status::TableWrongKind);
    let (status, _) = load_with(palpate_interface_table_load, tables.tensor_mass.bytes());
    assert_eq!(status, Status::TableWrongKind);
}
