//! The partition of a mesh into the hybrid model's regions (MODELS.md §5, RR-3510 §6), chosen
//! from a scene's zones: the smallest set of tets that contains every zone plus `k` element
//! rings is tensor-mass (dynamic, cuttable), the rest pre-computed.
//!
//! - Zone tets: [`TetGrid::select`] (a tet is in a zone when their interiors meet).
//! - Margin: `k` times, every tet sharing a vertex with the set joins it (a breadth-first pass
//!   from the last ring's tets).
//! - Regions: the pre-computed tets form one region (in one or more pieces); the dynamic tets
//!   form one region per connected component. Tets are connected when they share a vertex (a
//!   shared vertex is a shared degree of freedom in either model).
//! - Held faces: a pre-computed tet with a boundary face whose three vertices are all
//!   connection nodes joins the dynamic set: the connection nodes are held in the pre-computed
//!   region's table, so it could answer no contact on that face, while the tensor-mass region
//!   can. Repeated until no such tet remains (each pass only grows the set). Faces held by
//!   fixed vertices are left as they are: the fixed side is where the organ rests.
//! - Connection nodes: vertices of both a dynamic and a pre-computed tet.
//! - Law of a dynamic component: linear (MODELS.md §3) unless it holds a tet of a
//!   large-deformation zone, then St Venant-Kirchhoff (MODELS.md §4), with the incompressibility
//!   penalty when `ν ≥` [`INCOMPRESSIBLE_POISSON`].
//! - Refused ([`PlanError`]): a zone that takes no tet; a dynamic component, or a piece of the
//!   pre-computed region, with no fixed vertex and no connection node (it floats: its stiffness
//!   is singular). A pre-computed region in several pieces is accepted when every piece is held
//!   (each piece's table is independent; the report says how many pieces).
//!
//! Cost: linear in the mesh per ring and per component pass, plus the zone tests of the tets
//! near each zone.

use palpate_kernel::table::format::tet_face_vertices;
use palpate_kernel::tensor_mass::{ElasticLaw, StvkForm};

use super::geometry::TetGrid;
use crate::fix::fixed_vertices;
use crate::mesh::{MeshReport, TetMesh, boundary_face_slots};
use crate::scene::{Scene, Zone, ZoneKind};

/// Poisson ratio from which a St Venant-Kirchhoff region gets the incompressibility penalty
/// (Picinbono 2001 §3.2: nearly incompressible soft tissue; the built-in block's ν = 0.45).
pub const INCOMPRESSIBLE_POISSON: f64 = 0.45;

/// The model of a planned region.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RegionModel {
    /// Quasi-static linear, a compliance table (RR-3510 §4): cheap, cannot be cut.
    Precomputed,
    /// Dynamic tensor-mass (RR-3510 §5): cuttable.
    TensorMass {
        /// The elastic law: [`ElasticLaw::Linear`] or St Venant-Kirchhoff per tet.
        law: ElasticLaw,
        /// Whether the incompressibility penalty applies (St Venant-Kirchhoff, `ν ≥`
        /// [`INCOMPRESSIBLE_POISSON`]).
        incompressibility: bool,
    },
}

impl RegionModel {
    /// `precomputed` or `tensor-mass`.
    pub fn name(&self) -> &'static str {
        match self {
            RegionModel::Precomputed => "precomputed",
            RegionModel::TensorMass { .. } => "tensor-mass",
        }
    }

    /// The law as a scene file names it: `linear`, `stvk` or `stvk-incompressible` (the
    /// pre-computed model is linear).
    pub fn law_name(&self) -> &'static str {
        match self {
            RegionModel::TensorMass {
                law: ElasticLaw::StVenantKirchhoff(_),
                incompressibility: true,
            } => "stvk-incompressible",
            RegionModel::TensorMass {
                law: ElasticLaw::StVenantKirchhoff(_),
                ..
            } => "stvk",
            _ => "linear",
        }
    }
}

/// One region of a [`Partition`].
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedRegion {
    /// The region's id, the VTK cell field `region`: 0 for the pre-computed region, 1, 2, …
    /// for the dynamic components in order of their lowest tet.
    pub id: u32,
    /// Its model.
    pub model: RegionModel,
    /// Its tets, ascending.
    pub tets: Vec<u32>,
    /// Distinct vertices of its tets.
    pub vertices: usize,
    /// Connection nodes among them.
    pub connection_nodes: usize,
    /// Vertex-connected pieces (1 for a dynamic component).
    pub pieces: usize,
    /// Why it got its model, one sentence for people.
    pub why: String,
}

