//! The study's truth: the compressible neo-Hookean equilibrium
//! ([`crate::fem::newton::solve_neo_hookean`], its P2 element
//! [`crate::fem::neo_hookean_p2`]) of each load and level on the finest
//! chart mesh, solved on a sequence of discretizations of that mesh's
//! geometry ([`Discretization`]: P1 or P2 on the mesh or its red
//! refinements, each tet split into 8); the last is the truth ([`Truth`]),
//! and the relative change of the charted quantity ([`super::tip_m`] of
//! the consistent face loads, `chart::face`) between the last two its
//! convergence figure: the runs are scored against it only where that is
//! at most [`CONVERGED`] ([`Truth::converged`]).
//!
//! The refinements keep the geometry (the polygonal cylinder of the finest
//! chart mesh), so the levels differ in their discretization only: the
//! coarser chart meshes' errors against the truth include their own
//! geometry's.

use anyhow::Context;
use serde::Serialize;

use super::body::{Body, Load, tip_m};
use super::face::{loaded_faces, p1_shape, p2_shape};
use crate::fem::material::TetMaterials;
use crate::fem::neo_hookean_p2::P2Mesh;
use crate::fem::newton::{NewtonOptions, StaticProblem, solve_neo_hookean, solve_neo_hookean_p2};

/// The largest relative change of the charted quantity between the two
/// finest truth levels for the truth to be called converged.
pub const CONVERGED: f64 = 1e-3;

/// Newton's convergence: the largest residual force over the largest nodal
/// load. 1e-10 did not converge P2 on 2x10 at ν = 0.49 under the 1 % bend
/// (400 iterations at a residual of 2.3e-14 N, rounding: the consistent
/// loads of a P2 face are small at its corners); 1e-8 moves the charted
/// quantity by far less than the [`CONVERGED`] bound.
const TOLERANCE: f64 = 1e-8;

/// Newton load increments per 1 % of tip displacement (at least one).
const STEPS_PER_PERCENT: f64 = 0.5;

/// One truth level: the element order on the finest chart mesh refined
/// `refinements` times (each tet into 8 by its edge midpoints).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Discretization {
    /// 1 (4-node tets) or 2 (10-node tets).
    pub order: u8,
    /// Red refinements of the finest chart mesh.
    pub refinements: u32,
}

impl Discretization {
    /// P1 on the mesh refined `refinements` times.
    pub const fn p1(refinements: u32) -> Self {
        Self {
            order: 1,
            refinements,
        }
    }

    /// P2 on the mesh refined `refinements` times.
    pub const fn p2(refinements: u32) -> Self {
        Self {
            order: 2,
            refinements,
        }
    }

    /// `P2 on 3x15 ×2` (the mesh's edges halved once).
    pub fn label(&self, mesh: &str) -> String {
        let scale = 1u32 << self.refinements;
        format!("P{} on {mesh} ×{scale}", self.order)
    }
}

/// One level's solution.
#[derive(Clone, Debug, Serialize)]
pub struct TruthLevel {
    /// What was solved ([`Discretization::label`]).
    pub label: String,
    /// The discretization.
    pub discretization: Discretization,
    /// Nodes (vertices, and mid-edge nodes for P2).
    pub nodes: usize,
    /// Tets.
    pub tets: usize,
    /// Newton iterations over all increments.
    pub iterations: usize,
    /// Wall time of the level's solve (refinement, loads, Newton), s.
    pub seconds: f64,
    /// The charted quantity, m (`NaN` on a fault).
    pub tip_m: f64,
    /// `null`, or why Newton failed.
    pub fault: Option<String>,
}

/// The truth of one load and level.
#[derive(Clone, Debug, Serialize)]
pub struct Truth {
    /// The load.
    pub load: Load,
    /// The level.
    pub level: f64,
    /// Total force (N) or torque (N·m).
    pub magnitude: f64,
    /// Every level, coarsest first.
    pub levels: Vec<TruthLevel>,
    /// The truth: the last level's quantity, m (`NaN` if it failed).
    pub tip_m: f64,
    /// `|q_last − q_previous| / |q_last|`, the convergence figure (`null`
    /// with fewer than two levels solved).
    pub change: Option<f64>,
}

