//! Tables: loaded and validated once from a pointer and a length (flash or
//! RAM), then read in place by everything created from them.
//!
//! The kernel has no unchecked load: `palpate_*_table_load` always checks
//! the whole table (magic, version, sizes, bounds, alignment, CRC-32,
//! indices, finite values, positive definite compliance blocks) and then
//! trusts the view. A table corrupted after its load gives wrong numbers,
//! never a crash (the kernel reads every index from a table through a
//! checked look-up); loading the same bytes again finds the corruption
//! (the CRC-32), which is how firmware re-checks its flash.

use palpate_kernel::table::format::TableKind as KernelKind;
use palpate_kernel::table::{InterfaceTable, TensorMassTable};
use palpate_kernel::{LoadError, PrecomputedTable};

use crate::error::{Detail, Error, finish};
use crate::handle::{self, Handle};
use crate::status::Status;

/// Words of a `palpate_table` on 64-bit targets (the host).
#[cfg(target_pointer_width = "64")]
pub const PALPATE_TABLE_WORDS: usize = 87;
/// Words of a `palpate_table` on 32-bit targets (Cortex-M).
#[cfg(not(target_pointer_width = "64"))]
pub const PALPATE_TABLE_WORDS: usize = 62;

/// A loaded table (opaque): a validated view of the caller's bytes, which
/// must stay in place and unchanged while the table and anything created
/// from it are used. Do not copy it: pass its address. Zero-initialize it
/// (static storage is).
#[repr(C)]
pub struct Table {
    opaque: [u64; PALPATE_TABLE_WORDS],
}

/// Zeroed, as C's static storage: not initialized until created.
impl Default for Table {
    fn default() -> Self {
        Self {
            opaque: [0; PALPATE_TABLE_WORDS],
        }
    }
}

/// What a table is for (the kind in its header).
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TableKind {
    /// The pre-computed model's compliance (RR-3510 §4).
    Precomputed = 1,
    /// The tensor-mass model's stiffness and masses (RR-3510 §5).
    TensorMass = 2,
    /// The hybrid's interface, condensing its pre-computed region (RR-3510 §6.2).
    Interface = 3,
}

// The kinds are the header's values (`table/format/section.rs`).
const _: () = assert!(
    TableKind::Precomputed as u32 == KernelKind::Precomputed as u32
        && TableKind::TensorMass as u32 == KernelKind::TensorMass as u32
        && TableKind::Interface as u32 == KernelKind::Interface as u32
);

/// A table's counts (`palpate_table_get_info`); 0 where a kind has none.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TableInfo {
    /// The table's kind.
    pub kind: TableKind,
    /// Mesh vertices: the length of a displacement field.
    pub vertex_count: u32,
    /// Free (not fixed) vertices: pre-computed and interface tables.
    pub free_count: u32,
    /// Touchable (free boundary-surface) vertices: pre-computed tables.
    pub touchable_count: u32,
    /// Tets: tensor-mass tables.
    pub tet_count: u32,
    /// Edges: tensor-mass tables.
    pub edge_count: u32,
    /// Connection nodes: interface tables.
    pub connection_count: u32,
}

/// A validated view, of one of the three kinds. Held in place in the
/// caller's fixed-size handle (no allocator: a variant cannot be boxed), so
/// the largest variant's size is the handle's whatever the others'.
#[derive(Clone, Copy, Debug)]
#[allow(clippy::large_enum_variant)]
pub enum View {
    /// A pre-computed table.
    Precomputed(PrecomputedTable<'static, f32>),
    /// A tensor-mass table.
    TensorMass(TensorMassTable<'static, f32>),
    /// An interface table.
    Interface(InterfaceTable<'static, f32>),
}

impl View {
    /// The pre-computed table, or `WrongTable`.
    pub(crate) fn precomputed(&self) -> Result<&PrecomputedTable<'static, f32>, Status> {
        match self {
            Self::Precomputed(t) => Ok(t),
            _ => Err(Status::WrongTable),
        }
    }

    /// The tensor-mass table, or `WrongTable`.
    pub(crate) fn tensor_mass(&self) -> Result<TensorMassTable<'static, f32>, Status> {
        match self {
            Self::TensorMass(t) => Ok(*t),
            _ => Err(Status::WrongTable),
        }
    }

    /// The interface table, or `WrongTable`.
    pub(crate) fn interface(&self) -> Result<InterfaceTable<'static, f32>, Status> {
        match self {
            Self::Interface(t) => Ok(*t),
            _ => Err(Status::WrongTable),
        }
    }
}

// SAFETY: `Table` is a `#[repr(C)]` struct of `u64` words.
unsafe impl Handle for Table {
    type Value = View;
    const MAGIC: u32 = u32::from_le_bytes(*b"PTbl");
}

/// The view of live table handle `t`.
///
/// # Safety
///
/// As [`handle::get`]; the table's bytes are still in place and unchanged.
pub(crate) unsafe fn view<'h>(t: *const Table) -> Result<&'h View, Status> {
    // SAFETY: the contract.
    unsafe { handle::get(t) }
}

