//! The static equilibrium of St Venant-Kirchhoff by Newton's method with a
//! direct sparse factorization (faer): the converged reference the
//! speed/accuracy study measures the kernel's models against, independent
//! of the kernel ([`super::stvk`] is its own element).
//!
//! Problem: find `u` with `f_int(u) + f_ext = 0` on the unknown DOFs, the
//! fixed vertices at zero and the prescribed ones at their displacement,
//! under dead loads `f_ext`. The load (and the prescribed displacement) is
//! applied in `load_steps` equal increments; at each, Newton iterations
//! `K_t Δu = f_int + f_ext` (the tangent [`StvkTet::tangent`] assembled on
//! the unknown DOFs and factorized by sparse Cholesky) with a backtracking
//! line search on the residual's norm, until the largest residual force is
//! at most `tolerance` times the load scale (the largest load, or the
//! largest residual at the increment's start when only displacements are
//! prescribed). A tangent that is not positive definite means the
//! equilibrium path has lost stability (buckling, St Venant-Kirchhoff's
//! collapse under compression): an error naming the increment.

use anyhow::{Context, bail, ensure};
use faer::Mat;
use faer::sparse::SparseColMat;
use nalgebra::Vector3;

use super::assembly::assemble_restricted_with;
use super::llt::SparseLlt;
use super::material::TetMaterials;
use super::stvk::StvkTet;

/// Newton controls.
#[derive(Clone, Copy, Debug)]
pub struct NewtonOptions {
    /// Equal load increments (≥ 1).
    pub load_steps: usize,
    /// Newton iterations per increment at most.
    pub max_iterations: usize,
    /// Convergence: largest residual force over the load scale.
    pub tolerance: f64,
    /// Follow the stable equilibria past a limit point or a bifurcation
    /// (buckling) instead of failing there: each increment minimizes the
    /// total potential energy `Π(u) = Σ W_e(u) − s f·u` from the previous
    /// equilibrium by Newton steps on the tangent shifted by `μ d̄ I` (`d̄`
    /// the mean absolute diagonal; `μ` raised ×10 from [`MIN_SHIFT`] until
    /// the factorization succeeds or a step fails to lower `Π`, lowered
    /// ÷10 after each full step, dropped below [`MIN_SHIFT`]): a
    /// Levenberg-Marquardt (trust-region) descent, which cannot stop at a
    /// saddle of `Π`, with the plain Newton step (quadratic convergence)
    /// wherever the tangent is positive definite. The line search accepts
    /// a step that lowers `Π`, or one that lowers the residual while `Π`
    /// changes by less than its rounding ([`ENERGY_ROUNDING`]). The end
    /// state's unshifted tangent must factorize: the equilibrium returned
    /// is stable. `false`: plain Newton, failing where the tangent is not
    /// positive definite.
    pub descent: bool,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        Self {
            load_steps: 1,
            max_iterations: 40,
            tolerance: 1e-10,
            descent: false,
        }
    }
}

/// A static problem on a tet mesh.
pub struct StaticProblem<'a> {
    /// Rest positions, m.
    pub positions: &'a [[f64; 3]],
    /// Tets (positively oriented).
    pub tets: &'a [[u32; 4]],
    /// One material per tet.
    pub materials: &'a TetMaterials,
    /// Fixed vertices (zero displacement).
    pub fixed: &'a [bool],
    /// Prescribed displacements, m (vertices neither fixed nor repeated).
    pub prescribed: &'a [(u32, [f64; 3])],
    /// Dead loads per vertex, N (empty: none).
    pub loads_n: &'a [[f64; 3]],
}

/// A converged equilibrium.
#[derive(Clone, Debug)]
pub struct Equilibrium {
    /// Displacement of every vertex, m.
    pub u: Vec<[f64; 3]>,
    /// Newton iterations over all increments.
    pub iterations: usize,
    /// Largest residual force on an unknown DOF at the end, N.
    pub residual_n: f64,
    /// `false` when an increment ended at rounding level above the
    /// requested tolerance (below 1e-6 of the load scale, where no step
    /// decreased the residual): `residual_n` says how close it got.
    pub tolerance_met: bool,
    /// For each prescribed vertex, in order, the force the constraint
    /// applies to the body, `−f_int − f_ext`, N.
    pub reactions_n: Vec<[f64; 3]>,
}

/// Halvings of the Newton step at most in the line search.
const MAX_HALVINGS: usize = 12;
/// The smallest tangent shift of [`NewtonOptions::descent`], over the mean
/// absolute diagonal.
pub const MIN_SHIFT: f64 = 1e-6;
/// Raises of the shift (×10 each) at most within one iteration: up to
/// `1e14` times [`MIN_SHIFT`], a gradient step.
const MAX_SHIFTS: usize = 20;
/// Energy changes below this fraction of `Σ|W_e| + |f·u|` are rounding.
pub const ENERGY_ROUNDING: f64 = 1e-12;

