//! The contact system's dense LDLᵀ factorization, on the stack.
//!
//! The contact system of MODELS.md §2 is symmetric positive definite with
//! `3m × 3m` scalars for `m ≤ M` contacts. Stable Rust cannot size an array
//! `3·M`, so [`ContactMatrix`] holds it as `M` block rows of three scalar
//! rows of `M` blocks of three scalars: the same bytes as a row-major
//! `3M × 3M` array. It is factorized by 3×3 blocks as `A = L D Lᵀ` (`L`
//! unit lower-triangular, `D` diagonal; Golub & Van Loan, *Matrix
//! Computations*, 4th ed., §4.1.2 and §4.2.9): no square root, one division
//! per row, and `D_jj` is exactly the square of the Cholesky factor's
//! diagonal, so the pivot test is the textbook Cholesky one.

use nalgebra::Vector3;

use crate::Real;

/// The lower triangle of a symmetric `3m × 3m` matrix of at most `M`
/// contacts: scalar `(3q + r, 3p + c)` is `rows[q][r][p][c]`. Only entries
/// on or below the diagonal are read.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ContactMatrix<T, const M: usize> {
    rows: [[[[T; 3]; M]; 3]; M],
}

impl<T: Real, const M: usize> ContactMatrix<T, M> {
    /// All zero.
    pub(crate) fn zeros() -> Self {
        Self {
            rows: [[[[T::zero(); 3]; M]; 3]; M],
        }
    }

    /// Copies `from`'s block `(i, j)` to block `(q, p)`, row by row;
    /// `false` (nothing copied) beyond `M`.
    pub(crate) fn copy_block(
        &mut self,
        q: usize,
        p: usize,
        from: &Self,
        i: usize,
        j: usize,
    ) -> bool {
        let (Some(rows), Some(from_rows)) = (self.rows.get_mut(q), from.rows.get(i)) else {
            return false;
        };
        for (row, from_row) in rows.iter_mut().zip(from_rows) {
            let (Some(out), Some(values)) = (row.get_mut(p), from_row.get(j)) else {
                return false;
            };
            *out = *values;
        }
        true
    }

    /// The diagonal of block `(q, q)`, zero beyond `M`.
    pub(crate) fn diagonal(&self, q: usize) -> [T; 3] {
        let mut diagonal = [T::zero(); 3];
        if let Some(rows) = self.rows.get(q) {
            for (r, (d, row)) in diagonal.iter_mut().zip(rows).enumerate() {
                if let Some(&c) = row.get(q).and_then(|b| b.get(r)) {
                    *d = c;
                }
            }
        }
        diagonal
    }

    /// Sets block `(q, p)`; nothing beyond `M`.
    pub(crate) fn set_block(&mut self, q: usize, p: usize, block: &[[T; 3]; 3]) {
        if let Some(rows) = self.rows.get_mut(q) {
            for (row, values) in rows.iter_mut().zip(block) {
                if let Some(out) = row.get_mut(p) {
                    *out = *values;
                }
            }
        }
    }

    /// Block `(q, p)`, zero beyond `M`: the factorization's read, written
    /// out (through a helper returning `Option` the Cortex-M4F's
    /// pre-computed haptic path grows by 520 bytes of `.text`, past its
    /// 24 576-byte target: `tools/firmware-check.sh --c`).
    #[inline(always)]
    fn at(&self, q: usize, p: usize) -> Block<T> {
        let mut block = [[T::zero(); 3]; 3];
        if let Some(rows) = self.rows.get(q) {
            for (out, row) in block.iter_mut().zip(rows) {
                if let Some(values) = row.get(p) {
                    *out = *values;
                }
            }
        }
        block
    }

    /// Factorizes the leading `3m × 3m` part of `A`, `A = L D Lᵀ`, by 3×3
    /// blocks into this matrix (`L_qp` below the diagonal, the unit lower
    /// `L_pp` on it; the upper blocks are not touched), with `A` the
    /// matrix `a`, only read, or for `None` this matrix's own lower blocks
    /// (in place: each block of `A` is read once, before its block of `L`
    /// is written there), and solves `A g = d` in place of `d` (`m` is
    /// clamped to `M`): `L y = d`, `z = D⁻¹ y`, `Lᵀ g = z`. By blocks, each
    /// product of two 3×3 blocks loads 18 scalars for 27 multiply-adds.
    ///
    /// Returns `Err(p)` with the contact (block row) of the first pivot
    /// `D_jj` that is not finite or not greater than `min_pivot` (a
    /// singular or ill-conditioned contact set). Work: about `(3m)³/6`
    /// multiply-adds and `3m` divisions.
    pub(crate) fn solve(
        &mut self,
        a: Option<&Self>,
        d: &mut [Vector3<T>; M],
        m: usize,
        min_pivot: T,
    ) -> Result<(), usize> {
        let m = m.min(M);
        let inverse_pivots = self.factor(a, m, min_pivot)?;
        let l = &*self;
        // L y = d, block row by block row.
        for p in 0..m {
            let mut y = d.get(p).map_or([T::zero(); 3], |v| [v.x, v.y, v.z]);
            for (r, x) in d.iter().enumerate().take(p) {
                subtract_product(&mut y, &l.at(p, r), &[x.x, x.y, x.z]);
            }
            let l = l.at(p, p);
            y[1] -= l[1][0] * y[0];
            y[2] -= l[2][0] * y[0] + l[2][1] * y[1];
            if let Some(out) = d.get_mut(p) {
                *out = Vector3::new(y[0], y[1], y[2]);
            }
        }
        // Lᵀ g = z with z = D⁻¹ y, from the last block row.
        for (p, inv) in inverse_pivots.iter().enumerate().take(m).rev() {
            let y = d.get(p).map_or([T::zero(); 3], |v| [v.x, v.y, v.z]);
            let mut x = [y[0] * inv[0], y[1] * inv[1], y[2] * inv[2]];
            for (q, g) in d.iter().enumerate().take(m).skip(p + 1) {
                subtract_transposed_product(&mut x, &l.at(q, p), &[g.x, g.y, g.z]);
            }
            let l = l.at(p, p);
            x[1] -= l[2][1] * x[2];
            x[0] -= l[1][0] * x[1] + l[2][0] * x[2];
            if let Some(out) = d.get_mut(p) {
                *out = Vector3::new(x[0], x[1], x[2]);
            }
        }
        Ok(())
    }

