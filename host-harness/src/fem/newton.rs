//! The static equilibrium of a hyperelastic body (St Venant-Kirchhoff,
//! [`solve_stvk`]; compressible neo-Hookean, [`solve_neo_hookean`], and on
//! 10-node tets [`solve_neo_hookean_p2`]) by
//! Newton's method with a direct sparse factorization (faer): the converged
//! references the speed/accuracy study measures the kernel's models
//! against, independent of the kernel ([`super::stvk`] and
//! [`super::neo_hookean`] are their own elements).
//!
//! Problem: find `u` with `f_int(u) + f_ext = 0` on the unknown DOFs, the
//! fixed vertices at zero and the prescribed ones at their displacement,
//! under dead loads `f_ext`. The load (and the prescribed displacement) is
//! applied in `load_steps` equal increments; at each, Newton iterations
//! `K_t Δu = f_int + f_ext` (the tangent [`HyperelasticTet::tangent`] assembled on
//! the unknown DOFs and factorized by sparse Cholesky) with a backtracking
//! line search on the residual's norm, until the largest residual force is
//! at most `tolerance` times the load scale (the largest load, or the
//! largest residual at the increment's start when only displacements are
//! prescribed). A tangent that is not positive definite means the
//! equilibrium path has lost stability (buckling, St Venant-Kirchhoff's
//! collapse under compression): an error naming the increment.
//!
//! Inversion: where a law is not defined ([`HyperelasticTet::admissible`]:
//! neo-Hookean's `J ≤ 0`, its energy `+∞`), a line-search trial that
//! inverts a tet is rejected and the step halved, as one that does not
//! lower the merit function; an increment whose prescribed displacements
//! alone invert a tet is an error (more load steps are needed).

use anyhow::{Context, bail, ensure};
use faer::Mat;
use faer::sparse::SparseColMat;
use nalgebra::Vector3;

use super::assembly::assemble_restricted_with;
use super::hyperelastic::HyperelasticTet;
use super::llt::SparseLlt;
use super::material::TetMaterials;
use super::neo_hookean::NeoHookeanTet;
use super::neo_hookean_p2::NeoHookeanP2Tet;
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

/// A static problem on a mesh of `N`-node tets (P1: 4; P2: 10, the nodes
/// of [`super::neo_hookean_p2::P2Mesh`]); "vertex" below is any node.
pub struct StaticProblem<'a, const N: usize = 4> {
    /// Rest positions, m.
    pub positions: &'a [[f64; 3]],
    /// Tets (positively oriented).
    pub tets: &'a [[u32; N]],
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

/// Solves `problem` for St Venant-Kirchhoff ([`solve`]).
pub fn solve_stvk(
    problem: &StaticProblem<'_>,
    options: &NewtonOptions,
) -> anyhow::Result<Equilibrium> {
    solve::<4, StvkTet>(problem, options)
}

/// Solves `problem` for the compressible neo-Hookean law
/// ([`super::neo_hookean`]) with [`NewtonOptions::descent`] always on: the
/// line search is on the total potential energy (`+∞` where a tet inverts,
/// so such a trial is halved) and the equilibrium returned is stable.
pub fn solve_neo_hookean(
    problem: &StaticProblem<'_>,
    options: &NewtonOptions,
) -> anyhow::Result<Equilibrium> {
    let options = NewtonOptions {
        descent: true,
        ..*options
    };
    solve::<4, NeoHookeanTet>(problem, &options)
}

/// [`solve_neo_hookean`] on 10-node tets ([`super::neo_hookean_p2`]); an
/// equilibrium that folds a tet between its quadrature points
/// ([`NeoHookeanP2Tet::keeps_orientation`]: `J ≤ 0` at a node) is an error,
/// a state of the quadrature, not of the body.
pub fn solve_neo_hookean_p2(
    problem: &StaticProblem<'_, 10>,
    options: &NewtonOptions,
) -> anyhow::Result<Equilibrium> {
    let options = NewtonOptions {
        descent: true,
        ..*options
    };
    let equilibrium = solve::<10, NeoHookeanP2Tet>(problem, &options)?;
    let (positions, u) = (problem.positions, &equilibrium.u);
    for (t, (tet, material)) in problem
        .tets
        .iter()
        .zip(problem.materials.per_tet())
        .enumerate()
    {
        let element = NeoHookeanP2Tet::at_rest(&tet.map(|v| positions[v as usize]), material);
        let x = tet.map(|v| {
            let (p, d) = (positions[v as usize], u[v as usize]);
            [p[0] + d[0], p[1] + d[1], p[2] + d[2]]
        });
        ensure!(
            element.keeps_orientation(&x),
            "the equilibrium found folds tet {t} between its quadrature points (J ≤ 0 at a \
             node, > 0 at the points): a state of the quadrature, not of the body"
        );
    }
    Ok(equilibrium)
}

