//! The hierarchical compliance built column batch by column batch, never
//! holding the dense table: the touchable rows of each batch of columns
//! (consecutive leaves) are cut into the blocks they touch; a near block is
//! copied, a far block's part truncated ([`TruncatedSvd`]) and added to its
//! factors, recompressed as they grow and once more when the block is
//! complete.
//!
//! **Error budget** of a far block `B` split over `p` batches into parts
//! `B_1 … B_p` (disjoint columns, `‖B‖² = Σ ‖B_i‖²`), `tol` the table's
//! tolerance: each part truncated at `tol/2 · ‖B_i‖_F` (together
//! `≤ tol/2 · ‖B‖_F`, the errors in disjoint columns), each of the `p − 2`
//! intermediate recompressions at `tol/(4(p − 2)) · ‖B_1..i‖_F`, the final
//! one at `tol/4 · ‖B‖_F`: `‖B − L Rᵀ‖_F ≤ tol · ‖B‖_F`. A block within one
//! batch is truncated once at `tol · ‖B‖_F`.
//!
//! **Relative to the whole matrix** ([`Assembler::relative_to_whole`], the
//! hybrid's condensed stiffness): `‖B‖_F` above is replaced everywhere by
//! `((‖B‖_F² + ‖A‖_F² · mn / N²) / 2)^{1/2}` for a block of `m × n` of the
//! matrix `A`'s `N × N` vertices (squares add over disjoint columns, as
//! `‖B‖_F²` does). Summed over every block (mirrors included, `Σ mn = N²`)
//! the squared thresholds are at most `tol² ‖A‖_F²`, so
//! `‖A − Ã‖_F ≤ tol · ‖A‖_F` still holds, while a block negligible against
//! `‖A‖_F` (a stiffness's far blocks) truncates to a low rank or to zero.
//!
//! A far block is stored as entries (`L Rᵀ`, within the same bound) when
//! its rank would exceed [`HIERARCHY_MAX_RANK`] or its factors would not be
//! smaller (`3(m + n) r ≥ 9 m n`, `m × n` vertices); truncated to rank zero,
//! as rank-1 zero factors (the format's far blocks have a rank of at least
//! one) when they are smaller than its entries. An inadmissible
//! (near) block off the diagonal, two neighbouring leaves, is truncated at
//! the same `tol · ‖B‖_F` and stored as factors when they are smaller
//! (on the built-in organ at `tol = 1e-2`, all 84 such blocks: 36 % of their entries'
//! bytes), else as its exact entries. The diagonal near
//! blocks `(τ, τ)` are symmetrized (`(D + Dᵀ)/2`), like the coded tables'
//! `C_kk`.

use core::ops::Range;

use faer::{Mat, MatRef};
use palpate_kernel::table::format::{
    HIERARCHY_MAX_RANK, HIERARCHY_MIRRORED, HierarchyBlock, HierarchyRecord,
};

use super::super::compress::Hierarchy;
use super::cluster::ClusterTree;
use super::lowrank::TruncatedSvd;
use super::partition::Partition;

/// Touchable vertices per batch of columns, at least (whole leaves are
/// added until it is reached): 64 vertices, 192 right-hand sides, as the
/// dense build's batches.
pub const BATCH_VERTICES: usize = 64;

/// The batches: consecutive leaves of at least [`BATCH_VERTICES`] vertices
/// (the last may hold fewer).
pub fn batches(tree: &ClusterTree) -> Vec<Range<usize>> {
    let mut out: Vec<Range<usize>> = Vec::new();
    for leaf in &tree.leaves {
        match out.last_mut() {
            Some(last) if last.len() < BATCH_VERTICES => last.end = leaf.end,
            _ => out.push(leaf.clone()),
        }
    }
    out
}

/// A block's data as stored: entries (row-major 3×3 blocks, rows by
/// columns) or the balanced factors (row-major, `3·rows × r`, `3·cols × r`).
enum Stored {
    Near(Vec<f64>),
    Far {
        left: Vec<f64>,
        right: Vec<f64>,
        rank: usize,
    },
}

/// A far block being accumulated.
struct Pending {
    /// Batches its columns span, in all.
    parts: usize,
    /// Batches seen.
    seen: usize,
    /// `‖B‖_F²` over the columns seen.
    norm2: f64,
    /// Vertex pairs (`rows × columns`) seen.
    pairs: usize,
    /// `(L, R)` with `B ≈ L Rᵀ` over the columns seen (`R` zero beyond).
    factors: Option<(Mat<f64>, Mat<f64>)>,
}

/// What one owned block (row start ≤ column start: it holds the data of
/// itself and its mirror) needs while the batches go by.
enum Work {
    Near,
    Far(Pending),
    Done,
}

