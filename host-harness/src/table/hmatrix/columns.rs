//! Compliance columns on demand: `C e_(k,b) = A⁻¹ e_(k,b)` for any set of
//! touchable vertices `k` (three right-hand sides each, m/N per N), by one
//! sparse Cholesky factorization of the restricted stiffness `A` (N/m) kept
//! for the whole build (Cotin RR-3510 §4), the right-hand sides split over
//! the machine's cores.

use anyhow::Context;
use faer::Mat;

use crate::fem::assembly::{FreeOrdering, assemble_restricted};
use crate::fem::llt::SparseLlt;
use crate::fem::material::TetMaterials;

/// The factorized stiffness of the free DOFs.
pub struct ColumnSolver {
    llt: SparseLlt,
    dof: usize,
}

impl ColumnSolver {
    /// Assembles and factorizes `A` for the mesh (`positions` in m), the
    /// materials and the free ordering. Errors if `A` is not positive
    /// definite.
    pub fn new(
        positions: &[[f64; 3]],
        tets: &[[u32; 4]],
        materials: &TetMaterials,
        ordering: &FreeOrdering,
    ) -> anyhow::Result<Self> {
        let dof = 3 * ordering.free_count();
        let a = assemble_restricted(
            positions,
            tets,
            materials,
            &ordering.vertex_slot,
            ordering.free_count(),
        );
        let llt = SparseLlt::new(a.as_ref()).context("compliance: factorizing A")?;
        Ok(Self { llt, dof })
    }

    /// Scalars of the factor `L` (its memory is 8 bytes each).
    pub fn factor_len(&self) -> usize {
        self.llt.factor_len()
    }

    /// The columns of the free vertices `vertices` (free indices), all
    /// `3F` rows: column `3i + b` is `C e_(vertices[i], b)`.
    pub fn columns(&self, vertices: &[usize]) -> Mat<f64> {
        let mut x = Mat::<f64>::zeros(self.dof, 3 * vertices.len());
        for (i, &k) in vertices.iter().enumerate() {
            for b in 0..3 {
                x[(3 * k + b, 3 * i + b)] = 1.0;
            }
        }
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
        let per = x.ncols().div_ceil(threads).max(1);
        std::thread::scope(|scope| {
            let mut rest = x.as_mut();
            while rest.ncols() > 0 {
                let take = per.min(rest.ncols());
                let (chunk, tail) = rest.split_at_col_mut(take);
                rest = tail;
                scope.spawn(move || self.llt.solve_in_place(chunk));
            }
        });
        x
    }
}
