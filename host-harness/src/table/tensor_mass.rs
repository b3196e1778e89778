//! Tensor-mass arrays (RR-3510 §5, MODELS.md §1 and §3) and their table file:
//! vertex tensors `K_ii`, edge tensors `K_ij` on a CSR edge list (each edge
//! once), lumped masses, and per tet its vertices, edge references, rest
//! shape data and face neighbours; and the St Venant-Kirchhoff cubic and
//! quartic terms on vertices, edges, mesh triangles (every tet face once) and
//! tets (Picinbono 2001 §3.1, table 1), each the sum of the kernel's
//! `tet_terms` over the tets around the primitive.

use std::collections::HashMap;

use bytemuck::Zeroable;
use nalgebra::Vector3;
use palpate_kernel::math::element::stiffness_block;
use palpate_kernel::table::format::{
    EDGE_TERMS_LEN, NO_NEIGHBOUR, RawHeader, SectionKind, TET_EDGE_PAIRS, TET_LANE_ROWS, TET_LANES,
    TET_SHAPE_LEN, TET_TERMS_LEN, TRIANGLE_TERMS_LEN, TableKind, VERTEX_TERMS_LEN,
    tet_edge_vertices, tet_face_vertices,
};
use palpate_kernel::tensor_mass::stvk_terms::{TermArraysMut, TetPlace, tet_terms};

use super::file::{Precision, Section, write_container};
use crate::fem::assembly::FreeOrdering;
use crate::fem::element::shape_gradients;
use crate::fem::material::TetMaterials;
use crate::mesh::TetMesh;

/// The arrays of a tensor-mass table, in f64 before rounding.
#[derive(Clone, Debug, PartialEq)]
pub struct TensorMassArrays {
    /// Each tet's material the tensors and terms were assembled with (its
    /// Lamé coefficients are the `tet-material` section, its default the
    /// header's `young_pa` and `poisson`).
    pub materials: TetMaterials,
    /// Mass density the masses were lumped with, kg/m³ (the header's).
    pub density_kg_m3: f64,
    /// `true` for fixed vertices (N).
    pub fixed: Vec<bool>,
    /// Lumped masses `ρ Σ V/4`, kg (N).
    pub masses_kg: Vec<f64>,
    /// `K_ii`, row-major, N/m (N).
    pub vertex_tensors: Vec<[f64; 9]>,
    /// CSR row starts (N + 1).
    pub row_start: Vec<u32>,
    /// CSR columns `j > i` (E).
    pub column: Vec<u32>,
    /// `K_ij`, `i < j`, row-major, N/m (E).
    pub edge_tensors: Vec<[f64; 9]>,
    /// Edge index of each tet's vertex pairs, `tet_edge_vertices` order.
    pub tet_edges: Vec<[u32; 6]>,
    /// Rest gradients `a_0..a_3` (1/m) and volume (m³) per tet.
    pub tet_shapes: Vec<[f64; TET_SHAPE_LEN]>,
    /// Tet across the face opposite each vertex, or `NO_NEIGHBOUR`.
    pub neighbours: Vec<[u32; 4]>,
    /// St Venant-Kirchhoff terms of each vertex `[c.x, c.y, c.z, d]`
    /// (N/m², N/m³), one per vertex.
    pub vertex_terms: Vec<[f64; VERTEX_TERMS_LEN]>,
    /// St Venant-Kirchhoff terms of each CSR edge (E).
    pub edge_terms: Vec<[f64; EDGE_TERMS_LEN]>,
    /// Every tet face once, ids ascending, sorted lexicographically.
    pub mesh_triangles: Vec<[u32; 3]>,
    /// St Venant-Kirchhoff terms of each mesh triangle.
    pub triangle_terms: Vec<[f64; TRIANGLE_TERMS_LEN]>,
    /// Mesh-triangle index of each tet's face opposite each local vertex.
    pub tet_triangles: Vec<[u32; 4]>,
    /// St Venant-Kirchhoff quartic terms of each tet (N/m³).
    pub tet_terms: Vec<[f64; TET_TERMS_LEN]>,
}

