//! A mesh split into its pre-computed and tensor-mass regions, and the
//! connection nodes they share (RR-3510 §6.2).

use anyhow::{bail, ensure};

use crate::mesh::TetMesh;

/// The two regions of a hybrid mesh.
///
/// Invariants: every tet is in exactly one region; both regions have tets;
/// the connection nodes are the vertices of both regions that are not
/// fixed, in ascending mesh order, and there is at least one; the
/// tensor-mass region numbers its vertices compactly, the connection nodes
/// first (connection `j` is tensor-mass vertex `j`), then the others in
/// ascending mesh order.
#[derive(Clone, Debug, PartialEq)]
pub struct RegionSplit {
    /// Per mesh tet: `true` in the tensor-mass region.
    pub dynamic_tet: Vec<bool>,
    /// Tensor-mass number → mesh vertex.
    pub dynamic_vertex: Vec<u32>,
    /// Mesh vertex → tensor-mass number, `None` outside that region.
    pub dynamic_index: Vec<Option<u32>>,
    /// Per mesh vertex: used by a pre-computed tet.
    pub in_precomputed: Vec<bool>,
    /// The connection nodes (mesh vertices), ascending.
    pub connection: Vec<u32>,
}

impl RegionSplit {
    /// The split of `mesh` with `dynamic_tet` (one flag per tet) and the
    /// `fixed` vertices (one flag per vertex; a fixed vertex shared by both
    /// regions is held in both and is no connection node).
    pub fn new(mesh: &TetMesh, fixed: &[bool], dynamic_tet: &[bool]) -> anyhow::Result<Self> {
        let n = mesh.positions.len();
        ensure!(
            dynamic_tet.len() == mesh.tets.len() && fixed.len() == n,
            "the region flags do not match the mesh"
        );
        let dynamic_count = dynamic_tet.iter().filter(|&&d| d).count();
        if dynamic_count == 0 || dynamic_count == mesh.tets.len() {
            bail!(
                "a hybrid model needs tets in both regions ({dynamic_count} of {} tets dynamic)",
                mesh.tets.len()
            );
        }
        let mut in_dynamic = vec![false; n];
        let mut in_precomputed = vec![false; n];
        for (tet, &dynamic) in mesh.tets.iter().zip(dynamic_tet) {
            let region = if dynamic {
                &mut in_dynamic
            } else {
                &mut in_precomputed
            };
            for &v in tet {
                region[v as usize] = true;
            }
        }
        let connects = |v: usize| in_dynamic[v] && in_precomputed[v] && !fixed[v];
        let connection: Vec<u32> = (0..n as u32).filter(|&v| connects(v as usize)).collect();
        if connection.is_empty() {
            bail!("the regions share no free vertex: nothing connects them");
        }
        // The connection nodes first: their displacements and forces are
        // then one contiguous run of the tensor-mass arrays.
        let others = (0..n as u32).filter(|&v| in_dynamic[v as usize] && !connects(v as usize));
        let dynamic_vertex: Vec<u32> = connection.iter().copied().chain(others).collect();
        let mut dynamic_index = vec![None; n];
        for (d, &v) in dynamic_vertex.iter().enumerate() {
            dynamic_index[v as usize] = Some(d as u32);
        }
        Ok(Self {
            dynamic_tet: dynamic_tet.to_vec(),
            dynamic_vertex,
            dynamic_index,
            in_precomputed,
            connection,
        })
    }

    /// The pre-computed region as a mesh over all the mesh's vertices (its
    /// tets only; the numbering stays the mesh's).
    pub fn precomputed_mesh(&self, mesh: &TetMesh) -> TetMesh {
        TetMesh {
            positions: mesh.positions.clone(),
            tets: self.tets_of(mesh, false).collect(),
        }
    }

    /// The tensor-mass region as a mesh of its own vertices, renumbered
    /// ([`Self::dynamic_vertex`]).
    pub fn dynamic_mesh(&self, mesh: &TetMesh) -> TetMesh {
        TetMesh {
            positions: self
                .dynamic_vertex
                .iter()
                .map(|&v| mesh.positions[v as usize])
                .collect(),
            tets: self
                .tets_of(mesh, true)
                .map(|t| t.map(|v| self.dynamic_index[v as usize].unwrap_or(u32::MAX)))
                .collect(),
        }
    }

    /// Tets in the tensor-mass region.
    pub fn dynamic_tet_count(&self) -> usize {
        self.dynamic_tet.iter().filter(|&&d| d).count()
    }

    fn tets_of<'m>(
        &'m self,
        mesh: &'m TetMesh,
        dynamic: bool,
    ) -> impl Iterator<Item = [u32; 4]> + 'm {
        mesh.tets
            .iter()
            .zip(&self.dynamic_tet)
            .filter(move |(_, d)| **d == dynamic)
            .map(|(t, _)| *t)
    }
}