/// The regions of a mesh.
///
/// Invariants: `dynamic.len()` is the mesh's tet count; every tet is in exactly one region; the
/// pre-computed region, if any tets are pre-computed, comes first; `connection_nodes` is
/// ascending.
#[derive(Clone, Debug, PartialEq)]
pub struct Partition {
    /// Per tet: true = dynamic (tensor-mass).
    pub dynamic: Vec<bool>,
    /// Vertices used by both a dynamic and a pre-computed tet, ascending.
    pub connection_nodes: Vec<u32>,
    /// The regions: the pre-computed one (if any tets) and each connected dynamic component.
    pub regions: Vec<PlannedRegion>,
}

/// What [`plan`] needs.
#[derive(Clone, Copy, Debug)]
pub struct PlanInput<'a> {
    /// The mesh.
    pub mesh: &'a TetMesh,
    /// Per vertex, whether it is fixed (`fix::fixed_vertices`).
    pub fixed: &'a [bool],
    /// The zones.
    pub zones: &'a [Zone],
    /// Element rings around the zones.
    pub margin_rings: u32,
    /// Poisson ratio `ν` of the tissue.
    pub poisson: f64,
    /// Names the scene in messages.
    pub scene: &'a str,
    /// Names the mesh in messages.
    pub mesh_name: &'a str,
}

/// Why a partition was refused. Each message is one line starting with the scene.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PlanError {
    /// A zone meets no tet (outside the mesh, or between its parts).
    #[error("{scene}: {zone} contains no tet of mesh {mesh}")]
    EmptyZone {
        /// The scene.
        scene: String,
        /// The zone's label ([`Zone::label`]).
        zone: String,
        /// The mesh.
        mesh: String,
    },
    /// A region (or a piece of the pre-computed one) has no fixed vertex and no connection node.
    #[error(
        "{scene}: {region} ({tets} tets around ({:.4}, {:.4}, {:.4}) m) has no fixed vertex and no connection node: it floats; fix one of its vertices (fix = [...]) or change the [[zone]]s",
        at_m[0], at_m[1], at_m[2]
    )]
    Floating {
        /// The scene.
        scene: String,
        /// Which region: `the pre-computed region` (or a piece of it), `dynamic region 2`.
        region: String,
        /// Its tet count.
        tets: usize,
        /// The centroid of its first tet, m.
        at_m: [f64; 3],
    },
}

impl Partition {
    /// The partition of `scene` on its loaded `mesh` (the scene's fixed vertices, zones,
    /// margin and Poisson ratio).
    pub fn of_scene(
        scene: &Scene,
        mesh: &TetMesh,
        report: &MeshReport,
    ) -> Result<Partition, PlanError> {
        let (fixed, _) = fixed_vertices(&mesh.positions, &scene.fix, &report.unreferenced_vertices);
        plan(&PlanInput {
            mesh,
            fixed: &fixed,
            zones: &scene.zones,
            margin_rings: scene.partition.margin_rings,
            poisson: scene.material.elastic.poisson,
            scene: &scene.source,
            mesh_name: &report.source,
        })
    }

    /// Per tet, the id of its region ([`PlannedRegion::id`]).
    pub fn region_of_tets(&self) -> Vec<u32> {
        let mut ids = vec![0; self.dynamic.len()];
        for r in &self.regions {
            for &t in &r.tets {
                ids[t as usize] = r.id;
            }
        }
        ids
    }
}

/// Per vertex, the tets that use it (CSR: `start[v]..start[v + 1]` of `tets`).
struct VertexTets {
    start: Vec<usize>,
    tets: Vec<u32>,
}

impl VertexTets {
    fn new(mesh: &TetMesh) -> Self {
        let mut start = vec![0usize; mesh.positions.len() + 1];
        for &v in mesh.tets.iter().flatten() {
            start[v as usize + 1] += 1;
        }
        for i in 1..start.len() {
            start[i] += start[i - 1];
        }
        let mut fill = start.clone();
        let mut tets = vec![0u32; start[mesh.positions.len()]];
        for (t, tet) in mesh.tets.iter().enumerate() {
            for &v in tet {
                tets[fill[v as usize]] = t as u32;
                fill[v as usize] += 1;
            }
        }
        Self { start, tets }
    }

