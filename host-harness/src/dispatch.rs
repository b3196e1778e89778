//! Run-time CPU-feature dispatch of the kernel's hot loops
//! ([`palpate_kernel::math::dispatch`]): the release binary is built for the
//! x86-64 baseline (SSE2), which runs everywhere; at start-up the host
//! checks whether the CPU has AVX2 and FMA and, if so, runs the kernel's
//! passes from a function compiled for them ([`HostDispatch::detect`]).
//!
//! Which paths use it: `palpate dynamic run` (the tensor-mass step; a
//! hybrid scene's steps stay portable), `palpate session run` on a dynamic
//! scene (the physics updates' steps; a hybrid scene's stay portable) and
//! `palpate bench` (the steps and the pre-computed displacement update).
//! Everything whose output is compared bit for bit with the firmware
//! (`precomputed replay`, `scene replay-hybrid`, `tools/firmware-check.sh`),
//! `budget` (whose instruction counts stand for the firmware's), the
//! library's other entry points (`TensorMassModel::step`, the haptic
//! loops' ticks) and the tests' references run
//! [`palpate_kernel::math::Portable`].
//!
//! The kernel's passes do the same IEEE-754 operations either way (Rust does
//! not contract `a * b + c` into a fused multiply-add; AVX2 brings wider
//! vectors): `tests/host/dispatch.rs` checks that the dispatched step equals
//! the portable one bit for bit.
//!
//! The one module of the host that allows `unsafe`: calling a
//! `#[target_feature]` function from code compiled without the feature.

#![allow(unsafe_code)]

use palpate_kernel::math::Dispatch;

/// Where the kernel's hot passes run: the build's baseline, or (x86-64)
/// code compiled for AVX2 and FMA on a CPU that has them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HostDispatch {
    /// The build's own instruction set (the kernel's `Portable`).
    Portable,
    /// x86-64 with AVX2 and FMA, detected at run time.
    #[cfg(target_arch = "x86_64")]
    Avx2Fma(Avx2Fma),
}

/// Proof that the running CPU has AVX2 and FMA: only
/// [`HostDispatch::detect`] makes one, after `is_x86_feature_detected!`.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Avx2Fma {
    _detected: (),
}

impl HostDispatch {
    /// The best this CPU runs: [`HostDispatch::Avx2Fma`] on an x86-64 CPU
    /// with AVX2 and FMA (checked once per call by CPUID, cached by `std`),
    /// else [`HostDispatch::Portable`].
    pub fn detect() -> Self {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
        {
            return HostDispatch::Avx2Fma(Avx2Fma { _detected: () });
        }
        HostDispatch::Portable
    }

    /// A short name for reports: `portable` or `avx2+fma`.
    pub fn name(self) -> &'static str {
        match self {
            HostDispatch::Portable => "portable",
            #[cfg(target_arch = "x86_64")]
            HostDispatch::Avx2Fma(_) => "avx2+fma",
        }
    }
}

impl Dispatch for HostDispatch {
    #[inline(always)]
    fn run<R>(self, pass: impl FnOnce() -> R) -> R {
        match self {
            HostDispatch::Portable => pass(),
            #[cfg(target_arch = "x86_64")]
            // SAFETY: an `Avx2Fma` exists only when `detect` found AVX2 and
            // FMA on this CPU (`is_x86_feature_detected!`), which is what
            // calling a function with `#[target_feature(enable = "avx2,fma")]`
            // requires.
            HostDispatch::Avx2Fma(_) => unsafe { run_avx2_fma(pass) },
        }
    }
}

/// Calls `pass`, compiled (with everything the kernel inlines into it: its
/// passes are `#[inline(always)]` closures) for AVX2 and FMA.
///
/// # Safety
/// The CPU must have AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn run_avx2_fma<R>(pass: impl FnOnce() -> R) -> R {
    pass()
}