/// Solves `problem` (module documentation) with the element `E`: the load
/// in [`NewtonOptions::load_steps`] increments (`Discrete::increment`), the
/// stability of the end state in descent, and the reactions of the
/// prescribed vertices.
pub fn solve<const N: usize, E: HyperelasticTet<N>>(
    problem: &StaticProblem<'_, N>,
    options: &NewtonOptions,
) -> anyhow::Result<Equilibrium> {
    let model = Discrete::<N, E>::new(problem, options)?;
    let mut u = vec![[0.0; 3]; problem.positions.len()];
    let mut iterations = 0;
    let mut residual_n = 0.0;
    let mut tolerance_met = true;
    for step in 1..=options.load_steps {
        let increment = model.increment(&mut u, step, options)?;
        iterations += increment.iterations;
        residual_n = increment.residual_n;
        tolerance_met &= increment.tolerance_met;
    }
    if options.descent {
        SparseLlt::new(model.tangent(&u).as_ref()).context(
            "the equilibrium reached is not stable (its tangent is not positive definite)",
        )?;
    }
    let reactions_n = model.reactions_n(&u);
    Ok(Equilibrium {
        u,
        iterations,
        residual_n,
        tolerance_met,
        reactions_n,
    })
}

/// How one load increment ended.
struct Increment {
    /// Newton iterations it took.
    iterations: usize,
    /// Largest residual force on an unknown DOF at its end, N.
    residual_n: f64,
    /// `false` when it stopped at rounding level above the tolerance.
    tolerance_met: bool,
}

/// A checked [`StaticProblem`] discretized: one element `E` per tet and
/// the numbering of the unknown DOFs (the vertices neither fixed nor
/// prescribed).
struct Discrete<'p, 'a, const N: usize, E> {
    problem: &'p StaticProblem<'a, N>,
    /// One element per tet, at the rest positions.
    elements: Vec<E>,
    /// Mesh vertex → unknown index, `None` for a fixed or prescribed vertex.
    slot: Vec<Option<u32>>,
    /// Unknown index → mesh vertex.
    unknown: Vec<usize>,
}

impl<'p, 'a, const N: usize, E: HyperelasticTet<N>> Discrete<'p, 'a, N, E> {
    /// Checks that `problem`'s flags, loads, materials and prescribed
    /// vertices fit its mesh and that `options` has a load step, then builds
    /// the elements and numbers the unknowns.
    fn new(problem: &'p StaticProblem<'a, N>, options: &NewtonOptions) -> anyhow::Result<Self> {
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
        let elements: Vec<E> = problem
            .tets
            .iter()
            .zip(problem.materials.per_tet())
            .map(|(t, m)| E::at_rest(&t.map(|v| problem.positions[v as usize]), m))
            .collect();
        let mut slot = vec![None; n];
        let mut unknown = Vec::new();
        for v in 0..n {
            if !known[v] {
                slot[v] = Some(unknown.len() as u32);
                unknown.push(v);
            }
        }
        Ok(Self {
            problem,
            elements,
            slot,
            unknown,
        })
    }

    /// Dead load on vertex `v`, N (zero without loads).
    fn load(&self, v: usize) -> [f64; 3] {
        self.problem.loads_n.get(v).copied().unwrap_or([0.0; 3])
    }

    /// Deformed corners of tet `t` at displacement `u`, m: rest position
    /// plus displacement.
    fn corners(&self, t: &[u32; N], u: &[[f64; 3]]) -> [[f64; 3]; N] {
        t.map(|v| {
            let (p, d) = (self.problem.positions[v as usize], u[v as usize]);
            [p[0] + d[0], p[1] + d[1], p[2] + d[2]]
        })
    }

