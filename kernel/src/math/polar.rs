//! The rotation closest to a 3×3 matrix (the rotation factor of its polar
//! decomposition, with the sign fixed so that it is a proper rotation):
//! bounded work, branch-free per lane (selects only), no panic and a finite
//! result for every finite input.
//!
//! Fast path (every tet of a step that is neither inverted nor extremely
//! distorted): the scaled Newton iteration for the polar factor (Higham
//! 1986, "Computing the polar decomposition — with applications", §3;
//! Higham, "Functions of Matrices" §8.6), `X₀ = F`,
//! `X_{k+1} = ½ (γ_k X_k + γ_k⁻¹ X_k⁻ᵀ)` with `X⁻ᵀ = cof X / det X` and the
//! Frobenius scaling `γ = (|X⁻¹| / |X|)^½` on the first
//! [`NEWTON_SCALED_STEPS`] steps, [`NEWTON_STEPS`] steps in all. Writing
//! `F = R S` (`S` symmetric positive definite when `det F > 0`), every
//! iterate is `R S_k` with `S_k → I` quadratically: the convergence
//! depends on `F`'s singular values only, not on its rotation, so a fixed
//! count serves tets rotated by any angle, cold (no previous rotation is
//! kept). A lane is accepted when `det F > 0` (the iteration keeps the
//! sign of `det`, so its limit is then a proper rotation) and the last
//! step moved no entry by more than `√ε` of the scalar ([`crate::Real`]'s
//! `MIN_PIVOT_RATIO`): quadratic convergence then leaves an error of
//! order `ε`.
//!
//! Fallback (a block with any lane not accepted: an inverted or nearly
//! degenerate tet, or a singular-value ratio beyond about 10³): the signed
//! SVD of Irving, Teran & Fedkiw 2004 §5, computed as McAdams et al. 2011
//! "Computing the singular value decomposition of 3×3 matrices with
//! minimal branching" §2–4, with exact Jacobi rotations: the eigenvectors
//! `V` of `FᵀF` by [`JACOBI_SWEEPS`] cyclic Jacobi sweeps, sorted by
//! decreasing eigenvalue with `det V = +1`; `U` from `F V`:
//! `u₁ = b₁/|b₁|`, `u₂` = `b₂` orthogonalized against `u₁` (twice) and
//! normalized, `u₃ = u₁ × u₂`, so that `det U = +1`; `R = U Vᵀ`. When
//! `det F < 0` this puts the sign on the smallest singular value: `R` is
//! the proper rotation closest to `F`, and `RᵀF` is symmetric. Both paths
//! compute the same rotation to rounding; which one ran depends only on
//! the block's input, the same on every target (bit-identical firmware).
//!
//! Lanes: [`closest_rotations`] computes `N` matrices at once, each entry
//! a `[T; N]` array (the per-tet pass's structure-of-arrays blocks, `N` =
//! 8). Every step is a short loop over the lanes with a branch-free scalar
//! body (selects only, no inner loop), the form the compiler turns into
//! SIMD operations (square roots and divisions included); a per-lane loop
//! around the whole computation does not vectorize (its body, with the
//! iterations, is too large to unroll first). [`closest_rotation`] is the
//! same code with one lane.
//!
//! Accuracy: `R` is orthonormal with `det R = +1` to rounding (Newton:
//! accepted only once converged; Jacobi: by construction, a product of
//! Givens rotations and a re-orthogonalized frame). Cyclic Jacobi on a 3×3
//! symmetric matrix converges quadratically: four sweeps leave
//! off-diagonal residuals at rounding for singular-value ratios up to
//! `1e6`, so `RᵀF` is symmetric to about `1e-12 |F|` in f64 (`1e-5 |F|` in
//! f32); tests/kernel/polar.rs measures it on random and near-singular `F`.
//! Degenerate inputs (`F = 0`, rank one) give a rotation among the equally
//! close ones.

use crate::Real;

/// Cyclic Jacobi sweeps (three rotations each) on `FᵀF` (the fallback).
pub const JACOBI_SWEEPS: usize = 4;

/// Newton steps of the fast path, in all.
pub const NEWTON_STEPS: usize = 4;

/// Of [`NEWTON_STEPS`], the first ones with the Frobenius scaling (the
/// later ones start close to the rotation, where `γ ≈ 1`).
pub const NEWTON_SCALED_STEPS: usize = 2;

/// A 3×3 matrix by rows.
pub type Mat3<T> = [[T; 3]; 3];

/// Below this squared length a frame vector counts as zero (a singular
/// direction): the frame falls back to a fixed orthogonal choice.
const TINY2: f64 = 1e-30;

/// Off-diagonal entries of `FᵀF` below this fraction of their diagonal
/// pair are treated as zero by the Jacobi rotation ([`rotate`]).
const FLUSH: f64 = 1e-18;