    fn of(&self, v: u32) -> &[u32] {
        &self.tets[self.start[v as usize]..self.start[v as usize + 1]]
    }
}

/// Chooses the partition (module doc).
pub fn plan(input: &PlanInput<'_>) -> Result<Partition, PlanError> {
    let mesh = input.mesh;
    let ZoneTets {
        taken,
        mut dynamic,
        large,
    } = zone_tets(input)?;
    let adjacency = VertexTets::new(mesh);
    grow_rings(mesh, &adjacency, &mut dynamic, input.margin_rings);
    absorb_held_faces(mesh, &mut dynamic);
    let connection = connection_vertices(mesh, &dynamic);
    let connection_nodes: Vec<u32> = (0..connection.len() as u32)
        .filter(|&v| connection[v as usize])
        .collect();
    let builder = RegionBuilder {
        input,
        adjacency: &adjacency,
        connection: &connection,
    };
    let mut regions = Vec::new();
    regions.extend(builder.precomputed(&dynamic)?);
    regions.extend(builder.dynamic(&dynamic, &taken, &large)?);
    Ok(Partition {
        dynamic,
        connection_nodes,
        regions,
    })
}

/// The tets the zones take, per tet.
struct ZoneTets {
    /// Per zone, per tet: taken by the zone.
    taken: Vec<Vec<bool>>,
    /// Taken by any zone (the dynamic set before the margin).
    dynamic: Vec<bool>,
    /// Taken by a large-deformation zone.
    large: Vec<bool>,
}

/// The tets each zone of `input` takes ([`TetGrid::select`]); a zone that
/// takes none is refused.
fn zone_tets(input: &PlanInput<'_>) -> Result<ZoneTets, PlanError> {
    let mesh = input.mesh;
    let n_tets = mesh.tets.len();
    let grid = TetGrid::new(mesh);
    let mut zone_tets: Vec<Vec<bool>> = Vec::with_capacity(input.zones.len());
    let mut dynamic = vec![false; n_tets];
    let mut large = vec![false; n_tets];
    for (i, zone) in input.zones.iter().enumerate() {
        let mut taken = vec![false; n_tets];
        if grid.select(&zone.shape, &mut taken) == 0 {
            return Err(PlanError::EmptyZone {
                scene: input.scene.to_owned(),
                zone: zone.label(i),
                mesh: input.mesh_name.to_owned(),
            });
        }
        for t in 0..n_tets {
            if taken[t] {
                dynamic[t] = true;
                if zone.kind == ZoneKind::LargeDeformation {
                    large[t] = true;
                }
            }
        }
        zone_tets.push(taken);
    }
    Ok(ZoneTets {
        taken: zone_tets,
        dynamic,
        large,
    })
}

/// Moves into the `dynamic` set every pre-computed tet with a held boundary face (module doc),
/// pass after pass until none remains: at most one pass per tet, as each pass that changes
/// nothing ends it.
fn absorb_held_faces(mesh: &TetMesh, dynamic: &mut [bool]) {
    let boundary = boundary_face_slots(mesh);
    loop {
        let connection = connection_vertices(mesh, dynamic);
        let mut moved = false;
        for (t, &tet) in mesh.tets.iter().enumerate() {
            let held = |(j, face): (usize, &[u32; 3])| {
                boundary[4 * t + j] && face.iter().all(|&v| connection[v as usize])
            };
            if !dynamic[t] && tet_face_vertices(tet).iter().enumerate().any(held) {
                dynamic[t] = true;
                moved = true;
            }
        }
        if !moved {
            return;
        }
    }
}

/// Per vertex, whether it is a connection node: a vertex of both a
/// `dynamic` tet and a pre-computed one.
fn connection_vertices(mesh: &TetMesh, dynamic: &[bool]) -> Vec<bool> {
    let mut on_dynamic = vec![false; mesh.positions.len()];
    let mut on_static = vec![false; mesh.positions.len()];
    for (tet, &d) in mesh.tets.iter().zip(dynamic) {
        for &v in tet {
            if d {
                on_dynamic[v as usize] = true;
            } else {
                on_static[v as usize] = true;
            }
        }
    }
    on_dynamic
        .iter()
        .zip(&on_static)
        .map(|(a, b)| *a && *b)
        .collect()
}