/// The truncation threshold of a set of a block's entries (module docs,
/// error budget): `tolerance · ‖B‖_F`, or relative to the whole matrix
/// with `floor2_per_pair = ‖A‖_F² / N²` (zero: relative to the block).
#[derive(Clone, Copy, Debug)]
struct Budget {
    tolerance: f64,
    floor2_per_pair: f64,
}

impl Budget {
    /// The threshold of entries of squared norm `norm2` over `pairs`
    /// vertex pairs (m/N, Frobenius norm of what may be discarded).
    fn threshold(self, norm2: f64, pairs: usize) -> f64 {
        if self.floor2_per_pair > 0.0 {
            self.tolerance * (0.5 * (norm2 + self.floor2_per_pair * pairs as f64)).sqrt()
        } else {
            self.tolerance * norm2.sqrt()
        }
    }
}

/// The builder's state over the batches.
pub struct Assembler<'a> {
    tree: &'a ClusterTree,
    partition: &'a Partition,
    budget: Budget,
    work: Vec<Work>,
    stored: Vec<Option<Stored>>,
}

impl<'a> Assembler<'a> {
    /// Ready for the batches `batches` of `tree` and `partition`, far
    /// blocks truncated at relative `tolerance`.
    pub fn new(
        tree: &'a ClusterTree,
        partition: &'a Partition,
        batches: &[Range<usize>],
        tolerance: f64,
    ) -> Self {
        let work = partition
            .blocks
            .iter()
            .map(|b| {
                let (rows, cols) = (&tree.clusters[b.row].range, &tree.clusters[b.col].range);
                match (rows.start <= cols.start, b.far) {
                    (false, _) => Work::Done,
                    (true, false) => Work::Near,
                    (true, true) => Work::Far(Pending {
                        parts: batches
                            .iter()
                            .filter(|r| r.start < cols.end && cols.start < r.end)
                            .count(),
                        seen: 0,
                        norm2: 0.0,
                        pairs: 0,
                        factors: None,
                    }),
                }
            })
            .collect();
        Self {
            tree,
            partition,
            budget: Budget {
                tolerance,
                floor2_per_pair: 0.0,
            },
            work,
            stored: (0..partition.blocks.len()).map(|_| None).collect(),
        }
    }

    /// The same with every threshold relative to the whole matrix (module
    /// docs): `norm2` is `‖A‖_F²` of the `N × N`-vertex matrix compressed
    /// (`N` the tree's vertices).
    pub fn relative_to_whole(mut self, norm2: f64) -> Self {
        let n = self.tree.order.len().max(1) as f64;
        self.budget.floor2_per_pair = norm2 / (n * n);
        self
    }

    /// Takes the columns of touchable vertices `batch`: `x` holds (at least)
    /// the `3S` touchable rows, column `3(k − batch.start) + b` the column
    /// of `(k, b)`. Each block the batch touches is processed, over the
    /// machine's cores.
    pub fn add_batch(&mut self, batch: &Range<usize>, x: MatRef<'_, f64>) -> anyhow::Result<()> {
        let (tree, partition, budget) = (self.tree, self.partition, self.budget);
        let mut items: Vec<(usize, &mut Work, &mut Option<Stored>)> = self
            .work
            .iter_mut()
            .zip(self.stored.iter_mut())
            .enumerate()
            .filter(|(i, (w, _))| {
                let cols = &tree.clusters[partition.blocks[*i].col].range;
                !matches!(w, Work::Done) && cols.start < batch.end && batch.start < cols.end
            })
            .map(|(i, (w, s))| (i, w, s))
            .collect();
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
        let per = items.len().div_ceil(threads).max(1);
        let failed = std::thread::scope(|scope| {
            let handles: Vec<_> = items
                .chunks_mut(per)
                .map(|chunk| {
                    scope.spawn(move || {
                        chunk.iter_mut().try_for_each(|(i, work, stored)| {
                            let block = &partition.blocks[*i];
                            let rows = tree.clusters[block.row].range.clone();
                            let cols = tree.clusters[block.col].range.clone();
                            let part = Part {
                                rows,
                                cols,
                                batch: batch.clone(),
                                x,
                            };
                            match part.process(work, budget) {
                                Some(Some(s)) => {
                                    **stored = Some(s);
                                    **work = Work::Done;
                                    Some(())
                                }
                                Some(None) => Some(()),
                                None => None,
                            }
                        })
                    })
                })
                .collect();
            handles
                .into_iter()
                .any(|h| h.join().ok().flatten().is_none())
        });
        anyhow::ensure!(
            !failed,
            "compressing the compliance: an SVD did not converge (non-finite compliance?)"
        );
        Ok(())
    }

