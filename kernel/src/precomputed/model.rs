//! The multi-contact solve and the displacement update.

use core::fmt;

use nalgebra::Vector3;

use super::constraint::{AsConstraint, ContactError, ContactPoint, ResolvedPoint, resolve};
use super::remap::QuasiNonLinear;
use crate::math::ldlt::ContactMatrix;
use crate::math::{Dispatch, Portable};
use crate::table::format::surface_block_index;
use crate::table::{ComplianceBlocks, PrecomputedTable};
use crate::{MAX_CONTACT_CAPACITY, Real};

/// The pre-computed model over a validated table (RR-3510 §4, MODELS.md §2).
/// Holds no mutable state: every query is a pure function of the table and
/// the contact set, so it is trivially deterministic and re-entrant.
/// Optionally quasi-non-linear ([`Self::with_remap`], Cotin 1999 TVCG §3).
#[derive(Clone, Copy, Debug)]
pub struct PrecomputedModel<'a, T: Real> {
    table: PrecomputedTable<'a, T>,
    remap: Option<QuasiNonLinear<T>>,
}

/// Contact forces for one contact set: the output of the haptic path, and the
/// input of [`PrecomputedModel::displacements`]. Size on the stack:
/// `M · (3·4 + 3·size_of::<T>() + 3·size_of::<T>()) + …` bytes, see
/// `size_of::<ContactSolution<f32, 4>>()` in the README.
///
/// Only the first `len` entries of each array belong to the solution (a
/// solve writes those, not the rest): equality compares those.
#[derive(Clone, Copy, Debug)]
pub struct ContactSolution<T: Real, const M: usize> {
    points: [ResolvedPoint<T>; M],
    /// The remapped forces of a quasi-non-linear model (when `forces` is
    /// [`ToolForces::Remapped`]).
    remapped_forces_n: [Vector3<T>; M],
    /// The linear `g`, which the displacement update superposes.
    linear_forces_n: [Vector3<T>; M],
    /// Which of the two are the forces on the tool's side.
    forces: ToolForces<T>,
    len: usize,
}

/// Which forces of a [`ContactSolution`] are on the tool's side.
#[derive(Clone, Copy, Debug, PartialEq)]
enum ToolForces<T> {
    /// The linear `g` (the linear model: no copy of them).
    Linear,
    /// The remapped ones (the quasi-non-linear model), with `d̂` of its
    /// field: the direction of the contact with the largest imposed
    /// displacement (`None`: no contact displaced).
    Remapped { direction: Option<Vector3<T>> },
}

impl<T: Real, const M: usize> PartialEq for ContactSolution<T, M> {
    fn eq(&self, other: &Self) -> bool {
        self.len == other.len
            && self.forces == other.forces
            && self.points.get(..self.len) == other.points.get(..other.len)
            && self.linear_forces_n.get(..self.len) == other.linear_forces_n.get(..other.len)
            && self.contact_forces_n() == other.contact_forces_n()
    }
}

impl<T: Real, const M: usize> ContactSolution<T, M> {
    /// No contact.
    pub(crate) fn empty() -> Self {
        Self {
            points: [ResolvedPoint::empty(); M],
            remapped_forces_n: [Vector3::zeros(); M],
            linear_forces_n: [Vector3::zeros(); M],
            forces: ToolForces::Linear,
            len: 0,
        }
    }

    /// Number of contacts solved.
    pub fn len(&self) -> usize {
        self.len
    }

    /// `true` for an empty contact set (zero force).
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// `g_p`: the force the tool applies to the tissue at each contact, N, in
    /// the order the contacts were given (with its colinear amplitude
    /// remapped by `ψ` when the model is quasi-non-linear).
    pub fn contact_forces_n(&self) -> &[Vector3<T>] {
        let forces = match self.forces {
            ToolForces::Linear => &self.linear_forces_n,
            ToolForces::Remapped { .. } => &self.remapped_forces_n,
        };
        forces.get(..self.len).unwrap_or(&[])
    }

    /// `-Σ g_p`: the force the tissue applies to the tool, what the haptic
    /// device renders, N. Without contact it is `+0` in every component
    /// (subtracting from zero, not negating a sum, so no `-0` reaches the device).
    pub fn device_force_n(&self) -> Vector3<T> {
        self.contact_forces_n()
            .iter()
            .fold(Vector3::zeros(), |acc, g| acc - g)
    }

