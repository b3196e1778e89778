//! Picinbono's split St Venant-Kirchhoff terms (Picinbono, Debunne, Ayache
//! 2001 §3.1, eq. 13–15 and table 1; MODELS.md §4), stored per mesh primitive
//! so that removing a tet is a local subtraction.
//!
//! With the rest shape-function gradients `a_j` (1/m), rest volume `V` (m³),
//! Lamé coefficients `λ`, `μ` (Pa) and corner displacements `u_j` (m), the
//! energy of a tet is (eq. 13, with `V` included)
//!
//! `W_T = Σ_jk u_jᵀ B_jk u_k + Σ_jkl (u_j·C_jkl)(u_k·u_l) + Σ_jklm D_jklm (u_j·u_k)(u_l·u_m)`
//!
//! with (eq. 14) `B_jk = K_jk / 2` (the linear tensors, stored elsewhere),
//! `C_jkl = V [λ/2 a_j (a_k·a_l) + μ/2 (a_l (a_j·a_k) + a_k (a_j·a_l))]` (N/m²)
//! and `D_jklm = V [λ/8 (a_j·a_k)(a_l·a_m) + μ/4 (a_j·a_m)(a_k·a_l)]` (N/m³).
//! It equals `V (λ/2 (tr E)² + μ tr E²)` with the Green strain of
//! `∇U = Σ_j u_j a_jᵀ`.
//!
//! # Monomial basis (table 1)
//!
//! The cubic terms are grouped by `(a, {b, c})` into one vector coefficient
//! `c` of the monomial `(u_a·c)(u_b·u_c)`, the quartic terms by
//! `{{a, b}, {c, d}}` into one scalar `d` of `d (u_a·u_b)(u_c·u_d)`. A
//! primitive (vertex, edge, triangle, tet) owns the monomials whose distinct
//! vertices are exactly its own. Indices below are local positions in the
//! primitive's vertex list: ascending global id for vertices, edges and
//! triangles, the tet's own order for tets. A term array holds the cubic
//! vectors first (`x, y, z` each, in pattern order), then the quartic
//! scalars:
//!
//! | primitive | cubic `(a, b, c)`, `b ≤ c` | quartic `(a, b, c, d)` | scalars |
//! |---|---|---|---|
//! | vertex | [`VERTEX_CUBIC`] | [`VERTEX_QUARTIC`] | 4 |
//! | edge `(lo, hi)` | [`EDGE_CUBIC`] | [`EDGE_QUARTIC`] | 16 |
//! | triangle `p < q < r` | [`TRIANGLE_CUBIC`] | [`TRIANGLE_QUARTIC`] | 15 |
//! | tet | none | [`TET_QUARTIC`] | 3 |
//!
//! The coefficient of a pattern is the sum of `C_jkl` (or `D_jklm`) over all
//! ordered local index tuples of the tet that map to it ([`tet_terms`]); the
//! global arrays hold the sums over the tets around each primitive (built on
//! the host, minus the terms of removed tets in the kernel).
//!
//! # Force
//!
//! `−∂W/∂u` (eq. 15) is evaluated monomial by monomial from the stored
//! coefficients: for `(u_a·c)(u_b·u_c)`, `∂/∂u_a = c (u_b·u_c)`,
//! `∂/∂u_b = (u_a·c) u_c`, `∂/∂u_c = (u_a·c) u_b`; for
//! `d (u_a·u_b)(u_c·u_d)`, `∂/∂u_a = d (u_c·u_d) u_b` and symmetrically. One
//! evaluator, driven by the pattern tables above, serves the four primitive
//! kinds ([`NonLinearTerms`]).

use nalgebra::Vector3;

use crate::Real;
use crate::table::format::{
    EDGE_TERMS_LEN, TET_EDGE_PAIRS, TET_TERMS_LEN, TRIANGLE_TERMS_LEN, VERTEX_TERMS_LEN,
};
use crate::table::{TensorMassTable, span};