    /// `A = L D Lᵀ` of the leading `m × m` blocks of `a` (`None`: of this
    /// matrix), `L` into this matrix; returns `D⁻¹` by block row (see
    /// [`Self::solve`] for the error).
    fn factor(&mut self, a: Option<&Self>, m: usize, min_pivot: T) -> Result<[[T; 3]; M], usize> {
        let l = self;
        let mut pivots = [[T::zero(); 3]; M];
        let mut inverse_pivots = [[T::zero(); 3]; M];
        for p in 0..m {
            // `L_pp` and `D_p⁻¹`, set at `q = p`.
            let mut unit = [[T::zero(); 3]; 3];
            let mut inverse = [T::zero(); 3];
            for q in p..m {
                // X = A_qp − Σ_r L_qr D_r L_prᵀ (one copy of the products
                // for the diagonal block and those below it).
                let mut x = a.unwrap_or(&*l).at(q, p);
                for (r, pivot) in pivots.iter().enumerate().take(p) {
                    let w = scale_columns(&l.at(p, r), pivot);
                    subtract_block_product(&mut x, &l.at(q, r), &w);
                }
                if q == p {
                    // X = L_pp D_p L_ppᵀ.
                    let pivot;
                    (unit, pivot, inverse) = ldlt3(&x, min_pivot).ok_or(p)?;
                    if let (Some(d), Some(inv)) = (pivots.get_mut(p), inverse_pivots.get_mut(p)) {
                        *d = pivot;
                        *inv = inverse;
                    }
                    l.set_block(p, p, &unit);
                } else {
                    // L_qp = X L_ppᵀ⁻¹ D_p⁻¹: each row x of X solves
                    // L_pp y = x, over D_p.
                    let l_qp = x.map(|mut y| {
                        y[1] -= unit[1][0] * y[0];
                        y[2] -= unit[2][0] * y[0] + unit[2][1] * y[1];
                        [y[0] * inverse[0], y[1] * inverse[1], y[2] * inverse[2]]
                    });
                    l.set_block(q, p, &l_qp);
                }
            }
        }
        Ok(inverse_pivots)
    }
}

/// A 3×3 block, row-major.
pub(crate) type Block<T> = [[T; 3]; 3];

/// Whether the symmetric 3×3 `s` (its lower triangle read) is positive
/// definite: its `L D Lᵀ` has finite positive pivots.
pub(crate) fn positive_definite3<T: Real>(s: &Block<T>) -> bool {
    ldlt3(s, T::zero()).is_some()
}

/// `S = L D Lᵀ` of the symmetric 3×3 `s` (its lower triangle read):
/// the unit lower `L`, `D` and `D⁻¹`; `None` if a pivot is not finite or
/// not greater than `min_pivot`.
fn ldlt3<T: Real>(s: &Block<T>, min_pivot: T) -> Option<(Block<T>, [T; 3], [T; 3])> {
    let pivot_ok = |d: T| d.finite() && d > min_pivot;
    let d0 = s[0][0];
    if !pivot_ok(d0) {
        return None;
    }
    let i0 = T::one() / d0;
    let l10 = s[1][0] * i0;
    let l20 = s[2][0] * i0;
    let d1 = s[1][1] - l10 * s[1][0];
    if !pivot_ok(d1) {
        return None;
    }
    let i1 = T::one() / d1;
    let l21 = (s[2][1] - l20 * s[1][0]) * i1;
    let d2 = s[2][2] - l20 * s[2][0] - l21 * l21 * d1;
    if !pivot_ok(d2) {
        return None;
    }
    let (z, o) = (T::zero(), T::one());
    Some((
        [[o, z, z], [l10, o, z], [l20, l21, o]],
        [d0, d1, d2],
        [i0, i1, T::one() / d2],
    ))
}

