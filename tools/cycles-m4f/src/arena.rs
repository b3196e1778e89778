//! One static RAM region handed out as typed slices, bump-allocated, so that
//! each run builds its tissue's buffers with the lengths the kernel asks for
//! (`SurfaceBuffers::lengths`, `HybridSurfaceBuffers::lengths`, the tables'
//! counts), as the host's heap-owned buffers do, without a fixed capacity
//! per scene. Nothing is freed but everything at once ([`Arena::reset`],
//! between runs, which the borrow checker allows only once every slice is
//! gone).

use core::cell::{Cell, UnsafeCell};
use core::mem::MaybeUninit;
use core::sync::atomic::{AtomicBool, Ordering};

/// Bytes of the arena: room for the organ's hybrid buffers (about 2 MB).
const ARENA_BYTES: usize = 8 << 20;

/// The arena's memory, in `.uninit` (not zeroed at reset: every slice is
/// initialized when handed out).
#[unsafe(link_section = ".uninit.ARENA")]
static ARENA: Memory = Memory(UnsafeCell::new(MaybeUninit::uninit()));

/// Set once the arena is taken.
static TAKEN: AtomicBool = AtomicBool::new(false);

#[repr(align(16))]
struct Memory(UnsafeCell<MaybeUninit<[u8; ARENA_BYTES]>>);

// SAFETY: only the one `Arena` that `Arena::take` returns (once) reaches the
// memory; the program is single-threaded without interrupts.
unsafe impl Sync for Memory {}

/// The arena (see the module docs).
pub struct Arena {
    start: *mut u8,
    used: Cell<usize>,
}

impl Arena {
    /// The arena over the static memory; `None` after the first call.
    pub fn take() -> Option<Self> {
        if TAKEN.swap(true, Ordering::Relaxed) {
            return None;
        }
        Some(Self {
            start: ARENA.0.get().cast::<u8>(),
            used: Cell::new(0),
        })
    }

    /// `len` copies of `value`, in memory no other slice of this arena
    /// holds until [`Self::reset`]; `None` if the arena is full.
    #[allow(clippy::mut_from_ref)] // a bump allocator: each call a fresh region
    pub fn slice<T: Copy>(&self, len: usize, value: T) -> Option<&mut [T]> {
        let at = self.used.get().next_multiple_of(align_of::<T>());
        let end = at.checked_add(size_of::<T>().checked_mul(len)?)?;
        if end > ARENA_BYTES {
            return None;
        }
        self.used.set(end);
        // SAFETY: `at..end` lies inside the arena's `ARENA_BYTES` (checked
        // above), `at` is aligned for `T` (the arena is 16-byte aligned and
        // `T`'s alignment divides 16 for every type this program takes),
        // and no other live slice overlaps it: `used` only grows until
        // `reset`, which takes `&mut self` and so outlives every slice.
        unsafe {
            let first = self.start.add(at).cast::<T>();
            for i in 0..len {
                first.add(i).write(value);
            }
            Some(core::slice::from_raw_parts_mut(first, len))
        }
    }

    /// Bytes handed out since the last reset.
    pub fn used(&self) -> usize {
        self.used.get()
    }

    /// Takes every slice back (the next run builds anew).
    pub fn reset(&mut self) {
        self.used.set(0);
    }
}