    /// Whether every tet's law is defined at `u`
    /// ([`HyperelasticTet::admissible`]).
    fn admissible(&self, u: &[[f64; 3]]) -> bool {
        self.problem
            .tets
            .iter()
            .zip(&self.elements)
            .all(|(t, e)| e.admissible(&self.corners(t, u)))
    }

    /// Internal force `f_int(u)` on every vertex, N.
    fn internal(&self, u: &[[f64; 3]]) -> Vec<Vector3<f64>> {
        let mut f = vec![Vector3::zeros(); self.problem.positions.len()];
        for (t, e) in self.problem.tets.iter().zip(&self.elements) {
            for (v, fv) in t.iter().zip(e.forces_n(&self.corners(t, u))) {
                f[*v as usize] += fv;
            }
        }
        f
    }

    /// Residual `f_int(u) + s f_ext` on the unknown vertices, N.
    fn residual(&self, u: &[[f64; 3]], s: f64) -> Vec<Vector3<f64>> {
        let f = self.internal(u);
        self.unknown
            .iter()
            .map(|&v| f[v] + Vector3::from(self.load(v)) * s)
            .collect()
    }

    /// `Π(u) = Σ W_e(u) − s f·u` and the scale of its rounding,
    /// `Σ|W_e| + |s f·u|`, J.
    fn energy(&self, u: &[[f64; 3]], s: f64) -> (f64, f64) {
        let elastic: f64 = self
            .problem
            .tets
            .iter()
            .zip(&self.elements)
            .map(|(t, e)| e.energy_j(&self.corners(t, u)))
            .sum();
        let work: f64 = self
            .unknown
            .iter()
            .map(|&v| s * Vector3::from(self.load(v)).dot(&Vector3::from(u[v])))
            .sum();
        (elastic - work, elastic.abs() + work.abs())
    }

    /// Tangent stiffness `K_t(u)` on the unknown DOFs, N/m.
    fn tangent(&self, u: &[[f64; 3]]) -> SparseColMat<usize, f64> {
        let tets = self.problem.tets;
        let n = self.problem.positions.len();
        assemble_restricted_with(n, tets, &self.slot, self.unknown.len(), |t| {
            self.elements[t].tangent(&self.corners(&tets[t], u))
        })
    }