/// The proper rotation closest to `f` (rows) (see the module
/// documentation): [`closest_rotations`] with one lane.
#[inline(always)]
pub fn closest_rotation<T: Real>(f: &Mat3<T>) -> Mat3<T> {
    let one_lane = f.map(|row| row.map(|x| [x]));
    closest_rotations(&one_lane).map(|row| row.map(|[x]| x))
}

/// Per lane, the proper rotation closest to `f` (rows; entry `f[i][j][l]`
/// of lane `l`): the Newton iteration when it converges on every lane,
/// else the signed SVD for the whole block (see the module
/// documentation). Always inlined, so that its lane loops see the
/// caller's fixed `N`.
#[inline(always)]
pub fn closest_rotations<T: Real, const N: usize>(f: &Mat3<[T; N]>) -> Mat3<[T; N]> {
    let (r, accepted) = newton_rotations(f);
    if accepted.iter().all(|&a| a) {
        r
    } else {
        svd_rotations(f)
    }
}

/// Per lane, [`NEWTON_STEPS`] Newton steps from `f` (see the module
/// documentation), and whether the lane is accepted: `det f > 0` and the
/// last step moved no entry by more than `MIN_PIVOT_RATIO` (`√ε`). A
/// non-finite iterate is not accepted (its comparisons are false).
#[expect(
    clippy::indexing_slicing,
    reason = "i, j are literals < 3 at every call of the closures"
)]
#[inline(always)]
fn newton_rotations<T: Real, const N: usize>(f: &Mat3<[T; N]>) -> (Mat3<[T; N]>, [bool; N]) {
    let zero = T::zero();
    let mut x = *f;
    let mut accepted = [false; N];
    for (l, ok) in accepted.iter_mut().enumerate() {
        *ok = determinant(&lane(f, l)) > zero;
    }
    for step in 0..NEWTON_STEPS - 1 {
        let scaled = step < NEWTON_SCALED_STEPS;
        for l in 0..N {
            let next = newton_step(&lane(&x, l), scaled);
            set_lane(&mut x, l, &next);
        }
    }
    for (l, ok) in accepted.iter_mut().enumerate() {
        let xl = lane(&x, l);
        let next = newton_step(&xl, NEWTON_STEPS <= NEWTON_SCALED_STEPS);
        let moved = [0, 1, 2].map(|i| {
            let d = |j: usize| (next[i][j] - xl[i][j]).abs();
            d(0).larger(d(1)).larger(d(2))
        });
        let moved = moved[0].larger(moved[1]).larger(moved[2]);
        *ok = *ok && moved <= T::MIN_PIVOT_RATIO;
        set_lane(&mut x, l, &next);
    }
    (x, accepted)
}

/// One Newton step `½ (γ X + γ⁻¹ X⁻ᵀ)`, `X⁻ᵀ = cof X / det X`, with the
/// Frobenius scaling `γ = (|X⁻¹| / |X|)^½ = (|cof X| / (|det X| |X|))^½`
/// when `scaled`, else `γ = 1`.
#[expect(
    clippy::indexing_slicing,
    reason = "i is a literal < 3 at every call of the closure"
)]
#[inline(always)]
fn newton_step<T: Real>(x: &Mat3<T>, scaled: bool) -> Mat3<T> {
    let half = T::of_f64(0.5);
    let c = cofactor(x);
    let inverse_det = T::one() / (x[0][0] * c[0][0] + x[0][1] * c[0][1] + x[0][2] * c[0][2]);
    let (a, b) = if scaled {
        let gamma2 = (frobenius2(&c) / frobenius2(x)).sqrt() * inverse_det.abs();
        let gamma = gamma2.sqrt();
        (half * gamma, half * inverse_det * gamma / gamma2)
    } else {
        (half, half * inverse_det)
    };
    let row = |i: usize| {
        [
            a * x[i][0] + b * c[i][0],
            a * x[i][1] + b * c[i][1],
            a * x[i][2] + b * c[i][2],
        ]
    };
    [row(0), row(1), row(2)]
}

/// `det m`.
#[inline(always)]
fn determinant<T: Real>(m: &Mat3<T>) -> T {
    let c = cofactor(m);
    m[0][0] * c[0][0] + m[0][1] * c[0][1] + m[0][2] * c[0][2]
}

/// `|m|²`, the sum of the squared entries.
#[inline(always)]
fn frobenius2<T: Real>(m: &Mat3<T>) -> T {
    dot(&m[0], &m[0]) + dot(&m[1], &m[1]) + dot(&m[2], &m[2])
}

