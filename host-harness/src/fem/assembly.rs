//! Global assembly of the P1 stiffness matrix and the free-vertex ordering
//! shared with the kernel's compliance table (`MODELS.md` §1–2).

use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use palpate_kernel::table::format::FIXED_SLOT;

use super::element::element_stiffness;
use super::material::TetMaterials;

/// Full global stiffness `K` (N/m), `3N × 3N` for `N = positions.len()`, with
/// DOF `3 * vertex + component` (component 0 = x, 1 = y, 2 = z).
///
/// `K = Σ_tets` of the element blocks of [`element_stiffness`]
/// (`MODELS.md` §1), each tet with its own material `m.per_tet()[t]`, so
/// `K u = f` gives the external nodal forces `f` (N)
/// balancing displacements `u` (m). Every block `(i, j)` of an edge or vertex
/// of the mesh is stored (both triangles, sorted row indices); vertices used
/// by no tet get empty columns.
///
/// # Panics
/// If a tet references a vertex `>= positions.len()` or `m` is not for
/// `tets.len()` tets.
pub fn assemble_stiffness(
    positions: &[[f64; 3]],
    tets: &[[u32; 4]],
    m: &TetMaterials,
) -> SparseColMat<usize, f64> {
    let n = u32::try_from(positions.len()).expect("vertex count fits in u32");
    let slot: Vec<Option<u32>> = (0..n).map(Some).collect();
    assemble_restricted(positions, tets, m, &slot, positions.len())
}

/// Stiffness restricted to a subset of vertices, renumbered (N/m).
///
/// `slot[v]` is the new index of mesh vertex `v` in `0..slot_count`, or
/// `None` to drop the vertex (its rows and columns are removed, i.e. the
/// vertex is fixed or handled elsewhere). The result is `3·slot_count`
/// square with DOF `3 * slot + component`: with `slot = vertex_slot` of a
/// [`FreeOrdering`] it is the matrix `A` of `MODELS.md` §2 (Cotin RR-3510 §4),
/// the stiffness restricted to the free DOFs. Both triangles are stored.
///
/// # Panics
/// If `slot.len() != positions.len()`, a slot is `>= slot_count`, a tet
/// references a vertex `>= positions.len()`, or `m` is not for `tets.len()`
/// tets.
pub fn assemble_restricted(
    positions: &[[f64; 3]],
    tets: &[[u32; 4]],
    m: &TetMaterials,
    slot: &[Option<u32>],
    slot_count: usize,
) -> SparseColMat<usize, f64> {
    assert_eq!(m.len(), tets.len(), "one material per tet");
    assemble_restricted_with(positions.len(), tets, slot, slot_count, |t| {
        element_stiffness(&tets[t].map(|v| positions[v as usize]), &m.per_tet()[t])
    })
}

/// [`assemble_restricted`] of any element matrices of `N`-node tets:
/// `element(t)` gives tet `t`'s `N`×`N` blocks of 3×3 (`K[j][k][a][b]`, the stiffness `−∂f_{j,a}/∂x_{k,b}`,
/// N/m) for the `vertex_count`-vertex mesh `tets`. The Newton reference's
/// tangent ([`super::newton`]) uses it with the St Venant-Kirchhoff tangent.
///
/// # Panics
/// If `slot.len() != vertex_count`, a slot is `>= slot_count` or a tet
/// references a vertex `>= vertex_count`.
pub fn assemble_restricted_with<const N: usize>(
    vertex_count: usize,
    tets: &[[u32; N]],
    slot: &[Option<u32>],
    slot_count: usize,
    mut element: impl FnMut(usize) -> [[[[f64; 3]; 3]; N]; N],
) -> SparseColMat<usize, f64> {
    assert_eq!(slot.len(), vertex_count, "one slot per vertex");
    assert!(
        slot.iter().flatten().all(|&s| (s as usize) < slot_count),
        "slot out of range"
    );
    // Block pattern: sorted neighbour slots (self included) of every slot.
    let mut nbr: Vec<Vec<u32>> = vec![Vec::new(); slot_count];
    for t in tets {
        let s = t.map(|v| slot[v as usize]);
        for sj in s.iter().flatten() {
            nbr[*sj as usize].extend(s.iter().flatten());
        }
    }
    for l in &mut nbr {
        l.sort_unstable();
        l.dedup();
    }
    let dof = 3 * slot_count;
    let mut col_ptr = Vec::with_capacity(dof + 1);
    col_ptr.push(0usize);
    let mut row_idx = Vec::new();
    for l in &nbr {
        for _ in 0..3 {
            for &w in l {
                let w = 3 * w as usize;
                row_idx.extend_from_slice(&[w, w + 1, w + 2]);
            }
            col_ptr.push(row_idx.len());
        }
    }
    let mut val = vec![0.0f64; row_idx.len()];
    for (t, tet) in tets.iter().enumerate() {
        let s = tet.map(|v| slot[v as usize]);
        if s.iter().all(Option::is_none) {
            continue;
        }
        let ke = element(t);
        // Block (row j, column k) goes to column slot s[k], neighbour s[j].
        for (k, sk) in s.iter().enumerate() {
            let Some(sk) = *sk else { continue };
            let l = &nbr[sk as usize];
            for (j, sj) in s.iter().enumerate() {
                let Some(sj) = *sj else { continue };
                let pos = l.binary_search(&sj).expect("pattern holds every block");
                for b in 0..3 {
                    let base = col_ptr[3 * sk as usize + b] + 3 * pos;
                    for a in 0..3 {
                        val[base + a] += ke[j][k][a][b];
                    }
                }
            }
        }
    }
    let symbolic = SymbolicSparseColMat::new_checked(dof, dof, col_ptr, None, row_idx);
    SparseColMat::new(symbolic, val)
}

