//! The unsafe core of the boundary: Rust values placed in the caller's
//! fixed-size handle structs, and the caller's memory block carved into
//! the kernel's buffers. Everything else reaches C memory through these
//! functions and [`out`], [`slice`] and [`slice_mut`].
//!
//! A handle struct is `uint64_t opaque[N]` (8-byte aligned on every
//! target). A live handle holds a [`Cell`]: a magic word naming its type,
//! then the value. A function that receives a handle checks the pointer
//! (not null, aligned) and the magic before it reads the value, so a handle
//! whose creation failed (the magic is cleared) or that was never created
//! (zero-initialized storage) is refused, never read.

use core::mem::{align_of, size_of};
use core::ptr::{addr_of, addr_of_mut};

use crate::status::Status;

/// A handle type: the C struct and what it holds. A value that outgrows its
/// struct fails the build ([`init`]'s compile-time assertion): raise the
/// handle's `PALPATE_*_WORDS` (the header's sizes) and
/// `PALPATE_ABI_VERSION`.
///
/// # Safety
///
/// `Self` must be a `#[repr(C)]` struct of `u64` words only (any bit
/// pattern valid, 8-byte aligned), so that a [`Cell<Self::Value>`] can be
/// written over it.
pub(crate) unsafe trait Handle {
    /// The Rust value a live handle holds.
    type Value;
    /// The magic word of a live handle of this type (never 0).
    const MAGIC: u32;
}

/// A live handle's contents.
#[repr(C)]
struct Cell<V> {
    magic: u32,
    value: V,
}

/// `Err(NullPointer)` for a null `p`, `Err(Misaligned)` for a `p` not
/// aligned for `E`.
pub(crate) fn check<E>(p: *const E) -> Result<(), Status> {
    if p.is_null() {
        Err(Status::NullPointer)
    } else if !p.is_aligned() {
        Err(Status::Misaligned)
    } else {
        Ok(())
    }
}

/// Writes `value` into handle `h` and marks it live. On `Err` (a null or
/// misaligned `h`) nothing is written.
///
/// # Safety
///
/// A non-null, aligned `h` points to a writable `H` that nothing else
/// accesses during the call. The value may borrow from other handles or
/// memory: the caller of the C function keeps those alive and unmoved
/// while `h` is used (the header says so for each function).
pub(crate) unsafe fn init<H: Handle>(h: *mut H, value: H::Value) -> Result<(), Status> {
    const {
        assert!(size_of::<Cell<H::Value>>() <= size_of::<H>());
        assert!(align_of::<Cell<H::Value>>() <= align_of::<H>());
    };
    check(h)?;
    // SAFETY: `h` is non-null, aligned and writable (contract); the cell
    // fits in `H` and needs no more alignment (checked above at compile
    // time); a write does not read or drop the old contents.
    unsafe {
        h.cast::<Cell<H::Value>>().write(Cell {
            magic: H::MAGIC,
            value,
        })
    };
    Ok(())
}

/// Marks handle `h` dead (a failed creation), when it is non-null and
/// aligned; the value is not dropped (the kernel's types own nothing).
///
/// # Safety
///
/// As [`init`].
pub(crate) unsafe fn clear<H: Handle>(h: *mut H) {
    if check(h).is_ok() {
        // SAFETY: `h` is non-null, aligned and writable (contract); the
        // magic word is the first field of the cell, inside `H`.
        unsafe { addr_of_mut!((*h.cast::<Cell<H::Value>>()).magic).write(0) };
    }
}

/// The value of live handle `h`.
///
/// # Safety
///
/// A non-null, aligned `h` points to a readable `H` (initialized memory: a
/// handle written by [`init`], or zeroed or static storage) that nothing
/// writes during `'h`.
pub(crate) unsafe fn get<'h, H: Handle>(h: *const H) -> Result<&'h H::Value, Status> {
    check(h)?;
    let cell = h.cast::<Cell<H::Value>>();
    // SAFETY: `h` is non-null, aligned and readable (contract); the magic
    // word is a `u32` at the start of `H`, initialized memory.
    let magic = unsafe { addr_of!((*cell).magic).read() };
    if magic != H::MAGIC {
        return Err(Status::NotInitialized);
    }
    // SAFETY: the magic says `init` wrote a value of this type here, and
    // only `init` writes the magic; nothing writes it during `'h`.
    Ok(unsafe { &*addr_of!((*cell).value) })
}

/// The value of live handle `h`, mutably.
///
/// # Safety
///
/// As [`get`], and nothing else reads or writes `*h` during `'h`.
pub(crate) unsafe fn get_mut<'h, H: Handle>(h: *mut H) -> Result<&'h mut H::Value, Status> {
    // SAFETY: the contract of `get`, which this function's contract includes.
    unsafe { get::<H>(h) }?;
    // SAFETY: `get` checked the pointer and the magic; access is exclusive
    // during `'h` (contract).
    Ok(unsafe { &mut *addr_of_mut!((*h.cast::<Cell<H::Value>>()).value) })
}