/// Cubic monomials owned by a vertex: `(u_0·c)(u_0·u_0)`.
pub const VERTEX_CUBIC: [[usize; 3]; 1] = [[0, 0, 0]];
/// Quartic monomials owned by a vertex: `d (u_0·u_0)²`.
pub const VERTEX_QUARTIC: [[usize; 4]; 1] = [[0, 0, 0, 0]];
/// Cubic monomials owned by an edge (positions 0 = lower, 1 = higher global id).
pub const EDGE_CUBIC: [[usize; 3]; 4] = [[0, 0, 1], [0, 1, 1], [1, 0, 0], [1, 0, 1]];
/// Quartic monomials owned by an edge.
pub const EDGE_QUARTIC: [[usize; 4]; 4] = [[0, 0, 0, 1], [0, 0, 1, 1], [0, 1, 0, 1], [0, 1, 1, 1]];
/// Cubic monomials owned by a triangle (positions by ascending global id).
pub const TRIANGLE_CUBIC: [[usize; 3]; 3] = [[0, 1, 2], [1, 0, 2], [2, 0, 1]];
/// Quartic monomials owned by a triangle.
pub const TRIANGLE_QUARTIC: [[usize; 4]; 6] = [
    [0, 0, 1, 2],
    [0, 1, 0, 2],
    [0, 2, 1, 1],
    [0, 1, 1, 2],
    [0, 1, 2, 2],
    [0, 2, 1, 2],
];
/// Cubic monomials owned by a tet: none (a cubic monomial has at most three
/// distinct vertices).
pub const TET_CUBIC: [[usize; 3]; 0] = [];
/// Quartic monomials owned by a tet (positions in the tet's own order).
pub const TET_QUARTIC: [[usize; 4]; 3] = [[0, 1, 2, 3], [0, 2, 1, 3], [0, 3, 1, 2]];

const _: () = {
    assert!(3 * VERTEX_CUBIC.len() + VERTEX_QUARTIC.len() == VERTEX_TERMS_LEN);
    assert!(3 * EDGE_CUBIC.len() + EDGE_QUARTIC.len() == EDGE_TERMS_LEN);
    assert!(3 * TRIANGLE_CUBIC.len() + TRIANGLE_QUARTIC.len() == TRIANGLE_TERMS_LEN);
    assert!(3 * TET_CUBIC.len() + TET_QUARTIC.len() == TET_TERMS_LEN);
};

/// The cubic and quartic St Venant-Kirchhoff terms of one tet, split over its
/// primitives in the monomial basis of the module docs: `c` coefficients in
/// N/m², `d` coefficients in N/m³.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TetTerms<T> {
    /// Terms of local vertex `j`: `[c.x, c.y, c.z, d]`.
    pub vertex: [[T; VERTEX_TERMS_LEN]; 4],
    /// Terms of each edge in [`TET_EDGE_PAIRS`] order, positions oriented by
    /// ascending global id (`lo`, `hi`), as in the table's CSR edge list.
    pub edge: [[T; EDGE_TERMS_LEN]; 6],
    /// Terms of face `j`, opposite local vertex `j`
    /// ([`crate::table::format::tet_face_vertices`]), positions by ascending
    /// global id.
    pub triangle: [[T; TRIANGLE_TERMS_LEN]; 4],
    /// Terms of the tet itself, positions in its own vertex order.
    pub tet: [T; TET_TERMS_LEN],
}

/// The global term arrays a tet's terms are added to or subtracted from
/// (indexed like the table sections: vertex, edge, mesh triangle, tet).
#[derive(Debug)]
pub struct TermArraysMut<'a, T> {
    /// Vertex terms, one per vertex.
    pub vertex: &'a mut [[T; VERTEX_TERMS_LEN]],
    /// Edge terms, one per CSR edge.
    pub edge: &'a mut [[T; EDGE_TERMS_LEN]],
    /// Triangle terms, one per mesh triangle.
    pub triangle: &'a mut [[T; TRIANGLE_TERMS_LEN]],
    /// Tet terms, one per tet.
    pub tet: &'a mut [[T; TET_TERMS_LEN]],
}

