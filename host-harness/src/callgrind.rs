//! Callgrind's client request `CALLGRIND_START_INSTRUMENTATION`
//! (`valgrind/callgrind.h`), which `palpate budget`'s probe issues just
//! before its first tick ([`crate::budget::measure`] runs it with
//! `--instr-atstart=no`): callgrind then instruments only the ticks (and a
//! dynamic tissue's physics updates between them), not the start-up, the
//! table's load and validation. Each per-tick dump walks every basic block
//! callgrind has instrumented, so this makes the dumps, most of a budget's
//! time, cheaper.
//!
//! The host's second module that allows `unsafe` (with `dispatch.rs`): the
//! request is the magic instruction sequence of `valgrind/valgrind.h`
//! (x86-64), which outside Valgrind leaves every register but the flags as
//! it was.

#![allow(unsafe_code)]

/// Whether this build issues the request (x86-64 Linux, the platform of
/// `valgrind.h`'s sequence below). Elsewhere [`start_instrumentation`] does
/// nothing and the budget instruments from the start
/// ([`crate::budget::InstrumentFrom::Start`]).
pub const STARTS_INSTRUMENTATION: bool = cfg!(all(target_arch = "x86_64", target_os = "linux"));

/// `VG_USERREQ_TOOL_BASE('C', 'T') + 4`: callgrind's
/// `VG_USERREQ__START_INSTRUMENTATION`.
#[cfg(all(target_arch = "x86_64", target_os = "linux"))]
const START_INSTRUMENTATION: u64 = ((b'C' as u64) << 24 | (b'T' as u64) << 16) + 4;

/// Asks callgrind to start instrumenting (run with `--instr-atstart=no`);
/// a no-op outside Valgrind and on other platforms.
pub fn start_instrumentation() {
    #[cfg(all(target_arch = "x86_64", target_os = "linux"))]
    {
        let args: [u64; 6] = [START_INSTRUMENTATION, 0, 0, 0, 0, 0];
        // SAFETY: `valgrind.h`'s client request for amd64. The four
        // rotations of rdi add up to 128 bits (rdi ends as it began) and
        // `xchg rbx, rbx` exchanges rbx with itself: outside Valgrind the
        // sequence changes no register but the flags (`rol` sets them;
        // not `preserves_flags`). Under Valgrind it reads the six words at
        // rax (alive for the whole block) and writes rdx (the request's
        // result, 0 by default here; unused).
        unsafe {
            core::arch::asm!(
                "rol rdi, 3",
                "rol rdi, 13",
                "rol rdi, 61",
                "rol rdi, 51",
                "xchg rbx, rbx",
                in("rax") args.as_ptr(),
                inout("rdx") 0u64 => _,
                options(nostack),
            );
        }
    }
}