impl Truth {
    /// Whether the change is at most [`CONVERGED`]: only then are the runs
    /// scored against it (`chart::reference::score_truth`).
    pub fn converged(&self) -> bool {
        self.change.is_some_and(|c| c <= CONVERGED)
    }

    /// What the report says of this truth: `converged`, or `no converged
    /// truth: ` and why (the change above [`CONVERGED`], or the fault of
    /// the first of the two finest levels that failed: Newton's, or the P2
    /// solve's refusal of a folded element; a level after a failed one is
    /// not solved, [`truth`]).
    pub fn verdict(&self) -> String {
        match (
            self.change,
            self.levels[self.levels.len().saturating_sub(2)..]
                .iter()
                .find_map(|l| l.fault.as_deref()),
        ) {
            (Some(c), _) if c <= CONVERGED => "converged".into(),
            (Some(c), _) => format!("no converged truth: change {c:.2e} > {CONVERGED:e}"),
            (None, Some(fault)) => format!("no converged truth: {fault}"),
            (None, None) => "no converged truth: fewer than two levels".into(),
        }
    }
}

/// The truth of `load` at `level` (total `magnitude`) on `body` (the
/// finest chart mesh) over `levels`.
pub fn truth(
    body: &Body,
    levels: &[Discretization],
    load: Load,
    level: f64,
    magnitude: f64,
) -> Truth {
    // The truth converges only if the two finest levels are solved: once
    // one of them fails, the finer ones are not solved (the post-buckling
    // press's P2 solve, which ends in a fold, took 21 s on 2x10).
    let last_two = levels.len().saturating_sub(2);
    let mut solved: Vec<TruthLevel> = Vec::with_capacity(levels.len());
    for (i, &d) in levels.iter().enumerate() {
        let failed = solved[last_two.min(i)..].iter().find(|l| l.fault.is_some());
        if let Some(failed) = failed {
            let fault = format!("not solved: {} failed", failed.label);
            solved.push(TruthLevel {
                label: d.label(&body.label),
                discretization: d,
                nodes: 0,
                tets: 0,
                iterations: 0,
                seconds: 0.0,
                tip_m: f64::NAN,
                fault: Some(fault),
            });
            continue;
        }
        let start = std::time::Instant::now();
        let mut this = solve_level(body, d, load, level, magnitude);
        this.seconds = start.elapsed().as_secs_f64();
        solved.push(this);
    }
    let tips: Vec<f64> = solved.iter().map(|l| l.tip_m).collect();
    let tip_m = tips.last().copied().unwrap_or(f64::NAN);
    let change = match tips.as_slice() {
        [.., a, b] if a.is_finite() && b.is_finite() => Some((b - a).abs() / b.abs()),
        _ => None,
    };
    Truth {
        load,
        level,
        magnitude,
        levels: solved,
        tip_m,
        change,
    }
}

/// The refined mesh: positions, tets, and the per-vertex `flags` carried
/// to the new vertices (an edge midpoint flagged where both ends are).
type Refined = (Vec<[f64; 3]>, Vec<[u32; 4]>, Vec<Vec<bool>>);

/// `positions`, `tets` red-refined once: each tet into its 4 corner tets
/// and the 4 of its inner octahedron (split along the diagonal between the
/// midpoints of edges 0–2 and 1–3), every one positively oriented; `flags`
/// carried along.
pub fn refine(positions: &[[f64; 3]], tets: &[[u32; 4]], flags: &[Vec<bool>]) -> Refined {
    let p2 = P2Mesh::new(positions, tets);
    // The P2 nodes: corners 0–3, then the midpoints of 01 12 02 03 13 23.
    const CHILDREN: [[usize; 4]; 8] = [
        [0, 4, 6, 7],
        [4, 1, 5, 8],
        [6, 5, 2, 9],
        [7, 8, 9, 3],
        [6, 8, 4, 5],
        [6, 8, 5, 9],
        [6, 8, 9, 7],
        [6, 8, 7, 4],
    ];
    let volume = |t: &[u32; 4]| {
        let p = t.map(|v| nalgebra::Vector3::from(p2.positions[v as usize]));
        (p[1] - p[0]).cross(&(p[2] - p[0])).dot(&(p[3] - p[0]))
    };
    let mut refined = Vec::with_capacity(8 * tets.len());
    for nodes in &p2.tets {
        for child in CHILDREN {
            let mut t = child.map(|i| nodes[i]);
            if volume(&t) < 0.0 {
                t.swap(2, 3);
            }
            refined.push(t);
        }
    }
    let flags = flags.iter().map(|f| p2.node_flags(f)).collect();
    (p2.positions, refined, flags)
}