/// A residual below this fraction of the load scale that no step decreases
/// is rounding (the element forces that cancel at a vertex are each of the
/// load's size): converged. Above it, a stagnating line search is an error.
const STAGNATION: f64 = 1e-6;

/// Solves `problem` (module documentation).
pub fn solve_stvk(
    problem: &StaticProblem<'_>,
    options: &NewtonOptions,
) -> anyhow::Result<Equilibrium> {
    let n = problem.positions.len();
    ensure!(
        problem.fixed.len() == n,
        "fixed has {} flags for {n} vertices",
        problem.fixed.len()
    );
    ensure!(
        problem.loads_n.is_empty() || problem.loads_n.len() == n,
        "loads has {} entries for {n} vertices",
        problem.loads_n.len()
    );
    ensure!(options.load_steps >= 1, "at least one load step");
    problem.materials.check_tet_count(problem.tets.len())?;
    let mut known = problem.fixed.to_vec();
    for &(v, _) in problem.prescribed {
        let vi = v as usize;
        ensure!(
            vi < n && !known[vi],
            "prescribed vertex {v} is out of range, fixed or repeated"
        );
        known[vi] = true;
    }
    let elements: Vec<StvkTet> = problem
        .tets
        .iter()
        .zip(problem.materials.per_tet())
        .map(|(t, m)| StvkTet::new(&t.map(|v| problem.positions[v as usize]), m))
        .collect();
    let mut slot = vec![None; n];
    let mut unknown = Vec::new();
    for v in 0..n {
        if !known[v] {
            slot[v] = Some(unknown.len() as u32);
            unknown.push(v);
        }
    }
    let load = |v: usize| problem.loads_n.get(v).copied().unwrap_or([0.0; 3]);
    let internal = |u: &[[f64; 3]]| -> Vec<Vector3<f64>> {
        let mut f = vec![Vector3::zeros(); n];
        for (t, e) in problem.tets.iter().zip(&elements) {
            let x = t.map(|v| {
                let (p, d) = (problem.positions[v as usize], u[v as usize]);
                [p[0] + d[0], p[1] + d[1], p[2] + d[2]]
            });
            for (v, fv) in t.iter().zip(e.forces_n(&x)) {
                f[*v as usize] += fv;
            }
        }
        f
    };

    let mut u = vec![[0.0; 3]; n];
    let mut iterations = 0;
    let mut residual_n = 0.0;
    let mut tolerance_met = true;
    for step in 1..=options.load_steps {
        let s = step as f64 / options.load_steps as f64;
        for &(v, d) in problem.prescribed {
            u[v as usize] = d.map(|x| s * x);
        }
        let residual = |u: &[[f64; 3]]| -> Vec<Vector3<f64>> {
            let f = internal(u);
            unknown
                .iter()
                .map(|&v| f[v] + Vector3::from(load(v)) * s)
                .collect()
        };
        let norm = |r: &[Vector3<f64>]| r.iter().map(|x| x.norm_squared()).sum::<f64>().sqrt();
        let largest = |r: &[Vector3<f64>]| r.iter().map(|x| x.amax()).fold(0.0, f64::max);
        let mut r = residual(&u);
        let scale = (0..n)
            .map(|v| Vector3::from(load(v)).amax() * s)
            .fold(largest(&r), f64::max);
        let tolerance_n = options.tolerance * scale;
        // Π(u) and the scale of its rounding, Σ|W_e| + |s f·u|, J.
        let energy = |u: &[[f64; 3]]| -> (f64, f64) {
            let elastic: f64 = problem
                .tets
                .iter()
                .zip(&elements)
                .map(|(t, e)| {
                    e.energy_j(&t.map(|v| {
                        let (p, d) = (problem.positions[v as usize], u[v as usize]);
                        [p[0] + d[0], p[1] + d[1], p[2] + d[2]]
                    }))
                })
                .sum();
            let work: f64 = unknown
                .iter()
                .map(|&v| s * Vector3::from(load(v)).dot(&Vector3::from(u[v])))
                .sum();
            (elastic - work, elastic.abs() + work.abs())
        };
        let mut shift = 0.0;
        let mut converged = largest(&r) <= tolerance_n;
        let mut k = 0;
        while !converged {
            ensure!(
                k < options.max_iterations,
                "load step {step}/{}: no convergence in {} Newton iterations (residual {:.3e} N)",
                options.load_steps,
                options.max_iterations,
                largest(&r)
            );
            k += 1;
            let tangent = assemble_restricted_with(n, problem.tets, &slot, unknown.len(), |t| {
                let x = problem.tets[t].map(|v| {
                    let (p, d) = (problem.positions[v as usize], u[v as usize]);
                    [p[0] + d[0], p[1] + d[1], p[2] + d[2]]
                });
                elements[t].tangent(&x)
            });
            let factorized = if options.descent {
                factor_shifted(&tangent, &mut shift)
            } else {
                SparseLlt::new(tangent.as_ref())
            };
            let llt = factorized.with_context(|| {
                format!(
                    "load step {step}/{}: the tangent stiffness is not positive definite \
                     (the equilibrium lost stability: buckling or collapse)",
                    options.load_steps
                )
            })?;
            let mut delta = Mat::<f64>::zeros(3 * unknown.len(), 1);
            for (i, ri) in r.iter().enumerate() {
                for c in 0..3 {
                    delta[(3 * i + c, 0)] = ri[c];
                }
            }
            llt.solve_in_place(delta.as_mut());
            let before = norm(&r);
            let (energy_before, energy_scale) = if options.descent {
                energy(&u)
            } else {
                (0.0, 0.0)
            };
            let mut alpha = 1.0;
            let mut accepted = false;
            for _ in 0..=MAX_HALVINGS {
                let mut trial = u.clone();
                for (i, &v) in unknown.iter().enumerate() {
                    for c in 0..3 {
                        trial[v][c] += alpha * delta[(3 * i + c, 0)];
                    }
                }
                let r_trial = residual(&trial);
                let lower = norm(&r_trial) < before || largest(&r_trial) <= tolerance_n;
                let take = if options.descent {
                    let (e, _) = energy(&trial);
                    e < energy_before
                        || (lower && e <= energy_before + ENERGY_ROUNDING * energy_scale)
                } else {
                    lower
                };
                if take {
                    (u, r) = (trial, r_trial);
                    accepted = true;
                    break;
                }
                alpha *= 0.5;
            }
            if options.descent {
                if accepted && alpha == 1.0 {
                    shift = if shift / 10.0 < MIN_SHIFT {
                        0.0
                    } else {
                        shift / 10.0
                    };
                } else if !accepted && largest(&r) > STAGNATION * scale {
                    // Trust the tangent less: a shorter, steeper step.
                    shift = (10.0 * shift).max(MIN_SHIFT);
                    continue;
                }
            }
            if !accepted && largest(&r) <= STAGNATION * scale {
                // At rounding level: no step can decrease the residual.
                tolerance_met = false;
                break;
            }
            if !accepted {
                bail!(
                    "load step {step}/{}: the line search found no decrease of the residual \
                     ({before:.3e} N)",
                    options.load_steps
                );
            }
            converged = largest(&r) <= tolerance_n;
        }
        iterations += k;
        residual_n = largest(&r);
    }
    if options.descent {
        let tangent = assemble_restricted_with(n, problem.tets, &slot, unknown.len(), |t| {
            let x = problem.tets[t].map(|v| {
                let (p, d) = (problem.positions[v as usize], u[v as usize]);
                [p[0] + d[0], p[1] + d[1], p[2] + d[2]]
            });
            elements[t].tangent(&x)
        });
        SparseLlt::new(tangent.as_ref()).context(
            "the equilibrium reached is not stable (its tangent is not positive definite)",
        )?;
    }
    let f = internal(&u);
    let reactions_n = problem
        .prescribed
        .iter()
        .map(|&(v, _)| (-(f[v as usize] + Vector3::from(load(v as usize)))).into())
        .collect();
    Ok(Equilibrium {
        u,
        iterations,
        residual_n,
        tolerance_met,
        reactions_n,
    })
}