/// What the regions are built from: the input, the tets around each
/// vertex and the connection nodes (per vertex).
struct RegionBuilder<'a> {
    input: &'a PlanInput<'a>,
    adjacency: &'a VertexTets,
    connection: &'a [bool],
}

impl RegionBuilder<'_> {
    /// Whether `tets` hold a fixed vertex or a connection node.
    fn held(&self, tets: &[u32]) -> bool {
        tets.iter()
            .flat_map(|&t| self.input.mesh.tets[t as usize])
            .any(|v| self.input.fixed.get(v as usize) == Some(&true) || self.connection[v as usize])
    }

    /// The refusal of `region`, its `tets` floating.
    fn floating(&self, region: String, tets: &[u32]) -> PlanError {
        PlanError::Floating {
            scene: self.input.scene.to_owned(),
            region,
            tets: tets.len(),
            at_m: self.input.mesh.tet_centroid(tets[0] as usize),
        }
    }

    /// The region `id` of `tets` (ascending) with its model, pieces and
    /// reason, its vertices and connection nodes counted.
    fn region(
        &self,
        id: u32,
        model: RegionModel,
        pieces: usize,
        tets: Vec<u32>,
        why: String,
    ) -> PlannedRegion {
        let vertices = distinct_vertices(self.input.mesh, &tets);
        PlannedRegion {
            id,
            model,
            vertices: vertices.len(),
            connection_nodes: vertices
                .iter()
                .filter(|&&v| self.connection[v as usize])
                .count(),
            pieces,
            tets,
            why,
        }
    }

    /// The pre-computed region (region 0), if any tet is not `dynamic`:
    /// refused if a piece of it floats.
    fn precomputed(&self, dynamic: &[bool]) -> Result<Option<PlannedRegion>, PlanError> {
        let static_pieces = components(self.input.mesh, self.adjacency, dynamic, false);
        if static_pieces.is_empty() {
            return Ok(None);
        }
        let several = static_pieces.len() > 1;
        for (i, piece) in static_pieces.iter().enumerate() {
            if !self.held(piece) {
                let region = if several {
                    format!(
                        "piece {} of {} of the pre-computed region",
                        i + 1,
                        static_pieces.len()
                    )
                } else {
                    "the pre-computed region".to_owned()
                };
                return Err(self.floating(region, piece));
            }
        }
        let mut tets: Vec<u32> = static_pieces.concat();
        tets.sort_unstable();
        let why = precomputed_why(self.input, static_pieces.len());
        Ok(Some(self.region(
            0,
            RegionModel::Precomputed,
            static_pieces.len(),
            tets,
            why,
        )))
    }

    /// The dynamic regions (1, 2, …), one per connected component of the
    /// `dynamic` tets, each with its law (St Venant-Kirchhoff when it holds
    /// a `large`-deformation tet) and the zones (`taken`) it serves:
    /// refused if one floats.
    fn dynamic(
        &self,
        dynamic: &[bool],
        taken: &[Vec<bool>],
        large: &[bool],
    ) -> Result<Vec<PlannedRegion>, PlanError> {
        let input = self.input;
        let mut regions = Vec::new();
        for (i, tets) in components(input.mesh, self.adjacency, dynamic, true)
            .into_iter()
            .enumerate()
        {
            let id = i as u32 + 1;
            if !self.held(&tets) {
                return Err(self.floating(format!("dynamic region {id}"), &tets));
            }
            let stvk = tets.iter().any(|&t| large[t as usize]);
            let incompressibility = stvk && input.poisson >= INCOMPRESSIBLE_POISSON;
            let model = RegionModel::TensorMass {
                law: if stvk {
                    ElasticLaw::StVenantKirchhoff(StvkForm::PerTet)
                } else {
                    ElasticLaw::Linear
                },
                incompressibility,
            };
            let zones: Vec<usize> = (0..input.zones.len())
                .filter(|&z| tets.iter().any(|&t| taken[z][t as usize]))
                .collect();
            let whole = tets.len() == input.mesh.tets.len();
            let why = dynamic_why(input, &zones, model, whole);
            regions.push(self.region(id, model, 1, tets, why));
        }
        Ok(regions)
    }
}