/// Where a tet's primitives live in the global arrays.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TetPlace {
    /// Tet index.
    pub tet: u32,
    /// Its vertices (table order).
    pub vertices: [u32; 4],
    /// Edge index of each [`TET_EDGE_PAIRS`] pair (table `tet-edge`).
    pub edges: [u32; 6],
    /// Mesh-triangle index of the face opposite each local vertex (table
    /// `tet-triangle`).
    pub triangles: [u32; 4],
}

impl<T: Real> TetTerms<T> {
    /// All coefficients zero.
    pub fn zero() -> Self {
        let z = T::zero();
        Self {
            vertex: [[z; VERTEX_TERMS_LEN]; 4],
            edge: [[z; EDGE_TERMS_LEN]; 6],
            triangle: [[z; TRIANGLE_TERMS_LEN]; 4],
            tet: [z; TET_TERMS_LEN],
        }
    }

    /// Adds these terms to `arrays` at `place` (the host's assembly,
    /// Picinbono table 1). References outside the arrays are skipped (the
    /// table validates them at load).
    pub fn add_to(&self, place: &TetPlace, arrays: &mut TermArraysMut<'_, T>) {
        self.scatter(place, arrays, T::one());
    }

    /// Subtracts these terms from `arrays` at `place`: removing the tet
    /// leaves the arrays of the mesh without it, to rounding. Bounded: 15
    /// small updates; no allocation, no panic.
    pub fn subtract_from(&self, place: &TetPlace, arrays: &mut TermArraysMut<'_, T>) {
        self.scatter(place, arrays, -T::one());
    }

    // `TetPlace` is plain `u32` data (the host's assembly builds it from its
    // mesh): its entries are widened here, one bounds-checked `get_mut` each.
    fn scatter(&self, place: &TetPlace, arrays: &mut TermArraysMut<'_, T>, sign: T) {
        for (&v, terms) in place.vertices.iter().zip(&self.vertex) {
            axpy(arrays.vertex.get_mut(v as usize), terms, sign);
        }
        for (&e, terms) in place.edges.iter().zip(&self.edge) {
            axpy(arrays.edge.get_mut(e as usize), terms, sign);
        }
        for (&t, terms) in place.triangles.iter().zip(&self.triangle) {
            axpy(arrays.triangle.get_mut(t as usize), terms, sign);
        }
        axpy(arrays.tet.get_mut(place.tet as usize), &self.tet, sign);
    }
}

/// `target += sign · terms` when `target` exists.
fn axpy<T: Real, const L: usize>(target: Option<&mut [T; L]>, terms: &[T; L], sign: T) {
    if let Some(target) = target {
        for (t, &x) in target.iter_mut().zip(terms) {
            *t += sign * x;
        }
    }
}