    /// The contact points with their linear forces.
    pub(crate) fn resolved(&self) -> impl Iterator<Item = (&ResolvedPoint<T>, &Vector3<T>)> {
        self.points
            .iter()
            .zip(self.linear_forces_n.iter())
            .take(self.len)
    }
}

/// The output buffer of [`PrecomputedModel::displacements`] has the wrong length.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DisplacementError {
    /// Vertices of the table.
    pub expected: usize,
    /// Length of the buffer given.
    pub found: usize,
}

impl fmt::Display for DisplacementError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "displacement buffer holds {} vertices, the table has {}",
            self.found, self.expected
        )
    }
}

impl core::error::Error for DisplacementError {}

impl<'a, T: Real> PrecomputedModel<'a, T> {
    /// A model over a table validated by [`PrecomputedTable::load`].
    pub fn new(table: PrecomputedTable<'a, T>) -> Self {
        Self { table, remap: None }
    }

    /// The quasi-non-linear model (Cotin 1999 TVCG §3, [`QuasiNonLinear`]):
    /// contact forces and displacements are the linear ones with their
    /// amplitudes remapped.
    pub fn with_remap(self, remap: QuasiNonLinear<T>) -> Self {
        Self {
            remap: Some(remap),
            ..self
        }
    }

    /// The remap, `None` for the linear model.
    pub fn remap(&self) -> Option<&QuasiNonLinear<T>> {
        self.remap.as_ref()
    }