impl TensorMassArrays {
    /// Assembles the arrays of `mesh` (positions in m) for the per-tet
    /// `materials`, density `density_kg_m3` and the `fixed` flags (one per
    /// vertex). Every block comes from the kernel's `stiffness_block`, and
    /// every St Venant-Kirchhoff term from the kernel's `tet_terms`, each with
    /// its tet's Lamé coefficients: the formulas the kernel subtracts when it
    /// removes a tet.
    ///
    /// # Panics
    /// If `materials` is not for `mesh.tets.len()` tets.
    pub fn new(
        mesh: &TetMesh,
        materials: &TetMaterials,
        density_kg_m3: f64,
        fixed: Vec<bool>,
    ) -> Self {
        assert_eq!(materials.len(), mesh.tets.len(), "one material per tet");
        let n = mesh.positions.len();
        let (row_start, column) = edge_csr(n, &mesh.tets);
        let edge_index = |a: u32, b: u32| -> u32 {
            let (lo, hi) = (a.min(b), a.max(b));
            let start = row_start[lo as usize];
            let row = &column[start as usize..row_start[lo as usize + 1] as usize];
            start + row.binary_search(&hi).expect("edge of a tet is in the CSR") as u32
        };
        let mesh_triangles = mesh_triangles(&mesh.tets);
        let tet_triangles: Vec<[u32; 4]> = mesh
            .tets
            .iter()
            .map(|&tet| {
                tet_face_vertices(tet).map(|mut face| {
                    face.sort_unstable();
                    mesh_triangles
                        .binary_search(&face)
                        .expect("face of a tet is a mesh triangle") as u32
                })
            })
            .collect();
        let mut arrays = Self {
            materials: materials.clone(),
            density_kg_m3,
            fixed,
            masses_kg: vec![0.0; n],
            vertex_tensors: vec![[0.0; 9]; n],
            edge_tensors: vec![[0.0; 9]; column.len()],
            tet_edges: Vec::with_capacity(mesh.tets.len()),
            tet_shapes: Vec::with_capacity(mesh.tets.len()),
            neighbours: face_neighbours(&mesh.tets),
            row_start: row_start.clone(),
            vertex_terms: vec![[0.0; VERTEX_TERMS_LEN]; n],
            edge_terms: vec![[0.0; EDGE_TERMS_LEN]; column.len()],
            triangle_terms: vec![[0.0; TRIANGLE_TERMS_LEN]; mesh_triangles.len()],
            tet_terms: vec![[0.0; TET_TERMS_LEN]; mesh.tets.len()],
            mesh_triangles,
            tet_triangles,
            column: column.clone(),
        };
        for (tet, material) in mesh.tets.iter().zip(materials.per_tet()) {
            let (lambda, mu) = material.lame();
            let p = tet.map(|v| mesh.positions[v as usize]);
            let (a, volume) = shape_gradients(&p);
            let a = a.map(Vector3::from);
            let block = |j: usize, k: usize| -> [f64; 9] {
                let b = stiffness_block(&a[j], &a[k], volume, lambda, mu);
                core::array::from_fn(|e| b[(e / 3, e % 3)])
            };
            for (j, &v) in tet.iter().enumerate() {
                add(&mut arrays.vertex_tensors[v as usize], &block(j, j));
                arrays.masses_kg[v as usize] += density_kg_m3 * volume / 4.0;
            }
            let edges = tet_edge_vertices(*tet).map(|[a, b]| edge_index(a, b));
            for (&[j, k], &e) in TET_EDGE_PAIRS.iter().zip(&edges) {
                // The stored tensor couples the lower vertex (row) to the higher.
                let (row, col) = if tet[j] < tet[k] { (j, k) } else { (k, j) };
                add(&mut arrays.edge_tensors[e as usize], &block(row, col));
            }
            let place = TetPlace {
                tet: arrays.tet_edges.len() as u32,
                vertices: *tet,
                edges,
                triangles: arrays.tet_triangles[arrays.tet_edges.len()],
            };
            let terms = tet_terms(*tet, &a, volume, lambda, mu);
            terms.add_to(
                &place,
                &mut TermArraysMut {
                    vertex: &mut arrays.vertex_terms,
                    edge: &mut arrays.edge_terms,
                    triangle: &mut arrays.triangle_terms,
                    tet: &mut arrays.tet_terms,
                },
            );
            arrays.tet_edges.push(edges);
            let mut shape = [0.0; TET_SHAPE_LEN];
            for (j, aj) in a.iter().enumerate() {
                shape[3 * j..3 * j + 3].copy_from_slice(aj.as_slice());
            }
            shape[12] = volume;
            arrays.tet_shapes.push(shape);
        }
        arrays
    }
}

