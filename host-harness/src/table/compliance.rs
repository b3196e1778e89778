//! Offline compliance computation of the pre-computed quasi-static model
//! (`MODELS.md` §2, Cotin RR-3510 §4).

use anyhow::{Context, ensure};
use faer::Mat;
use faer::sparse::SparseColMat;
use indicatif::ProgressBar;
use palpate_kernel::table::format::surface_block_index;

use super::cg::JacobiCg;
use crate::fem::assembly::{FreeOrdering, assemble_restricted};
use crate::fem::llt::SparseLlt;
use crate::fem::material::TetMaterials;
use crate::output::stderr;

/// How [`compute_compliance`] solves `A x = e`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Solver {
    /// One sparse Cholesky factorization of `A` (AMD ordering), then
    /// batched triangular solves, 3 right-hand sides per touchable vertex.
    Cholesky,
    /// Jacobi-preconditioned conjugate gradient per right-hand side
    /// (relative residual `1e-10`, at most `10·dof` iterations): the
    /// paper's slow baseline.
    Cg,
}

/// Compliance blocks `C = A⁻¹` (m/N) of the free DOFs, `A` = stiffness
/// restricted to the free vertices (fixed vertices removed), in the layout the
/// kernel table uses (`MODELS.md` §2: `u_n = C_nk C_kk⁻¹ d`, force
/// `C_kk⁻¹ d`).
///
/// With `S = touchable_count`, `F = free_count`, `I = F - S` of the
/// [`FreeOrdering`]:
/// * `surface`: length `S(S+1)/2`, packed upper by columns: column `k` in
///   `0..S` holds rows `n = 0..=k` at index `k(k+1)/2 + n`;
/// * `interior`: length `I·S`: column `k` holds rows `i` in `0..I` (free
///   index `S + i`) at index `k·I + i`.
///
/// Each block is `C_{n,k}` row-major: entry `[3a + b]` =
/// `C[(free n, comp a), (touchable k, comp b)]` in m/N. `C` is symmetric, so
/// `C_{k,n} = C_{n,k}ᵀ` gives the lower surface blocks.
#[derive(Debug, Clone, PartialEq)]
pub struct Compliance {
    /// Surface–surface blocks `C_{n,k}`, `n ≤ k < S`, packed upper by columns
    /// (index [`surface_block_index`]`(n, k)`, the kernel's own layout).
    pub surface: Vec<[f64; 9]>,
    /// Interior–surface blocks `C_{S+i,k}`, column-major (`k·I + i`).
    pub interior: Vec<[f64; 9]>,
}

/// Touchable vertices per batch of right-hand sides (3 columns each).
pub const BATCH_VERTICES: usize = 64;
/// CG relative residual target.
const CG_REL_TOL: f64 = 1e-10;

/// Computes the compliance table ([`Compliance`]) of the mesh
/// (`positions` in m, positively oriented `tets`) for the per-tet materials
/// `m` (heterogeneous tissue; [`TetMaterials::uniform`] for one), with the
/// fixed/touchable split of `ordering`.
///
/// `A` (N/m) is [`assemble_restricted`] with `ordering.vertex_slot`; the
/// columns of `C = A⁻¹` for the `3S` touchable DOFs are `A⁻¹ e_(k,b)`
/// (Cotin RR-3510 §4), computed with `solver`. `progress` shows a progress
/// bar over the touchable vertices on stderr.
///
/// Errors if the ordering or the materials do not match the mesh, a tet
/// references a missing vertex, `A` is not positive definite (nothing
/// fixed), or CG does not converge.
///
/// Stages: the inputs checked (`check_inputs`), `A` assembled, the
/// columns solved by `solve_cholesky` or `solve_cg` and scattered into
/// the blocks (`Compliance::store`).
pub fn compute_compliance(
    positions: &[[f64; 3]],
    tets: &[[u32; 4]],
    m: &TetMaterials,
    ordering: &FreeOrdering,
    solver: Solver,
    progress: bool,
) -> anyhow::Result<Compliance> {
    check_inputs(positions, tets, m, ordering)?;
    let f = ordering.free_count();
    let s = ordering.touchable_count;
    let interior_count = f - s;
    let mut out = Compliance {
        surface: vec![[0.0; 9]; s * (s + 1) / 2],
        interior: vec![[0.0; 9]; interior_count * s],
    };
    if s == 0 {
        return Ok(out);
    }
    let a = assemble_restricted(positions, tets, m, &ordering.vertex_slot, f);
    let bar = progress_bar(progress, s);
    let store = |k0: usize, x: &Mat<f64>| out.store(s, interior_count, k0, x);
    match solver {
        Solver::Cholesky => solve_cholesky(&a, s, &bar, store)?,
        Solver::Cg => solve_cg(&a, s, &bar, store)?,
    }
    bar.finish_and_clear();
    Ok(out)
}