/// The cubic and quartic St Venant-Kirchhoff terms of the tet `tet` (global
/// vertex ids, 4 distinct) with rest gradients `a` (1/m), rest volume
/// `volume_m3` (m³) and Lamé coefficients `lambda_pa`, `mu_pa` (Pa), split
/// over its vertices, edges, faces and itself (Picinbono 2001 eq. 14,
/// table 1; module docs).
///
/// Each pattern's coefficient is the sum of `C_jkl` or `D_jklm` over the
/// ordered local tuples that map to it: all 64 cubic and 256 quartic tuples
/// are visited once. Used by the host build and by the kernel when a tet is
/// cut: no allocation, no panic, fixed work (a few thousand flops).
pub fn tet_terms<T: Real>(
    tet: [u32; 4],
    a: &[Vector3<T>; 4],
    volume_m3: T,
    lambda_pa: T,
    mu_pa: T,
) -> TetTerms<T> {
    // G_jk = a_j·a_k (1/m²).
    let mut g = [[T::zero(); 4]; 4];
    for (row, aj) in g.iter_mut().zip(a) {
        for (gjk, ak) in row.iter_mut().zip(a) {
            *gjk = aj.dot(ak);
        }
    }
    let dot = |j: usize, k: usize| -> T {
        g.get(j)
            .and_then(|row| row.get(k))
            .copied()
            .unwrap_or_else(T::zero)
    };
    let grad = |j: usize| -> Vector3<T> { a.get(j).copied().unwrap_or_else(Vector3::zeros) };
    let half = T::of_f64(0.5);
    let (l2, m2) = (lambda_pa * half * volume_m3, mu_pa * half * volume_m3);
    let (l8, m4) = (
        lambda_pa * T::of_f64(0.125) * volume_m3,
        mu_pa * T::of_f64(0.25) * volume_m3,
    );
    // Eq. 14, with V.
    let c = |j: usize, k: usize, l: usize| -> Vector3<T> {
        grad(j) * (l2 * dot(k, l)) + (grad(l) * dot(j, k) + grad(k) * dot(j, l)) * m2
    };
    let d = |j: usize, k: usize, l: usize, m: usize| -> T {
        l8 * dot(j, k) * dot(l, m) + m4 * dot(j, m) * dot(k, l)
    };
    let coefficients = Coefficients { c, d };

    let mut out = TetTerms::zero();
    for (j, terms) in out.vertex.iter_mut().enumerate() {
        coefficients.expand(&VERTEX_CUBIC, &VERTEX_QUARTIC, &[j], terms);
    }
    let global = |j: usize| tet.get(j).copied().unwrap_or(u32::MAX);
    for (&[j, k], terms) in TET_EDGE_PAIRS.iter().zip(&mut out.edge) {
        let local = if global(j) < global(k) {
            [j, k]
        } else {
            [k, j]
        };
        coefficients.expand(&EDGE_CUBIC, &EDGE_QUARTIC, &local, terms);
    }
    for (opposite, terms) in out.triangle.iter_mut().enumerate() {
        // The other three local vertices, sorted by global id.
        let mut local = [0usize; 3];
        for (slot, j) in local.iter_mut().zip((0..4).filter(|&j| j != opposite)) {
            *slot = j;
        }
        let [mut p, mut q, mut r] = local;
        if global(p) > global(q) {
            core::mem::swap(&mut p, &mut q);
        }
        if global(q) > global(r) {
            core::mem::swap(&mut q, &mut r);
        }
        if global(p) > global(q) {
            core::mem::swap(&mut p, &mut q);
        }
        coefficients.expand(&TRIANGLE_CUBIC, &TRIANGLE_QUARTIC, &[p, q, r], terms);
    }
    coefficients.expand(&TET_CUBIC, &TET_QUARTIC, &[0, 1, 2, 3], &mut out.tet);
    out
}

/// `C_jkl` and `D_jklm` of one tet, as functions of local indices.
struct Coefficients<C, D> {
    c: C,
    d: D,
}

impl<T, C, D> Coefficients<C, D>
where
    T: Real,
    C: Fn(usize, usize, usize) -> Vector3<T>,
    D: Fn(usize, usize, usize, usize) -> T,
{
    /// Fills `out` (layout of the module docs) for one primitive whose
    /// position `p` is the tet's local vertex `local[p]`: each pattern gets
    /// the sum over the ordered local tuples that map to it.
    fn expand<const L: usize>(
        &self,
        cubic: &[[usize; 3]],
        quartic: &[[usize; 4]],
        local: &[usize],
        out: &mut [T; L],
    ) {
        let at = |p: usize| local.get(p).copied();
        let Some((cubic_out, quartic_out)) = out.split_at_mut_checked(3 * cubic.len()) else {
            return;
        };
        for (&[a, b, c], slot) in cubic.iter().zip(cubic_out.chunks_exact_mut(3)) {
            let (Some(ja), Some(jb), Some(jc)) = (at(a), at(b), at(c)) else {
                continue;
            };
            // (u_a·C)(u_b·u_c) collects C_{a b c} and, for b ≠ c, C_{a c b}.
            let mut sum = (self.c)(ja, jb, jc);
            if b != c {
                sum += (self.c)(ja, jc, jb);
            }
            for (s, x) in slot.iter_mut().zip(sum.iter()) {
                *s = *x;
            }
        }
        for (&[a, b, c, d], slot) in quartic.iter().zip(quartic_out) {
            let (Some(ja), Some(jb), Some(jc), Some(jd)) = (at(a), at(b), at(c), at(d)) else {
                continue;
            };
            // Every ordering of each pair, and of the two pairs when they differ.
            let first = orderings(ja, jb, a == b);
            let second = orderings(jc, jd, c == d);
            let mut sum = T::zero();
            for &[j, k] in first.iter().flatten() {
                for &[l, m] in second.iter().flatten() {
                    sum += (self.d)(j, k, l, m);
                    if [a, b] != [c, d] {
                        sum += (self.d)(l, m, j, k);
                    }
                }
            }
            *slot = sum;
        }
    }
}

