//! What `palpate scene plan` prints: per region its model, law, sizes, predicted step cost,
//! stable step and why; the interface; as text or as the JSON object of the contract
//! (`{"regions": [...], "connection_nodes": N}`, extra keys allowed).

use core::fmt::Write as _;

use palpate_kernel::tensor_mass::Integrator;
use serde::Serialize;

use super::cost::{CostOptions, InterfaceCost, RegionCost, costs};
use super::plan::{Partition, RegionModel};
use crate::fix::fixed_vertices;
use crate::limits::human_bytes;
use crate::limits::{MAX_TABLE_FILE_BYTES, mem_available_bytes};
use crate::mesh::{MeshReport, TetMesh};
use crate::scene::{ModelSpec, Scene};

/// One region of the JSON report.
#[derive(Clone, Debug, Serialize)]
pub struct RegionReport {
    /// The region's id (the VTK cell field `region`).
    pub region: u32,
    /// `precomputed` or `tensor-mass`.
    pub model: &'static str,
    /// `linear`, `stvk` or `stvk-incompressible`.
    pub law: &'static str,
    /// Tets.
    pub tets: usize,
    /// Distinct vertices of its tets.
    pub vertices: usize,
    /// Connection nodes among them.
    pub connection_nodes: usize,
    /// Vertex-connected pieces.
    pub pieces: usize,
    /// Its table, bytes (f32): for the pre-computed region, the estimate the hybrid build
    /// checks before it starts.
    pub table_bytes: u64,
    /// Why a session would refuse to build this table (above the largest table file, or the
    /// hybrid build's peak above the memory available now), or `null` when it fits.
    pub refused: Option<String>,
    /// Predicted time of a step (tensor-mass, with the interface update) or a tick
    /// (pre-computed: the contact solve, with the interface solves), s.
    pub step_cost_s: f64,
    /// Largest stable step, s; `null` for the pre-computed region.
    pub critical_dt_s: Option<f64>,
    /// Why it got its model.
    pub why: String,
}

/// The interface of the JSON report.
#[derive(Clone, Debug, Serialize)]
pub struct InterfaceReport {
    /// Connection nodes `c`.
    pub connection_nodes: u64,
    /// Free vertices of the pre-computed region, connection nodes counted fixed (`F_P`).
    pub precomputed_free: u64,
    /// The interface table, bytes (f32).
    pub table_bytes: u64,
    /// Why a session would refuse to build it (see [`RegionReport::refused`]), or `null`.
    pub refused: Option<String>,
    /// One interface update, s.
    pub update_s: f64,
}

/// The JSON object of `scene plan --json`.
#[derive(Clone, Debug, Serialize)]
pub struct PlanReport {
    /// The regions, the pre-computed one first.
    pub regions: Vec<RegionReport>,
    /// Connection nodes of the whole partition.
    pub connection_nodes: usize,
    /// The interface.
    pub interface: InterfaceReport,
    /// Element rings of the margin.
    pub margin_rings: u32,
    /// The tensor-mass regions' integrator (timing and stable step).
    pub integrator: &'static str,
    /// The mesh's tets.
    pub mesh_tets: usize,
    /// The mesh's vertices.
    pub mesh_vertices: usize,
}

/// The cost options of `scene` on `mesh`: its materials per tet (`Scene::tet_materials`, the
/// sessions' own, with their checks), its tool's radius, and its dynamic settings when
/// `[model]` is dynamic, else symplectic Euler without damping (its undamped bound
/// `2/ω_max`), and a hybrid's interface compressed as its `[tables]` says.
pub fn cost_options(
    scene: &Scene,
    mesh: &TetMesh,
    report: &MeshReport,
) -> anyhow::Result<CostOptions> {
    let materials = scene.tet_materials(mesh, report)?;
    let (integrator, damping_per_s, incompressibility_n) = match &scene.model {
        ModelSpec::Dynamic(d) => (d.integrator, d.damping_per_s, d.incompressibility_n),
        ModelSpec::Precomputed => (Integrator::SymplecticEuler, 0.0, None),
    };
    Ok(CostOptions {
        materials,
        tool_radius_m: scene.tool.radius_m,
        density_kg_m3: scene.material.density_kg_m3,
        integrator,
        damping_per_s,
        incompressibility_n,
        interface_compression: scene.tables.interface_compression(),
    })
}

