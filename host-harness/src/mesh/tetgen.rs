//! TetGen `.node` / `.ele` reader.

use super::cursor::{NOT_A_REGION, cap, parse_tok, region_id, show};
use super::validate::{Numbering, RawMesh, validate};
use super::{MeshError, MeshReport, TetMesh};

/// Non-empty lines with `#` comments removed, with 1-based line numbers.
fn lines(bytes: &[u8]) -> impl Iterator<Item = (usize, Vec<&[u8]>)> {
    bytes
        .split(|&c| c == b'\n')
        .enumerate()
        .filter_map(|(i, l)| {
            let l = l.split(|&c| c == b'#').next().unwrap_or(&[]);
            let toks: Vec<&[u8]> = l
                .split(|c| c.is_ascii_whitespace())
                .filter(|t| !t.is_empty())
                .collect();
            (!toks.is_empty()).then_some((i + 1, toks))
        })
}

fn perr(file: &str, line: usize, msg: impl core::fmt::Display) -> MeshError {
    MeshError::Parse {
        file: file.to_string(),
        msg: format!("line {line}: {msg}"),
    }
}

fn num<T: core::str::FromStr>(
    file: &str,
    line: usize,
    toks: &[&[u8]],
    k: usize,
    what: &str,
) -> Result<T, MeshError> {
    let tok = toks
        .get(k)
        .ok_or_else(|| perr(file, line, format_args!("missing {what}")))?;
    parse_tok(tok).ok_or_else(|| {
        perr(
            file,
            line,
            format_args!("{what}: expected a number, found {:?}", show(tok)),
        )
    })
}

/// Read a TetGen mesh from the contents of its `.node` and `.ele` files.
///
/// `source` names the mesh (e.g. the path without extension): messages about vertices name
/// `{source}.node`, messages about tets `{source}.ele`. The numbering base (0 or 1) is the first
/// index in the `.node` file; node indices must then be consecutive. `.ele` files with 10-node tets
/// are read using their first 4 nodes (the corners). The first `.ele` attribute of each tet is its
/// region id ([`MeshReport::tet_regions`], an integer from 0 to `u32::MAX`); other attributes, the
/// `.node` attributes and boundary markers are ignored.
pub fn read_tetgen(
    node: &[u8],
    ele: &[u8],
    source: &str,
) -> Result<(TetMesh, MeshReport), MeshError> {
    let nf = format!("{source}.node");
    let ef = format!("{source}.ele");
    let (positions, base) = read_node(node, &nf)?;
    let Ele { tets, tet_regions } = read_ele(ele, &ef)?;
    let raw = RawMesh {
        positions,
        node_ids: None,
        tets,
        elem_ids: None,
        numbering: Numbering::Base(base),
        skipped: 0,
        tet_regions,
    };
    validate(raw, &nf, &ef, &nf)
}