    /// The table this model reads.
    pub fn table(&self) -> &PrecomputedTable<'a, T> {
        &self.table
    }

    /// Contact forces for `contacts` (MODELS.md §2): builds the point
    /// compliances `C_pq = Σ_a Σ_b β^p_a β^q_b C_{v^p_a v^q_b}` and solves
    /// `Σ_q C_pq g_q = d_p` by a dense LDLᵀ on the stack. The haptic path.
    ///
    /// Bounded: at most `M` contacts × 3 vertices each, `(3M)³/6`
    /// multiply-adds. An empty set gives zero force. Errors: see
    /// [`ContactError`]; no force is returned unless every check passed and
    /// every force is finite.
    pub fn contact_forces<const M: usize>(
        &self,
        contacts: &[impl AsConstraint<T>],
    ) -> Result<ContactSolution<T, M>, ContactError> {
        const {
            assert!(
                M >= 1 && M <= MAX_CONTACT_CAPACITY,
                "contact capacity M must be in 1..=MAX_CONTACT_CAPACITY"
            )
        };
        let mut solution = ContactSolution::empty();
        self.solve_into(contacts, &mut SolveBuffers::new(), &mut solution)?;
        Ok(solution)
    }

    /// [`Self::contact_forces`] into `solution`, with the working memory
    /// `buffers` (the haptic path's: no copy of the solution or the
    /// matrices): the point compliances of points `buffers` remembers are
    /// taken from it instead of the table, and any set that is not
    /// remembered points in their order leaves its own there, so that a
    /// re-solve after a release in the same tick, or the same contacts at
    /// the next tick (before or after their releases: a re-solve keeps the
    /// larger set remembered), reads no compliance block again. The same
    /// result. On `Err`, `solution` holds no solution. `M` is checked by
    /// the callers (`1..=MAX_CONTACT_CAPACITY`).
    pub(crate) fn solve_into<const M: usize>(
        &self,
        contacts: &[impl AsConstraint<T>],
        buffers: &mut SolveBuffers<T, M>,
        solution: &mut ContactSolution<T, M>,
    ) -> Result<(), ContactError> {
        let m = contacts.len();
        if m > M {
            return Err(ContactError::TooManyContacts {
                given: m,
                capacity: M,
            });
        }
        // Entries past `m` are not the solution's (no copy of the rest).
        solution.len = m;
        solution.forces = ToolForces::Linear;
        self.resolve_all(contacts, solution)?;
        if m == 0 {
            return Ok(());
        }
        self.factor_and_solve(buffers, solution, m)?;
        if let Some(remap) = &self.remap {
            remap_forces(remap, contacts, solution, m);
        }
        if !solution
            .contact_forces_n()
            .iter()
            .all(|g| g.iter().all(|x| x.finite()))
        {
            return Err(ContactError::NonFiniteResult);
        }
        Ok(())
    }

    /// The first stage of [`Self::solve_into`]: each contact's resolved
    /// point and imposed displacement `d_p` (into the linear forces, which
    /// the solve overwrites with `g`), and no two vertex contacts on one
    /// vertex.
    #[inline(always)]
    fn resolve_all<const M: usize>(
        &self,
        contacts: &[impl AsConstraint<T>],
        solution: &mut ContactSolution<T, M>,
    ) -> Result<(), ContactError> {
        for (p, ((contact, point), d)) in contacts
            .iter()
            .zip(solution.points.iter_mut())
            .zip(solution.linear_forces_n.iter_mut())
            .enumerate()
        {
            *point = resolve(&self.table, p, contact)?;
            *d = contact.displacement_m();
        }
        check_duplicates(contacts)
    }

    /// The second stage of [`Self::solve_into`] for `m ≥ 1` contacts: the
    /// point-compliance matrix assembled over the last solve's factor
    /// ([`Self::assemble`]), factorized and solved for the linear forces
    /// `g` in place of `d`, with `buffers` updated ([`SolveBuffers`]).
    #[inline(always)]
    fn factor_and_solve<const M: usize>(
        &self,
        buffers: &mut SolveBuffers<T, M>,
        solution: &mut ContactSolution<T, M>,
        m: usize,
    ) -> Result<(), ContactError> {
        // The lower blocks of the point-compliance matrix, and its scale,
        // into the buffer the last solve's factor used.
        // Where the remembered points hold this set's; the entries past
        // `m` are looked up too and never read (at most `M × M` point
        // comparisons: restricting the map to `m` measured 128 cycles more
        // at the 4 probes' arrival on the Cortex-M4F).
        let remembered = solution.points.map(|point| buffers.position(&point));
        let SolveBuffers {
            matrices,
            points,
            len,
            second_current,
        } = buffers;
        let [first, second] = matrices;
        // `last`: the remembered compliances; `matrix` this set's.
        let (last, matrix) = if *second_current {
            (second, first)
        } else {
            (first, second)
        };
        // Every point remembered, in the last set's order (a re-solve after
        // a release, tools at rest): the remembered matrix stays as it is,
        // for the solves after this one.
        let mut previous = None;
        let subset = remembered.iter().take(m).all(|&at| {
            let increasing = at.is_some_and(|i| previous.is_none_or(|p| i > p));
            previous = at;
            increasing
        });
        let scale = self.assemble(&solution.points, &remembered, last, matrix, m);
        let min_pivot = T::MIN_PIVOT_RATIO * scale;
        if scale <= T::zero() || !scale.finite() {
            return Err(ContactError::IllConditioned { contact: 0 });
        }
        let factored = if subset {
            // Factorized in place: `last` stays the remembered matrix.
            matrix.solve(None, &mut solution.linear_forces_n, m, min_pivot)
        } else {
            // This set's compliances become the remembered ones, its
            // factor goes where the last set's were.
            for (remembered, point) in points.iter_mut().zip(&solution.points).take(m) {
                *remembered = *point;
            }
            *len = m;
            *second_current = !*second_current;
            last.solve(Some(matrix), &mut solution.linear_forces_n, m, min_pivot)
        };
        factored.map_err(|contact| ContactError::IllConditioned { contact })
    }

    /// The lower blocks of the point-compliance matrix of the first `m`
    /// `points` into `matrix`, each block copied from `last` where both its
    /// points are `remembered` there in order (`copy_block`), else computed
    /// from the table ([`Self::point_compliance`]); returns its scale, the
    /// largest diagonal entry, m/N.
    #[inline(always)]
    fn assemble<const M: usize>(
        &self,
        points: &[ResolvedPoint<T>; M],
        remembered: &[Option<usize>; M],
        last: &ContactMatrix<T, M>,
        matrix: &mut ContactMatrix<T, M>,
        m: usize,
    ) -> T {
        let mut scale = T::zero();
        for (q, pq) in points.iter().enumerate().take(m) {
            for (p, pp) in points.iter().enumerate().take(q + 1) {
                let copied = match (remembered.get(q), remembered.get(p)) {
                    (Some(&Some(i)), Some(&Some(j))) if i >= j => {
                        matrix.copy_block(q, p, last, i, j)
                    }
                    _ => false,
                };
                if !copied {
                    matrix.set_block(q, p, &self.point_compliance(pq, pp, p == q));
                }
                if p == q {
                    scale = matrix.diagonal(q).iter().fold(scale, |s, &c| s.larger(c));
                }
            }
        }
        scale
    }

    /// `C_qp = Σ_a Σ_b β^q_a β^p_b C_{v^q_a v^p_b}` (3×3 row-major, m/N):
    /// each stored block (`C_lo,hi`) read once and added, or its transpose,
    /// to one sum (nine scalars the firmware target keeps in registers);
    /// for `q = p` (`same`) the pair `a ≠ b` is one read of the stored block
    /// for both its terms, `β_a β_b (C_ab + C_abᵀ)`, so at most six reads
    /// instead of nine.
    #[inline(always)]
    fn point_compliance(
        &self,
        q: &ResolvedPoint<T>,
        p: &ResolvedPoint<T>,
        same: bool,
    ) -> [[T; 3]; 3] {
        // The part's kind chosen once, not per block: a dense part's blocks
        // are read in place.
        match self.table.surface_blocks() {
            ComplianceBlocks::Dense(blocks) => {
                self.weighted_blocks(q, p, same, |j, _| blocks.get(j).copied())
            }
            coded => self.weighted_blocks(q, p, same, |j, column| coded.block(j, column)),
        }
    }

    /// [`Self::point_compliance`] with the surface part's blocks read by
    /// `block(index, column)`.
    #[inline(always)]
    fn weighted_blocks(
        &self,
        q: &ResolvedPoint<T>,
        p: &ResolvedPoint<T>,
        same: bool,
        block: impl Fn(usize, usize) -> Option<[T; 9]>,
    ) -> [[T; 3]; 3] {
        let mut sum = [[T::zero(); 3]; 3];
        // All three terms, those past `len` too: their weight is zero, so
        // they add zero (a trip count that does not depend on `len`).
        for (i, (&a, &beta_a)) in q.touchable.iter().zip(&q.weights).enumerate() {
            let first = if same { i } else { 0 };
            for (j, (&b, &beta_b)) in p.touchable.iter().zip(&p.weights).enumerate() {
                if j < first {
                    continue;
                }
                let (index, column, transposed) = PrecomputedTable::<T>::stored_block_index(a, b);
                let Some(block) = block(index, column) else {
                    continue;
                };
                let both = same && j > i;
                let w = beta_a * beta_b;
                if !transposed || both {
                    add_scaled(&mut sum, w, &block, false);
                }
                if transposed || both {
                    add_scaled(&mut sum, w, &block, true);
                }
            }
        }
        sum
    }

    /// The displacement of every free vertex for a solved contact set, m, by
    /// free index: `out[i]` belongs to vertex
    /// [`PrecomputedTable::free_vertices`]`()[i]` (fixed vertices do not
    /// move and have no entry). MODELS.md §2:
    /// `u_n = Σ_q Σ_b β^q_b C_{n v^q_b} g_q`. Overwrites all of `out`, which
    /// must hold [`PrecomputedTable::free_count`] entries.
    ///
    /// The fast path of the update (a renderer maps free indices to vertices
    /// once): one pass per contact term over one compliance column, written
    /// contiguously. Bounded: ≤ 3·M columns of `F` blocks.
    pub fn free_displacements<const M: usize>(
        &self,
        solution: &ContactSolution<T, M>,
        out: &mut [[T; 3]],
    ) -> Result<(), DisplacementError> {
        self.free_displacements_with(Portable, solution, out)
    }

    /// [`Self::free_displacements`] with its pass over the compliance
    /// columns run through `dispatch`: a host's run-time CPU-feature
    /// dispatch ([`crate::math::dispatch`]). Same results.
    pub fn free_displacements_with<const M: usize>(
        &self,
        dispatch: impl Dispatch,
        solution: &ContactSolution<T, M>,
        out: &mut [[T; 3]],
    ) -> Result<(), DisplacementError> {
        check_length(self.table.free_count(), out)?;
        out.fill([T::zero(); 3]);
        self.add_rows(dispatch, solution, 0, out);
        self.remap_rows(solution, out);
        Ok(())
    }

    /// The displacement of every vertex for a solved contact set, m, in mesh
    /// vertex order (fixed vertices get zero): [`Self::free_displacements`]
    /// scattered to vertex order, through a 64-vertex buffer on the stack.
    /// Overwrites all of `out`, which must hold
    /// [`PrecomputedTable::vertex_count`] entries. Not needed by the haptic
    /// path.
    pub fn displacements<const M: usize>(
        &self,
        solution: &ContactSolution<T, M>,
        out: &mut [[T; 3]],
    ) -> Result<(), DisplacementError> {
        self.displacements_with(Portable, solution, out)
    }

    /// [`Self::displacements`] with its passes over the compliance columns
    /// run through `dispatch` (see [`Self::free_displacements_with`]).
    pub fn displacements_with<const M: usize>(
        &self,
        dispatch: impl Dispatch,
        solution: &ContactSolution<T, M>,
        out: &mut [[T; 3]],
    ) -> Result<(), DisplacementError> {
        const CHUNK: usize = 64;
        check_length(self.table.vertex_count(), out)?;
        // Fixed vertices stay zero; a memset is cheaper than picking them out.
        out.fill([T::zero(); 3]);
        for (chunk, vertices) in self.table.free_vertices().chunks(CHUNK).enumerate() {
            let mut buffer = [[T::zero(); 3]; CHUNK];
            let rows = buffer.get_mut(..vertices.len()).unwrap_or(&mut []);
            self.add_rows(dispatch, solution, chunk * CHUNK, rows);
            self.remap_rows(solution, rows);
            for (u, &v) in rows.iter().zip(vertices) {
                if let Some(o) = out.get_mut(v as usize) {
                    *o = *u;
                }
            }
        }
        Ok(())
    }

    /// The quasi-non-linear model's displacement remap of `rows` (m), in
    /// place; nothing for the linear model or a set without direction.
    fn remap_rows<const M: usize>(&self, solution: &ContactSolution<T, M>, rows: &mut [[T; 3]]) {
        let direction = match &solution.forces {
            ToolForces::Remapped { direction } => direction.as_ref(),
            ToolForces::Linear => None,
        };
        if let (Some(remap), Some(direction)) = (&self.remap, direction) {
            for u in rows {
                *u = remap.displacement(direction, Vector3::from(*u)).into();
            }
        }
    }

    /// `out[i] += Σ_terms C_{first+i, k} w` over the contact terms: free rows
    /// `first .. first + out.len()`, run through `dispatch`.
    fn add_rows<const M: usize>(
        &self,
        dispatch: impl Dispatch,
        solution: &ContactSolution<T, M>,
        first: usize,
        out: &mut [[T; 3]],
    ) {
        dispatch.run(
            #[inline(always)]
            || {
                for (point, g) in solution.resolved() {
                    for (k, beta) in point.terms() {
                        self.add_column_rows(k.get(), &(g * beta), first, out);
                    }
                }
            },
        );
    }

    /// `out[i] += C_{n,k} w` for the free rows `n = first + i` (format in
    /// [`crate::table::format`]): rows `n ≤ k` from column `k` of the packed
    /// surface part, rows `k < n < S` as `C_knᵀ` from column `n`, interior
    /// rows from column `k` of the interior part. Rows outside `0..F` are
    /// skipped. A compressed part is decoded on the fly (a dropped block adds
    /// nothing); the work is the same `F` blocks per column either way.
    /// Always inlined (one caller), so that a [`Dispatch`] compiles it where
    /// it runs.
    #[inline(always)]
    fn add_column_rows(&self, k: usize, w: &Vector3<T>, first: usize, out: &mut [[T; 3]]) {
        let s = self.table.touchable_count();
        let f = self.table.free_count();
        let end = (first + out.len()).min(f);
        let surface = self.table.surface_blocks();
        // Which rows of `first..end` fall in `lo..hi`, and where they go in `out`.
        let window = |lo: usize, hi: usize| {
            let (a, b) = (first.max(lo), end.min(hi));
            (a < b).then(|| (a, a - first..b - first))
        };
        // The rows of the two parts' columns (`n ≤ k` from the packed
        // surface column, `n ≥ S` from the interior column) through one call
        // site, so that inlining it for a [`Dispatch`] does not copy it;
        // the windows are disjoint, so the order adds nothing different.
        let columns = [
            window(0, k + 1).map(|(a, rows)| (surface, surface_block_index(a, k), rows)),
            window(s, f)
                .map(|(a, rows)| (self.table.interior_blocks(), k * (f - s) + (a - s), rows)),
        ];
        for (part, start, rows) in columns.into_iter().flatten() {
            if let Some(out) = out.get_mut(rows) {
                part.add_products(start, k, w, out);
            }
        }
        if let Some((a, rows)) = window(k + 1, s)
            && let Some(out) = out.get_mut(rows)
        {
            surface.add_transposed_products(k, a, w, out);
        }
    }
}

