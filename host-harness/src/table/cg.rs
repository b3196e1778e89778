//! Jacobi-preconditioned conjugate gradient on a sparse SPD matrix: the
//! per-column iterative baseline of Cotin RR-3510 §4 (`MODELS.md` §2).

use faer::sparse::SparseColMatRef;

/// Conjugate gradient did not reach the requested tolerance.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error(
    "conjugate gradient did not converge: relative residual {rel_residual:e} after {iterations} iterations"
)]
pub struct CgError {
    /// Iterations performed.
    pub iterations: usize,
    /// `|b - A x| / |b|` reached.
    pub rel_residual: f64,
}

/// Sparse symmetric positive definite matrix (both triangles stored) with
/// its Jacobi preconditioner `diag(A)⁻¹`.
#[derive(Debug, Clone, Copy)]
pub struct JacobiCg<'a> {
    a: SparseColMatRef<'a, usize, f64>,
}

impl<'a> JacobiCg<'a> {
    /// Wraps `a` (square, both triangles stored, positive diagonal).
    pub fn new(a: SparseColMatRef<'a, usize, f64>) -> Self {
        assert_eq!(a.nrows(), a.ncols(), "square matrix");
        Self { a }
    }

    /// `y = A x`.
    pub fn mul(&self, x: &[f64], y: &mut [f64]) {
        let (sym, val) = self.a.parts();
        let col_ptr = sym.col_ptr();
        let row_idx = sym.row_idx();
        y.fill(0.0);
        for (j, &xj) in x.iter().enumerate() {
            for p in col_ptr[j]..col_ptr[j + 1] {
                y[row_idx[p]] += val[p] * xj;
            }
        }
    }

    /// The inverse diagonal `1 / A_ii` (the Jacobi preconditioner).
    pub fn inv_diag(&self) -> Vec<f64> {
        let (sym, val) = self.a.parts();
        let col_ptr = sym.col_ptr();
        let row_idx = sym.row_idx();
        (0..self.a.ncols())
            .map(|j| {
                let d: f64 = (col_ptr[j]..col_ptr[j + 1])
                    .filter(|&p| row_idx[p] == j)
                    .map(|p| val[p])
                    .sum();
                1.0 / d
            })
            .collect()
    }

    /// Solves `A x = b` by preconditioned conjugate gradient from `x = 0`
    /// until `|b - A x|₂ ≤ rel_tol |b|₂`, at most `max_iter` iterations.
    /// `inv_diag` is [`Self::inv_diag`]. Returns `x` and the iteration count.
    pub fn solve(
        &self,
        b: &[f64],
        inv_diag: &[f64],
        rel_tol: f64,
        max_iter: usize,
    ) -> Result<(Vec<f64>, usize), CgError> {
        let n = b.len();
        let mut x = vec![0.0f64; n];
        let b_norm = norm(b);
        if b_norm == 0.0 {
            return Ok((x, 0));
        }
        let mut r = b.to_vec();
        let mut z: Vec<f64> = r.iter().zip(inv_diag).map(|(r, d)| r * d).collect();
        let mut p = z.clone();
        let mut q = vec![0.0f64; n];
        let mut rz = dot(&r, &z);
        let mut rel = 1.0;
        for it in 0..max_iter {
            self.mul(&p, &mut q);
            let alpha = rz / dot(&p, &q);
            for i in 0..n {
                x[i] += alpha * p[i];
                r[i] -= alpha * q[i];
            }
            rel = norm(&r) / b_norm;
            if rel <= rel_tol {
                return Ok((x, it + 1));
            }
            for i in 0..n {
                z[i] = r[i] * inv_diag[i];
            }
            let rz_new = dot(&r, &z);
            let beta = rz_new / rz;
            rz = rz_new;
            for i in 0..n {
                p[i] = z[i] + beta * p[i];
            }
        }
        Err(CgError {
            iterations: max_iter,
            rel_residual: rel,
        })
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}