/// The `.node` file `node` (named `nf` in messages): the header `N dim
/// [nattr [nbnd]]` (3 dimensions), then `N` vertices with consecutive
/// indices from 0 or 1. Returns the positions and the numbering base.
fn read_node(node: &[u8], nf: &str) -> Result<(Vec<[f64; 3]>, i64), MeshError> {
    let mut it = lines(node);
    let (hl, h) = it.next().ok_or_else(|| MeshError::Parse {
        file: nf.to_string(),
        msg: "empty file: missing header `N dim nattr nbnd`".into(),
    })?;
    let n: usize = num(nf, hl, &h, 0, "number of nodes")?;
    let dim: usize = num(nf, hl, &h, 1, "dimension")?;
    if dim != 3 {
        return Err(perr(nf, hl, format_args!("dimension {dim}, expected 3")));
    }
    // Attributes and boundary markers are ignored, but the header must be numeric.
    let _nattr: usize = if h.len() > 2 {
        num(nf, hl, &h, 2, "attribute count")?
    } else {
        0
    };
    let _nbnd: usize = if h.len() > 3 {
        num(nf, hl, &h, 3, "boundary marker flag")?
    } else {
        0
    };
    let mut positions = Vec::with_capacity(cap(n, node.len()));
    let mut base = 0i64;
    for i in 0..n {
        let (l, t) = it.next().ok_or_else(|| MeshError::Parse {
            file: nf.to_string(),
            msg: format!("unexpected end of file (truncated?) at vertex {i} of {n}"),
        })?;
        let idx: i64 = num(nf, l, &t, 0, &format!("vertex {i}: node index"))?;
        if i == 0 {
            base = idx;
            if base != 0 && base != 1 {
                return Err(perr(
                    nf,
                    l,
                    format_args!("first node index {idx}, expected 0 or 1"),
                ));
            }
        } else if i128::from(idx) != i128::from(base) + i as i128 {
            return Err(perr(
                nf,
                l,
                format_args!(
                    "vertex {i}: node index {idx}, expected {}",
                    i128::from(base) + i as i128
                ),
            ));
        }
        let mut p = [0.0; 3];
        for (c, x) in p.iter_mut().enumerate() {
            *x = num(nf, l, &t, 1 + c, &format!("vertex {i}: coordinate {c}"))?;
        }
        positions.push(p);
    }
    Ok((positions, base))
}

/// An `.ele` file as read.
struct Ele {
    /// Each tet's first 4 node indices, as written.
    tets: Vec<[i64; 4]>,
    /// Where the tets have attributes, the first of each as its region id.
    tet_regions: Option<Vec<u32>>,
}

/// The `.ele` file `ele` (named `ef` in messages): the header `M
/// [nodes_per_tet [nattr]]` (4 or 10 nodes), then `M` tets, read by their
/// first 4 nodes (the corners).
fn read_ele(ele: &[u8], ef: &str) -> Result<Ele, MeshError> {
    let mut it = lines(ele);
    let (hl, h) = it.next().ok_or_else(|| MeshError::Parse {
        file: ef.to_string(),
        msg: "empty file: missing header `M nodes_per_tet nattr`".into(),
    })?;
    let m: usize = num(ef, hl, &h, 0, "number of tets")?;
    let npt: usize = if h.len() > 1 {
        num(ef, hl, &h, 1, "nodes per tet")?
    } else {
        4
    };
    if npt != 4 && npt != 10 {
        return Err(perr(
            ef,
            hl,
            format_args!("{npt} nodes per tet, expected 4 or 10"),
        ));
    }
    let nattr: usize = if h.len() > 2 {
        num(ef, hl, &h, 2, "attribute count")?
    } else {
        0
    };
    let mut tets = Vec::with_capacity(cap(m, ele.len()));
    let mut regions = Vec::with_capacity(if nattr > 0 { cap(m, ele.len()) } else { 0 });
    for i in 0..m {
        let (l, t) = it.next().ok_or_else(|| MeshError::Parse {
            file: ef.to_string(),
            msg: format!("unexpected end of file (truncated?) at tet {i} of {m}"),
        })?;
        if t.len() < 1 + npt {
            return Err(perr(
                ef,
                l,
                format_args!(
                    "tet {i}: {} vertex indices, expected {npt}",
                    t.len().saturating_sub(1)
                ),
            ));
        }
        let mut tet = [0i64; 4];
        for (c, v) in tet.iter_mut().enumerate() {
            *v = num(ef, l, &t, 1 + c, &format!("tet {i}: vertex index"))?;
        }
        tets.push(tet);
        if nattr > 0 {
            let attribute: f64 = num(ef, l, &t, 1 + npt, &format!("tet {i}: region attribute"))?;
            let region = region_id(attribute).ok_or_else(|| {
                perr(
                    ef,
                    l,
                    format_args!("tet {i}: region attribute {attribute} {NOT_A_REGION}"),
                )
            })?;
            regions.push(region);
        }
    }
    Ok(Ele {
        tets,
        tet_regions: (nattr > 0).then_some(regions),
    })
}