/// Solves one level; a failure is the level's fault.
fn solve_level(
    body: &Body,
    discretization: Discretization,
    load: Load,
    level: f64,
    magnitude: f64,
) -> TruthLevel {
    let mut loaded = vec![false; body.mesh.positions.len()];
    for &v in &body.top {
        loaded[v as usize] = true;
    }
    let (mut positions, mut tets) = (body.mesh.positions.clone(), body.mesh.tets.clone());
    let mut flags = vec![body.fixed.clone(), loaded];
    for _ in 0..discretization.refinements {
        (positions, tets, flags) = refine(&positions, &tets, &flags);
    }
    let options = NewtonOptions {
        load_steps: ((100.0 * level * STEPS_PER_PERCENT).ceil() as usize).max(1),
        max_iterations: 400,
        tolerance: TOLERANCE,
        descent: true,
    };
    let materials = TetMaterials::uniform(body.material, tets.len());
    let faces = loaded_faces(&tets, &flags[1]);
    let solved = if faces.is_empty() {
        Err(anyhow::anyhow!(
            "the loaded vertices form no face: the truth needs a loaded face"
        ))
    } else if discretization.order == 1 {
        let loads = body.face_loads(&positions, &faces, p1_shape, load, magnitude);
        let problem = StaticProblem {
            positions: &positions,
            tets: &tets,
            materials: &materials,
            fixed: &flags[0],
            prescribed: &[],
            loads_n: &loads,
        };
        solve_neo_hookean(&problem, &options)
            .map(|e| (tip_m(&loads, &e.u), e.iterations, positions.len()))
    } else {
        p2_loads(body, (&positions, &tets), &faces, load, magnitude).and_then(
            |(problem_loads, p2)| {
                let fixed = p2.node_flags(&flags[0]);
                let problem = StaticProblem::<10> {
                    positions: &p2.positions,
                    tets: &p2.tets,
                    materials: &materials,
                    fixed: &fixed,
                    prescribed: &[],
                    loads_n: &problem_loads,
                };
                solve_neo_hookean_p2(&problem, &options).map(|e| {
                    (
                        tip_m(&problem_loads, &e.u),
                        e.iterations,
                        p2.positions.len(),
                    )
                })
            },
        )
    };
    let label = discretization.label(&body.label);
    match solved {
        Ok((tip_m, iterations, nodes)) => TruthLevel {
            label,
            discretization,
            nodes,
            tets: tets.len(),
            iterations,
            seconds: 0.0,
            tip_m,
            fault: None,
        },
        Err(e) => TruthLevel {
            label,
            discretization,
            nodes: positions.len(),
            tets: tets.len(),
            iterations: 0,
            seconds: 0.0,
            tip_m: f64::NAN,
            fault: Some(format!("{e:#}")),
        },
    }
}

/// The P2 mesh of `(positions, tets)` and the consistent loads of its
/// 6-node loaded faces (the P1 `faces` with their mid-edge nodes).
fn p2_loads(
    body: &Body,
    (positions, tets): (&[[f64; 3]], &[[u32; 4]]),
    faces: &[[u32; 3]],
    load: Load,
    magnitude: f64,
) -> anyhow::Result<(Vec<[f64; 3]>, P2Mesh)> {
    let p2 = P2Mesh::new(positions, tets);
    let first = positions.len() as u32;
    let mid: std::collections::HashMap<[u32; 2], u32> = p2
        .edges
        .iter()
        .enumerate()
        .map(|(e, &key)| (key, first + e as u32))
        .collect();
    let node = |a: u32, b: u32| {
        mid.get(&[a.min(b), a.max(b)])
            .copied()
            .context("a face edge without its mid-edge node")
    };
    let faces6 = faces
        .iter()
        .map(|&[a, b, c]| Ok([a, b, c, node(a, b)?, node(b, c)?, node(c, a)?]))
        .collect::<anyhow::Result<Vec<[u32; 6]>>>()?;
    let loads = body.face_loads(&p2.positions, &faces6, p2_shape, load, magnitude);
    Ok((loads, p2))
}
