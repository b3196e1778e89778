//! The rotation closest to a 3×3 matrix (the rotation factor of its polar
//! decomposition, with the sign fixed so that it is a proper rotation), by a
//! fixed number of Jacobi sweeps: bounded, branch-free per lane (selects
//! only), no panic and a finite result for every finite input.
//!
//! Method (the signed SVD of Irving, Teran & Fedkiw 2004 §5, computed as
//! McAdams et al. 2011 "Computing the singular value decomposition of 3×3
//! matrices with minimal branching" §2–4, with exact Jacobi rotations):
//! the eigenvectors `V` of `FᵀF` by [`JACOBI_SWEEPS`] cyclic Jacobi sweeps,
//! sorted by decreasing eigenvalue with `det V = +1`; `U` from `F V`:
//! `u₁ = b₁/|b₁|`, `u₂` = `b₂` orthogonalized against `u₁` (twice) and
//! normalized, `u₃ = u₁ × u₂`, so that `det U = +1`; `R = U Vᵀ`. When
//! `det F < 0` this puts the sign on the smallest singular value: `R` is
//! the proper rotation closest to `F`, and `RᵀF` is symmetric.
//!
//! Accuracy: `R` is orthonormal with `det R = +1` to rounding by
//! construction (a product of Givens rotations and a re-orthogonalized
//! frame). Cyclic Jacobi on a 3×3 symmetric matrix converges
//! quadratically: four sweeps leave off-diagonal residuals at rounding for
//! singular-value ratios up to `1e6`, so `RᵀF` is symmetric to about
//! `1e-12 |F|` in f64 (`1e-5 |F|` in f32); tests/kernel/polar.rs measures
//! it on random and near-singular `F`. Degenerate inputs (`F = 0`, rank
//! one) give a rotation among the equally close ones.

use crate::Real;

/// Cyclic Jacobi sweeps (three rotations each) on `FᵀF`.
pub const JACOBI_SWEEPS: usize = 4;

/// A 3×3 matrix by rows.
pub type Mat3<T> = [[T; 3]; 3];

/// Below this squared length a frame vector counts as zero (a singular
/// direction): the frame falls back to a fixed orthogonal choice.
const TINY2: f64 = 1e-30;

/// Off-diagonal entries of `FᵀF` below this fraction of their diagonal
/// pair are treated as zero by the Jacobi rotation ([`rotate`]).
const FLUSH: f64 = 1e-18;

/// The proper rotation closest to `f` (rows), `R = U Vᵀ` of the signed SVD
/// (see the module documentation). Always inlined, so that a lane loop that
/// calls it stays one loop.
#[expect(
    clippy::indexing_slicing,
    reason = "from_fn indices and k are < 3 over 3×3 arrays; tools/nopanic-check proves no panic is left"
)]
#[inline(always)]
pub fn closest_rotation<T: Real>(f: &Mat3<T>) -> Mat3<T> {
    let v = right_vectors(f);
    // Columns of V: v[.][k]; b_k = F v_k.
    let b = |k: usize| -> [T; 3] {
        core::array::from_fn(|r| f[r][0] * v[0][k] + f[r][1] * v[1][k] + f[r][2] * v[2][k])
    };
    let tiny = T::of_f64(TINY2);
    let b1 = b(0);
    let n1 = dot(&b1, &b1);
    let u1 = if n1 > tiny {
        scale(&b1, T::one() / n1.sqrt())
    } else {
        [T::one(), T::zero(), T::zero()]
    };
    let mut w = b(1);
    for _ in 0..2 {
        let along = dot(&u1, &w);
        w = core::array::from_fn(|r| w[r] - along * u1[r]);
    }
    let n2 = dot(&w, &w);
    let u2 = if n2 > tiny {
        scale(&w, T::one() / n2.sqrt())
    } else {
        perpendicular(&u1)
    };
    let u3 = cross(&u1, &u2);
    let u = [u1, u2, u3];
    // R_ij = Σ_k U_ik V_jk, U's columns u_k.
    core::array::from_fn(|i| {
        core::array::from_fn(|j| u[0][i] * v[j][0] + u[1][i] * v[j][1] + u[2][i] * v[j][2])
    })
}

/// The eigenvectors of `FᵀF` as the columns of a rotation `V` (rows),
/// sorted by decreasing eigenvalue.
#[expect(
    clippy::indexing_slicing,
    reason = "from_fn indices and k are < 3 over 3×3 arrays; tools/nopanic-check proves no panic is left"
)]
#[inline(always)]
fn right_vectors<T: Real>(f: &Mat3<T>) -> Mat3<T> {
    let column = |c: usize| [f[0][c], f[1][c], f[2][c]];
    let cols = [column(0), column(1), column(2)];
    let mut s: Mat3<T> =
        core::array::from_fn(|i| core::array::from_fn(|j| dot(&cols[i], &cols[j])));
    let (zero, one) = (T::zero(), T::one());
    let mut v = [[one, zero, zero], [zero, one, zero], [zero, zero, one]];
    for _ in 0..JACOBI_SWEEPS {
        rotate(&mut s, &mut v, 0, 1, 2);
        rotate(&mut s, &mut v, 0, 2, 1);
        rotate(&mut s, &mut v, 1, 2, 0);
    }
    // Sort the eigenvalues s_kk downwards, swapping columns of V; the
    // swapped-in column changes sign so that det V stays +1.
    for (p, q) in [(0, 1), (1, 2), (0, 1)] {
        swap_if_smaller(&mut s, &mut v, p, q);
    }
    v
}