    /// The hierarchy once every batch was added: offsets assigned in block
    /// order, mirrors pointed at their owners' data. Errors if a block was
    /// never completed (the batches did not cover `0..S`).
    pub fn finish(self, s: usize, eta: f64, leaf_size: usize) -> anyhow::Result<Hierarchy> {
        let (tree, partition) = (self.tree, self.partition);
        let mut data = Vec::new();
        let mut blocks = Vec::with_capacity(partition.blocks.len());
        let mut max_rank = 0usize;
        for (i, b) in partition.blocks.iter().enumerate() {
            let (rows, cols) = (&tree.clusters[b.row].range, &tree.clusters[b.col].range);
            let mut block = HierarchyBlock {
                row_start: rows.start as u32,
                row_end: rows.end as u32,
                col_start: cols.start as u32,
                col_end: cols.end as u32,
                rank: 0,
                left: 0,
                right: 0,
                flags: 0,
            };
            if rows.start <= cols.start {
                let offset = |data: &Vec<f64>| u32::try_from(data.len());
                match &self.stored[i] {
                    Some(Stored::Near(entries)) => {
                        block.left = offset(&data)?;
                        data.extend_from_slice(entries);
                    }
                    Some(Stored::Far { left, right, rank }) => {
                        block.rank = *rank as u32;
                        block.left = offset(&data)?;
                        data.extend_from_slice(left);
                        block.right = offset(&data)?;
                        data.extend_from_slice(right);
                        max_rank = max_rank.max(*rank);
                    }
                    None => anyhow::bail!("compressing the compliance: block {i} not computed"),
                }
            }
            blocks.push(block);
        }
        for (i, m) in partition.mirror.iter().enumerate() {
            if blocks[i].row_start > blocks[i].col_start {
                let owner = *blocks.get(*m).ok_or_else(|| {
                    anyhow::anyhow!("compressing the compliance: block {i} has no mirror")
                })?;
                let b = &mut blocks[i];
                if owner.rank == 0 {
                    (b.left, b.flags) = (owner.left, HIERARCHY_MIRRORED);
                } else {
                    (b.rank, b.left, b.right) = (owner.rank, owner.right, owner.left);
                }
            }
        }
        let mut leaves = Vec::with_capacity(tree.leaves.len() + 1);
        let mut column_blocks = Vec::new();
        for (leaf, list) in tree.leaves.iter().zip(&partition.columns) {
            leaves.push([leaf.start as u32, column_blocks.len() as u32]);
            column_blocks.extend_from_slice(list);
        }
        leaves.push([s as u32, column_blocks.len() as u32]);
        let record = HierarchyRecord {
            leaf_count: tree.leaves.len() as u32,
            block_count: blocks.len() as u32,
            max_rank: max_rank as u32,
            max_column_blocks: partition.max_column_blocks() as u32,
            leaf_size: leaf_size as u32,
            depth: tree.depth as u32,
            tolerance: self.budget.tolerance,
            eta,
        };
        Ok(Hierarchy {
            record,
            leaves,
            blocks,
            column_blocks,
            data,
            q16: false,
        })
    }
}

/// One owned block's columns in one batch.
struct Part<'x> {
    rows: Range<usize>,
    cols: Range<usize>,
    batch: Range<usize>,
    x: MatRef<'x, f64>,
}