/// The ordering is of the mesh's vertices and consistent (free index ↔
/// vertex both ways, no more touchable than free vertices), the materials
/// one per tet, every tet's vertices in range.
fn check_inputs(
    positions: &[[f64; 3]],
    tets: &[[u32; 4]],
    m: &TetMaterials,
    ordering: &FreeOrdering,
) -> anyhow::Result<()> {
    let nv = positions.len();
    ensure!(
        ordering.vertex_slot.len() == nv,
        "ordering is for {} vertices, mesh has {nv}",
        ordering.vertex_slot.len()
    );
    m.check_tet_count(tets.len())?;
    let f = ordering.free_count();
    let s = ordering.touchable_count;
    ensure!(s <= f, "touchable_count {s} exceeds free count {f}");
    for (i, &v) in ordering.free_vertex.iter().enumerate() {
        ensure!(
            (v as usize) < nv && ordering.vertex_slot[v as usize] == Some(i as u32),
            "ordering is inconsistent at free index {i}"
        );
    }
    ensure!(
        ordering.vertex_slot.iter().flatten().count() == f,
        "ordering is inconsistent: vertex_slot and free_vertex disagree"
    );
    for (t, tet) in tets.iter().enumerate() {
        ensure!(
            tet.iter().all(|&v| (v as usize) < nv),
            "tet {t} references a vertex out of range"
        );
    }
    Ok(())
}

/// A progress bar over the `s` touchable vertices on stderr, or a hidden
/// one without `progress`.
fn progress_bar(progress: bool, s: usize) -> ProgressBar {
    stderr::progress_bar(
        s as u64,
        "compliance {bar:40} {pos}/{len} touchable vertices ({eta})",
        progress,
    )
}

impl Compliance {
    /// Scatters the solved columns `x` (3 per vertex) of touchable vertices
    /// `k0..k0 + x.ncols()/3` into the blocks, of `s` touchable and
    /// `interior_count` interior vertices.
    fn store(&mut self, s: usize, interior_count: usize, k0: usize, x: &Mat<f64>) {
        let nb = x.ncols() / 3;
        for kk in 0..nb {
            let k = k0 + kk;
            let block = |n: usize| {
                let mut blk = [0.0f64; 9];
                for a in 0..3 {
                    for b in 0..3 {
                        blk[3 * a + b] = x[(3 * n + a, 3 * kk + b)];
                    }
                }
                blk
            };
            for n in 0..=k {
                self.surface[surface_block_index(n, k)] = block(n);
            }
            for i in 0..interior_count {
                self.interior[k * interior_count + i] = block(s + i);
            }
        }
    }
}

/// The columns of `A⁻¹` of the `s` touchable vertices by one sparse
/// Cholesky factorization, solved [`BATCH_VERTICES`] vertices at a time and
/// handed to `store(first vertex, columns)`.
fn solve_cholesky(
    a: &SparseColMat<usize, f64>,
    s: usize,
    bar: &ProgressBar,
    mut store: impl FnMut(usize, &Mat<f64>),
) -> anyhow::Result<()> {
    let dof = a.ncols();
    let llt = SparseLlt::new(a.as_ref()).context("compliance: factorizing A")?;
    log::debug!(
        "compliance: {dof} free DOFs, {} non-zeros in A, {} in L",
        a.compute_nnz(),
        llt.factor_len()
    );
    let mut k0 = 0;
    while k0 < s {
        let nb = BATCH_VERTICES.min(s - k0);
        let mut x = Mat::<f64>::zeros(dof, 3 * nb);
        for c in 0..3 * nb {
            x[(3 * k0 + c, c)] = 1.0;
        }
        llt.solve_in_place(x.as_mut());
        store(k0, &x);
        k0 += nb;
        bar.inc(nb as u64);
    }
    Ok(())
}