/// One Jacobi rotation in the `(p, q)` plane (`r` the third index) that
/// zeroes `s_pq` of the symmetric `s`, accumulated into `v`'s columns
/// (Numerical Recipes §11.1, eq. 11.1.8–11.1.18): `θ = (s_qq − s_pp)/(2s_pq)`,
/// `t = sgn θ/(|θ| + √(θ²+1))`, written as
/// `t = 2 s_pq sgn(τ)/(|τ| + √(τ² + 4 s_pq²))` with `τ = s_qq − s_pp`, so
/// that `s_pq = 0` gives `t = 0` and no division by zero.
#[expect(
    clippy::indexing_slicing,
    reason = "p, q, r are literals < 3 at every call"
)]
#[inline(always)]
fn rotate<T: Real>(s: &mut Mat3<T>, v: &mut Mat3<T>, p: usize, q: usize, r: usize) {
    let (zero, one) = (T::zero(), T::one());
    let (spp, sqq) = (s[p][p], s[q][q]);
    // An off-diagonal already below 1e-18 of the diagonal counts as zero:
    // below f64's rounding, and it keeps the squares and products of the
    // later sweeps out of the subnormal range (f32 below 1.2e-38), whose
    // arithmetic is a hundred times slower on x86.
    let spq = if s[p][q].abs() > T::of_f64(FLUSH) * (spp.abs() + sqq.abs()) {
        s[p][q]
    } else {
        zero
    };
    let tau = sqq - spp;
    let sign = if tau < zero { -one } else { one };
    let denominator = tau.abs() + (tau * tau + T::of_f64(4.0) * spq * spq).sqrt();
    let t = if denominator > zero {
        (spq + spq) * sign / denominator
    } else {
        zero
    };
    let c = one / (one + t * t).sqrt();
    let sn = t * c;
    s[p][p] = spp - t * spq;
    s[q][q] = sqq + t * spq;
    s[p][q] = zero;
    s[q][p] = zero;
    let (srp, srq) = (s[r][p], s[r][q]);
    s[r][p] = c * srp - sn * srq;
    s[r][q] = sn * srp + c * srq;
    s[p][r] = s[r][p];
    s[q][r] = s[r][q];
    for row in v.iter_mut() {
        let (vp, vq) = (row[p], row[q]);
        row[p] = c * vp - sn * vq;
        row[q] = sn * vp + c * vq;
    }
}

/// Swaps eigenvalues `p < q` (the diagonal of `s`) and `v`'s columns when
/// `s_pp < s_qq`, negating the new column `q` (det `v` unchanged).
#[expect(clippy::indexing_slicing, reason = "p, q are literals < 3")]
#[inline(always)]
fn swap_if_smaller<T: Real>(s: &mut Mat3<T>, v: &mut Mat3<T>, p: usize, q: usize) {
    let swap = s[p][p] < s[q][q];
    let (spp, sqq) = (s[p][p], s[q][q]);
    s[p][p] = if swap { sqq } else { spp };
    s[q][q] = if swap { spp } else { sqq };
    for row in v.iter_mut() {
        let (vp, vq) = (row[p], row[q]);
        row[p] = if swap { vq } else { vp };
        row[q] = if swap { -vp } else { vq };
    }
}

/// A unit vector perpendicular to the unit vector `u`: `u × e_x` when `u`
/// is far from `e_x` (`|u_x| < ½`, length ≥ √3/2), else `u × e_y` (length
/// ≥ ½ since then `|u_y|² ≤ ¾`).
#[inline(always)]
fn perpendicular<T: Real>(u: &[T; 3]) -> [T; 3] {
    let zero = T::zero();
    let c = if u[0].abs() < T::of_f64(0.5) {
        [zero, u[2], -u[1]]
    } else {
        [-u[2], zero, u[0]]
    };
    scale(&c, T::one() / dot(&c, &c).sqrt())
}

#[inline(always)]
fn dot<T: Real>(a: &[T; 3], b: &[T; 3]) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
fn scale<T: Real>(a: &[T; 3], k: T) -> [T; 3] {
    [a[0] * k, a[1] * k, a[2] * k]
}

#[inline(always)]
fn cross<T: Real>(a: &[T; 3], b: &[T; 3]) -> [T; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
