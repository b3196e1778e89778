//! Direct Dirichlet solves with the full stiffness (f64 reference path).

use anyhow::{Context, bail, ensure};
use faer::Mat;

use super::assembly::{assemble_restricted, assemble_stiffness};
use super::llt::SparseLlt;
use super::material::TetMaterials;

/// One 3-vector per vertex (or per prescribed vertex): displacements in m or
/// forces in N. Plain `Vec<[f64; 3]>`.
pub type VertexVectors = Vec<[f64; 3]>;

/// Direct Dirichlet solve of linear elasticity (`MODELS.md` §2, Cotin
/// RR-3510 §4): the displacement `u_p` (m, all 3 components) is prescribed at
/// the vertices of `prescribed`, displacements are zero at `fixed` vertices,
/// and every other vertex is force-free.
///
/// With `K` the full stiffness ([`assemble_stiffness`]) and `U` the unknown
/// (free, unprescribed) DOFs it solves `K_UU u_U = -K_UP u_P` by sparse
/// Cholesky and returns
/// * the displacement of every vertex (m), prescribed and fixed ones included;
/// * for each entry of `prescribed`, in the same order, the reaction
///   `f_p = (K u)_p` (N): the force the constraint applies to the tissue
///   at that vertex (for a single contact, `f = C_kk⁻¹ u_p`).
///
/// Each tet has its own material `m.per_tet()[t]` ([`TetMaterials::uniform`]
/// for a homogeneous body).
///
/// Errors if `fixed.len() != positions.len()`, `m` is not for `tets.len()`
/// tets, a prescribed vertex is out of range, fixed or listed twice, a tet
/// references a missing vertex, or the reduced system is not positive
/// definite (e.g. nothing holds the body).
pub fn solve_prescribed(
    positions: &[[f64; 3]],
    tets: &[[u32; 4]],
    m: &TetMaterials,
    fixed: &[bool],
    prescribed: &[(u32, [f64; 3])],
) -> anyhow::Result<(VertexVectors, VertexVectors)> {
    solve_loaded(positions, tets, m, fixed, prescribed, &[])
}

/// [`solve_prescribed`] with nodal loads as well: `loads_n` (N, one per
/// vertex, or empty for none) acts on the unknown DOFs, so it solves
/// `K_UU u_U = f_U − K_UP u_P`; the reactions are `(K u)_p − f_p`, the force
/// the constraint applies. The reference of the hybrid model's steady
/// states (gravity as lumped nodal loads `ρ V/4 g`, point loads).
pub fn solve_loaded(
    positions: &[[f64; 3]],
    tets: &[[u32; 4]],
    m: &TetMaterials,
    fixed: &[bool],
    prescribed: &[(u32, [f64; 3])],
    loads_n: &[[f64; 3]],
) -> anyhow::Result<(VertexVectors, VertexVectors)> {
    let n = positions.len();
    ensure!(
        loads_n.is_empty() || loads_n.len() == n,
        "loads has {} entries for {n} vertices",
        loads_n.len()
    );
    let load = |v: usize| loads_n.get(v).copied().unwrap_or([0.0; 3]);
    ensure!(
        fixed.len() == n,
        "fixed has {} flags for {n} vertices",
        fixed.len()
    );
    ensure!(u32::try_from(n).is_ok(), "too many vertices");
    m.check_tet_count(tets.len())?;
    for (t, tet) in tets.iter().enumerate() {
        ensure!(
            tet.iter().all(|&v| (v as usize) < n),
            "tet {t} references a vertex out of range"
        );
    }
    let mut u = vec![[0.0f64; 3]; n];
    let mut known = fixed.to_vec();
    for &(v, d) in prescribed {
        let vi = v as usize;
        ensure!(vi < n, "prescribed vertex {v} out of range");
        if fixed[vi] {
            bail!("prescribed vertex {v} is fixed");
        }
        if known[vi] {
            bail!("vertex {v} is prescribed twice");
        }
        known[vi] = true;
        u[vi] = d;
    }
    let k = assemble_stiffness(positions, tets, m);
    // r = K u with the known part of u only.
    let mut slot = vec![None; n];
    let mut unknown = Vec::new();
    for v in 0..n {
        if !known[v] {
            slot[v] = Some(unknown.len() as u32);
            unknown.push(v);
        }
    }
    if !unknown.is_empty() {
        let ku = sparse_mul(&k, &u);
        let a = assemble_restricted(positions, tets, m, &slot, unknown.len());
        let llt = SparseLlt::new(a.as_ref()).context("direct Dirichlet solve")?;
        let mut rhs = Mat::<f64>::zeros(3 * unknown.len(), 1);
        for (s, &v) in unknown.iter().enumerate() {
            for c in 0..3 {
                rhs[(3 * s + c, 0)] = load(v)[c] - ku[v][c];
            }
        }
        llt.solve_in_place(rhs.as_mut());
        for (s, &v) in unknown.iter().enumerate() {
            for c in 0..3 {
                u[v][c] = rhs[(3 * s + c, 0)];
            }
        }
    }
    let f = sparse_mul(&k, &u);
    let reactions = prescribed
        .iter()
        .map(|&(v, _)| {
            let (kv, fv) = (f[v as usize], load(v as usize));
            [kv[0] - fv[0], kv[1] - fv[1], kv[2] - fv[2]]
        })
        .collect();
    Ok((u, reactions))
}

/// `K u` for a `3N × 3N` matrix and per-vertex vectors.
fn sparse_mul(k: &faer::sparse::SparseColMat<usize, f64>, u: &[[f64; 3]]) -> Vec<[f64; 3]> {
    let mut out = vec![[0.0f64; 3]; u.len()];
    let (sym, val) = k.parts();
    let col_ptr = sym.col_ptr();
    let row_idx = sym.row_idx();
    for j in 0..3 * u.len() {
        let x = u[j / 3][j % 3];
        if x == 0.0 {
            continue;
        }
        for p in col_ptr[j]..col_ptr[j + 1] {
            let i = row_idx[p];
            out[i / 3][i % 3] += val[p] * x;
        }
    }
    out
}
