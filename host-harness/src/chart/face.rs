//! Consistent face loads: a traction `t(x)` (N/m²) integrated over the
//! loaded face's triangles, `f_i = ∫ N_i t dA` per node, so that a load is
//! the same continuous load on every mesh and element (P1: the three
//! corners; P2: the corners and the three mid-edge nodes) and the charted
//! displacement ([`super::tip_m`], the work-conjugate mean `Σ f·u / Σ|f|`
//! of `∫ t·u dA`) converges with refinement. Equal shares per vertex, the
//! study's former loads, are a different traction on every mesh.

use std::collections::BTreeMap;

use nalgebra::Vector3;

/// Triangle quadrature of degree 4 (Dunavant 1985, 6 points): barycentric
/// coordinates and weights (summing to 1). Exact for the P2 shape
/// functions (degree 2) times a traction linear in `x` (the twist's).
const RULE: [([f64; 3], f64); 6] = {
    const A: f64 = 0.445_948_490_915_965;
    const WA: f64 = 0.223_381_589_678_011;
    const B: f64 = 0.091_576_213_509_771;
    const WB: f64 = 0.109_951_743_655_322;
    [
        ([A, A, 1.0 - 2.0 * A], WA),
        ([A, 1.0 - 2.0 * A, A], WA),
        ([1.0 - 2.0 * A, A, A], WA),
        ([B, B, 1.0 - 2.0 * B], WB),
        ([B, 1.0 - 2.0 * B, B], WB),
        ([1.0 - 2.0 * B, B, B], WB),
    ]
};

/// The faces of a tet, as its local vertex indices.
const TET_FACES: [[usize; 3]; 4] = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];

/// The boundary triangles of `tets` (faces of exactly one tet) whose three
/// vertices are all `loaded`, in a deterministic order (sorted by their
/// sorted vertices).
pub fn loaded_faces(tets: &[[u32; 4]], loaded: &[bool]) -> Vec<[u32; 3]> {
    let mut faces: BTreeMap<[u32; 3], ([u32; 3], usize)> = BTreeMap::new();
    for tet in tets {
        for face in TET_FACES {
            let f = face.map(|i| tet[i]);
            if f.iter().all(|&v| loaded[v as usize]) {
                let mut key = f;
                key.sort_unstable();
                faces.entry(key).or_insert((f, 0)).1 += 1;
            }
        }
    }
    faces
        .into_values()
        .filter(|&(_, count)| count == 1)
        .map(|(f, _)| f)
        .collect()
}

/// P1 triangle shape functions: the barycentric coordinates.
pub fn p1_shape(l: [f64; 3]) -> [f64; 3] {
    l
}

/// P2 (6-node) triangle shape functions, nodes: the corners, then the
/// mid-edge nodes of (0,1), (1,2), (2,0).
pub fn p2_shape(l: [f64; 3]) -> [f64; 6] {
    [
        l[0] * (2.0 * l[0] - 1.0),
        l[1] * (2.0 * l[1] - 1.0),
        l[2] * (2.0 * l[2] - 1.0),
        4.0 * l[0] * l[1],
        4.0 * l[1] * l[2],
        4.0 * l[2] * l[0],
    ]
}

/// `∫ g dA` over the straight triangles `faces` (their first three nodes
/// the corners, positions m) by [`RULE`]: `g` gets the point and its
/// barycentric coordinates.
pub fn integrate<const K: usize>(
    positions: &[[f64; 3]],
    faces: &[[u32; K]],
    mut g: impl FnMut(&[u32; K], &Vector3<f64>, [f64; 3], f64),
) {
    for face in faces {
        let [a, b, c] = [0, 1, 2].map(|i| Vector3::from(positions[face[i] as usize]));
        let area = 0.5 * (b - a).cross(&(c - a)).norm();
        for (l, w) in RULE {
            let x = a * l[0] + b * l[1] + c * l[2];
            g(face, &x, l, w * area);
        }
    }
}

/// The consistent nodal loads `f_i = ∫ N_i t dA` (N) of the traction `t`
/// (N/m² at a point) over `faces` with the shape functions `shape`, for
/// `node_count` nodes.
pub fn nodal_loads<const K: usize>(
    positions: &[[f64; 3]],
    faces: &[[u32; K]],
    shape: fn([f64; 3]) -> [f64; K],
    traction: impl Fn(&Vector3<f64>) -> Vector3<f64>,
) -> Vec<[f64; 3]> {
    let mut f = vec![Vector3::zeros(); positions.len()];
    integrate(positions, faces, |face, x, l, w| {
        let t = traction(x) * w;
        for (node, n) in face.iter().zip(shape(l)) {
            f[*node as usize] += t * n;
        }
    });
    f.into_iter().map(Into::into).collect()
}
