//! A tet's local numbering: its edges and faces in the order the
//! tensor-mass sections store them.

/// The vertex pairs of a tet's six edges, in [`super::SectionKind::TetEdge`] order:
/// local pairs (0,1), (0,2), (0,3), (1,2), (1,3), (2,3).
pub const fn tet_edge_vertices(tet: [u32; 4]) -> [[u32; 2]; 6] {
    let [a, b, c, d] = tet;
    [[a, b], [a, c], [a, d], [b, c], [b, d], [c, d]]
}

/// The faces of a positively oriented tet, face `j` opposite local vertex `j`,
/// each ordered so its right-hand normal points out of the tet.
pub const fn tet_face_vertices(tet: [u32; 4]) -> [[u32; 3]; 4] {
    let [a, b, c, d] = tet;
    [[b, c, d], [a, d, c], [a, b, d], [a, c, b]]
}

/// The local vertex pairs `(j, k)` of [`tet_edge_vertices`], for code that
/// needs local indices (stiffness blocks `K_jk`).
pub const TET_EDGE_PAIRS: [[usize; 2]; 6] = [[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]];