/// `Err` unless `out` holds `expected` entries.
fn check_length<E>(expected: usize, out: &[E]) -> Result<(), DisplacementError> {
    if out.len() == expected {
        Ok(())
    } else {
        Err(DisplacementError {
            expected,
            found: out.len(),
        })
    }
}

/// `sum += w B` for the row-major 3×3 `block` `B`, or `w Bᵀ`.
#[inline(always)]
fn add_scaled<T: Real>(sum: &mut [[T; 3]; 3], w: T, block: &[T; 9], transposed: bool) {
    for (r, row) in sum.iter_mut().enumerate() {
        for (c, s) in row.iter_mut().enumerate() {
            let k = if transposed { 3 * c + r } else { 3 * r + c };
            if let Some(&x) = block.get(k) {
                *s += w * x;
            }
        }
    }
}

/// The working memory of a contact solve (MODELS.md §2): two contact
/// matrices, one holding the remembered point compliances (of the last
/// set that was not remembered points in their order) with their points,
/// the other the last LDLᵀ factor. The next solve assembles its matrix
/// over that factor, copying the blocks of remembered points; a set of
/// remembered points only, in their order (a release, tools at rest), is
/// factorized there in place and the remembered ones stay; any other set's
/// factor goes over the remembered matrix, and its own matrix becomes the
/// remembered one ([`PrecomputedModel::solve_into`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct SolveBuffers<T: Real, const M: usize> {
    matrices: [ContactMatrix<T, M>; 2],
    /// The remembered points, `len` of them, whose compliances the second
    /// matrix holds if `second_current`, else the first.
    points: [ResolvedPoint<T>; M],
    len: usize,
    second_current: bool,
}

