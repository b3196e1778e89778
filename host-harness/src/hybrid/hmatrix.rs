//! The interface's condensed stiffness as a hierarchical matrix (scene
//! `[tables] compress = "hmatrix"` on a hybrid; layout in
//! `palpate_kernel::table::format::hierarchy`, with the connection nodes as
//! its vertices): the builder of the pre-computed tables' hierarchical
//! compliance ([`crate::table::hmatrix`]) run over the dense `S`, a cluster
//! tree of the connection nodes' rest positions ordering it. `S` is the
//! Dirichlet-to-Neumann map of the pre-computed region on its connection
//! nodes: its blocks between well-separated clusters of them are
//! numerically low-rank, as the compliance's are (Hackbusch, *Hierarchical
//! Matrices*, 2015, ch. 5–6).

use faer::Mat;

use crate::table::compress::Hierarchy;
use crate::table::hmatrix::assemble::{Assembler, batches};
use crate::table::hmatrix::cluster::{ClusterTree, LEAF_SIZE};
use crate::table::hmatrix::partition::{ETA, Partition};
use crate::table::hmatrix::{DEFAULT_TOLERANCE, estimate_with_leaves};

/// How the interface's condensed stiffness is compressed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InterfaceCompression {
    /// The relative tolerance, in `(0, 1)`: `‖S − S̃‖_F ≤ tolerance ·
    /// ‖S‖_F`, each block truncated relative to the whole `S`
    /// (`crate::table::hmatrix::assemble`, error budget), so that blocks
    /// negligible against `‖S‖_F` (a stiffness's far blocks) drop to a
    /// low rank or to zero.
    pub tolerance: f64,
    /// Connection nodes of a leaf cluster, at most (`≥ 1`).
    pub leaf_size: usize,
}

impl Default for InterfaceCompression {
    /// The pre-computed tables' defaults: tolerance
    /// [`DEFAULT_TOLERANCE`], leaves of [`LEAF_SIZE`].
    fn default() -> Self {
        Self {
            tolerance: DEFAULT_TOLERANCE,
            leaf_size: LEAF_SIZE,
        }
    }
}

/// The condensed stiffness in hierarchical form: the hierarchy sections'
/// contents (in hierarchy order) and the `hierarchy-order` section.
pub struct CondensedHierarchy {
    /// The blocks of `S` (N/m), hierarchy index `i` being connection node
    /// `order[i][0]`.
    pub hierarchy: Hierarchy,
    /// Per hierarchy index `i`: `[connection node at i, hierarchy index of
    /// connection node i]`.
    pub order: Vec<[u32; 2]>,
}

/// Compresses the dense condensed stiffness `condensed` (the interface
/// layout, `3c` rows of `c` triples, N/m) of the connection nodes at rest
/// `points` (m, `c` of them) as `compression` asks. Memory: one batch of
/// columns (`3c × 3·64` scalars) besides the blocks.
pub fn compress_condensed(
    points: &[[f64; 3]],
    condensed: &[[f64; 3]],
    compression: &InterfaceCompression,
) -> anyhow::Result<CondensedHierarchy> {
    let c = points.len();
    anyhow::ensure!(
        condensed.len() == 3 * c * c && compression.leaf_size >= 1,
        "compressing the condensed stiffness: {} triples for {c} connection nodes",
        condensed.len()
    );
    let tree = ClusterTree::new(points, compression.leaf_size);
    let partition = Partition::new(&tree, ETA);
    let batches = batches(&tree);
    let norm2: f64 = condensed.iter().flatten().map(|x| x * x).sum();
    let mut assembler =
        Assembler::new(&tree, &partition, &batches, compression.tolerance).relative_to_whole(norm2);
    for batch in &batches {
        // Rows and columns in hierarchy order: S[(order i, a), (order k, b)].
        let x = Mat::from_fn(3 * c, 3 * batch.len(), |r, col| {
            let (node, a) = (tree.order[r / 3], r % 3);
            let (other, b) = (tree.order[batch.start + col / 3], col % 3);
            condensed[(3 * node + a) * c + other][b]
        });
        assembler.add_batch(batch, x.as_ref())?;
    }
    let hierarchy = assembler.finish(c, ETA, compression.leaf_size)?;
    let mut order = vec![[0u32; 2]; c];
    for (i, &node) in tree.order.iter().enumerate() {
        order[i][0] = node as u32;
        order[node][1] = i as u32;
    }
    Ok(CondensedHierarchy { hierarchy, order })
}

/// The condensed stiffness of `c` connection nodes at rest `points` (m)
/// compressed as `compression` asks, estimated before a build (the
/// pre-computed tables' estimate, every far block at its rank,
/// `crate::table::hmatrix::ESTIMATE_RANK`): its scalars (one multiply-add
/// each per product `S u`, against `9c²` dense) and the bytes of its
/// sections in a table of `scalar_bytes`-byte floats (the hierarchy order's
/// included).
pub fn estimate(
    points: &[[f64; 3]],
    compression: &InterfaceCompression,
    scalar_bytes: u64,
) -> (u64, u64) {
    let (scalars, other) = estimate_with_leaves(points, compression.leaf_size.max(1), 0);
    let order = 8 * points.len() as u64;
    (scalars, scalars * scalar_bytes + other + order)
}