    /// Load increment `step` of [`NewtonOptions::load_steps`]: the
    /// prescribed displacements and the loads scaled to `step / load_steps`,
    /// then Newton iterations ([`Self::direction`], [`Self::line_search`])
    /// from `u` until the largest residual force is within the tolerance of
    /// the load scale. In descent, the tangent's shift is raised where no
    /// step was taken and lowered after a full step.
    fn increment(
        &self,
        u: &mut Vec<[f64; 3]>,
        step: usize,
        options: &NewtonOptions,
    ) -> anyhow::Result<Increment> {
        let s = step as f64 / options.load_steps as f64;
        for &(v, d) in self.problem.prescribed {
            u[v as usize] = d.map(|x| s * x);
        }
        ensure!(
            self.admissible(u),
            "load step {step}/{}: the prescribed displacements invert a tet (more load steps)",
            options.load_steps
        );
        let mut r = self.residual(u, s);
        let scale = (0..self.problem.positions.len())
            .map(|v| Vector3::from(self.load(v)).amax() * s)
            .fold(largest(&r), f64::max);
        let tolerance_n = options.tolerance * scale;
        let mut shift = 0.0;
        let mut tolerance_met = true;
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
            let delta = self.direction(u, &r, &mut shift, step, options)?;
            let taken = self.line_search(u, &mut r, &delta, s, tolerance_n, options.descent);
            if options.descent {
                if taken == Some(1.0) {
                    shift = if shift / 10.0 < MIN_SHIFT {
                        0.0
                    } else {
                        shift / 10.0
                    };
                } else if taken.is_none() && largest(&r) > STAGNATION * scale {
                    // Trust the tangent less: a shorter, steeper step.
                    shift = (10.0 * shift).max(MIN_SHIFT);
                    continue;
                }
            }
            if taken.is_none() && largest(&r) <= STAGNATION * scale {
                // At rounding level: no step can decrease the residual.
                tolerance_met = false;
                break;
            }
            if taken.is_none() {
                // `r` is the one the line search started from.
                bail!(
                    "load step {step}/{}: the line search found no decrease of the residual \
                     ({:.3e} N)",
                    options.load_steps,
                    norm(&r)
                );
            }
            converged = largest(&r) <= tolerance_n;
        }
        Ok(Increment {
            iterations: k,
            residual_n: largest(&r),
            tolerance_met,
        })
    }

    /// The Newton step `Δu = K_t⁻¹ r` at `u` (`3 × unknowns` rows), the
    /// tangent shifted by `shift` in descent ([`factor_shifted`]). Errors,
    /// naming load increment `step`, where the tangent does not factorize.
    fn direction(
        &self,
        u: &[[f64; 3]],
        r: &[Vector3<f64>],
        shift: &mut f64,
        step: usize,
        options: &NewtonOptions,
    ) -> anyhow::Result<Mat<f64>> {
        let tangent = self.tangent(u);
        let factorized = if options.descent {
            factor_shifted(&tangent, shift)
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
        let mut delta = Mat::<f64>::zeros(3 * self.unknown.len(), 1);
        for (i, ri) in r.iter().enumerate() {
            for c in 0..3 {
                delta[(3 * i + c, 0)] = ri[c];
            }
        }
        llt.solve_in_place(delta.as_mut());
        Ok(delta)
    }

    /// Backtracking line search along `delta` from `u`, halving the step
    /// fraction at most [`MAX_HALVINGS`] times: skips a trial where a tet's
    /// law is not defined ([`Self::admissible`]), takes the first whose
    /// residual norm is below that of `r` (or whose largest residual force is
    /// within `tolerance_n`), in descent the first that lowers `Π` or lowers
    /// the residual while `Π` grows by less than its rounding
    /// ([`ENERGY_ROUNDING`]). On a take, `u` and `r` become the trial's and
    /// the step fraction is returned; `None` leaves them as they were.
    fn line_search(
        &self,
        u: &mut Vec<[f64; 3]>,
        r: &mut Vec<Vector3<f64>>,
        delta: &Mat<f64>,
        s: f64,
        tolerance_n: f64,
        descent: bool,
    ) -> Option<f64> {
        let before = norm(r);
        let (energy_before, energy_scale) = if descent {
            self.energy(u, s)
        } else {
            (0.0, 0.0)
        };
        let mut alpha = 1.0;
        for _ in 0..=MAX_HALVINGS {
            let mut trial = u.clone();
            for (i, &v) in self.unknown.iter().enumerate() {
                for c in 0..3 {
                    trial[v][c] += alpha * delta[(3 * i + c, 0)];
                }
            }
            if !self.admissible(&trial) {
                alpha *= 0.5;
                continue;
            }
            let r_trial = self.residual(&trial, s);
            let lower = norm(&r_trial) < before || largest(&r_trial) <= tolerance_n;
            let take = if descent {
                let (e, _) = self.energy(&trial, s);
                e < energy_before || (lower && e <= energy_before + ENERGY_ROUNDING * energy_scale)
            } else {
                lower
            };
            if take {
                (*u, *r) = (trial, r_trial);
                return Some(alpha);
            }
            alpha *= 0.5;
        }
        None
    }

    /// For each prescribed vertex, in order, the force the constraint
    /// applies to the body at `u`, `−f_int − f_ext`, N.
    fn reactions_n(&self, u: &[[f64; 3]]) -> Vec<[f64; 3]> {
        let f = self.internal(u);
        self.problem
            .prescribed
            .iter()
            .map(|&(v, _)| (-(f[v as usize] + Vector3::from(self.load(v as usize)))).into())
            .collect()
    }
}

/// Euclidean norm of a residual, N.
fn norm(r: &[Vector3<f64>]) -> f64 {
    r.iter().map(|x| x.norm_squared()).sum::<f64>().sqrt()
}

/// Largest force component of a residual, N.
fn largest(r: &[Vector3<f64>]) -> f64 {
    r.iter().map(|x| x.amax()).fold(0.0, f64::max)
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