/// Adds `rings` element rings to `set`: each ring, every tet sharing a vertex with the tets the
/// previous ring added (the zones' tets first).
fn grow_rings(mesh: &TetMesh, adjacency: &VertexTets, set: &mut [bool], rings: u32) {
    let mut frontier: Vec<u32> = (0..set.len() as u32).filter(|&t| set[t as usize]).collect();
    for _ in 0..rings {
        let mut next = Vec::new();
        for &t in &frontier {
            for &v in &mesh.tets[t as usize] {
                for &u in adjacency.of(v) {
                    if !set[u as usize] {
                        set[u as usize] = true;
                        next.push(u);
                    }
                }
            }
        }
        if next.is_empty() {
            break;
        }
        frontier = next;
    }
}

/// The vertex-connected components of the tets whose `dynamic` flag equals `which`, each
/// ascending, in order of their lowest tet.
fn components(
    mesh: &TetMesh,
    adjacency: &VertexTets,
    dynamic: &[bool],
    which: bool,
) -> Vec<Vec<u32>> {
    let mut seen: Vec<bool> = dynamic.iter().map(|&d| d != which).collect();
    let mut out = Vec::new();
    for first in 0..dynamic.len() {
        if seen[first] {
            continue;
        }
        seen[first] = true;
        let mut part = vec![first as u32];
        let mut next = 0;
        while let Some(&t) = part.get(next) {
            next += 1;
            for &v in &mesh.tets[t as usize] {
                for &u in adjacency.of(v) {
                    if !seen[u as usize] {
                        seen[u as usize] = true;
                        part.push(u);
                    }
                }
            }
        }
        part.sort_unstable();
        out.push(part);
    }
    out
}

/// The distinct vertices of `tets`, ascending.
pub fn distinct_vertices(mesh: &TetMesh, tets: &[u32]) -> Vec<u32> {
    let mut v: Vec<u32> = tets.iter().flat_map(|&t| mesh.tets[t as usize]).collect();
    v.sort_unstable();
    v.dedup();
    v
}

/// Why the pre-computed region is pre-computed.
fn precomputed_why(input: &PlanInput<'_>, pieces: usize) -> String {
    let mut why = if input.zones.is_empty() {
        "no [[zone]]: nothing is cut or deformed past the linear range, so the whole mesh is \
         pre-computed (quasi-static linear, the cheapest per tick; RR-3510 §4)"
            .to_owned()
    } else {
        format!(
            "outside every [[zone]] and its {}-ring margin: quasi-static linear, the cheapest per \
             tick, not cuttable (RR-3510 §4)",
            input.margin_rings
        )
    };
    if pieces > 1 {
        why.push_str(&format!(
            "; in {pieces} pieces, each held by a fixed vertex or a connection node"
        ));
    }
    why
}

/// Why a dynamic component is tensor-mass with its law.
fn dynamic_why(input: &PlanInput<'_>, zones: &[usize], model: RegionModel, whole: bool) -> String {
    let labels: Vec<String> = zones.iter().map(|&z| input.zones[z].label(z)).collect();
    let cut = zones.iter().any(|&z| input.zones[z].kind == ZoneKind::Cut);
    let mut why = format!(
        "tensor-mass (RR-3510 §5) for {} plus {} element rings{}",
        labels.join(", "),
        input.margin_rings,
        if cut { ": cuttable" } else { "" }
    );
    match model {
        RegionModel::TensorMass {
            law: ElasticLaw::StVenantKirchhoff(_),
            incompressibility,
        } => {
            why.push_str(
                "; St Venant-Kirchhoff (MODELS.md §4): a large-deformation zone goes past the \
                 linear model's validity (about 10 % of the object's size, MODELS.md §2)",
            );
            if incompressibility {
                why.push_str(&format!(
                    ", with the incompressibility penalty (nu = {} >= {INCOMPRESSIBLE_POISSON})",
                    input.poisson
                ));
            }
        }
        _ => why.push_str("; linear: no large-deformation zone in it"),
    }
    if whole {
        why.push_str("; the zones and margin cover the whole mesh: no pre-computed region");
    }
    why
}
