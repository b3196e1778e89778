//! Static condensation of the pre-computed region onto its connection nodes
//! (RR-3510 §6.2; MODELS.md §2 for the stiffness): the interface table's
//! arrays.

use anyhow::Context;
use faer::Mat;

use crate::fem::assembly::{FreeOrdering, assemble_restricted, assemble_stiffness};
use crate::fem::llt::SparseLlt;
use crate::fem::material::TetMaterials;

/// The pre-computed region condensed onto `c` connection nodes, in f64.
///
/// With the region's stiffness `K` split into its free vertices `i` (the
/// connection nodes held: the pre-computed table's free vertices) and the
/// connection nodes `c`: `H = −K_ii⁻¹ K_ic`, `S = K_cc + K_ci H` (the Schur
/// complement `K_cc − K_ci K_ii⁻¹ K_ic`), and for the region's load `f`
/// (on its free vertices) `u_load = K_ii⁻¹ f`, `p_load = Hᵀ f`.
#[derive(Clone, Debug, PartialEq)]
pub struct Condensed {
    /// `S` (N/m) as the `3c × 3c` matrix, row-major in triples: row
    /// `3j + a` is `c` triples at `(3j + a)·c`, triple `k` holding columns
    /// `3k..3k+3` (the interface table's layout); symmetrized,
    /// `(S + Sᵀ)/2`.
    pub condensed: Vec<[f64; 3]>,
    /// `H` (m/m) as the `3F × 3c` matrix in the same layout (row `3n + a`,
    /// `n` the free index).
    pub response: Vec<[f64; 3]>,
    /// `u_load` per free index, m.
    pub load_displacement: Vec<[f64; 3]>,
    /// `p_load` per connection node, N.
    pub load_force: Vec<[f64; 3]>,
}

/// Condenses the region of `tets` (positions in m, one material per tet in
/// `m`) with the
/// free/fixed split of `ordering` (connection nodes fixed in it) onto the
/// `connection` nodes (mesh vertices, ascending), under the nodal load
/// `load_n` (N, one per mesh vertex; only free vertices' entries count).
///
/// One sparse Cholesky factorization of `K_ii` and `3c + 1` solves; memory
/// `24 F (3c + 1)` bytes for the dense right-hand sides.
pub fn condense(
    positions: &[[f64; 3]],
    tets: &[[u32; 4]],
    m: &TetMaterials,
    ordering: &FreeOrdering,
    connection: &[u32],
    load_n: &[[f64; 3]],
) -> anyhow::Result<Condensed> {
    let f = ordering.free_count();
    let c = connection.len();
    let a = assemble_restricted(positions, tets, m, &ordering.vertex_slot, f);
    let llt = SparseLlt::new(a.as_ref()).context("factorizing the pre-computed region")?;
    let k = assemble_stiffness(positions, tets, m);
    let (symbolic, values) = k.parts();
    let (col_ptr, row_idx) = (symbolic.col_ptr(), symbolic.row_idx());
    let column =
        |dof: usize| (col_ptr[dof]..col_ptr[dof + 1]).map(move |p| (row_idx[p], values[p]));
    let free_slot = |dof: usize| ordering.vertex_slot[dof / 3].map(|n| 3 * n as usize + dof % 3);

    // Right-hand sides: −K_ic column by column, then the load.
    let mut rhs = Mat::<f64>::zeros(3 * f, 3 * c + 1);
    for (j, &v) in connection.iter().enumerate() {
        for b in 0..3 {
            for (row, value) in column(3 * v as usize + b) {
                if let Some(r) = free_slot(row) {
                    rhs[(r, 3 * j + b)] = -value;
                }
            }
        }
    }
    for (n, &v) in ordering.free_vertex.iter().enumerate() {
        for a in 0..3 {
            rhs[(3 * n + a, 3 * c)] = load_n[v as usize][a];
        }
    }
    llt.solve_in_place(rhs.as_mut());

    let mut response = vec![[0.0; 3]; 3 * f * c];
    for (r, row) in response.chunks_exact_mut(c).enumerate() {
        for (j, triple) in row.iter_mut().enumerate() {
            *triple = core::array::from_fn(|b| rhs[(r, 3 * j + b)]);
        }
    }
    // S = K_cc + K_ci H, column (k, b) by column: K times (H column on the
    // free DOFs, 1 at (k, b)), read on the connection DOFs.
    let mut connection_slot = vec![None; positions.len()];
    for (j, &v) in connection.iter().enumerate() {
        connection_slot[v as usize] = Some(j);
    }
    // Dense 3c × 3c, row-major in scalars.
    let mut s = vec![0.0f64; 9 * c * c];
    for (kk, &vk) in connection.iter().enumerate() {
        for b in 0..3 {
            let mut add_column = |dof: usize, x: f64| {
                for (row, value) in column(dof) {
                    if let Some(j) = connection_slot[row / 3] {
                        s[(3 * j + row % 3) * 3 * c + 3 * kk + b] += value * x;
                    }
                }
            };
            add_column(3 * vk as usize + b, 1.0);
            for (n, &v) in ordering.free_vertex.iter().enumerate() {
                for a in 0..3 {
                    let x = rhs[(3 * n + a, 3 * kk + b)];
                    if x != 0.0 {
                        add_column(3 * v as usize + a, x);
                    }
                }
            }
        }
    }
    let condensed = symmetrized(&s, c);
    let load_displacement = (0..f)
        .map(|n| core::array::from_fn(|a| rhs[(3 * n + a, 3 * c)]))
        .collect::<Vec<[f64; 3]>>();
    // p = Hᵀ f: row 3n + a of H scaled by f_n[a].
    let mut load_force = vec![[0.0; 3]; c];
    for n in 0..f {
        let fv = load_n[ordering.free_vertex[n] as usize];
        for (a, &fa) in fv.iter().enumerate() {
            let row = &response[(3 * n + a) * c..(3 * n + a + 1) * c];
            for (p, h) in load_force.iter_mut().zip(row) {
                for (pb, hb) in p.iter_mut().zip(h) {
                    *pb += hb * fa;
                }
            }
        }
    }
    Ok(Condensed {
        condensed,
        response,
        load_displacement,
        load_force,
    })
}

/// `(S + Sᵀ)/2` of the `n × n` row-major `s` (`n = 3c`), as rows of `c`
/// triples.
fn symmetrized(s: &[f64], c: usize) -> Vec<[f64; 3]> {
    let n = 3 * c;
    (0..n)
        .flat_map(|r| (0..c).map(move |k| (r, k)))
        .map(|(r, k)| {
            core::array::from_fn(|b| 0.5 * (s[r * n + 3 * k + b] + s[(3 * k + b) * n + r]))
        })
        .collect()
}
