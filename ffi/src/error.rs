//! A failure's details: the kernel's error value behind a status code
//! (which contact, vertex, section or buffer), kept in the caller's
//! `palpate_error` and formatted by `palpate_error_message` into the
//! kernel's own message, byte for byte what the host prints.

use core::ffi::c_char;
use core::fmt::{self, Write};

use palpate_kernel::haptic::LoopError;
use palpate_kernel::hybrid::{FieldError, HybridError, HybridTissueError};
use palpate_kernel::precomputed::DisplacementError;
use palpate_kernel::tensor_mass::{DynamicTissueError, Fault, PhysicsError, StateError};
use palpate_kernel::{ContactError, LoadError};

use crate::handle::{self, Handle};
use crate::status::Status;

/// Words of a `palpate_error`.
pub const PALPATE_ERROR_WORDS: usize = 8;

/// The details of the last failure recorded in it (opaque): pass a pointer
/// to one as the last argument of a function that takes it (or `NULL` for
/// none); on failure the function writes the details there, and
/// `palpate_error_message` formats them. A success leaves it as it was.
/// Zero-initialize it (static storage is): an error never written formats
/// as the empty string.
#[repr(C)]
pub struct Error {
    opaque: [u64; PALPATE_ERROR_WORDS],
}

/// Zeroed, as C's static storage: not initialized until created.
impl Default for Error {
    fn default() -> Self {
        Self {
            opaque: [0; PALPATE_ERROR_WORDS],
        }
    }
}

/// A failure: the boundary's own status, or a kernel error.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Detail {
    /// A check of the boundary (pointers, handles, arguments, memory).
    Abi(Status),
    /// `*_table_load`.
    Load(LoadError),
    /// `palpate_precomputed_solve`.
    Contact(ContactError),
    /// A displacement buffer's length.
    Displacement(DisplacementError),
    /// A loop's configuration.
    Loop(LoopError),
    /// The tensor-mass model's state or parameters.
    State(StateError),
    /// The tensor-mass tissue's buffers or physics configuration.
    DynamicTissue(DynamicTissueError),
    /// A physics update.
    Physics(PhysicsError),
    /// The tensor-mass model's latched fault.
    Fault(Fault),
    /// The hybrid coupling.
    Hybrid(HybridError),
    /// The hybrid tissue.
    HybridTissue(HybridTissueError),
    /// The hybrid's displacement field.
    Field(FieldError),
}

impl Detail {
    /// The status code of this failure.
    pub fn status(&self) -> Status {
        match *self {
            Self::Abi(s) => s,
            Self::Load(e) => e.into(),
            Self::Contact(e) => e.into(),
            Self::Displacement(e) => e.into(),
            Self::Loop(e) => e.into(),
            Self::State(e) => e.into(),
            Self::DynamicTissue(e) => e.into(),
            Self::Physics(e) => e.into(),
            Self::Fault(e) => e.into(),
            Self::Hybrid(e) => e.into(),
            Self::HybridTissue(e) => e.into(),
            Self::Field(e) => e.into(),
        }
    }
}

impl fmt::Display for Detail {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Abi(s) => match s.message().to_str() {
                Ok(m) => f.write_str(m),
                Err(_) => Ok(()),
            },
            Self::Load(e) => e.fmt(f),
            Self::Contact(e) => e.fmt(f),
            Self::Displacement(e) => e.fmt(f),
            Self::Loop(e) => e.fmt(f),
            Self::State(e) => e.fmt(f),
            Self::DynamicTissue(e) => e.fmt(f),
            Self::Physics(e) => e.fmt(f),
            Self::Fault(e) => e.fmt(f),
            Self::Hybrid(e) => e.fmt(f),
            Self::HybridTissue(e) => e.fmt(f),
            Self::Field(e) => e.fmt(f),
        }
    }
}

macro_rules! detail_from {
    ($($variant:ident($error:ty)),* $(,)?) => {
        $(impl From<$error> for Detail {
            fn from(e: $error) -> Self {
                Self::$variant(e)
            }
        })*
    };
}

detail_from!(
    Abi(Status),
    Load(LoadError),
    Contact(ContactError),
    Displacement(DisplacementError),
    Loop(LoopError),
    State(StateError),
    DynamicTissue(DynamicTissueError),
    Physics(PhysicsError),
    Fault(Fault),
    Hybrid(HybridError),
    HybridTissue(HybridTissueError),
    Field(FieldError),
);

// SAFETY: `Error` is a `#[repr(C)]` struct of `u64` words.
unsafe impl Handle for Error {
    type Value = Detail;
    const MAGIC: u32 = u32::from_le_bytes(*b"PErr");
}

/// The status of `result`, with its failure's details written to `error`
/// (when not null: a null, misaligned or unwritable `error` is skipped,
/// the status still says what failed). The one exit of every fallible
/// entry point.
///
/// # Safety
///
/// A non-null, aligned `error` points to a writable `palpate_error`.
pub(crate) unsafe fn finish(result: Result<(), Detail>, error: *mut Error) -> Status {
    match result {
        Ok(()) => Status::Ok,
        Err(detail) => {
            // SAFETY: the contract; a null or misaligned `error` is refused
            // by `init` without a write, which is what "skipped" means here.
            let _ = unsafe { handle::init(error, detail) };
            detail.status()
        }
    }
}

/// A `fmt::Write` into a C buffer: keeps what fits before the NUL and
/// counts the whole message.
struct Truncating<'b> {
    buffer: &'b mut [u8],
    written: usize,
    total: usize,
}

impl Write for Truncating<'_> {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        for (slot, &b) in self.buffer.iter_mut().skip(self.written).zip(s.as_bytes()) {
            *slot = b;
            self.written += 1;
        }
        self.total = self.total.saturating_add(s.len());
        Ok(())
    }
}

/// Writes the message of the failure recorded in `error` into `buffer`
/// (`capacity` bytes, NUL-terminated, truncated to fit), the kernel's own
/// words (for example `contact 1: vertex 0 is fixed`). Returns the
/// message's full length in bytes without the NUL, as `snprintf` does: the
/// message was truncated if that is `>= capacity`. `buffer` may be `NULL`
/// when `capacity` is 0 (to ask for the length). An `error` that is `NULL`,
/// misaligned or never written gives the empty message (0).
///
/// # Safety
///
/// `error` is `NULL` or points to a readable `palpate_error`; `buffer`
/// points to `capacity` writable bytes (any alignment).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn palpate_error_message(
    error: *const Error,
    buffer: *mut c_char,
    capacity: usize,
) -> usize {
    // SAFETY: the contract; a null, misaligned or dead handle is refused
    // (the empty message).
    let detail = unsafe { handle::get(error) }.ok();
    let buffer: &mut [u8] = if capacity == 0 {
        &mut []
    } else {
        // SAFETY: `capacity` writable bytes at `buffer` (contract); a byte
        // array needs no alignment; `slice_mut` refuses null.
        match unsafe { handle::slice_mut(buffer.cast::<u8>(), capacity) } {
            Ok(b) => b,
            Err(_) => &mut [],
        }
    };
    // The text, leaving room for the NUL.
    let text = buffer.len().saturating_sub(1);
    let mut out = Truncating {
        buffer: buffer.get_mut(..text).unwrap_or(&mut []),
        written: 0,
        total: 0,
    };
    if let Some(detail) = detail {
        let _ = write!(out, "{detail}");
    }
    let (written, total) = (out.written, out.total);
    if let Some(nul) = buffer.get_mut(written) {
        *nul = 0;
    }
    total
}
