//! What each planned region costs: its table's size, its predicted step time and, for a
//! tensor-mass region, its largest stable step (MODELS.md §3, §5).
//!
//! - Table sizes: the pre-computed region's and the interface's are the hybrid build's own
//!   estimate ([`HybridEstimate`], f32 tables as the sessions build them), which the build
//!   checks against the limits before it starts; a tensor-mass region's, its sub-mesh's with
//!   its connection nodes fixed (the interface imposes their displacement).
//! - Materials: the scene's per tet (`[material]` and `[[region]]`s), as the sessions take
//!   them, in every region's table, timing and stable step.
//! - A tensor-mass region's step: its sub-mesh's f32 table built in memory, stepped alone under
//!   gravity ([`TIMED_STEPS`] steps after [`WARMUP_STEPS`], the median of the single steps),
//!   plus the interface update: the `9c²` multiply-adds of the condensed stiffness `S`
//!   applied to the connection displacements (MODELS.md §5), timed as the kernel's `3c` row
//!   products of a dense `3c × 3c` f32 matrix (median of [`TIMED_PRODUCTS`]; above
//!   [`MAX_TIMED_CONNECTIONS`] connection nodes, timed at that size and scaled by `c²`).
//! - The pre-computed region's tick: the kernel's contact solve for [`MAX_CONTACTS`] vertex
//!   contacts (median of [`TIMED_SOLVES`]), whose work is `O(m³)` and independent of the mesh
//!   (README "The model"), timed on a 4 × 4 × 4-cell box of the scene's material; plus, when
//!   there are connection nodes, the interface update (the pre-computed region's response to
//!   the connection nodes is read per contact from the background the physics update
//!   computes, so a tick adds nothing per connection node; the update is listed once more as
//!   the region's share of each physics step).
//! - A tensor-mass region's stable step: `ω_max` of its f64 linear model at rest (Lanczos,
//!   `stable_step_of_model`, the scene check's own computation), the
//!   connection nodes fixed. The coupled limit (`dynamic critical-dt --scene`) is measured at
//!   or above the all-tensor-mass model's (README "The hybrid model").

use std::time::Instant;

use anyhow::Context;
use core::hint::black_box;
use nalgebra::Vector3;
use palpate_kernel::MAX_CONTACTS;
use palpate_kernel::math::dense::dot;
use palpate_kernel::precomputed::{Constraint, PrecomputedModel};
use palpate_kernel::table::format::TableKind;
use palpate_kernel::table::{PrecomputedTable, TensorMassTable};
use palpate_kernel::tensor_mass::{
    DynamicParams, ElasticLaw, Integrator, TensorMassModel, VertexMode,
};

use super::plan::{Partition, RegionModel};
use crate::fem::material::{Material, TetMaterials};
use crate::fix::FixPredicate;
use crate::hybrid::RegionSplit;
use crate::hybrid::estimate::{HybridEstimate, PrecomputedRegion};
use crate::hybrid::hmatrix::InterfaceCompression;
use crate::mesh::generate::box_mesh;
use crate::mesh::{MeshReport, TetMesh, boundary_surface};
use crate::table::build::{BuildOptions, build};
use crate::table::compliance::Solver;
use crate::table::estimate::TableEstimate;
use crate::table::file::Precision;
use crate::table::tensor_mass::{TensorMassArrays, write_tensor_mass_table};
use crate::tensor_mass::OwnedState;
use crate::tensor_mass::run::diagonal;
use crate::tensor_mass::stability::stable_step_of_model;

/// Steps of a tensor-mass region run before timing.
pub const WARMUP_STEPS: usize = 20;
/// Single steps of a tensor-mass region timed; the median is reported.
pub const TIMED_STEPS: usize = 300;
/// Interface products timed; the median is reported.
pub const TIMED_PRODUCTS: usize = 101;
/// Contact solves timed; the median is reported.
pub const TIMED_SOLVES: usize = 1001;
/// Largest connection count whose dense `3c × 3c` product is timed as is (a 113 MB f32 matrix);
/// above it the time at this size is scaled by `c²`.
pub const MAX_TIMED_CONNECTIONS: usize = 1024;