impl<T: Real, const M: usize> SolveBuffers<T, M> {
    /// Remembering no point.
    pub(crate) fn new() -> Self {
        Self {
            matrices: [ContactMatrix::zeros(); 2],
            points: [ResolvedPoint::empty(); M],
            len: 0,
            second_current: false,
        }
    }

    /// Forgets every point.
    pub(crate) fn clear(&mut self) {
        self.len = 0;
    }

    /// Where `point` is among the remembered points.
    fn position(&self, point: &ResolvedPoint<T>) -> Option<usize> {
        self.points.iter().take(self.len).position(|p| p == point)
    }
}

/// The last stage of [`PrecomputedModel::solve_into`] for a
/// quasi-non-linear model: each of the first `m` linear forces remapped
/// along its contact's imposed displacement (`remap.force`), and the
/// direction of the largest displacement kept for the field.
#[inline(always)]
fn remap_forces<T: Real, const M: usize>(
    remap: &QuasiNonLinear<T>,
    contacts: &[impl AsConstraint<T>],
    solution: &mut ContactSolution<T, M>,
    m: usize,
) {
    let mut largest = T::zero();
    let mut largest_direction = None;
    let forces = solution
        .remapped_forces_n
        .iter_mut()
        .zip(&solution.linear_forces_n);
    for ((g, linear), contact) in forces.zip(contacts).take(m) {
        let d = contact.displacement_m();
        *g = *linear;
        if let Some(direction) = QuasiNonLinear::direction(&d) {
            *g = remap.force(&direction, *g);
            // `direction` is `d / |d|`, so `d·direction` is `|d|`.
            let length = d.dot(&direction);
            if length > largest {
                largest = length;
                largest_direction = Some(direction);
            }
        }
    }
    solution.forces = ToolForces::Remapped {
        direction: largest_direction,
    };
}

/// Two vertex contacts on one vertex make the system exactly singular; name them.
fn check_duplicates<T: Real>(contacts: &[impl AsConstraint<T>]) -> Result<(), ContactError> {
    use ContactPoint::Vertex;
    for (second, b) in contacts.iter().enumerate() {
        for (first, a) in contacts.iter().enumerate().take(second) {
            if let (Vertex(va), Vertex(vb)) = (a.point(), b.point())
                && va == vb
            {
                return Err(ContactError::DuplicateContact { first, second });
            }
        }
    }
    Ok(())
}
