//! Fixed-size dense Cholesky on 3×3 blocks, on the stack.
//!
//! The contact system of MODELS.md §2 has `3m × 3m` entries for `m ≤ M`
//! contacts. Stable Rust cannot size an array `3·M`, so the matrix is kept as
//! `M × M` blocks of 3×3 and factorized block by block:
//! `L_pp = chol(C_pp − Σ_{r<p} L_pr L_prᵀ)`,
//! `L_qp = (C_qp − Σ_{r<p} L_qr L_prᵀ) L_pp⁻ᵀ` for `q > p`.
//! Scalar pivots are the same as those of the scalar Cholesky of the full
//! matrix, so the conditioning test is the textbook one.

use nalgebra::{Matrix3, Vector3};

use crate::Real;

/// Lower Cholesky factor of the symmetric 3×3 `s` (only its lower triangle is
/// read). `None` if a pivot `d` (the squared diagonal of `L`) is not greater
/// than `min_pivot` or is not finite.
pub(crate) fn cholesky3<T: Real>(s: &Matrix3<T>, min_pivot: T) -> Option<Matrix3<T>> {
    let pivot_ok = |d: T| d.finite() && d > min_pivot;
    let d0 = s.m11;
    if !pivot_ok(d0) {
        return None;
    }
    let l00 = d0.sqrt();
    let l10 = s.m21 / l00;
    let l20 = s.m31 / l00;
    let d1 = s.m22 - l10 * l10;
    if !pivot_ok(d1) {
        return None;
    }
    let l11 = d1.sqrt();
    let l21 = (s.m32 - l20 * l10) / l11;
    let d2 = s.m33 - l20 * l20 - l21 * l21;
    if !pivot_ok(d2) {
        return None;
    }
    let l22 = d2.sqrt();
    let z = T::zero();
    Some(Matrix3::new(l00, z, z, l10, l11, z, l20, l21, l22))
}

/// The reciprocals of the diagonal of lower-triangular `l` (non-zero):
/// three divisions per factor, so the substitutions below multiply (a
/// division costs 14 cycles on the Cortex-M4F, a multiplication 1).
fn reciprocal_diagonal<T: Real>(l: &Matrix3<T>) -> Vector3<T> {
    Vector3::new(T::one() / l.m11, T::one() / l.m22, T::one() / l.m33)
}

/// `L⁻¹ b` for lower-triangular `l` with `inv` its
/// [`reciprocal_diagonal`].
fn forward3<T: Real>(l: &Matrix3<T>, inv: &Vector3<T>, b: &Vector3<T>) -> Vector3<T> {
    let y0 = b.x * inv.x;
    let y1 = (b.y - l.m21 * y0) * inv.y;
    let y2 = (b.z - l.m31 * y0 - l.m32 * y1) * inv.z;
    Vector3::new(y0, y1, y2)
}

/// `L⁻ᵀ b` for lower-triangular `l` with `inv` its
/// [`reciprocal_diagonal`].
fn backward3<T: Real>(l: &Matrix3<T>, inv: &Vector3<T>, b: &Vector3<T>) -> Vector3<T> {
    let x2 = b.z * inv.z;
    let x1 = (b.y - l.m32 * x2) * inv.y;
    let x0 = (b.x - l.m21 * x1 - l.m31 * x2) * inv.x;
    Vector3::new(x0, x1, x2)
}

/// Factorizes the `m × m` block matrix `a` (lower blocks `a[q][p]`, `q ≥ p`,
/// are read; the factor overwrites them) and solves `A g = d` in place of `d`.
///
/// Returns `Err(p)` with the first block row whose pivot is not greater than
/// `min_pivot` (singular or ill-conditioned contact set). Work: `O(m³)` block
/// products, `m ≤ M`.
// Every index below is `< m ≤ M` (m is clamped on entry), so the optimiser
// removes the bounds checks; `tools/nopanic-check` proves it at link time.
#[allow(clippy::indexing_slicing)]
pub(crate) fn solve_blocks<T: Real, const M: usize>(
    a: &mut [[Matrix3<T>; M]; M],
    d: &mut [Vector3<T>; M],
    m: usize,
    min_pivot: T,
) -> Result<(), usize> {
    let m = m.min(M);
    let mut inv = [Vector3::zeros(); M];
    for p in 0..m {
        let mut s = a[p][p];
        for l_pr in a[p].iter().take(p) {
            s -= l_pr * l_pr.transpose();
        }
        let l_pp = cholesky3(&s, min_pivot).ok_or(p)?;
        a[p][p] = l_pp;
        inv[p] = reciprocal_diagonal(&l_pp);
        for q in p + 1..m {
            let mut x = a[q][p];
            for (l_qr, l_pr) in a[q].iter().zip(a[p].iter()).take(p) {
                x -= l_qr * l_pr.transpose();
            }
            // L_qp = X L_pp⁻ᵀ: each row of L_qp is L_pp⁻¹ applied to a row of X.
            let rows = [0, 1, 2].map(|i| forward3(&l_pp, &inv[p], &x.row(i).transpose()));
            a[q][p] = Matrix3::from_rows(&rows.map(|r| r.transpose()));
        }
    }
    for p in 0..m {
        let mut y = d[p];
        for r in 0..p {
            y -= a[p][r] * d[r];
        }
        d[p] = forward3(&a[p][p], &inv[p], &y);
    }
    for p in (0..m).rev() {
        let mut y = d[p];
        for q in p + 1..m {
            y -= a[q][p].transpose() * d[q];
        }
        d[p] = backward3(&a[p][p], &inv[p], &y);
    }
    Ok(())
}