impl PlanReport {
    /// The report of `partition`, a plan of `scene` on `mesh`: every region's and the
    /// interface's costs ([`costs`]).
    pub fn new(
        scene: &Scene,
        mesh: &TetMesh,
        report: &MeshReport,
        partition: &Partition,
    ) -> anyhow::Result<PlanReport> {
        scene.check_on_mesh(mesh)?;
        let options = cost_options(scene, mesh, report)?;
        let (fixed, _) = fixed_vertices(&mesh.positions, &scene.fix, &report.unreferenced_vertices);
        let (region_costs, interface, estimate) = costs(mesh, &fixed, partition, &options)?;
        // What the session's build would say: each table against the largest table file,
        // and the hybrid build's peak against the memory available now.
        let short_of_memory = estimate.and_then(|e| {
            let available = mem_available_bytes()?;
            (e.peak_bytes > available).then(|| {
                format!(
                    "the hybrid build needs about {} of memory, only {} is available \
                     (MemAvailable)",
                    human_bytes(e.peak_bytes),
                    human_bytes(available)
                )
            })
        });
        let refused = |bytes: u64, built_with_hybrid: bool| -> Option<String> {
            if bytes > MAX_TABLE_FILE_BYTES {
                Some(format!(
                    "{} is above the largest table file, {} (MAX_TABLE_FILE_BYTES)",
                    human_bytes(bytes),
                    human_bytes(MAX_TABLE_FILE_BYTES)
                ))
            } else if built_with_hybrid {
                short_of_memory.clone()
            } else {
                None
            }
        };
        Ok(PlanReport {
            regions: partition
                .regions
                .iter()
                .zip(region_costs)
                .map(|(r, c): (_, RegionCost)| RegionReport {
                    region: r.id,
                    model: r.model.name(),
                    law: r.model.law_name(),
                    tets: r.tets.len(),
                    vertices: r.vertices,
                    connection_nodes: r.connection_nodes,
                    pieces: r.pieces,
                    table_bytes: c.table_bytes,
                    refused: refused(c.table_bytes, r.model == RegionModel::Precomputed),
                    step_cost_s: c.step_cost_s,
                    critical_dt_s: c.critical_dt_s,
                    why: r.why.clone(),
                })
                .collect(),
            connection_nodes: partition.connection_nodes.len(),
            interface: InterfaceReport {
                refused: refused(interface.table_bytes, interface.connection_nodes > 0),
                ..interface_report(&interface)
            },
            margin_rings: scene.partition.margin_rings,
            integrator: options.integrator.name(),
            mesh_tets: mesh.tets.len(),
            mesh_vertices: mesh.positions.len(),
        })
    }

    /// The report for people: one block per region, then the interface.
    pub fn text(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "{} tets, {} vertices: {} region(s), {} connection node(s), margin {} ring(s)",
            self.mesh_tets,
            self.mesh_vertices,
            self.regions.len(),
            self.connection_nodes,
            self.margin_rings
        );
        for r in &self.regions {
            let _ = writeln!(s, "region {}: {} ({})", r.region, r.model, r.law);
            let _ = writeln!(
                s,
                "  tets {}, vertices {}, connection nodes {}{}",
                r.tets,
                r.vertices,
                r.connection_nodes,
                if r.pieces > 1 {
                    format!(", {} pieces", r.pieces)
                } else {
                    String::new()
                }
            );
            let _ = writeln!(
                s,
                "  table {}, step cost {:.3e} s, critical dt {}",
                human_bytes(r.table_bytes),
                r.step_cost_s,
                r.critical_dt_s
                    .map_or("none (unconditionally stable)".into(), |dt| format!(
                        "{dt:.3e} s ({})",
                        self.integrator
                    ))
            );
            if let Some(refused) = &r.refused {
                let _ = writeln!(
                    s,
                    "  REFUSED: a session would not build this table: {refused}"
                );
            }
            let _ = writeln!(s, "  why: {}", r.why);
        }
        let i = &self.interface;
        if i.connection_nodes > 0 {
            let _ = writeln!(
                s,
                "interface: {} connection nodes, {} free pre-computed vertices, table {}, update {:.3e} s",
                i.connection_nodes,
                i.precomputed_free,
                human_bytes(i.table_bytes),
                i.update_s
            );
            if let Some(refused) = &i.refused {
                let _ = writeln!(
                    s,
                    "  REFUSED: a session would not build this table: {refused}"
                );
            }
        } else {
            let _ = writeln!(s, "interface: none (a single model)");
        }
        s
    }
}

fn interface_report(i: &InterfaceCost) -> InterfaceReport {
    InterfaceReport {
        connection_nodes: i.connection_nodes,
        precomputed_free: i.precomputed_free,
        table_bytes: if i.connection_nodes > 0 {
            i.table_bytes
        } else {
            0
        },
        update_s: i.update_s,
        refused: None,
    }
}
