//! The block partition of `S × S` over the cluster tree (Hackbusch,
//! *Hierarchical Matrices*, 2015, §5.5): a pair of clusters `(τ, σ)` is a
//! far (admissible) block when
//!
//! `min(diam τ, diam σ) ≤ η · dist(τ, σ)` (bounding boxes, [`ETA`]),
//!
//! else both are split (a leaf is kept whole) until two leaves remain: a
//! near block. The recursion starts at `(root, root)` and is symmetric, so
//! both triangles are in the partition and every block `(τ, σ)` has its
//! mirror `(σ, τ)`.

use std::collections::HashMap;

use super::cluster::ClusterTree;

/// The admissibility parameter `η`. The compliance of an elastic body
/// decays like `1/r` (Kelvin's solution), whose expansion about a cluster's
/// centre converges geometrically with ratio `≈ diam/dist`; at `η = 2` a
/// far block's singular values still fall by about a decade per few ranks
/// (ranks 5–15 at tolerance `1e-4` on a smooth organ), while `η = 1` would
/// keep about twice as many entries in near blocks.
pub const ETA: f64 = 2.0;

/// One block of the partition: its row and column clusters (indices into
/// [`ClusterTree::clusters`]) and whether it is far.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PartitionBlock {
    /// The row cluster `τ`.
    pub row: usize,
    /// The column cluster `σ`.
    pub col: usize,
    /// Admissible: stored as low-rank factors (or, when they would not pay
    /// off, as entries).
    pub far: bool,
}

/// The partition: its blocks (both triangles) and, per leaf, the blocks
/// over its columns sorted by row start (the format's column lists).
#[derive(Clone, Debug, PartialEq)]
pub struct Partition {
    /// Every block.
    pub blocks: Vec<PartitionBlock>,
    /// Per leaf, the indices of the blocks whose columns contain it, by
    /// ascending row start: their rows tile `0..S`.
    pub columns: Vec<Vec<u32>>,
    /// Per block, its mirror's index (itself on the diagonal).
    pub mirror: Vec<usize>,
}

impl Partition {
    /// The partition of `tree` with admissibility parameter `eta`.
    pub fn new(tree: &ClusterTree, eta: f64) -> Self {
        let mut blocks = Vec::new();
        if !tree.clusters.is_empty() {
            split(tree, eta, 0, 0, &mut blocks);
        }
        let index: HashMap<(usize, usize), usize> = blocks
            .iter()
            .enumerate()
            .map(|(i, b)| ((b.row, b.col), i))
            .collect();
        let mirror = blocks
            .iter()
            .map(|b| index.get(&(b.col, b.row)).copied().unwrap_or(usize::MAX))
            .collect();
        let mut columns = vec![Vec::new(); tree.leaves.len()];
        for (i, b) in blocks.iter().enumerate() {
            let cols = &tree.clusters[b.col].range;
            let first = tree.leaf_of(cols.start).unwrap_or(0);
            for (leaf, range) in tree.leaves.iter().enumerate().skip(first) {
                if range.start >= cols.end {
                    break;
                }
                columns[leaf].push(i as u32);
            }
        }
        for list in &mut columns {
            list.sort_by_key(|&i| tree.clusters[blocks[i as usize].row].range.start);
        }
        Self {
            blocks,
            columns,
            mirror,
        }
    }

    /// The longest column list.
    pub fn max_column_blocks(&self) -> usize {
        self.columns.iter().map(Vec::len).max().unwrap_or(0)
    }
}

/// Adds the blocks of `(row, col)` to `out` (module docs).
fn split(tree: &ClusterTree, eta: f64, row: usize, col: usize, out: &mut Vec<PartitionBlock>) {
    let (r, c) = (&tree.clusters[row], &tree.clusters[col]);
    let far = r.bbox.diameter().min(c.bbox.diameter()) <= eta * r.bbox.distance(&c.bbox)
        && r.bbox.distance(&c.bbox) > 0.0;
    if far {
        out.push(PartitionBlock { row, col, far });
        return;
    }
    match (r.sons, c.sons) {
        (None, None) => out.push(PartitionBlock { row, col, far }),
        (Some(rs), None) => rs.into_iter().for_each(|s| split(tree, eta, s, col, out)),
        (None, Some(cs)) => cs.into_iter().for_each(|s| split(tree, eta, row, s, out)),
        (Some(rs), Some(cs)) => {
            for rr in rs {
                for cc in cs {
                    split(tree, eta, rr, cc, out);
                }
            }
        }
    }
}

impl Partition {
    /// The hierarchy's data (scalars) if every far block had rank `rank`
    /// (stored as entries where the factors would not be smaller), with the
    /// owned blocks only (a mirror shares its owner's data): the size
    /// estimate of a build before its ranks are known.
    pub fn data_len_at_rank(&self, tree: &ClusterTree, rank: usize) -> u64 {
        self.blocks
            .iter()
            .filter(|b| tree.clusters[b.row].range.start <= tree.clusters[b.col].range.start)
            .map(|b| {
                let (m, n) = (
                    tree.clusters[b.row].range.len() as u64,
                    tree.clusters[b.col].range.len() as u64,
                );
                let near = 9 * m * n;
                let far = 3 * (m + n) * rank as u64;
                if b.far { near.min(far) } else { near }
            })
            .sum()
    }
}
