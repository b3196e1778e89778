//! Boundary surface extraction and closed/manifold checks.

use std::collections::HashMap;

// The four faces of a positively oriented tet, each with an outward right-hand normal (the
// kernel's convention, shared with the tensor-mass face neighbours).
use palpate_kernel::table::format::tet_face_vertices as faces;

use super::TetMesh;

/// Boundary surface of a tet mesh: the faces that belong to exactly one tet.
///
/// Each triangle is oriented outward: its right-hand normal `(b-a)×(c-a)` points out of the tet it
/// belongs to. Triangles come in tet order, then face order (faces opposite vertex 0, 1, 2, 3).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Surface {
    /// Boundary triangles as 0-based vertex indices into the mesh.
    pub triangles: Vec<[u32; 3]>,
    /// Vertices used by some boundary triangle: sorted ascending, unique.
    pub vertices: Vec<u32>,
}

fn sorted3(mut f: [u32; 3]) -> [u32; 3] {
    f.sort_unstable();
    f
}

/// How many tets use each face.
fn face_counts(mesh: &TetMesh) -> HashMap<[u32; 3], u32> {
    let mut counts: HashMap<[u32; 3], u32> = HashMap::with_capacity(mesh.tets.len() * 3);
    for &t in &mesh.tets {
        for f in faces(t) {
            *counts.entry(sorted3(f)).or_insert(0) += 1;
        }
    }
    counts
}

/// Extract the outward-oriented boundary surface (faces used by exactly one tet).
pub fn boundary_surface(mesh: &TetMesh) -> Surface {
    boundary_from(mesh, &face_counts(mesh))
}

fn boundary_from(mesh: &TetMesh, counts: &HashMap<[u32; 3], u32>) -> Surface {
    let mut triangles = Vec::new();
    for &t in &mesh.tets {
        for f in faces(t) {
            if counts.get(&sorted3(f)) == Some(&1) {
                triangles.push(f);
            }
        }
    }
    let mut vertices: Vec<u32> = triangles.iter().flatten().copied().collect();
    vertices.sort_unstable();
    vertices.dedup();
    Surface {
        triangles,
        vertices,
    }
}

/// Warnings about the boundary: faces shared by more than two tets, boundary edges not shared by
/// exactly two boundary triangles (open or non-manifold surface).
pub(crate) fn check(mesh: &TetMesh) -> Vec<String> {
    let mut warnings = Vec::new();
    let counts = face_counts(mesh);
    let mut over: Vec<[u32; 3]> = counts
        .iter()
        .filter(|(_, c)| **c > 2)
        .map(|(f, _)| *f)
        .collect();
    if !over.is_empty() {
        over.sort_unstable();
        warnings.push(format!(
            "non-manifold: {} faces shared by more than 2 tets (first: {:?})",
            over.len(),
            over.first().copied().unwrap_or_default()
        ));
    }
    let surf = boundary_from(mesh, &counts);
    let mut edges: HashMap<[u32; 2], u32> = HashMap::with_capacity(surf.triangles.len() * 2);
    for tri in &surf.triangles {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            *edges.entry([a.min(b), a.max(b)]).or_insert(0) += 1;
        }
    }
    let mut bad: Vec<([u32; 2], u32)> = edges.into_iter().filter(|(_, c)| *c != 2).collect();
    if !bad.is_empty() {
        bad.sort_unstable();
        let open = bad.iter().filter(|(_, c)| *c < 2).count();
        let nonmanifold = bad.len() - open;
        let (e, c) = bad.first().copied().unwrap_or_default();
        warnings.push(format!(
            "boundary surface not closed/manifold: {open} open edges and {nonmanifold} \
             non-manifold edges not shared by exactly 2 boundary triangles \
             (first: edge {e:?} in {c} triangles)"
        ));
    }
    warnings
}