/// The free/touchable vertex ordering shared with the kernel table format
/// (`MODELS.md` §2).
///
/// Free index `0..touchable_count` are the free surface (touchable) vertices
/// in ascending mesh-vertex order (or another order:
/// [`FreeOrdering::with_touchable_order`]); `touchable_count..free_count()` are the
/// remaining (interior) free vertices in ascending order. Fixed vertices have
/// no free index.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FreeOrdering {
    /// Free index → mesh vertex.
    pub free_vertex: Vec<u32>,
    /// Mesh vertex → free index, `None` if fixed.
    pub vertex_slot: Vec<Option<u32>>,
    /// Number of touchable (free surface) vertices, the first entries of
    /// `free_vertex`.
    pub touchable_count: usize,
}

impl FreeOrdering {
    /// Ordering for `vertex_count` vertices: `fixed[v]` marks fully fixed
    /// (zero-displacement) vertices; `surface_vertices` lists the boundary
    /// vertices (any order, duplicates allowed). Touchable = surface and not
    /// fixed.
    ///
    /// # Panics
    /// If `fixed.len() != vertex_count`, a surface vertex is
    /// `>= vertex_count`, or `vertex_count` does not fit in `u32`.
    pub fn new(vertex_count: usize, fixed: &[bool], surface_vertices: &[u32]) -> Self {
        assert_eq!(fixed.len(), vertex_count, "one fixed flag per vertex");
        assert!(
            u32::try_from(vertex_count).is_ok(),
            "vertex count fits in u32"
        );
        let mut on_surface = vec![false; vertex_count];
        for &v in surface_vertices {
            on_surface[v as usize] = true;
        }
        let mut free_vertex = Vec::with_capacity(vertex_count);
        free_vertex.extend(
            (0..vertex_count)
                .filter(|&v| on_surface[v] && !fixed[v])
                .map(|v| v as u32),
        );
        let touchable_count = free_vertex.len();
        free_vertex.extend(
            (0..vertex_count)
                .filter(|&v| !on_surface[v] && !fixed[v])
                .map(|v| v as u32),
        );
        let mut vertex_slot = vec![None; vertex_count];
        for (i, &v) in free_vertex.iter().enumerate() {
            vertex_slot[v as usize] = Some(i as u32);
        }
        Self {
            free_vertex,
            vertex_slot,
            touchable_count,
        }
    }

    /// The same ordering with the touchable vertices renumbered: touchable
    /// index `i` becomes the vertex that was `order[i]` (a permutation of
    /// `0..touchable_count`, e.g. a cluster tree's leaf order); the interior
    /// vertices keep theirs. The kernel reads any touchable order.
    ///
    /// # Panics
    /// If `order` is not a permutation of `0..touchable_count`.
    pub fn with_touchable_order(self, order: &[usize]) -> Self {
        let s = self.touchable_count;
        assert_eq!(order.len(), s, "one entry per touchable vertex");
        let mut free_vertex = self.free_vertex;
        let touchable: Vec<u32> = order.iter().map(|&i| free_vertex[i]).collect();
        free_vertex[..s].copy_from_slice(&touchable);
        let mut vertex_slot = vec![None; self.vertex_slot.len()];
        for (i, &v) in free_vertex.iter().enumerate() {
            assert!(vertex_slot[v as usize].is_none(), "order is a permutation");
            vertex_slot[v as usize] = Some(i as u32);
        }
        Self {
            free_vertex,
            vertex_slot,
            touchable_count: s,
        }
    }

    /// Number of free (not fixed) vertices `F`; the free DOF count is `3F`.
    pub fn free_count(&self) -> usize {
        self.free_vertex.len()
    }

    /// The vertex-slot section as a table file stores it (N entries): the
    /// free index, or the format's [`FIXED_SLOT`] for a fixed vertex.
    pub fn slot_entries(&self) -> Vec<u32> {
        self.vertex_slot
            .iter()
            .map(|slot| slot.unwrap_or(FIXED_SLOT))
            .collect()
    }
}
