//! The error of a hierarchical table, measured at build time against the
//! exact compliance columns (the dense table is never formed): for each
//! probe contact set ([`super::super::compress::probe_set_at`]) the columns
//! of its vertices are solved again from the kept factorization, the
//! reference solved in `f64` — forces `g = C_pp⁻¹ d` (`C_pp` the `3m × 3m`
//! compliance among its `m` vertices, MODELS.md §2), displacements
//! `u_n = Σ_q C_nq g_q` — and the kernel's answer on the table compared:
//! - force: `max_p |g_p − g'_p| / max_p |g'_p|`;
//! - touchable displacement: `max_{n<S} |u_n − u'_n| / max_n |u'_n|`, the
//!   scale over every free vertex.
//!
//! The table stores no interior rows, so its displacement error over
//! every free vertex would be that of leaving them out; the record's
//! `max_displacement_error` is the touchable one.
//!
//! Probe set: every touchable vertex when `S ≤`
//! [`PROBE_SAMPLE_COUNT`] ([`PROBE_SET_EVERY_TOUCHABLE`]), else the
//! sample [`PROBE_SET_SAMPLED`]: `9` solves per probed vertex at most.

use nalgebra::{DMatrix, DVector, Vector3};
use palpate_kernel::table::format::{
    PROBE_SAMPLE_COUNT, PROBE_SET_EVERY_TOUCHABLE, PROBE_SET_SAMPLED,
};
use palpate_kernel::{AsConstraint, ContactPoint, MAX_CONTACTS, PrecomputedModel};

use super::super::compress::{Measured, probe_set_at};
use super::columns::ColumnSolver;

/// Probed touchable vertices per batch of solves (up to 3 vertices each).
const PROBES_PER_BATCH: usize = 16;

/// The probe set's identifier and touchable indices for `s` touchable
/// vertices (module docs).
pub fn probe_indices(s: usize) -> (u32, Vec<usize>) {
    if s <= PROBE_SAMPLE_COUNT {
        (PROBE_SET_EVERY_TOUCHABLE, (0..s).collect())
    } else {
        let p = PROBE_SAMPLE_COUNT;
        (PROBE_SET_SAMPLED, (0..p).map(|i| i * s / p).collect())
    }
}

/// Measures `model` (a hierarchical table) against the exact columns of
/// `solver` (the same mesh, material and ordering; `slot` the mesh vertex →
/// free index map) over the probe set of `at` (module docs). A set the
/// model refuses counts as an error of 1.
pub fn measure(
    model: &PrecomputedModel<'_, f32>,
    solver: &ColumnSolver,
    slot: &[Option<u32>],
    at: &[usize],
) -> Measured {
    let table = model.table();
    let (free, s) = (table.free_count(), table.touchable_count());
    let mut out = Measured::default();
    let mut u = vec![[0.0f32; 3]; free];
    for chunk in at.chunks(PROBES_PER_BATCH) {
        let sets = probe_set_at(table, chunk.iter().copied());
        let mut vertices: Vec<usize> = sets
            .iter()
            .flatten()
            .filter_map(|c| free_index(c, slot))
            .collect();
        vertices.sort_unstable();
        vertices.dedup();
        let x = solver.columns(&vertices);
        let column = |k: usize| vertices.binary_search(&k).ok();
        for set in &sets {
            let Some(reference) = reference(set, slot, &x, column) else {
                continue;
            };
            out.probes += 1;
            let got = match model.contact_forces::<MAX_CONTACTS>(set) {
                Ok(got) if model.free_displacements(&got, &mut u).is_ok() => got,
                _ => {
                    out.refused += 1;
                    out.max_force_error = out.max_force_error.max(1.0);
                    out.max_surface_displacement_error =
                        out.max_surface_displacement_error.max(1.0);
                    continue;
                }
            };
            let (g, u_ref) = reference;
            let scale = g.iter().map(|v| v.norm()).fold(0.0f64, f64::max);
            let diff = g
                .iter()
                .zip(got.contact_forces_n())
                .map(|(a, b)| (b.cast::<f64>() - a).norm())
                .fold(0.0f64, f64::max);
            if scale > 0.0 {
                out.max_force_error = out.max_force_error.max(diff / scale);
            }
            let scale = u_ref.iter().map(|v| v.norm()).fold(0.0f64, f64::max);
            let diff = u_ref[..s]
                .iter()
                .zip(&u)
                .map(|(a, b)| (Vector3::from(*b).cast::<f64>() - a).norm())
                .fold(0.0f64, f64::max);
            if scale > 0.0 {
                out.max_surface_displacement_error =
                    out.max_surface_displacement_error.max(diff / scale);
            }
        }
    }
    out.max_displacement_error = out.max_surface_displacement_error;
    out
}

/// The free index of a vertex contact.
fn free_index(c: &impl AsConstraint<f32>, slot: &[Option<u32>]) -> Option<usize> {
    match c.point() {
        ContactPoint::Vertex(v) => slot.get(v as usize).copied().flatten().map(|i| i as usize),
        ContactPoint::Triangle { .. } => None,
    }
}

/// A contact set's exact forces (N, per contact) and free displacements (m,
/// per free vertex).
type Reference = (Vec<Vector3<f64>>, Vec<Vector3<f64>>);

/// The exact forces (N, per contact) and free displacements (m, per free
/// vertex) of a set of vertex contacts, from the columns `x` (`3F` rows,
/// column `3·column(k) + b` that of `(k, b)`). `None` if a contact is not
/// at a solved free vertex or `C_pp` is singular.
fn reference(
    set: &[impl AsConstraint<f32>],
    slot: &[Option<u32>],
    x: &faer::Mat<f64>,
    column: impl Fn(usize) -> Option<usize>,
) -> Option<Reference> {
    let m = set.len();
    let at: Vec<(usize, usize)> = set
        .iter()
        .map(|c| free_index(c, slot).and_then(|k| Some((k, column(k)?))))
        .collect::<Option<_>>()?;
    let c_pp = DMatrix::from_fn(3 * m, 3 * m, |i, j| {
        x[(3 * at[i / 3].0 + i % 3, 3 * at[j / 3].1 + j % 3)]
    });
    let d = DVector::from_fn(3 * m, |i, _| f64::from(set[i / 3].displacement_m()[i % 3]));
    let g = c_pp.cholesky()?.solve(&d);
    let forces = (0..m)
        .map(|p| Vector3::new(g[3 * p], g[3 * p + 1], g[3 * p + 2]))
        .collect();
    let u = (0..x.nrows() / 3)
        .map(|n| {
            Vector3::from_fn(|a, _| {
                (0..3 * m)
                    .map(|j| x[(3 * n + a, 3 * at[j / 3].1 + j % 3)] * g[j])
                    .sum()
            })
        })
        .collect();
    Some((forces, u))
}