/// The cofactor matrix `cof F = det F · F⁻ᵀ` of a 3×3 `F` (row-major),
/// written entry by entry so that the lane loops calling it stay
/// vectorizable; `det F = Σ_b F_0b cof_0b`.
#[inline(always)]
pub(crate) fn cofactor<T: Real>(f: &Mat3<T>) -> Mat3<T> {
    let [[f00, f01, f02], [f10, f11, f12], [f20, f21, f22]] = *f;
    [
        [
            f11 * f22 - f12 * f21,
            f12 * f20 - f10 * f22,
            f10 * f21 - f11 * f20,
        ],
        [
            f02 * f21 - f01 * f22,
            f00 * f22 - f02 * f20,
            f01 * f20 - f00 * f21,
        ],
        [
            f01 * f12 - f02 * f11,
            f02 * f10 - f00 * f12,
            f00 * f11 - f01 * f10,
        ],
    ]
}

/// Per lane, the proper rotation closest to `f`, `R = U Vᵀ` of the signed
/// SVD (the fallback; see the module documentation).
#[expect(
    clippy::indexing_slicing,
    reason = "literal indices < 3 and loop counters < N over fixed-size arrays; tools/nopanic-check proves no panic is left"
)]
#[inline(always)]
fn svd_rotations<T: Real, const N: usize>(f: &Mat3<[T; N]>) -> Mat3<[T; N]> {
    let v = right_vectors(f);
    let mut r = [[[T::zero(); N]; 3]; 3];
    for l in 0..N {
        let (fl, vl) = (lane(f, l), lane(&v, l));
        let u = frame(&fl, &vl);
        // R_ij = Σ_k U_ik V_jk, U's columns u_k.
        let entry =
            |i: usize, j: usize| u[0][i] * vl[j][0] + u[1][i] * vl[j][1] + u[2][i] * vl[j][2];
        let rl = [
            [entry(0, 0), entry(0, 1), entry(0, 2)],
            [entry(1, 0), entry(1, 1), entry(1, 2)],
            [entry(2, 0), entry(2, 1), entry(2, 2)],
        ];
        set_lane(&mut r, l, &rl);
    }
    r
}

/// The columns `u₁, u₂, u₃` of `U` (see the module documentation) for
/// one matrix `f` and its sorted right singular vectors `v` (columns).
#[expect(
    clippy::indexing_slicing,
    reason = "indices are literals < 3 at every call of the closures"
)]
#[inline(always)]
fn frame<T: Real>(f: &Mat3<T>, v: &Mat3<T>) -> Mat3<T> {
    // b_k = F v_k.
    let b = |k: usize| -> [T; 3] {
        let row = |r: usize| f[r][0] * v[0][k] + f[r][1] * v[1][k] + f[r][2] * v[2][k];
        [row(0), row(1), row(2)]
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
        w = [
            w[0] - along * u1[0],
            w[1] - along * u1[1],
            w[2] - along * u1[2],
        ];
    }
    let n2 = dot(&w, &w);
    let u2 = if n2 > tiny {
        scale(&w, T::one() / n2.sqrt())
    } else {
        perpendicular(&u1)
    };
    let u3 = cross(&u1, &u2);
    [u1, u2, u3]
}

/// Lane `l` (`< N`) of a matrix of lanes.
#[expect(
    clippy::indexing_slicing,
    reason = "literal indices < 3; l < N at every call"
)]
#[inline(always)]
fn lane<T: Real, const N: usize>(m: &Mat3<[T; N]>, l: usize) -> Mat3<T> {
    [
        [m[0][0][l], m[0][1][l], m[0][2][l]],
        [m[1][0][l], m[1][1][l], m[1][2][l]],
        [m[2][0][l], m[2][1][l], m[2][2][l]],
    ]
}

/// Stores `x` in lane `l` (`< N`) of a matrix of lanes.
#[expect(
    clippy::indexing_slicing,
    reason = "literal indices < 3; l < N at every call"
)]
#[inline(always)]
fn set_lane<T: Real, const N: usize>(m: &mut Mat3<[T; N]>, l: usize, x: &Mat3<T>) {
    for (row, x_row) in m.iter_mut().zip(x) {
        row[0][l] = x_row[0];
        row[1][l] = x_row[1];
        row[2][l] = x_row[2];
    }
}

