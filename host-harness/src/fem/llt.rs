//! Single-threaded sparse Cholesky (faer, supernodal, AMD ordering) of a
//! symmetric positive definite matrix stored with both triangles.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::SparseColMatRef;
use faer::sparse::linalg::cholesky::{
    LltRef, SymbolicCholesky, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::{Conj, MatMut, Par, Side};

/// `A = L Lᵀ` with a fill-reducing (AMD) permutation.
pub(crate) struct SparseLlt {
    symbolic: SymbolicCholesky<usize>,
    values: Vec<f64>,
    par: Par,
}

impl SparseLlt {
    /// Factorizes `a` (only its lower triangle is read), sequentially.
    pub(crate) fn new(a: SparseColMatRef<'_, usize, f64>) -> anyhow::Result<Self> {
        let par = Par::Seq;
        let symbolic = factorize_symbolic_cholesky(
            a.symbolic(),
            Side::Lower,
            SymmetricOrdering::Amd,
            Default::default(),
        )
        .map_err(|e| anyhow::anyhow!("symbolic Cholesky failed: {e:?}"))?;
        let mut values = vec![0.0f64; symbolic.len_val()];
        let mut mem = MemBuffer::try_new(
            symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default()),
        )
        .map_err(|_| anyhow::anyhow!("out of memory for the Cholesky factorization"))?;
        symbolic
            .factorize_numeric_llt(
                &mut values,
                a,
                Side::Lower,
                Default::default(),
                par,
                MemStack::new(&mut mem),
                Default::default(),
            )
            .map_err(|e| {
                anyhow::anyhow!(
                    "Cholesky factorization failed ({e:?}): the stiffness restricted to the free \
                     DOFs is not positive definite (too few fixed vertices?)"
                )
            })?;
        Ok(Self {
            symbolic,
            values,
            par,
        })
    }

    /// Number of non-zeros stored in the factor `L`.
    pub(crate) fn factor_len(&self) -> usize {
        self.values.len()
    }

    /// Overwrites `rhs` (one right-hand side per column) with `A⁻¹ rhs`.
    pub(crate) fn solve_in_place(&self, rhs: MatMut<'_, f64>) {
        let mut mem = MemBuffer::new(
            self.symbolic
                .solve_in_place_scratch::<f64>(rhs.ncols(), self.par),
        );
        LltRef::new(&self.symbolic, &self.values).solve_in_place_with_conj(
            Conj::No,
            rhs,
            self.par,
            MemStack::new(&mut mem),
        );
    }
}