/// The stored scalar of the tables the sessions run (f32).
const PRECISION: Precision = Precision::F32;

/// How the regions are timed: the scene's materials and dynamic settings.
#[derive(Clone, Debug)]
pub struct CostOptions {
    /// Young's modulus and Poisson ratio of every tet of the mesh (the scene's `[material]`
    /// and `[[region]]`s, `Scene::tet_materials`: the sessions' materials).
    pub materials: TetMaterials,
    /// The radius the pre-computed table's candidate lists serve (the scene's tool), m.
    pub tool_radius_m: f64,
    /// Density, kg/m³.
    pub density_kg_m3: f64,
    /// The tensor-mass regions' integrator.
    pub integrator: Integrator,
    /// Their mass-proportional damping, 1/s.
    pub damping_per_s: f64,
    /// Their incompressibility penalty `γ`, N, where they take it (`None`: the
    /// experiments' default, `crate::fem::penalty::penalty_n` of the region).
    pub incompressibility_n: Option<f64>,
    /// A hybrid's tables compressed (the scene's `[tables] compress = "hmatrix"`): the
    /// interface's condensed stiffness and the pre-computed region's table hierarchical, the
    /// response over the region's touchable rows (`HybridEstimate::compressed`); `None`: dense.
    pub interface_compression: Option<InterfaceCompression>,
}

/// The costs of one region.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RegionCost {
    /// Its table's size, bytes (f32).
    pub table_bytes: u64,
    /// Predicted time of one step (tensor-mass) or one haptic tick (pre-computed), s.
    pub step_cost_s: f64,
    /// Largest stable step of a tensor-mass region, s (`None`: pre-computed, unconditionally
    /// stable, or nothing free to move).
    pub critical_dt_s: Option<f64>,
}

/// The interface between the pre-computed region and the tensor-mass regions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InterfaceCost {
    /// Connection nodes `c`.
    pub connection_nodes: u64,
    /// Free vertices of the pre-computed region with the connection nodes counted fixed
    /// (`F_P`).
    pub precomputed_free: u64,
    /// The interface table's size, bytes ([`HybridEstimate::interface`], f32).
    pub table_bytes: u64,
    /// One interface update (`9c²` multiply-adds), s.
    pub update_s: f64,
}

/// A region's tets as a mesh of their own (vertices renumbered in ascending order of the
/// original ids, which are returned).
pub fn sub_mesh(mesh: &TetMesh, tets: &[u32]) -> (TetMesh, Vec<u32>) {
    let vertices = super::plan::distinct_vertices(mesh, tets);
    let mut new_id = vec![u32::MAX; mesh.positions.len()];
    for (i, &v) in vertices.iter().enumerate() {
        new_id[v as usize] = i as u32;
    }
    let sub = TetMesh {
        positions: vertices
            .iter()
            .map(|&v| mesh.positions[v as usize])
            .collect(),
        tets: tets
            .iter()
            .map(|&t| mesh.tets[t as usize].map(|v| new_id[v as usize]))
            .collect(),
    };
    (sub, vertices)
}

