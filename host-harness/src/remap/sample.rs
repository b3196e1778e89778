//! The compression test on a cylinder sample (Cotin 1999 TVCG §3: a sample
//! compressed at a fixed speed between two plates, its axial force and the
//! radial displacement of its mid-height circle measured): the linear
//! sample's response, which gives the remaps their inputs, and St
//! Venant-Kirchhoff curves that stand in for measured ones when no data is
//! given.
//!
//! The sample: [`cylinder_mesh`] (2 radial and 6 axial cells) of the given
//! height and radius, its base clamped, its top face clamped to the plate
//! and moved down by the compression (bonded plates: no slip at either end).

use anyhow::{Context, bail, ensure};
use faer::Mat;
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::tensor_mass::{DynamicParams, ElasticLaw, StvkForm, TensorMassModel};
use serde::Serialize;

use super::curves::CurvePoint;
use crate::fem::assembly::assemble_restricted;
use crate::fem::llt::SparseLlt;
use crate::fem::material::{Material, TetMaterials};
use crate::fem::static_solve::solve_prescribed;
use crate::mesh::TetMesh;
use crate::mesh::generate::cylinder_mesh;
use crate::output::number::shown;
use crate::table::tensor_mass::static_study_table;
use crate::tensor_mass::OwnedState;

/// Radial cells of the sample's mesh ([`cylinder_mesh`]).
const SAMPLE_RADIAL_CELLS: usize = 2;
/// Axial cells of the sample's mesh (even: a vertex ring at mid-height).
const SAMPLE_HEIGHT_CELLS: usize = 6;

/// A cylinder sample between two plates.
pub struct Sample {
    /// The rest mesh, m.
    pub mesh: TetMesh,
    /// Its tissue.
    pub material: Material,
    /// Height, m.
    pub height_m: f64,
    /// Base vertices (clamped).
    pub base: Vec<u32>,
    /// Top-face vertices (moved by the plate).
    pub top: Vec<u32>,
    /// The mid-height surface ring (radial displacement measured there).
    pub ring: Vec<u32>,
}

impl Sample {
    /// The sample of `height_m` × `radius_m` (m, positive) of `material`.
    pub fn new(height_m: f64, radius_m: f64, material: Material) -> anyhow::Result<Self> {
        ensure!(
            height_m > 0.0 && radius_m > 0.0 && height_m.is_finite() && radius_m.is_finite(),
            "sample height {height_m} m and radius {radius_m} m must be positive"
        );
        let mut mesh = cylinder_mesh(height_m, SAMPLE_RADIAL_CELLS, SAMPLE_HEIGHT_CELLS);
        // `cylinder_mesh` has radius H/5: scale the cross-section.
        let scale = radius_m / (height_m / 5.0);
        for p in &mut mesh.positions {
            p[0] *= scale;
            p[1] *= scale;
        }
        let on = |z: f64| -> Vec<u32> {
            (0..mesh.positions.len() as u32)
                .filter(|&v| mesh.positions[v as usize][2] == z)
                .collect()
        };
        let (base, top) = (on(0.0), on(height_m));
        let middle = height_m * 0.5;
        let ring = (0..mesh.positions.len() as u32)
            .filter(|&v| {
                let p = mesh.positions[v as usize];
                (p[2] - middle).abs() <= 1e-9 * height_m
                    && p[0].hypot(p[1]) >= (1.0 - 1e-9) * radius_m
            })
            .collect::<Vec<_>>();
        ensure!(!ring.is_empty(), "no mid-height ring on the sample mesh");
        Ok(Self {
            mesh,
            material,
            height_m,
            base,
            top,
            ring,
        })
    }

    /// Mean outward radial displacement of the ring, m.
    fn radial_m(&self, u: &[[f64; 3]]) -> f64 {
        let sum: f64 = self
            .ring
            .iter()
            .map(|&v| {
                let p = self.mesh.positions[v as usize];
                let r = p[0].hypot(p[1]);
                (u[v as usize][0] * p[0] + u[v as usize][1] * p[1]) / r
            })
            .sum();
        sum / self.ring.len() as f64
    }

    /// Fixed flags of the table: the base (the top is imposed by the plate).
    fn base_flags(&self) -> Vec<bool> {
        let mut fixed = vec![false; self.mesh.positions.len()];
        for &v in &self.base {
            fixed[v as usize] = true;
        }
        fixed
    }
}

/// The linear sample's response: force and mid-height radial displacement
/// per metre of compression (both exactly proportional to it).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LinearResponse {
    /// Axial force per axial compression, N/m.
    pub force_n_per_m: f64,
    /// Radial displacement per axial compression (dimensionless).
    pub radial_per_axial: f64,
}

/// The linear response of `sample`: one direct sparse solve (linear FEM,
/// the pre-computed model's law) with the top moved down by 1 % of the
/// height, scaled to one metre.
pub fn linear_response(sample: &Sample) -> anyhow::Result<LinearResponse> {
    let axial_m = 0.01 * sample.height_m;
    let prescribed: Vec<(u32, [f64; 3])> = sample
        .top
        .iter()
        .map(|&v| (v, [0.0, 0.0, -axial_m]))
        .collect();
    let materials = TetMaterials::uniform(sample.material, sample.mesh.tets.len());
    let (u, reactions) = solve_prescribed(
        &sample.mesh.positions,
        &sample.mesh.tets,
        &materials,
        &sample.base_flags(),
        &prescribed,
    )
    .context("linear compression of the sample")?;
    // The plate pushes down: the reactions `(K u)_p` at the top point down.
    let force_n: f64 = -reactions.iter().map(|r| r[2]).sum::<f64>();
    Ok(LinearResponse {
        force_n_per_m: force_n / axial_m,
        radial_per_axial: sample.radial_m(&u) / axial_m,
    })
}