/// Factorizes `k + shift d̄ I` (`d̄` the mean absolute diagonal of `k`),
/// raising `shift` ×10 from [`MIN_SHIFT`] (when 0 and `k` fails) until the
/// factorization succeeds, at most [`MAX_SHIFTS`] times.
fn factor_shifted(k: &SparseColMat<usize, f64>, shift: &mut f64) -> anyhow::Result<SparseLlt> {
    let symbolic = k.symbolic();
    let diagonal: Vec<usize> = (0..k.ncols())
        .filter_map(|j| symbolic.col_range(j).find(|&i| symbolic.row_idx()[i] == j))
        .collect();
    let mean =
        diagonal.iter().map(|&i| k.val()[i].abs()).sum::<f64>() / diagonal.len().max(1) as f64;
    let mut last = None;
    for _ in 0..=MAX_SHIFTS {
        let attempt = if *shift == 0.0 {
            SparseLlt::new(k.as_ref())
        } else {
            let mut shifted = k.clone();
            let values = shifted.val_mut();
            for &i in &diagonal {
                values[i] += *shift * mean;
            }
            SparseLlt::new(shifted.as_ref())
        };
        match attempt {
            Ok(llt) => return Ok(llt),
            Err(e) => last = Some(e),
        }
        *shift = (10.0 * *shift).max(MIN_SHIFT);
    }
    Err(last.unwrap_or_else(|| anyhow::anyhow!("no factorization tried"))).with_context(|| {
        format!("not positive definite with a shift of {shift:e} of its mean diagonal")
    })
}