/// Per lane, the eigenvectors of `FᵀF` as the columns of a rotation `V`
/// (rows), sorted by decreasing eigenvalue.
#[expect(
    clippy::indexing_slicing,
    reason = "literal indices < 3 and loop counters < N over fixed-size arrays"
)]
#[inline(always)]
fn right_vectors<T: Real, const N: usize>(f: &Mat3<[T; N]>) -> Mat3<[T; N]> {
    let (zero, one) = (T::zero(), T::one());
    let mut s = [[[zero; N]; 3]; 3];
    for l in 0..N {
        let fl = lane(f, l);
        // (FᵀF)_ij = Σ_r F_ri F_rj.
        let g =
            |i: usize, j: usize| fl[0][i] * fl[0][j] + fl[1][i] * fl[1][j] + fl[2][i] * fl[2][j];
        let (s01, s02, s12) = (g(0, 1), g(0, 2), g(1, 2));
        set_lane(
            &mut s,
            l,
            &[
                [g(0, 0), s01, s02],
                [s01, g(1, 1), s12],
                [s02, s12, g(2, 2)],
            ],
        );
    }
    let (zeros, ones) = ([zero; N], [one; N]);
    let mut v = [
        [ones, zeros, zeros],
        [zeros, ones, zeros],
        [zeros, zeros, ones],
    ];
    for _ in 0..JACOBI_SWEEPS {
        rotate(&mut s, &mut v, 0, 1, 2);
        rotate(&mut s, &mut v, 0, 2, 1);
        rotate(&mut s, &mut v, 1, 2, 0);
    }
    // Sort the eigenvalues s_kk downwards, swapping columns of V; the
    // swapped-in column changes sign so that det V stays +1.
    // (Three calls with literal indices, not a loop over pairs, so that
    // the indices stay constants and no bounds check is left.)
    swap_if_smaller(&mut s, &mut v, 0, 1);
    swap_if_smaller(&mut s, &mut v, 1, 2);
    swap_if_smaller(&mut s, &mut v, 0, 1);
    v
}

/// Per lane, one Jacobi rotation in the `(p, q)` plane (`r` the third
/// index) that zeroes `s_pq` of the symmetric `s`, accumulated into `v`'s
/// columns (Numerical Recipes §11.1, eq. 11.1.8–11.1.18):
/// `θ = (s_qq − s_pp)/(2s_pq)`, `t = sgn θ/(|θ| + √(θ²+1))`, written as
/// `t = 2 s_pq sgn(τ)/(|τ| + √(τ² + 4 s_pq²))` with `τ = s_qq − s_pp`, so
/// that `s_pq = 0` gives `t = 0` and no division by zero.
#[expect(
    clippy::indexing_slicing,
    reason = "p, q, r are literals < 3 at every call; l < N"
)]
#[inline(always)]
fn rotate<T: Real, const N: usize>(
    s: &mut Mat3<[T; N]>,
    v: &mut Mat3<[T; N]>,
    p: usize,
    q: usize,
    r: usize,
) {
    let (zero, one) = (T::zero(), T::one());
    let (mut c, mut sn) = ([zero; N], [zero; N]);
    for l in 0..N {
        let (spp, sqq) = (s[p][p][l], s[q][q][l]);
        // An off-diagonal already below 1e-18 of the diagonal counts as
        // zero: below f64's rounding, and it keeps the squares and products
        // of the later sweeps out of the subnormal range (f32 below
        // 1.2e-38), whose arithmetic is a hundred times slower on x86.
        let spq = if s[p][q][l].abs() > T::of_f64(FLUSH) * (spp.abs() + sqq.abs()) {
            s[p][q][l]
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
        let cl = one / (one + t * t).sqrt();
        let sl = t * cl;
        s[p][p][l] = spp - t * spq;
        s[q][q][l] = sqq + t * spq;
        s[p][q][l] = zero;
        s[q][p][l] = zero;
        let (srp, srq) = (s[r][p][l], s[r][q][l]);
        s[r][p][l] = cl * srp - sl * srq;
        s[r][q][l] = sl * srp + cl * srq;
        s[p][r][l] = s[r][p][l];
        s[q][r][l] = s[r][q][l];
        c[l] = cl;
        sn[l] = sl;
    }
    for row in v.iter_mut() {
        for l in 0..N {
            let (vp, vq) = (row[p][l], row[q][l]);
            row[p][l] = c[l] * vp - sn[l] * vq;
            row[q][l] = sn[l] * vp + c[l] * vq;
        }
    }
}

/// Per lane, swaps eigenvalues `p < q` (the diagonal of `s`) and `v`'s
/// columns when `s_pp < s_qq`, negating the new column `q` (det `v`
/// unchanged).
#[expect(clippy::indexing_slicing, reason = "p, q are literals < 3; l < N")]
#[inline(always)]
fn swap_if_smaller<T: Real, const N: usize>(
    s: &mut Mat3<[T; N]>,
    v: &mut Mat3<[T; N]>,
    p: usize,
    q: usize,
) {
    let mut swap = [false; N];
    for l in 0..N {
        let (spp, sqq) = (s[p][p][l], s[q][q][l]);
        swap[l] = spp < sqq;
        s[p][p][l] = if swap[l] { sqq } else { spp };
        s[q][q][l] = if swap[l] { spp } else { sqq };
    }
    for row in v.iter_mut() {
        for l in 0..N {
            let (vp, vq) = (row[p][l], row[q][l]);
            row[p][l] = if swap[l] { vq } else { vp };
            row[q][l] = if swap[l] { -vp } else { vq };
        }
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
