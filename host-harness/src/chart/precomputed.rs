//! The pre-computed models' static runs: the linear model's compliance
//! product and its quasi-non-linear remap.

use anyhow::Context;
use faer::Mat;
use nalgebra::Vector3;
use palpate_kernel::precomputed::QuasiNonLinear;

use super::body::Body;
use super::measure::{Outcome, median_s};
use crate::fem::assembly::assemble_restricted;
use crate::fem::llt::SparseLlt;

/// The pre-computed model under the nodal `loads`: the compliance columns
/// `C` of the loaded DOFs (one sparse Cholesky factorization, one solve per
/// column; the columns the pre-computed table stores), the step `u = C f`
/// over the free vertices, and with `quasi` the remap of each vertex's
/// displacement ([`remap_rows`]). Timed in f64 and f32.
pub(super) fn precomputed(
    body: &Body,
    loads: &[[f64; 3]],
    quasi: Option<&(QuasiNonLinear<f64>, QuasiNonLinear<f32>)>,
) -> anyhow::Result<Outcome> {
    let n = body.mesh.positions.len();
    let mut slot = vec![None; n];
    let mut free = Vec::new();
    for (v, s) in slot.iter_mut().enumerate() {
        if !body.fixed[v] {
            *s = Some(free.len() as u32);
            free.push(v);
        }
    }
    let loaded: Vec<usize> = (0..n)
        .filter(|&v| loads[v].iter().any(|&x| x != 0.0))
        .collect();
    let k = assemble_restricted(
        &body.mesh.positions,
        &body.mesh.tets,
        &body.materials(),
        &slot,
        free.len(),
    );
    let llt = SparseLlt::new(k.as_ref()).context("stiffness of the free vertices")?;
    let rows = 3 * free.len();
    let mut columns = Mat::<f64>::zeros(rows, 3 * loaded.len());
    let mut weights = Vec::with_capacity(3 * loaded.len());
    for (j, &v) in loaded.iter().enumerate() {
        let s = slot[v].context("a loaded vertex is fixed")? as usize;
        for c in 0..3 {
            columns[(3 * s + c, 3 * j + c)] = 1.0;
            weights.push(loads[v][c]);
        }
    }
    llt.solve_in_place(columns.as_mut());
    // Column-major dense compliance, the kernel's layout of a column walk.
    let c64: Vec<f64> = (0..weights.len())
        .flat_map(|j| (0..rows).map(move |i| (i, j)))
        .map(|(i, j)| columns[(i, j)])
        .collect();
    let c32: Vec<f32> = c64.iter().map(|&x| x as f32).collect();
    let w32: Vec<f32> = weights.iter().map(|&x| x as f32).collect();
    let mut out64 = vec![0.0f64; rows];
    let mut out32 = vec![0.0f32; rows];
    let direction = quasi.and_then(|_| {
        let total: Vector3<f64> = loads.iter().map(|f| Vector3::from(*f)).sum();
        QuasiNonLinear::direction(&total)
    });
    let total = direction.map_or(0.0, |d| {
        loads.iter().map(|f| Vector3::from(*f).dot(&d)).sum::<f64>()
    });
    let direction32 = direction.map(|d| d.map(|x| x as f32));
    let step_s = median_s(|| {
        compliance_product(&c64, &weights, &mut out64);
        if let (Some((q, _)), Some(d)) = (quasi, &direction) {
            remap_rows(q, d, 1.0, &mut out64);
        }
        core::hint::black_box(&out64);
    });
    let step_f32_s = median_s(|| {
        compliance_product(&c32, &w32, &mut out32);
        if let (Some((_, q)), Some(d)) = (quasi, &direction32) {
            remap_rows(q, d, 1.0, &mut out32);
        }
        core::hint::black_box(&out32);
    });
    compliance_product(&c64, &weights, &mut out64);
    if let (Some((q, _)), Some(d)) = (quasi, &direction) {
        remap_rows(q, d, axial_scale(q, total), &mut out64);
    }
    let mut u = vec![[0.0; 3]; n];
    for (s, &v) in free.iter().enumerate() {
        u[v] = [out64[3 * s], out64[3 * s + 1], out64[3 * s + 2]];
    }
    Ok(Outcome {
        u,
        fault: None,
        step_s,
        step_f32_s: Some(step_f32_s),
        steps: 1,
    })
}

/// `out = Σ_j w_j C_j` over the columns `C_j` of the column-major `c`.
fn compliance_product<T: palpate_kernel::Real>(c: &[T], w: &[T], out: &mut [T]) {
    out.fill(T::zero());
    for (column, &wj) in c.chunks_exact(out.len()).zip(w) {
        for (o, &cij) in out.iter_mut().zip(column) {
            *o += cij * wj;
        }
    }
}

/// Each vertex's displacement of `rows` (xyz triples) scaled by `scale`,
/// then its part orthogonal to `direction` remapped by φ
/// ([`QuasiNonLinear::displacement`]).
fn remap_rows<T: palpate_kernel::Real>(
    quasi: &QuasiNonLinear<T>,
    direction: &Vector3<T>,
    scale: T,
    rows: &mut [T],
) {
    for r in rows.chunks_exact_mut(3) {
        let u = Vector3::new(r[0], r[1], r[2]) * scale;
        let q = quasi.displacement(direction, u);
        r.copy_from_slice(q.as_slice());
    }
}

/// The quasi-non-linear model under a dead load of total colinear force
/// `force_n`: the compression the remapped force law `ψ` needs to carry
/// it, over the linear one (`ψ⁻¹(F)/F`, by bisection on the monotone ψ);
/// 1 for no force.
fn axial_scale(quasi: &QuasiNonLinear<f64>, force_n: f64) -> f64 {
    if force_n == 0.0 {
        return 1.0;
    }
    let target = force_n.abs();
    let (mut lo, mut hi) = (0.0, target);
    for _ in 0..64 {
        if quasi.force.apply(hi) >= target {
            break;
        }
        (lo, hi) = (hi, 2.0 * hi);
    }
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if quasi.force.apply(mid) < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi / target
}