/// Writes `value` to the caller's output `p`.
///
/// # Safety
///
/// A non-null, aligned `p` points to a writable `E`.
pub(crate) unsafe fn out<E>(p: *mut E, value: E) -> Result<(), Status> {
    check(p)?;
    // SAFETY: non-null, aligned, writable (contract); `E` is a plain C
    // struct or number with nothing to drop.
    unsafe { p.write(value) };
    Ok(())
}

/// The caller's input `p`, read by value.
///
/// # Safety
///
/// A non-null, aligned `p` points to a readable, initialized `E` (a C
/// struct of numbers: every bit pattern is a valid `E`).
pub(crate) unsafe fn read<E: Copy>(p: *const E) -> Result<E, Status> {
    check(p)?;
    // SAFETY: as the contract says.
    Ok(unsafe { p.read() })
}

/// The caller's array `p` of `len` elements.
///
/// # Safety
///
/// A non-null, aligned `p` points to `len` readable, initialized `E`s (every
/// bit pattern valid) that nothing writes during `'s`.
pub(crate) unsafe fn slice<'s, E>(p: *const E, len: usize) -> Result<&'s [E], Status> {
    check(p)?;
    // SAFETY: as the contract says; `len` elements of an object in memory
    // cannot exceed `isize::MAX` bytes.
    Ok(unsafe { core::slice::from_raw_parts(p, len) })
}

/// The caller's array `p` of `len` elements, writable.
///
/// # Safety
///
/// As [`slice`], writable, and nothing else accesses it during `'s`.
pub(crate) unsafe fn slice_mut<'s, E>(p: *mut E, len: usize) -> Result<&'s mut [E], Status> {
    check(p)?;
    // SAFETY: as the contract says.
    Ok(unsafe { core::slice::from_raw_parts_mut(p, len) })
}

/// The caller's memory block cut into the kernel's buffers, front to back,
/// each aligned for its element type; or, to size the block first, the
/// same cuts counted without memory ([`Arena::measure`]). One function
/// takes every buffer of a loop from an arena, so the size a
/// `palpate_*_memory_size` reports and the cuts `palpate_*_loop_create`
/// makes cannot disagree.
pub(crate) struct Arena {
    /// Start of the block; null while measuring.
    base: *mut u8,
    /// Bytes in the block (`usize::MAX` while measuring).
    len: usize,
    /// Bytes cut so far, from `base`.
    used: usize,
}

impl Arena {
    /// An arena that only counts: every buffer it hands out is empty.
    pub(crate) fn measure() -> Self {
        Self {
            base: core::ptr::null_mut(),
            len: usize::MAX,
            used: 0,
        }
    }

    /// An arena over the caller's block `memory` of `len` bytes.
    ///
    /// # Safety
    ///
    /// A non-null `memory` points to `len` writable bytes that nothing else
    /// accesses while the buffers cut from it are used (the loop created over
    /// it).
    pub(crate) unsafe fn over(memory: *mut u8, len: usize) -> Result<Self, Status> {
        if memory.is_null() {
            return Err(Status::NullPointer);
        }
        if memory.align_offset(crate::PALPATE_MEMORY_ALIGN as usize) != 0 {
            return Err(Status::Misaligned);
        }
        Ok(Self {
            base: memory,
            len,
            used: 0,
        })
    }

    /// Bytes cut so far: after every cut, the size the block needs.
    pub(crate) fn used(&self) -> usize {
        self.used
    }

    /// The next `n` elements, each set to `fill` (the block's contents are
    /// never read: C memory may hold any bytes, and a `bool` or an enum may
    /// not). `Err(MemoryTooSmall)` when the block ends first (or the size
    /// overflows).
    pub(crate) fn take<E: Copy>(&mut self, n: usize, fill: E) -> Result<&'static mut [E], Status> {
        const {
            assert!(align_of::<E>() <= crate::PALPATE_MEMORY_ALIGN as usize);
        };
        let start = self
            .used
            .checked_next_multiple_of(align_of::<E>())
            .ok_or(Status::MemoryTooSmall)?;
        let end = n
            .checked_mul(size_of::<E>())
            .and_then(|bytes| start.checked_add(bytes))
            .filter(|&end| end <= self.len)
            .ok_or(Status::MemoryTooSmall)?;
        self.used = end;
        if self.base.is_null() {
            return Ok(&mut []);
        }
        // SAFETY: `start..end` lies inside the caller's block (`end ≤ len`),
        // which `over`'s contract makes writable and exclusive; `base` is
        // aligned to `PALPATE_MEMORY_ALIGN` and `start` to `align_of::<E>()`
        // (at most that), so the elements are aligned; cuts never overlap
        // (`used` only grows). Each element is written before the slice is
        // made, so the slice holds valid `E`s.
        unsafe {
            let first = self.base.add(start).cast::<E>();
            for i in 0..n {
                first.add(i).write(fill);
            }
            Ok(core::slice::from_raw_parts_mut(first, n))
        }
    }
}