/// `L D`: column `k` of `l` times `d_k`.
#[inline(always)]
fn scale_columns<T: Real>(l: &Block<T>, d: &[T; 3]) -> Block<T> {
    l.map(|row| [row[0] * d[0], row[1] * d[1], row[2] * d[2]])
}

/// `x −= a bᵀ`.
#[inline(always)]
fn subtract_block_product<T: Real>(x: &mut Block<T>, a: &Block<T>, b: &Block<T>) {
    for (x_row, a_row) in x.iter_mut().zip(a) {
        for (x_ij, b_row) in x_row.iter_mut().zip(b) {
            *x_ij -= a_row[0] * b_row[0] + a_row[1] * b_row[1] + a_row[2] * b_row[2];
        }
    }
}

/// `y −= a v`.
#[inline(always)]
fn subtract_product<T: Real>(y: &mut [T; 3], a: &Block<T>, v: &[T; 3]) {
    for (y_i, a_row) in y.iter_mut().zip(a) {
        *y_i -= a_row[0] * v[0] + a_row[1] * v[1] + a_row[2] * v[2];
    }
}

/// `y −= aᵀ v`.
#[inline(always)]
fn subtract_transposed_product<T: Real>(y: &mut [T; 3], a: &Block<T>, v: &[T; 3]) {
    for (a_row, &v_i) in a.iter().zip(v) {
        for (y_j, &a_ij) in y.iter_mut().zip(a_row) {
            *y_j -= a_ij * v_i;
        }
    }
}

#[cfg(test)]
#[allow(clippy::indexing_slicing, clippy::expect_used)]
mod tests {
    use super::*;

    const M: usize = 4;

    /// The symmetric positive definite `A = B Bᵀ + 3m I` (12 × 12, m = 4)
    /// of a fixed `B`, as a contact matrix (lower blocks) and as scalars.
    fn spd() -> (ContactMatrix<f64, M>, [[f64; 12]; 12]) {
        let b = |i: usize, j: usize| ((7 * i + 3 * j) % 11) as f64 / 11.0 - 0.4;
        let mut dense = [[0.0; 12]; 12];
        for (i, row) in dense.iter_mut().enumerate() {
            for (j, a) in row.iter_mut().enumerate() {
                *a = (0..12).map(|k| b(i, k) * b(j, k)).sum::<f64>();
                if i == j {
                    *a += 12.0;
                }
            }
        }
        let mut matrix = ContactMatrix::zeros();
        for q in 0..M {
            for p in 0..=q {
                let block: Block<f64> =
                    core::array::from_fn(|r| core::array::from_fn(|c| dense[3 * q + r][3 * p + c]));
                matrix.set_block(q, p, &block);
            }
        }
        (matrix, dense)
    }

    fn rhs() -> [Vector3<f64>; M] {
        core::array::from_fn(|p| Vector3::new(1.0 + p as f64, -0.5 * p as f64, 0.25))
    }

    /// In place (`None`) and from another matrix (`Some`), the factor's
    /// lower blocks and the solution are the same bits, and the solution
    /// solves `A g = d` to 1e-13 of `|d|` (f64, a condition number below 2
    /// here: rounding alone).
    #[test]
    fn in_place_factorization_equals_the_factorization_of_a_copy() {
        let (a, dense) = spd();
        let (mut from_copy, mut in_place) = (ContactMatrix::zeros(), a);
        let (mut g1, mut g2) = (rhs(), rhs());
        from_copy
            .solve(Some(&a), &mut g1, M, 1e-9)
            .expect("positive definite");
        in_place
            .solve(None, &mut g2, M, 1e-9)
            .expect("positive definite");
        assert_eq!(g1, g2);
        for q in 0..M {
            for p in 0..=q {
                assert_eq!(from_copy.at(q, p), in_place.at(q, p), "block ({q}, {p})");
            }
        }
        let d = rhs();
        let g: [f64; 12] = core::array::from_fn(|i| g1[i / 3][i % 3]);
        for (i, row) in dense.iter().enumerate() {
            let ag: f64 = row.iter().zip(&g).map(|(a, g)| a * g).sum();
            assert!((ag - d[i / 3][i % 3]).abs() <= 1e-13 * 3.0, "row {i}: {ag}");
        }
    }

    /// A block row equal to an earlier one makes the matrix singular: both
    /// forms refuse it at that contact.
    #[test]
    fn both_forms_refuse_a_singular_set_at_the_same_contact() {
        let (mut a, _) = spd();
        // Contact 2 a copy of contact 1 among the first three: `A_2p = A_1p`
        // for `p < 2`, and `A_22 = A_12 = A_11`.
        for (p, from) in [(0, 0), (1, 1), (2, 1)] {
            let block: Block<f64> = core::array::from_fn(|r| a.rows[1][r][from]);
            a.set_block(2, p, &block);
        }
        let (mut from_copy, mut in_place) = (ContactMatrix::zeros(), a);
        let (mut g1, mut g2) = (rhs(), rhs());
        let refused = from_copy.solve(Some(&a), &mut g1, M, 1e-9);
        assert_eq!(refused, Err(2));
        assert_eq!(in_place.solve(None, &mut g2, M, 1e-9), refused);
    }
}