/// Most fixed-tangent iterations of one compression step. The tangent is
/// the linear stiffness: near-incompressible tissue converges slowly at
/// large compressions (ν = 0.45 at 25 % of the height needs more than 500;
/// 2 000 take about 0.1 s on the default sample).
const MAX_ITERATIONS: usize = 2000;

/// St Venant-Kirchhoff compression curves of `sample` at `steps` evenly
/// spaced compressions up to `max_strain` of its height (the rest state
/// first). Each is the static equilibrium `f_int(u) = 0` on the interior
/// vertices with the top held at the compression, by fixed-tangent Newton
/// iterations `u ← u + K⁻¹ f_int(u)` (`K` the linear stiffness of the
/// interior, factorized once; `f_int` the kernel's St Venant-Kirchhoff
/// forces), warm-started from the previous equilibrium scaled, until every
/// interior force is below 1e-9 of the linear force at the first step. The
/// force is the plate's: the elastic forces on the top vertices, summed.
pub fn stvk_curves(
    sample: &Sample,
    max_strain: f64,
    steps: usize,
) -> anyhow::Result<Vec<CurvePoint>> {
    ensure!(
        max_strain > 0.0 && max_strain < 0.5,
        "compression {max_strain} of the height must be in (0, 0.5): St Venant-Kirchhoff collapses \
         near 1 − 1/√3 = 0.42"
    );
    ensure!((1..=64).contains(&steps), "{steps} steps outside 1..=64");
    let mesh = &sample.mesh;
    let n = mesh.positions.len();
    let materials = TetMaterials::uniform(sample.material, mesh.tets.len());
    let file = static_study_table(mesh, &materials, sample.base_flags());
    let table = TensorMassTable::<f64>::load(file.bytes()).context("sample table")?;
    let mut state = OwnedState::for_table(&table);
    let params = DynamicParams::linear(0.0, sample.height_m)
        .with_law(ElasticLaw::StVenantKirchhoff(StvkForm::PerTet));
    let model = TensorMassModel::new(table, state.buffers(), params)?;

    // The interior: neither base nor top.
    let mut slot = vec![None; n];
    let mut interior = Vec::new();
    for v in 0..n as u32 {
        if !sample.base.contains(&v) && !sample.top.contains(&v) {
            slot[v as usize] = Some(interior.len() as u32);
            interior.push(v as usize);
        }
    }
    let k = assemble_restricted(
        &mesh.positions,
        &mesh.tets,
        &materials,
        &slot,
        interior.len(),
    );
    let llt = SparseLlt::new(k.as_ref()).context("sample stiffness")?;

    let linear = linear_response(sample)?;
    let first_axial_m = max_strain * sample.height_m / steps as f64;
    let tolerance_n = 1e-9 * linear.force_n_per_m * first_axial_m;
    let mut u = vec![[0.0; 3]; n];
    let mut forces = vec![[0.0; 3]; n];
    let mut rhs = Mat::<f64>::zeros(3 * interior.len(), 1);
    let mut points = vec![CurvePoint {
        force_n: 0.0,
        axial_m: 0.0,
        radial_m: 0.0,
    }];
    for step in 1..=steps {
        let axial_m = first_axial_m * step as f64;
        let scale = step as f64 / (step - 1).max(1) as f64;
        for &v in &interior {
            u[v] = u[v].map(|x| x * scale);
        }
        for &v in &sample.top {
            u[v as usize] = [0.0, 0.0, -axial_m];
        }
        let mut converged = false;
        let mut residual_n = f64::INFINITY;
        for _ in 0..MAX_ITERATIONS {
            model.elastic_forces_of(&u, &mut forces);
            residual_n = interior
                .iter()
                .flat_map(|&v| forces[v])
                .fold(0.0, |m: f64, f| m.max(f.abs()));
            if residual_n <= tolerance_n {
                converged = true;
                break;
            }
            for (s, &v) in interior.iter().enumerate() {
                for c in 0..3 {
                    rhs[(3 * s + c, 0)] = forces[v][c];
                }
            }
            llt.solve_in_place(rhs.as_mut());
            for (s, &v) in interior.iter().enumerate() {
                for c in 0..3 {
                    u[v][c] += rhs[(3 * s + c, 0)];
                }
            }
        }
        if !(converged && u.iter().flatten().all(|x| x.is_finite())) {
            let converged_strain = max_strain * (step - 1) as f64 / steps as f64;
            let lower = if step > 1 {
                format!(
                    "lower --max-strain to {converged_strain:.3} (the last compression that converged) or below"
                )
            } else {
                "lower --max-strain".to_owned()
            };
            bail!(
                "the St Venant-Kirchhoff sample (E = {} Pa, ν = {}) finds no equilibrium at \
                 {:.1} % compression (residual {residual_n:.2e} N after {MAX_ITERATIONS} \
                 iterations; St Venant-Kirchhoff softens and collapses under large \
                 compression): {lower}, or fit measured curves (--curves)",
                shown(sample.material.young_pa),
                shown(sample.material.poisson),
                100.0 * axial_m / sample.height_m,
            );
        }
        let force_n: f64 = sample.top.iter().map(|&v| forces[v as usize][2]).sum();
        points.push(CurvePoint {
            force_n,
            axial_m,
            radial_m: sample.radial_m(&u),
        });
    }
    Ok(points)
}
