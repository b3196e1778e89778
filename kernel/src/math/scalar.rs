//! The scalar the kernel computes in: `f32` on firmware, `f64` for verification.

use core::ops::{Add, Mul, Sub};

use nalgebra::RealField;

/// A floating-point scalar usable both as table storage and for computation.
///
/// Implemented for `f32` (firmware, the default table precision) and `f64`
/// (verification against reference FEM data).
///
/// `FromStr` lets scripts and command lines be parsed straight into the
/// scalar, with the same rounding on host and firmware.
pub trait Real:
    RealField + Copy + bytemuck::Pod + Default + PartialOrd + core::str::FromStr
{
    /// Bytes per stored value; written in the table header so an `f32` table is
    /// never read as `f64`.
    const BYTES: u32;
    /// A Cholesky pivot of the contact system below this fraction of the
    /// largest diagonal compliance means the contact set is (numerically)
    /// singular: `sqrt(machine epsilon)`, so that forces keep at least half the
    /// available digits (f32: 3.5e-4, f64: 1.5e-8).
    const MIN_PIVOT_RATIO: Self;
    /// Tolerance on barycentric weights: each in `[-tol, 1 + tol]`, sum within
    /// `tol` of one (f32: 1e-5, f64: 1e-12).
    const WEIGHT_TOLERANCE: Self;
    /// Converts from `f64` (rounding to nearest for `f32`).
    fn of_f64(x: f64) -> Self;
    /// Converts to `f64` (exact).
    fn as_f64(self) -> f64;
    /// Converts from `f32` (exact).
    fn of_f32(x: f32) -> Self;
    /// `true` if neither NaN nor infinite.
    fn finite(self) -> bool;
    /// Converts from `u32` (rounding to nearest for `f32` above 2²⁴), in
    /// the scalar itself: no `f64` on a target whose FPU has none.
    fn of_u32(x: u32) -> Self;
    /// Truncates towards zero to `u32`, saturating (NaN gives 0), in the
    /// scalar itself.
    fn trunc_u32(self) -> u32;
    /// The natural logarithm by the `libm` crate's software `logf` / `log`
    /// on every target, so that the host and the firmware compute the same
    /// bits (`ln` is the platform C library's on a host with `std`): the
    /// neo-Hookean law's `ln J`. Accurate to about one unit in the last
    /// place.
    fn portable_ln(self) -> Self;
    /// The larger of `self` and `other` by `>` (`other` when either is
    /// NaN): one compare, where `max` is a `fmaxf` call on a target
    /// without a maximum instruction (FPv4-SP).
    fn larger(self, other: Self) -> Self {
        if self > other { self } else { other }
    }
    /// Four values in one SIMD vector where the target has one (`wide`:
    /// `f32x4` in SSE, `f64x4` in AVX or two SSE2 halves on x86-64; four
    /// scalars on the Cortex-M4F), with lane-wise IEEE-754 `+ − ×`: the
    /// same results as the scalar operations, lane by lane.
    type Lanes: Copy
        + Add<Output = Self::Lanes>
        + Sub<Output = Self::Lanes>
        + Mul<Output = Self::Lanes>;
    /// `[x₀, x₁, x₂, x₃]` as lanes.
    fn lanes(x: [Self; 4]) -> Self::Lanes;
    /// The lanes' values.
    fn lane_values(v: Self::Lanes) -> [Self; 4];
}

/// The methods whose text is the same for `f32` and `f64` (each type's
/// own `is_finite`, cast and `wide` vector).
macro_rules! same_in_both {
    () => {
        fn finite(self) -> bool {
            self.is_finite()
        }
        fn trunc_u32(self) -> u32 {
            self as u32
        }
        #[inline(always)]
        fn lanes(x: [Self; 4]) -> Self::Lanes {
            Self::Lanes::new(x)
        }
        #[inline(always)]
        fn lane_values(v: Self::Lanes) -> [Self; 4] {
            v.to_array()
        }
    };
}

impl Real for f32 {
    const BYTES: u32 = 4;
    type Lanes = wide::f32x4;
    const MIN_PIVOT_RATIO: Self = 3.5e-4;
    const WEIGHT_TOLERANCE: Self = 1e-5;
    fn of_f64(x: f64) -> Self {
        x as f32
    }
    fn as_f64(self) -> f64 {
        f64::from(self)
    }
    fn of_f32(x: f32) -> Self {
        x
    }
    fn of_u32(x: u32) -> Self {
        x as f32
    }
    fn portable_ln(self) -> Self {
        libm::logf(self)
    }
    same_in_both!();
}

impl Real for f64 {
    const BYTES: u32 = 8;
    type Lanes = wide::f64x4;
    const MIN_PIVOT_RATIO: Self = 1.5e-8;
    const WEIGHT_TOLERANCE: Self = 1e-12;
    fn of_f64(x: f64) -> Self {
        x
    }
    fn as_f64(self) -> f64 {
        self
    }
    fn of_f32(x: f32) -> Self {
        f64::from(x)
    }
    fn of_u32(x: u32) -> Self {
        f64::from(x)
    }
    fn portable_ln(self) -> Self {
        libm::log(self)
    }
    same_in_both!();
}
