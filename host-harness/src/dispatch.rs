//! Run-time CPU-feature dispatch of the kernel's hot loops
//! ([`palpate_kernel::math::dispatch`]): the release binary is built for the
//! x86-64 baseline (SSE2), which runs everywhere; at start-up the host
//! checks whether the CPU has AVX2 and FMA (x86-64-v3), and AVX-512 F, VL,
//! DQ and BW (x86-64-v4), and runs the kernel's passes from a function
//! compiled for the best of them ([`HostDispatch::detect`]). Measured on
//! the 6144-tet cylinder (README, "Timing your own mesh"), AVX-512 is the
//! faster for the St Venant-Kirchhoff passes (f64: 111 µs against 132 µs
//! with AVX2), AVX2 for the linear pass (36 µs against 39 µs); both beat
//! the baseline (46 µs, 180 µs) and match a `-C target-cpu=native` build.
//! On Intel CPUs that lower their clock for 512-bit instructions
//! (Skylake-SP, Cascade Lake) the AVX-512 level may be the slower:
//! `palpate bench --dispatch all` times every level.
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
//! not contract `a * b + c` into a fused multiply-add; the levels bring
//! wider vectors): `tests/host/dispatch.rs` checks that every level's step
//! equals the portable one bit for bit.
//!
//! One of the host's two modules that allow `unsafe` (the other is
//! `callgrind.rs`'s client request): calling a
//! `#[target_feature]` function from code compiled without the feature.

#![allow(unsafe_code)]

use palpate_kernel::math::Dispatch;

/// Where the kernel's hot passes run: the build's baseline, or (x86-64)
/// code compiled for AVX2 and FMA, or for AVX-512, on a CPU that has them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HostDispatch {
    /// The build's own instruction set (the kernel's `Portable`).
    Portable,
    /// x86-64 with AVX2 and FMA, detected at run time.
    #[cfg(target_arch = "x86_64")]
    Avx2Fma(Avx2Fma),
    /// x86-64 with AVX-512 (F, VL, DQ, BW) as well, detected at run time.
    #[cfg(target_arch = "x86_64")]
    Avx512(Avx512),
}

/// Proof that the running CPU has AVX-512 F, VL, DQ and BW besides AVX2
/// and FMA: only [`HostDispatch::detect`] makes one.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Avx512 {
    _detected: (),
}

/// Proof that the running CPU has AVX2 and FMA: only
/// [`HostDispatch::detect`] makes one, after `is_x86_feature_detected!`.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Avx2Fma {
    _detected: (),
}

impl HostDispatch {
    /// The best this CPU runs: [`HostDispatch::Avx512`] on an x86-64 CPU
    /// with AVX2, FMA and AVX-512 F, VL, DQ, BW, [`HostDispatch::Avx2Fma`]
    /// with AVX2 and FMA only (CPUID, cached by `std`), else
    /// [`HostDispatch::Portable`]. Under valgrind, whose CPUID hides
    /// AVX-512, the AVX2 level.
    pub fn detect() -> Self {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::is_x86_feature_detected as has;
            if has!("avx2") && has!("fma") {
                if has!("avx512f") && has!("avx512vl") && has!("avx512dq") && has!("avx512bw") {
                    return HostDispatch::Avx512(Avx512 { _detected: () });
                }
                return HostDispatch::Avx2Fma(Avx2Fma { _detected: () });
            }
        }
        HostDispatch::Portable
    }

    /// Every level this CPU runs, the baseline first and [`Self::detect`]'s
    /// last (what `palpate bench --dispatch all` times).
    pub fn available() -> Vec<Self> {
        let mut levels = vec![HostDispatch::Portable];
        #[cfg(target_arch = "x86_64")]
        {
            let best = Self::detect();
            if best != HostDispatch::Portable {
                if matches!(best, HostDispatch::Avx512(_)) {
                    levels.push(HostDispatch::Avx2Fma(Avx2Fma { _detected: () }));
                }
                levels.push(best);
            }
        }
        levels
    }

    /// A short name for reports: `portable`, `avx2+fma` or `avx512`.
    pub fn name(self) -> &'static str {
        match self {
            HostDispatch::Portable => "portable",
            #[cfg(target_arch = "x86_64")]
            HostDispatch::Avx2Fma(_) => "avx2+fma",
            #[cfg(target_arch = "x86_64")]
            HostDispatch::Avx512(_) => "avx512",
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
            #[cfg(target_arch = "x86_64")]
            // SAFETY: an `Avx512` exists only when `detect` found AVX2, FMA
            // and AVX-512 F, VL, DQ and BW on this CPU.
            HostDispatch::Avx512(_) => unsafe { run_avx512(pass) },
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

/// Calls `pass`, compiled for AVX-512 (F, VL, DQ, BW) with AVX2 and FMA.
///
/// # Safety
/// The CPU must have those features.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,avx512f,avx512vl,avx512dq,avx512bw")]
unsafe fn run_avx512<R>(pass: impl FnOnce() -> R) -> R {
    pass()
}