/// The ordered pairs of the unordered pair `{j, k}`: one when the pattern's
/// positions coincide, two otherwise.
fn orderings(j: usize, k: usize, same: bool) -> [Option<[usize; 2]>; 2] {
    [Some([j, k]), if same { None } else { Some([k, j]) }]
}

/// The St Venant-Kirchhoff cubic and quartic terms of a mesh as the force
/// pass reads them (a view: the table's sections, or the model's copies
/// after cuts). The linear part is the vertex and edge tensors, evaluated
/// elsewhere.
#[derive(Clone, Copy, Debug)]
pub struct NonLinearTerms<'t, T> {
    /// Terms of each vertex (N entries).
    pub vertex_terms: &'t [[T; VERTEX_TERMS_LEN]],
    /// CSR row starts of the edge list (N + 1 entries).
    pub edge_row_start: &'t [u32],
    /// CSR columns: the higher end of each edge.
    pub edge_column: &'t [u32],
    /// Terms of each edge (one per column).
    pub edge_terms: &'t [[T; EDGE_TERMS_LEN]],
    /// Mesh triangles, ascending vertex ids.
    pub triangles: &'t [[u32; 3]],
    /// Terms of each mesh triangle.
    pub triangle_terms: &'t [[T; TRIANGLE_TERMS_LEN]],
    /// Tet vertices.
    pub tets: &'t [[u32; 4]],
    /// Terms of each tet.
    pub tet_terms: &'t [[T; TET_TERMS_LEN]],
    /// `false` for removed tets, whose tet terms are skipped (their vertex,
    /// edge and triangle shares are subtracted from the arrays instead).
    pub tet_alive: &'t [bool],
}

impl<'t, T: Real> NonLinearTerms<'t, T> {
    /// The terms of the uncut mesh as stored in `table`, with `tet_alive`
    /// (one flag per tet).
    pub fn of_table(table: &TensorMassTable<'t, T>, tet_alive: &'t [bool]) -> Self {
        Self {
            vertex_terms: table.vertex_terms(),
            edge_row_start: table.edge_row_starts(),
            edge_column: table.edge_columns(),
            edge_terms: table.edge_terms(),
            triangles: table.mesh_triangles(),
            triangle_terms: table.triangle_terms(),
            tets: table.tets(),
            tet_terms: table.tet_terms(),
            tet_alive,
        }
    }

    /// Adds the cubic and quartic part of the St Venant-Kirchhoff force,
    /// `−∂(W₃ + W₄)/∂u` (N; Picinbono eq. 15, terms `F₂` and `F₃`), of
    /// displacements `u` (m) to `f`. One pass over vertices, edges,
    /// triangles and live tets, bounded by the slice lengths; references
    /// outside `u` or `f` are skipped (validated at load). Always inlined,
    /// so that a [`crate::math::Dispatch`] compiles it where it runs.
    #[inline(always)]
    pub fn add_forces(&self, u: &[[T; 3]], f: &mut [[T; 3]]) {
        self.pass(u, |v, g| {
            if let Some(out) = f.get_mut(v as usize) {
                *out = [out[0] - g.x, out[1] - g.y, out[2] - g.z];
            }
        });
    }

    /// The cubic and quartic part of the St Venant-Kirchhoff energy,
    /// `W₃ + W₄` (J; Picinbono eq. 13 without the `B` term), of
    /// displacements `u` (m).
    pub fn energy_j(&self, u: &[[T; 3]]) -> T {
        self.pass(u, |_, _| {})
    }