/// The `tet-lanes` section of `shapes` and `lame` (per tet): blocks of
/// [`TET_LANES`] tets, row `r` of a block holding value `r` of each tet's
/// `a_1, a_2, a_3` (by component), volume, `λ`, `μ` in the tet's lane,
/// zero past the last tet (format: `SectionKind::TetLanes`).
fn tet_lanes(
    shapes: &[[f64; TET_SHAPE_LEN]],
    lame: &[[f64; 2]],
) -> Vec<[[f64; TET_LANES]; TET_LANE_ROWS]> {
    let mut blocks = vec![[[0.0; TET_LANES]; TET_LANE_ROWS]; shapes.len().div_ceil(TET_LANES)];
    for (t, (shape, &[lambda, mu])) in shapes.iter().zip(lame).enumerate() {
        let block = &mut blocks[t / TET_LANES];
        let material = [lambda, mu];
        let rows = shape[3..].iter().chain(&material);
        for (row, &x) in block.iter_mut().zip(rows) {
            row[t % TET_LANES] = x;
        }
    }
    blocks
}

fn add(target: &mut [f64; 9], block: &[f64; 9]) {
    for (t, b) in target.iter_mut().zip(block) {
        *t += b;
    }
}

/// The edges `(i, j)`, `i < j`, of every tet as a CSR: row starts (N + 1)
/// and ascending columns.
fn edge_csr(n: usize, tets: &[[u32; 4]]) -> (Vec<u32>, Vec<u32>) {
    let mut pairs: Vec<[u32; 2]> = tets
        .iter()
        .flat_map(|&t| tet_edge_vertices(t))
        .map(|[a, b]| [a.min(b), a.max(b)])
        .collect();
    pairs.sort_unstable();
    pairs.dedup();
    let mut row_start = vec![0u32; n + 1];
    for &[i, _] in &pairs {
        row_start[i as usize + 1] += 1;
    }
    for i in 0..n {
        row_start[i + 1] += row_start[i];
    }
    (row_start, pairs.iter().map(|&[_, j]| j).collect())
}

/// Every face of every tet once, vertex ids ascending, sorted.
fn mesh_triangles(tets: &[[u32; 4]]) -> Vec<[u32; 3]> {
    let mut faces: Vec<[u32; 3]> = tets
        .iter()
        .flat_map(|&t| tet_face_vertices(t))
        .map(|mut face| {
            face.sort_unstable();
            face
        })
        .collect();
    faces.sort_unstable();
    faces.dedup();
    faces
}

/// For each tet and local face (opposite vertex `j`), the tet sharing it.
fn face_neighbours(tets: &[[u32; 4]]) -> Vec<[u32; 4]> {
    let mut owner: HashMap<[u32; 3], (u32, usize)> = HashMap::with_capacity(tets.len() * 2);
    let mut neighbours = vec![[NO_NEIGHBOUR; 4]; tets.len()];
    for (t, &tet) in tets.iter().enumerate() {
        for (j, mut face) in tet_face_vertices(tet).into_iter().enumerate() {
            face.sort_unstable();
            if let Some((other, k)) = owner.remove(&face) {
                neighbours[t][j] = other;
                neighbours[other as usize][k] = t as u32;
            } else {
                owner.insert(face, (t as u32, j));
            }
        }
    }
    neighbours
}