/// Loads `len` bytes at `bytes` with `load` into handle `table`.
///
/// # Safety
///
/// As the `palpate_*_table_load` functions.
unsafe fn load_into(
    table: *mut Table,
    bytes: *const u8,
    len: usize,
    error: *mut Error,
    load: impl FnOnce(&'static [u8]) -> Result<View, LoadError>,
) -> Status {
    let result = (|| -> Result<(), Detail> {
        handle::check(table)?;
        // SAFETY: `bytes` is null or points to `len` bytes that stay in
        // place and unchanged while the table is used (the contract; hence
        // `'static`).
        let bytes = unsafe { handle::slice(bytes, len) }?;
        let view = load(bytes)?;
        // SAFETY: `table` is null or a writable handle (the contract).
        unsafe { handle::init(table, view) }?;
        Ok(())
    })();
    if result.is_err() {
        // SAFETY: as above.
        unsafe { handle::clear(table) };
    }
    // SAFETY: `error` is null or a writable error (contract).
    unsafe { finish(result, error) }
}

/// Loads and validates a pre-computed table (`palpate tables build`, f32)
/// of `len` bytes at `bytes` into `table`. The bytes must start on a
/// 16-byte boundary (`PALPATE_STATUS_TABLE_MISALIGNED` otherwise) and stay in
/// place and unchanged while `table` and anything created from it are
/// used; they are read in place, never copied. Cost: one pass over the
/// table (the CRC-32 and every check), not for the haptic path.
///
/// # Safety
///
/// `table` is `NULL` or points to a writable `palpate_table` that no
/// live loop uses; `bytes` is `NULL` or points to `len` readable bytes;
/// `error` is `NULL` or points to a writable `palpate_error`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn palpate_precomputed_table_load(
    table: *mut Table,
    bytes: *const u8,
    len: usize,
    error: *mut Error,
) -> Status {
    // SAFETY: the same contract.
    unsafe {
        load_into(table, bytes, len, error, |b| {
            PrecomputedTable::load(b).map(View::Precomputed)
        })
    }
}

/// Loads and validates a tensor-mass table (`palpate tables build --kind
/// tensor-mass`, f32), as `palpate_precomputed_table_load`.
///
/// # Safety
///
/// As `palpate_precomputed_table_load`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn palpate_tensor_mass_table_load(
    table: *mut Table,
    bytes: *const u8,
    len: usize,
    error: *mut Error,
) -> Status {
    // SAFETY: the same contract.
    unsafe {
        load_into(table, bytes, len, error, |b| {
            TensorMassTable::load(b).map(View::TensorMass)
        })
    }
}

/// Loads and validates a hybrid interface table (`palpate scene tables`,
/// f32), as `palpate_precomputed_table_load`.
///
/// # Safety
///
/// As `palpate_precomputed_table_load`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn palpate_interface_table_load(
    table: *mut Table,
    bytes: *const u8,
    len: usize,
    error: *mut Error,
) -> Status {
    // SAFETY: the same contract.
    unsafe {
        load_into(table, bytes, len, error, |b| {
            InterfaceTable::load(b).map(View::Interface)
        })
    }
}

/// A count as a `u32` (table counts are 32-bit indices: they fit).
fn count(n: usize) -> u32 {
    u32::try_from(n).unwrap_or(u32::MAX)
}

/// Writes `table`'s kind and counts to `info`.
///
/// # Safety
///
/// `table` is `NULL` or points to a `palpate_table`; `info` is `NULL` or
/// points to a writable `palpate_table_info`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn palpate_table_get_info(
    table: *const Table,
    info: *mut TableInfo,
) -> Status {
    // SAFETY: the contract.
    let view = match unsafe { view(table) } {
        Ok(v) => v,
        Err(s) => return s,
    };
    let none = TableInfo {
        kind: TableKind::Precomputed,
        vertex_count: 0,
        free_count: 0,
        touchable_count: 0,
        tet_count: 0,
        edge_count: 0,
        connection_count: 0,
    };
    let value = match view {
        View::Precomputed(t) => TableInfo {
            vertex_count: count(t.vertex_count()),
            free_count: count(t.free_count()),
            touchable_count: count(t.touchable_count()),
            ..none
        },
        View::TensorMass(t) => TableInfo {
            kind: TableKind::TensorMass,
            vertex_count: count(t.vertex_count()),
            tet_count: count(t.tet_count()),
            edge_count: count(t.edge_count()),
            ..none
        },
        View::Interface(t) => TableInfo {
            kind: TableKind::Interface,
            vertex_count: count(t.vertex_count()),
            free_count: count(t.free_count()),
            connection_count: count(t.connection_count()),
            ..none
        },
    };
    // SAFETY: the contract.
    match unsafe { handle::out(info, value) } {
        Ok(()) => Status::Ok,
        Err(s) => s,
    }
}