/// The columns of `A⁻¹` of the `s` touchable vertices by Jacobi-preconditioned
/// CG, one right-hand side at a time ([`CG_REL_TOL`], at most `10·dof`
/// iterations), handed to `store(vertex, its 3 columns)`.
fn solve_cg(
    a: &SparseColMat<usize, f64>,
    s: usize,
    bar: &ProgressBar,
    mut store: impl FnMut(usize, &Mat<f64>),
) -> anyhow::Result<()> {
    let dof = a.ncols();
    check_cg_work(s as u64, dof as u64, a.compute_nnz() as u64)?;
    let cg = JacobiCg::new(a.as_ref());
    let inv_diag = cg.inv_diag();
    ensure!(
        inv_diag.iter().all(|d| d.is_finite() && *d > 0.0),
        "A has a non-positive diagonal entry (a free vertex in no tet?)"
    );
    let max_iter = 10 * dof;
    let mut e = vec![0.0f64; dof];
    for k in 0..s {
        let mut x = Mat::<f64>::zeros(dof, 3);
        for b in 0..3 {
            e[3 * k + b] = 1.0;
            let (col, _) = cg
                .solve(&e, &inv_diag, CG_REL_TOL, max_iter)
                .with_context(|| {
                    format!("compliance: CG for touchable vertex {k}, component {b}")
                })?;
            e[3 * k + b] = 0.0;
            for (r, v) in col.into_iter().enumerate() {
                x[(r, b)] = v;
            }
        }
        store(k, &x);
        bar.inc(1);
    }
    Ok(())
}

/// Checks the estimated work of the CG compliance, `3S` solves of about `sqrt(dof)` iterations
/// (Jacobi-preconditioned CG on an elastic stiffness converges in `O(h⁻¹)` iterations, at most
/// `sqrt(dof)` for a 3-D mesh) of one product with `A` (`nnz` multiply-adds) each, against
/// [`crate::limits::MAX_CG_MULTIPLY_ADDS`], before the first solve: refused above it with the
/// figures, printed on stderr when longer than
/// [`crate::limits::PRINT_ESTIMATE_ABOVE_S`].
pub fn check_cg_work(touchable: u64, dof: u64, nnz: u64) -> anyhow::Result<()> {
    use crate::limits::{MAX_CG_MULTIPLY_ADDS, PRINT_ESTIMATE_ABOVE_S, SECONDS_PER_MULTIPLY_ADD};
    let iterations = (dof as f64).sqrt().ceil() as u64;
    let work = touchable
        .saturating_mul(3)
        .saturating_mul(iterations)
        .saturating_mul(nnz);
    let seconds = work as f64 * SECONDS_PER_MULTIPLY_ADD;
    let figures = format!(
        "{} solves x about {iterations} iterations x {nnz} non-zeros = {:.3e} multiply-adds, \
         about {seconds:.0} s",
        3 * touchable,
        work as f64
    );
    if work > MAX_CG_MULTIPLY_ADDS {
        anyhow::bail!(
            "compliance by CG: {figures}: above the limit of {:.0e} (MAX_CG_MULTIPLY_ADDS): \
             refused before the first solve; use --solver cholesky (the default), or a coarser \
             mesh",
            MAX_CG_MULTIPLY_ADDS as f64
        );
    }
    if seconds > PRINT_ESTIMATE_ABOVE_S {
        crate::output::stderr::line(&format!("compliance by CG: estimate: {figures}"));
    }
    Ok(())
}