    /// Evaluates every primitive's monomials at `u`, hands each vertex's
    /// gradient share `∂W/∂u_v` (N) to `gradient`, returns the energy (J).
    #[inline(always)]
    fn pass(&self, u: &[[T; 3]], mut gradient: impl FnMut(u32, Vector3<T>)) -> T {
        let mut energy = T::zero();
        for (v, (terms, uv)) in self.vertex_terms.iter().zip(u).enumerate() {
            let mut g = [Vector3::zeros()];
            energy += monomials(&VERTEX_CUBIC, &VERTEX_QUARTIC, terms, &[v3(uv)], &mut g);
            let [g0] = g;
            gradient(v as u32, g0);
        }
        let rows = self.edge_row_start.windows(2).zip(u);
        for (i, (row, ui)) in rows.enumerate() {
            let &[start, end] = row else {
                continue;
            };
            let range = span(start, end);
            let (Some(columns), Some(terms)) = (
                self.edge_column.get(range.clone()),
                self.edge_terms.get(range),
            ) else {
                continue;
            };
            let ui = v3(ui);
            let mut gi = Vector3::zeros();
            for (&j, terms) in columns.iter().zip(terms) {
                let Some(uj) = u.get(j as usize) else {
                    continue;
                };
                let mut g = [Vector3::zeros(); 2];
                energy += monomials(&EDGE_CUBIC, &EDGE_QUARTIC, terms, &[ui, v3(uj)], &mut g);
                let [g0, g1] = g;
                gi += g0;
                gradient(j, g1);
            }
            gradient(i as u32, gi);
        }
        for (&[p, q, r], terms) in self.triangles.iter().zip(self.triangle_terms) {
            let (Some(up), Some(uq), Some(ur)) =
                (u.get(p as usize), u.get(q as usize), u.get(r as usize))
            else {
                continue;
            };
            let mut g = [Vector3::zeros(); 3];
            let corners = [v3(up), v3(uq), v3(ur)];
            energy += monomials(&TRIANGLE_CUBIC, &TRIANGLE_QUARTIC, terms, &corners, &mut g);
            let [g0, g1, g2] = g;
            gradient(p, g0);
            gradient(q, g1);
            gradient(r, g2);
        }
        let tets = self.tets.iter().zip(self.tet_terms).zip(self.tet_alive);
        for ((&[t0, t1, t2, t3], terms), &alive) in tets {
            if !alive {
                continue;
            }
            let (Some(u0), Some(u1), Some(u2), Some(u3)) = (
                u.get(t0 as usize),
                u.get(t1 as usize),
                u.get(t2 as usize),
                u.get(t3 as usize),
            ) else {
                continue;
            };
            let mut g = [Vector3::zeros(); 4];
            let corners = [v3(u0), v3(u1), v3(u2), v3(u3)];
            energy += monomials(&TET_CUBIC, &TET_QUARTIC, terms, &corners, &mut g);
            let [g0, g1, g2, g3] = g;
            gradient(t0, g0);
            gradient(t1, g1);
            gradient(t2, g2);
            gradient(t3, g3);
        }
        energy
    }
}

#[inline(always)]
fn v3<T: Real>(p: &[T; 3]) -> Vector3<T> {
    Vector3::new(p[0], p[1], p[2])
}

