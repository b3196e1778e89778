//! What `tables info` says about a hierarchical compliance part beyond its
//! sections: its blocks by level and rank ([`describe_hierarchy`]).

use core::fmt::Write as _;

use palpate_kernel::Real;
use palpate_kernel::table::HierarchicalBlocks;
use palpate_kernel::table::format::HierarchyBlock;

/// Bounds of the rank histogram's bins: `1`, `2`, `3–4`, `5–8`, …, `33–64`
/// ([`palpate_kernel::table::format::HIERARCHY_MAX_RANK`] is 64).
const RANK_BINS: [u32; 7] = [1, 2, 4, 8, 16, 32, 64];

/// The level of a block in the cluster tree: the number of halvings from
/// `S` touchable vertices to its row cluster's size, `round(log₂(S/rows))`
/// (the tree bisects at the median, so a cluster of level `d` holds about
/// `S/2^d` vertices).
fn level(block: &HierarchyBlock, s: usize) -> usize {
    let ratio = s as f64 / block.rows().max(1) as f64;
    ratio.log2().round().max(0.0) as usize
}

/// Bytes a block's data take in the table (a mirrored near block's data
/// are its mirror's: 0 here, counted there; a far block below the diagonal
/// shares its mirror's factors: 0 too).
fn stored_bytes(block: &HierarchyBlock, scalar_bytes: usize) -> usize {
    let upper = block.row_start <= block.col_start;
    if upper {
        block.data_len() * scalar_bytes
    } else {
        0
    }
}

/// The hierarchical part for people: its leaves and blocks, the bytes of
/// each level (near entries and far factors), and the far blocks' rank
/// histogram.
pub fn describe_hierarchy<T: Real>(h: &HierarchicalBlocks<'_, T>) -> String {
    let r = h.record();
    let s = h.touchable_count();
    let scalar_bytes = h.value_bytes();
    let blocks = h.blocks();
    let far = blocks.iter().filter(|b| b.rank > 0).count();
    let mut out = String::new();
    let _ = writeln!(
        out,
        "hierarchy: {} leaves (leaf size {}, depth {}), {} blocks: {} near, {far} far \
         (admissibility eta {}, tolerance {:e} relative per block); max rank {}, longest \
         column list {} blocks; data {} bytes",
        h.leaf_count(),
        r.leaf_size,
        r.depth,
        blocks.len(),
        blocks.len() - far,
        r.eta,
        r.tolerance,
        r.max_rank,
        r.max_column_blocks,
        h.data_len() * scalar_bytes
    );
    let levels = blocks.iter().map(|b| level(b, s)).max().unwrap_or(0) + 1;
    let mut near_bytes = vec![0usize; levels];
    let mut far_bytes = vec![0usize; levels];
    for b in blocks {
        let bytes = if b.rank == 0 {
            &mut near_bytes
        } else {
            &mut far_bytes
        };
        bytes[level(b, s)] += stored_bytes(b, scalar_bytes);
    }
    for (d, (near, far)) in near_bytes.iter().zip(&far_bytes).enumerate() {
        if near + far > 0 {
            let _ = writeln!(
                out,
                "  level {d} (clusters of about {} vertices): near {near} bytes, far {far} bytes",
                s >> d.min(63)
            );
        }
    }
    let mut bins = [0usize; RANK_BINS.len()];
    for b in blocks
        .iter()
        .filter(|b| b.rank > 0 && b.row_start <= b.col_start)
    {
        let bin = RANK_BINS.iter().position(|&hi| b.rank <= hi);
        bins[bin.unwrap_or(RANK_BINS.len() - 1)] += 1;
    }
    let _ = write!(out, "  far-block ranks (upper triangle):");
    let mut lo = 1;
    for (hi, count) in RANK_BINS.iter().zip(bins) {
        if lo == *hi {
            let _ = write!(out, " {hi}: {count};");
        } else {
            let _ = write!(out, " {lo}-{hi}: {count};");
        }
        lo = hi + 1;
    }
    out.pop();
    out
}