/// The costs of every region of `partition` (in its order) and of the interface. `fixed`: per
/// mesh vertex, whether the scene fixes it. The pre-computed region's and the interface's
/// table sizes are the hybrid build's own estimate ([`HybridEstimate`], checked before it
/// builds), returned with the costs (`None` unless the partition is a hybrid).
pub fn costs(
    mesh: &TetMesh,
    fixed: &[bool],
    partition: &Partition,
    options: &CostOptions,
) -> anyhow::Result<(Vec<RegionCost>, InterfaceCost, Option<HybridEstimate>)> {
    let mut connection = vec![false; mesh.positions.len()];
    for &v in &partition.connection_nodes {
        connection[v as usize] = true;
    }
    let hybrid = partition.dynamic.iter().any(|&d| d) && partition.dynamic.iter().any(|&d| !d);
    let estimate = if hybrid {
        let split = RegionSplit::new(mesh, fixed, &partition.dynamic)?;
        let region = PrecomputedRegion::of(mesh, &split, fixed);
        let estimate = HybridEstimate::of(
            mesh,
            &split,
            fixed,
            &region,
            options.tool_radius_m,
            PRECISION,
        );
        // The scene's `compress = "hmatrix"`: the hierarchical S, region and touchable
        // response (`crate::session::model::hybrid_tables`).
        Some(match &options.interface_compression {
            Some(compression) => estimate.compressed(mesh, &split, &region, compression, true),
            None => estimate,
        })
    } else {
        None
    };
    let c = partition.connection_nodes.len();
    let mut update_s = if c > 0 { interface_update_s(c) } else { 0.0 };
    if let Some(e) = &estimate {
        // A hierarchical S: a product's multiply-adds (one per scalar) instead of 9c².
        let dense = 9 * (c as u64).pow(2);
        update_s *= e.condensed_scalars as f64 / dense.max(1) as f64;
    }
    let default = options.materials.default_material();
    let mut out = Vec::with_capacity(partition.regions.len());
    for region in &partition.regions {
        let (sub, ids) = sub_mesh(mesh, &region.tets);
        let sub_fixed: Vec<bool> = ids
            .iter()
            .map(|&v| fixed[v as usize] || connection[v as usize])
            .collect();
        let surface = boundary_surface(&sub);
        let table_bytes = |kind| {
            TableEstimate::of_surface(
                kind,
                PRECISION,
                &sub,
                &sub_fixed,
                &surface,
                options.tool_radius_m,
            )
            .table_bytes
        };
        out.push(match region.model {
            RegionModel::Precomputed => RegionCost {
                table_bytes: match &estimate {
                    Some(e) => e.precomputed.table_bytes,
                    None => table_bytes(TableKind::Precomputed),
                },
                step_cost_s: contact_solve_s(&default)? + update_s,
                critical_dt_s: None,
            },
            RegionModel::TensorMass {
                law,
                incompressibility,
            } => {
                let materials = options
                    .materials
                    .subset(region.tets.iter().map(|&t| t as usize));
                let arrays = TensorMassArrays::new(
                    &sub,
                    &materials,
                    options.density_kg_m3,
                    sub_fixed.clone(),
                );
                let gamma = incompressibility.then(|| {
                    options
                        .incompressibility_n
                        .unwrap_or_else(|| crate::fem::penalty::penalty_n(&sub, &default))
                });
                let critical_dt_s = stable_step_s(&sub, &surface.triangles, &arrays, options)
                    .with_context(|| format!("the stable step of dynamic region {}", region.id))?;
                // A step the region is stable at: a tenth of a millisecond, far below the limit
                // of any mesh the real-time loop runs, or half the region's limit if a stiff
                // material makes it lower (the cost of a step does not depend on its length).
                let dt_s = critical_dt_s.map_or(1e-4, |dt| (0.5 * dt).min(1e-4));
                let step_s = tensor_mass_step_s(
                    &sub,
                    &surface.triangles,
                    &arrays,
                    options,
                    (law, gamma),
                    dt_s,
                )
                .with_context(|| format!("timing dynamic region {}", region.id))?;
                RegionCost {
                    table_bytes: table_bytes(TableKind::TensorMass),
                    step_cost_s: step_s + update_s,
                    critical_dt_s,
                }
            }
        });
    }
    let interface = InterfaceCost {
        connection_nodes: c as u64,
        precomputed_free: estimate.map_or(0, |e| e.interface.counts.free),
        table_bytes: estimate.map_or(0, |e| e.interface.table_bytes),
        update_s,
    };
    Ok((out, interface, estimate))
}