impl Part<'_> {
    /// The block's entries over touchable `rows` and `cols` (both within
    /// the batch's columns) as a `3·rows × 3·cols` matrix view.
    fn view(&self, cols: &Range<usize>) -> MatRef<'_, f64> {
        self.x.submatrix(
            3 * self.rows.start,
            3 * (cols.start - self.batch.start),
            3 * self.rows.len(),
            3 * cols.len(),
        )
    }

    /// Processes the part: `Some(Some(data))` when the block is complete,
    /// `Some(None)` when it waits for more batches, `None` if an SVD failed.
    fn process(&self, work: &mut Work, budget: Budget) -> Option<Option<Stored>> {
        match work {
            Work::Done => Some(None),
            // A near block is leaf × leaf: its columns are in one batch.
            Work::Near if self.rows == self.cols => Some(Some(Stored::Near(near_entries(
                self.view(&self.cols),
                true,
            )))),
            Work::Near => self.near_off_diagonal(budget).map(Some),
            Work::Far(pending) => self.add_far(pending, budget),
        }
    }

    /// An inadmissible block off the diagonal (two neighbouring leaves):
    /// its factors truncated at the budget's threshold when they are
    /// smaller than its entries (`3(m + n) r < 9 m n`, rank within the
    /// kernel's bound), else its exact entries. `None` if the SVD failed.
    fn near_off_diagonal(&self, budget: Budget) -> Option<Stored> {
        let b = self.view(&self.cols);
        let pairs = self.rows.len() * self.cols.len();
        let svd = TruncatedSvd::of(b, budget.threshold(b.squared_norm_l2(), pairs))?;
        let (m, n, r) = (self.rows.len(), self.cols.len(), svd.rank());
        Some(
            if (1..=HIERARCHY_MAX_RANK).contains(&r) && 3 * (m + n) * r < 9 * m * n {
                stored(&svd, m, n)
            } else {
                Stored::Near(near_entries(b, false))
            },
        )
    }

    /// Adds this batch's part to a far block (module docs, error budget).
    fn add_far(&self, p: &mut Pending, budget: Budget) -> Option<Option<Stored>> {
        let within = self.cols.start.max(self.batch.start)..self.cols.end.min(self.batch.end);
        let part = self.view(&within);
        let part_norm2 = part.squared_norm_l2();
        let part_pairs = self.rows.len() * within.len();
        p.norm2 += part_norm2;
        p.pairs += part_pairs;
        p.seen += 1;
        let share = if p.parts == 1 { 1.0 } else { 0.5 };
        let svd = TruncatedSvd::of(part, share * budget.threshold(part_norm2, part_pairs))?;
        if p.parts == 1 {
            return Some(Some(stored(&svd, self.rows.len(), self.cols.len())));
        }
        let (l, v) = svd.weighted_left();
        let mut r = Mat::<f64>::zeros(3 * self.cols.len(), v.ncols());
        r.submatrix_mut(
            3 * (within.start - self.cols.start),
            0,
            v.nrows(),
            v.ncols(),
        )
        .copy_from(&v);
        let (l, r) = match p.factors.take() {
            None => (l, r),
            Some((l0, r0)) => (
                concat(l0.as_ref(), l.as_ref()),
                concat(r0.as_ref(), r.as_ref()),
            ),
        };
        let threshold = budget.threshold(p.norm2, p.pairs);
        if p.seen == p.parts {
            let svd = TruncatedSvd::of_product(l.as_ref(), r.as_ref(), threshold / 4.0)?;
            return Some(Some(stored(&svd, self.rows.len(), self.cols.len())));
        }
        p.factors = Some(if p.seen >= 2 {
            let steps = (p.parts - 2).max(1) as f64;
            TruncatedSvd::of_product(l.as_ref(), r.as_ref(), threshold / (4.0 * steps))?
                .weighted_left()
        } else {
            (l, r)
        });
        Some(None)
    }
}

/// `[a b]`: the columns of `a` then those of `b` (same row count).
fn concat(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    let mut out = Mat::<f64>::zeros(a.nrows(), a.ncols() + b.ncols());
    out.submatrix_mut(0, 0, a.nrows(), a.ncols()).copy_from(a);
    out.submatrix_mut(0, a.ncols(), b.nrows(), b.ncols())
        .copy_from(b);
    out
}

/// A complete far block of `rows × cols` vertices, truncated as `svd`: its
/// balanced factors, or its entries when they are smaller or the rank is
/// above the kernel's bound; truncated to zero, rank-1 zero factors when
/// they are smaller than its entries (module docs).
fn stored(svd: &TruncatedSvd, rows: usize, cols: usize) -> Stored {
    let r = svd.rank();
    if r == 0 && 3 * (rows + cols) < 9 * rows * cols {
        return Stored::Far {
            left: vec![0.0; 3 * rows],
            right: vec![0.0; 3 * cols],
            rank: 1,
        };
    }
    if r == 0 || r > HIERARCHY_MAX_RANK || 3 * (rows + cols) * r >= 9 * rows * cols {
        let (l, v) = svd.weighted_left();
        let product = &l * v.transpose();
        return Stored::Near(near_entries(product.as_ref(), false));
    }
    let (l, r_factor) = svd.balanced();
    Stored::Far {
        left: row_major(l.as_ref()),
        right: row_major(r_factor.as_ref()),
        rank: r,
    }
}

/// The entries of a `3m × 3n` block as the format stores a near block:
/// 3×3 blocks row-major, block `(i, j)` at `9(i·n + j)`; `symmetric`: the
/// average of the block and its transpose (a diagonal block `(τ, τ)`).
fn near_entries(b: MatRef<'_, f64>, symmetric: bool) -> Vec<f64> {
    let (m, n) = (b.nrows() / 3, b.ncols() / 3);
    let mut out = Vec::with_capacity(9 * m * n);
    for i in 0..m {
        for j in 0..n {
            for a in 0..3 {
                for c in 0..3 {
                    let (p, q) = (3 * i + a, 3 * j + c);
                    out.push(if symmetric {
                        0.5 * (b[(p, q)] + b[(q, p)])
                    } else {
                        b[(p, q)]
                    });
                }
            }
        }
    }
    out
}

/// A matrix's entries row by row.
fn row_major(a: MatRef<'_, f64>) -> Vec<f64> {
    (0..a.nrows())
        .flat_map(|i| (0..a.ncols()).map(move |j| a[(i, j)]))
        .collect()
}