/// The f64 tensor-mass table of `mesh` (`materials`, `fixed` vertices, its
/// boundary surface, density 1000 kg/m³) for the static studies (the volume
/// experiment, the compression sample, the Newton reference's checks): an
/// equilibrium does not depend on the mass.
pub fn static_study_table(
    mesh: &TetMesh,
    materials: &TetMaterials,
    fixed: Vec<bool>,
) -> crate::table::load::TableFile {
    let arrays = TensorMassArrays::new(mesh, materials, 1000.0, fixed);
    crate::table::load::TableFile::from_bytes(&write_tensor_mass_table(
        mesh,
        &crate::mesh::boundary_surface(mesh).triangles,
        &arrays,
        Precision::F64,
    ))
}

/// Serializes `arrays` of `mesh` with its boundary `triangles` (outward,
/// [`boundary_surface`](crate::mesh::boundary_surface)) as a tensor-mass
/// table (`TableKind::TensorMass`) with floats of `precision`. The free
/// vertices are numbered in vertex order (no touchable split: the model
/// finds its contacts on the deforming surface), the fixed ones stored as
/// the format's `FIXED_SLOT`.
pub fn write_tensor_mass_table(
    mesh: &TetMesh,
    triangles: &[[u32; 3]],
    arrays: &TensorMassArrays,
    precision: Precision,
) -> Vec<u8> {
    let ordering = FreeOrdering::new(mesh.positions.len(), &arrays.fixed, &[]);
    let header = RawHeader {
        table_kind: TableKind::TensorMass as u32,
        vertex_count: mesh.positions.len() as u32,
        tet_count: mesh.tets.len() as u32,
        free_count: ordering.free_count() as u32,
        triangle_count: triangles.len() as u32,
        edge_count: arrays.column.len() as u32,
        young_pa: arrays.materials.default_material().young_pa,
        poisson: arrays.materials.default_material().poisson,
        density_kg_m3: arrays.density_kg_m3,
        mesh_hash: mesh.content_hash(),
        mesh_triangle_count: arrays.mesh_triangles.len() as u64,
        ..RawHeader::zeroed()
    };
    let p = precision;
    let lame = arrays.materials.lame();
    let sections = [
        Section::ints(SectionKind::VertexSlot, &ordering.slot_entries()),
        Section::floats(SectionKind::RestPositions, &mesh.positions, p),
        Section::ints(SectionKind::SurfaceTriangles, triangles),
        Section::floats(SectionKind::LumpedMass, &arrays.masses_kg, p),
        Section::floats(SectionKind::VertexTensor, &arrays.vertex_tensors, p),
        Section::ints(SectionKind::EdgeRowStart, &arrays.row_start),
        Section::ints(SectionKind::EdgeColumn, &arrays.column),
        Section::floats(SectionKind::EdgeTensor, &arrays.edge_tensors, p),
        Section::ints(SectionKind::Tet, &mesh.tets),
        Section::ints(SectionKind::TetEdge, &arrays.tet_edges),
        Section::floats(SectionKind::TetShape, &arrays.tet_shapes, p),
        Section::ints(SectionKind::TetNeighbour, &arrays.neighbours),
        Section::floats(SectionKind::VertexTerms, &arrays.vertex_terms, p),
        Section::floats(SectionKind::EdgeTerms, &arrays.edge_terms, p),
        Section::ints(SectionKind::MeshTriangle, &arrays.mesh_triangles),
        Section::floats(SectionKind::TriangleTerms, &arrays.triangle_terms, p),
        Section::ints(SectionKind::TetTriangle, &arrays.tet_triangles),
        Section::floats(SectionKind::TetTerms, &arrays.tet_terms, p),
        Section::floats(SectionKind::TetMaterial, &lame, p),
        Section::floats(
            SectionKind::TetLanes,
            &tet_lanes(&arrays.tet_shapes, &lame),
            p,
        ),
    ];
    write_container(header, p, &sections)
}