/// The median of `samples` single timings, s, of `f`.
fn median_s(samples: usize, mut f: impl FnMut()) -> f64 {
    let mut times: Vec<f64> = (0..samples)
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed().as_secs_f64()
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

/// One step of the region's f32 model (module doc), s.
fn tensor_mass_step_s(
    sub: &TetMesh,
    triangles: &[[u32; 3]],
    arrays: &TensorMassArrays,
    options: &CostOptions,
    (law, gamma): (ElasticLaw, Option<f64>),
    dt_s: f64,
) -> anyhow::Result<f64> {
    let bytes = write_tensor_mass_table(sub, triangles, arrays, Precision::F32);
    let table = TensorMassTable::<f32>::load(&bytes)?;
    let mut state = OwnedState::for_table(&table);
    let params = DynamicParams::linear(
        options.damping_per_s as f32,
        diagonal(&sub.positions) as f32,
    )
    .with_law(law)
    .with_incompressibility(gamma.map(|g| g as f32))
    .with_gravity(Vector3::new(0.0, 0.0, -9.81));
    let mut model = TensorMassModel::new(table, state.buffers(), params)?;
    let dt_s = dt_s as f32;
    for _ in 0..WARMUP_STEPS {
        model.step(options.integrator, dt_s)?;
    }
    let mut fault = None;
    let median = median_s(TIMED_STEPS, || {
        if let Err(e) = black_box(model.step(options.integrator, dt_s)) {
            fault = Some(e);
        }
    });
    match fault {
        Some(e) => Err(e.into()),
        None => Ok(median),
    }
}

/// The region's largest stable step (module doc), s; `None` when nothing in it can move.
fn stable_step_s(
    sub: &TetMesh,
    triangles: &[[u32; 3]],
    arrays: &TensorMassArrays,
    options: &CostOptions,
) -> anyhow::Result<Option<f64>> {
    let bytes = write_tensor_mass_table(sub, triangles, arrays, Precision::F64);
    let table = TensorMassTable::<f64>::load(&bytes)?;
    let mut state = OwnedState::for_table(&table);
    let params = DynamicParams::linear(options.damping_per_s, diagonal(&sub.positions));
    let mut model = TensorMassModel::new(table, state.buffers(), params)?;
    let moving = (0..model.modes().len())
        .any(|v| model.modes()[v] == VertexMode::Free && model.masses_kg()[v] > 0.0);
    if !moving {
        return Ok(None);
    }
    let step = stable_step_of_model(
        &mut model,
        options.materials.default_material().young_pa,
        options.damping_per_s,
        options.integrator,
    )?;
    Ok(Some(step.limit_dt_s))
}

/// One interface update (`9c²` multiply-adds: the `3c` row products of the condensed
/// stiffness with the connection displacements, f32, with the kernel's own row product,
/// [`palpate_kernel::math::dense::dot`]), s.
pub fn interface_update_s(c: usize) -> f64 {
    let timed = c.min(MAX_TIMED_CONNECTIONS);
    let n = 3 * timed;
    let matrix: Vec<f32> = (0..n * n).map(|i| (i % 7) as f32 * 0.125).collect();
    let x: Vec<f32> = (0..n).map(|i| (i % 5) as f32).collect();
    let mut y = vec![0.0f32; n];
    let t = median_s(TIMED_PRODUCTS, || {
        for (row, out) in matrix.chunks_exact(n).zip(y.iter_mut()) {
            *out = dot(row, black_box(&x));
        }
        black_box(&mut y);
    });
    let scale = c as f64 / timed as f64;
    t * scale * scale
}

/// One contact solve of [`MAX_CONTACTS`] vertex contacts on the pre-computed model (module
/// doc), s.
pub fn contact_solve_s(material: &Material) -> anyhow::Result<f64> {
    let mesh = box_mesh([4, 4, 4], [0.04; 3]);
    let fix: Vec<FixPredicate> = vec!["z<0.001".parse().map_err(anyhow::Error::msg)?];
    let options = BuildOptions::precomputed(*material, fix, Solver::Cholesky, Precision::F32);
    let built = build(&mesh, &MeshReport::default(), &options)?;
    let table = PrecomputedTable::<f32>::load(&built.bytes)?;
    let model = PrecomputedModel::new(table);
    // Four top vertices (z = 0.04, the 5 × 5 grid's last layer), pressed 1 mm.
    let top = 4 * 25;
    let contacts: Vec<Constraint<f32>> = [6u32, 8, 16, 18]
        .iter()
        .take(MAX_CONTACTS)
        .map(|&v| Constraint::at_vertex(top + v, Vector3::new(0.0, 0.0, -0.001)))
        .collect();
    model.contact_forces::<MAX_CONTACTS>(&contacts)?;
    Ok(median_s(TIMED_SOLVES, || {
        let _ = black_box(model.contact_forces::<MAX_CONTACTS>(black_box(&contacts)));
    }))
}