/// Energy (J) of one primitive's monomials (module docs) at its corner
/// displacements `u` (m), and their gradient (N) added to `grad`. The pattern
/// tables drive the work; `L = 3·NC + NQ` is checked at compile time.
///
/// The dot products `u_x·u_y` occur in several monomials; their partial
/// derivatives are summed into one weight `w_xy` per pair first, so the
/// vector work is one `w_xy u_y` (and `w_xy u_x`) per pair.
#[inline(always)]
fn monomials<T: Real, const V: usize, const NC: usize, const NQ: usize, const L: usize>(
    cubic: &[[usize; 3]; NC],
    quartic: &[[usize; 4]; NQ],
    terms: &[T; L],
    u: &[Vector3<T>; V],
    grad: &mut [Vector3<T>; V],
) -> T {
    const { assert!(L == 3 * NC + NQ) };
    let dot = |x: usize, y: usize| -> T {
        match (u.get(x), u.get(y)) {
            (Some(ux), Some(uy)) => ux.dot(uy),
            _ => T::zero(),
        }
    };
    // w[x][y], x ≤ y: ∂W/∂(u_x·u_y), `None` for pairs no pattern uses (known
    // at compile time once the pattern loops are unrolled).
    let mut w: [[Option<T>; V]; V] = [[None; V]; V];
    let mut weigh = |x: usize, y: usize, by: T| {
        let (lo, hi) = if x <= y { (x, y) } else { (y, x) };
        if let Some(wxy) = w.get_mut(lo).and_then(|row| row.get_mut(hi)) {
            *wxy = Some(wxy.map_or(by, |sum| sum + by));
        }
    };
    let mut energy = T::zero();
    let Some((cubic_terms, quartic_terms)) = terms.split_at_checked(3 * NC) else {
        return T::zero();
    };
    for (&[a, b, c], cv) in cubic.iter().zip(cubic_terms.chunks_exact(3)) {
        let (&[cx, cy, cz], Some(ua)) = (cv, u.get(a)) else {
            continue;
        };
        let cv = Vector3::new(cx, cy, cz);
        // (u_a·c)(u_b·u_c)
        let s = ua.dot(&cv);
        let q = dot(b, c);
        energy += s * q;
        if let Some(ga) = grad.get_mut(a) {
            *ga += cv * q;
        }
        weigh(b, c, s);
    }
    for (&[a, b, c, d], &coefficient) in quartic.iter().zip(quartic_terms) {
        // d (u_a·u_b)(u_c·u_d)
        let (p, q) = (dot(a, b), dot(c, d));
        energy += coefficient * p * q;
        weigh(a, b, coefficient * q);
        weigh(c, d, coefficient * p);
    }
    // ∂(w (u_x·u_y)) = w u_y on x and w u_x on y (2 w u_x when x = y).
    for (x, row) in w.iter().enumerate() {
        for (y, &wxy) in row.iter().enumerate().skip(x) {
            let (Some(wxy), Some(&ux), Some(&uy)) = (wxy, u.get(x), u.get(y)) else {
                continue;
            };
            if let Some(gx) = grad.get_mut(x) {
                *gx += uy * wxy;
            }
            if let Some(gy) = grad.get_mut(y) {
                *gy += ux * wxy;
            }
        }
    }
    energy
}

#[cfg(test)]
#[allow(
    clippy::indexing_slicing,
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic
)]
mod tests {
    use super::*;

    /// Every ordered tuple lands in exactly one pattern of one primitive:
    /// with `C ≡ 1`-like counting functions the coefficients sum to 64 cubic
    /// and 256 quartic tuples.
    #[test]
    fn patterns_cover_every_tuple_once() {
        let counting = Coefficients {
            c: |_: usize, _: usize, _: usize| Vector3::new(1.0f64, 0.0, 0.0),
            d: |_: usize, _: usize, _: usize, _: usize| 1.0f64,
        };
        let mut cubic = 0.0;
        let mut quartic = 0.0;
        let mut count = |terms: &[f64], nc: usize| {
            for (i, x) in terms.iter().enumerate() {
                if i < 3 * nc {
                    cubic += x;
                } else {
                    quartic += x;
                }
            }
        };
        let mut v = [0.0; VERTEX_TERMS_LEN];
        let mut e = [0.0; EDGE_TERMS_LEN];
        let mut t = [0.0; TRIANGLE_TERMS_LEN];
        let mut k = [0.0; TET_TERMS_LEN];
        counting.expand(&VERTEX_CUBIC, &VERTEX_QUARTIC, &[0], &mut v);
        counting.expand(&EDGE_CUBIC, &EDGE_QUARTIC, &[0, 1], &mut e);
        counting.expand(&TRIANGLE_CUBIC, &TRIANGLE_QUARTIC, &[0, 1, 2], &mut t);
        counting.expand(&TET_CUBIC, &TET_QUARTIC, &[0, 1, 2, 3], &mut k);
        for _ in 0..4 {
            count(&v, VERTEX_CUBIC.len());
            count(&t, TRIANGLE_CUBIC.len());
        }
        for _ in 0..6 {
            count(&e, EDGE_CUBIC.len());
        }
        count(&k, 0);
        assert_eq!((cubic, quartic), (64.0, 256.0));
    }
}
