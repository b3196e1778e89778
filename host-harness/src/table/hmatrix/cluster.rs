//! The cluster tree of the touchable vertices (Hackbusch, *Hierarchical
//! Matrices*, 2015, §5.4): geometric bisection of their rest positions. A
//! cluster holding more than [`LEAF_SIZE`] vertices is split at the median
//! of its bounding box's longest axis into two halves of `⌊n/2⌋` and
//! `⌈n/2⌉` vertices, so the tree is balanced (depth `⌈log₂(S/LEAF_SIZE)⌉ + 1`)
//! and every cluster, numbered in the order of the leaves, is a range of
//! touchable indices.

use core::ops::Range;

/// Touchable vertices of a leaf cluster, at most. 32 vertices (96 DOFs): a
/// near block is then at most 32 × 32 blocks of 3×3 (36 KB in `f32`), and a
/// far block between two leaves pays off from rank `< 48` (`3(m+n)r < 9mn`),
/// where the far blocks of a smooth organ at tolerance `1e-4` have ranks
/// of 5–15. Smaller leaves lengthen each column's block list (the step
/// path's bound, `max_column_blocks`) for no gain in size; larger ones store
/// more entries in the near field.
pub const LEAF_SIZE: usize = 32;

/// An axis-aligned bounding box, m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoundingBox {
    /// Smallest coordinate per axis, m.
    pub min: [f64; 3],
    /// Largest coordinate per axis, m.
    pub max: [f64; 3],
}

impl BoundingBox {
    /// The box of `points` (an empty box, min > max, for none).
    pub fn of<'a>(points: impl IntoIterator<Item = &'a [f64; 3]>) -> Self {
        let mut b = Self {
            min: [f64::INFINITY; 3],
            max: [f64::NEG_INFINITY; 3],
        };
        for p in points {
            for (a, &x) in p.iter().enumerate() {
                b.min[a] = b.min[a].min(x);
                b.max[a] = b.max[a].max(x);
            }
        }
        b
    }

    /// The diagonal's length, m: the cluster's diameter bound.
    pub fn diameter(&self) -> f64 {
        (0..3)
            .map(|a| (self.max[a] - self.min[a]).max(0.0).powi(2))
            .sum::<f64>()
            .sqrt()
    }

    /// The Euclidean distance between two boxes, m (0 when they overlap).
    pub fn distance(&self, other: &Self) -> f64 {
        (0..3)
            .map(|a| {
                let gap = (other.min[a] - self.max[a]).max(self.min[a] - other.max[a]);
                gap.max(0.0).powi(2)
            })
            .sum::<f64>()
            .sqrt()
    }

    /// The axis of the longest extent (0, 1, 2).
    fn longest_axis(&self) -> usize {
        let extent = |a: usize| self.max[a] - self.min[a];
        (0..3).fold(0, |best, a| if extent(a) > extent(best) { a } else { best })
    }
}

/// One cluster: a range of touchable indices (in the tree's order), its
/// bounding box and its two sons (`None` for a leaf).
#[derive(Clone, Debug, PartialEq)]
pub struct Cluster {
    /// Its touchable indices, in the tree's numbering.
    pub range: Range<usize>,
    /// The bounding box of its vertices' rest positions.
    pub bbox: BoundingBox,
    /// Indices of its two sons in [`ClusterTree::clusters`].
    pub sons: Option<[usize; 2]>,
}

/// The cluster tree: the clusters (the root first) and the new numbering.
#[derive(Clone, Debug, PartialEq)]
pub struct ClusterTree {
    /// Every cluster, the root at 0, each son after its father.
    pub clusters: Vec<Cluster>,
    /// New touchable index → old: `order[i]` is the vertex (index into the
    /// positions given) numbered `i`.
    pub order: Vec<usize>,
    /// The leaves' ranges, ascending: they tile `0..S`.
    pub leaves: Vec<Range<usize>>,
    /// Levels, the root's included (0 for no vertex).
    pub depth: usize,
}

impl ClusterTree {
    /// The tree of `points` (rest positions, m) with leaves of at most
    /// `leaf_size ≥ 1` points.
    pub fn new(points: &[[f64; 3]], leaf_size: usize) -> Self {
        let leaf_size = leaf_size.max(1);
        let mut tree = Self {
            clusters: Vec::new(),
            order: (0..points.len()).collect(),
            leaves: Vec::new(),
            depth: 0,
        };
        if !points.is_empty() {
            tree.split(points, 0..points.len(), leaf_size, 1);
        }
        tree
    }

    /// Adds the cluster of `range` (of `self.order`) and, recursively, its
    /// sons; returns its index. Leaves are reached in ascending order.
    fn split(
        &mut self,
        points: &[[f64; 3]],
        range: Range<usize>,
        leaf_size: usize,
        level: usize,
    ) -> usize {
        let bbox = BoundingBox::of(self.order[range.clone()].iter().map(|&i| &points[i]));
        let index = self.clusters.len();
        self.clusters.push(Cluster {
            range: range.clone(),
            bbox,
            sons: None,
        });
        self.depth = self.depth.max(level);
        if range.len() <= leaf_size {
            self.leaves.push(range);
            return index;
        }
        let axis = bbox.longest_axis();
        let half = range.len() / 2;
        self.order[range.clone()]
            .select_nth_unstable_by(half, |&a, &b| points[a][axis].total_cmp(&points[b][axis]));
        let middle = range.start + half;
        let first = self.split(points, range.start..middle, leaf_size, level + 1);
        let second = self.split(points, middle..range.end, leaf_size, level + 1);
        self.clusters[index].sons = Some([first, second]);
        index
    }

    /// The index of the leaf holding touchable index `i` (`None` beyond).
    pub fn leaf_of(&self, i: usize) -> Option<usize> {
        let leaf = self.leaves.partition_point(|l| l.end <= i);
        (leaf < self.leaves.len()).then_some(leaf)
    }
}
