//! Gmsh MSH reader: versions 2.x and 4.1, ASCII and binary. Hand-written (no `mshio`) so that every
//! input, however broken, gives an error rather than a panic.
//!
//! Region ids ([`super::MeshReport::tet_regions`]): in 2.x the first tag of a tet element (its
//! physical tag), in 4.1 the first physical tag of the volume entity its element block names,
//! read from `$Entities`.

use std::collections::HashMap;

use super::MeshError;
use super::cursor::{Cursor, NOT_A_REGION, cap, parse_tok, show};
use super::validate::{Numbering, RawMesh};

/// Gmsh element type of the linear tet.
const TET4: i64 = 4;
/// Gmsh element type of the quadratic tet (first 4 nodes are the corners).
const TET10: i64 = 11;

/// Number of nodes of a Gmsh element type, `None` if unknown.
fn nodes_per_element(ty: i64) -> Option<usize> {
    Some(match ty {
        1 => 2,
        2 => 3,
        3 => 4,
        4 => 4,
        5 => 8,
        6 => 6,
        7 => 5,
        8 => 3,
        9 => 6,
        10 => 9,
        11 => 10,
        12 => 27,
        13 => 18,
        14 => 14,
        15 => 1,
        16 => 8,
        17 => 20,
        18 => 15,
        19 => 13,
        20 => 9,
        21 => 10,
        22 => 12,
        23 => 15,
        24 => 15,
        25 => 21,
        26 => 4,
        27 => 5,
        28 => 6,
        29 => 20,
        30 => 35,
        31 => 56,
        92 => 64,
        93 => 125,
        _ => return None,
    })
}

#[derive(Clone, Copy, PartialEq)]
enum Version {
    V2,
    V41,
}

struct Header {
    version: Version,
    binary: bool,
    big: bool,
    /// Size of `size_t` in 4.1 binary files.
    size_t: usize,
}

#[derive(Default)]
struct Acc {
    positions: Vec<[f64; 3]>,
    node_ids: Vec<i64>,
    tets: Vec<[i64; 4]>,
    elem_ids: Vec<i64>,
    /// Per tet: its first tag (2.x: the physical tag, 0 without tags) or the tag of the entity
    /// of its element block (4.1).
    tet_keys: Vec<i64>,
    /// 4.1 `$Entities`: volume entity tag → its first physical tag (0 without one); `None`
    /// without the section or if it does not parse.
    volume_physical: Option<HashMap<i64, i64>>,
    skipped: usize,
    have_nodes: bool,
    have_elements: bool,
}

impl Acc {
    /// Record element `id` of type `ty` with nodes `nodes` and region key `key` (see
    /// [`Acc::tet_keys`]).
    fn element(&mut self, ty: i64, id: i64, nodes: &[i64], key: i64) {
        if ty == TET4 || ty == TET10 {
            let mut t = [0i64; 4];
            for (s, n) in t.iter_mut().zip(nodes) {
                *s = *n;
            }
            self.tets.push(t);
            self.elem_ids.push(id);
            self.tet_keys.push(key);
        } else {
            self.skipped += 1;
        }
    }

    /// Each tet's region id: its key (2.x), or its entity's physical tag (4.1, `None` without
    /// `$Entities`; an entity not listed there has none: 0). Errors on a tag outside `u32`.
    fn tet_regions(&self, version: Version, file: &str) -> Result<Option<Vec<u32>>, MeshError> {
        let entities = match (version, &self.volume_physical) {
            (Version::V2, _) => None,
            (Version::V41, Some(map)) => Some(map),
            (Version::V41, None) => return Ok(None),
        };
        self.tet_keys
            .iter()
            .zip(&self.elem_ids)
            .enumerate()
            .map(|(t, (&key, &id))| {
                let tag = entities.map_or(key, |map| map.get(&key).copied().unwrap_or(0));
                u32::try_from(tag).map_err(|_| MeshError::Parse {
                    file: file.to_string(),
                    msg: format!("tet {t} (element id {id}): physical tag {tag} {NOT_A_REGION}"),
                })
            })
            .collect::<Result<Vec<u32>, _>>()
            .map(Some)
    }
}

/// Parse an MSH file into unvalidated arrays.
pub(crate) fn parse(bytes: &[u8], file: &str) -> Result<RawMesh, MeshError> {
    let mut cur = Cursor::new(bytes, file);
    let header = parse_header(&mut cur)?;
    let mut acc = Acc::default();
    while let Some(tok) = cur.token() {
        let Some(name) = tok.strip_prefix(b"$") else {
            return Err(cur.err(format_args!("expected a $Section, found {:?}", show(tok))));
        };
        match name {
            b"Nodes" => {
                if acc.have_nodes {
                    return Err(cur.err("second $Nodes section"));
                }
                cur.section = "$Nodes";
                match header.version {
                    Version::V2 => nodes_v2(&mut cur, &header, &mut acc)?,
                    Version::V41 => nodes_v41(&mut cur, &header, &mut acc)?,
                }
                acc.have_nodes = true;
                expect_end(&mut cur, b"$EndNodes")?;
            }
            b"Entities" if header.version == Version::V41 => {
                let body = cur.rest();
                if !cur.skip_past(b"$EndEntities") {
                    return Err(cur.eof("section $Entities"));
                }
                let len = body.len() - cur.rest().len() - b"$EndEntities".len();
                let mut entities = Cursor::new(body.get(..len).unwrap_or(&[]), file);
                entities.section = "$Entities";
                // Only the region ids need it: a section that does not parse gives none, and
                // the mesh is read as before.
                acc.volume_physical = entities_v41(&mut entities, &header).ok();
            }
            b"Elements" => {
                if acc.have_elements {
                    return Err(cur.err("second $Elements section"));
                }
                cur.section = "$Elements";
                match header.version {
                    Version::V2 => elements_v2(&mut cur, &header, &mut acc)?,
                    Version::V41 => elements_v41(&mut cur, &header, &mut acc)?,
                }
                acc.have_elements = true;
                expect_end(&mut cur, b"$EndElements")?;
            }
            _ => {
                let mut end = b"$End".to_vec();
                end.extend_from_slice(name);
                if !cur.skip_past(&end) {
                    return Err(cur.eof(format_args!("section ${}", show(name))));
                }
            }
        }
    }
    cur.section = "file";
    if !acc.have_nodes {
        return Err(cur.err("no $Nodes section"));
    }
    if !acc.have_elements {
        return Err(cur.err("no $Elements section"));
    }
    let numbering = Numbering::from_ids(&acc.node_ids).map_err(|(id, a, b)| MeshError::Parse {
        file: file.to_string(),
        msg: format!("$Nodes: node id {id} defined twice (vertices {a} and {b})"),
    })?;
    let tet_regions = acc.tet_regions(header.version, file)?;
    Ok(RawMesh {
        positions: acc.positions,
        node_ids: Some(acc.node_ids),
        tets: acc.tets,
        elem_ids: Some(acc.elem_ids),
        numbering,
        skipped: acc.skipped,
        tet_regions,
    })
}

fn expect_end(cur: &mut Cursor<'_>, end: &[u8]) -> Result<(), MeshError> {
    let what = show(end);
    match cur.token() {
        Some(t) if t == end => Ok(()),
        Some(t) => Err(cur.err(format_args!(
            "expected {what}, found {:?} (counts do not match the data?)",
            show(t)
        ))),
        None => Err(cur.eof(&what)),
    }
}

fn parse_header(cur: &mut Cursor<'_>) -> Result<Header, MeshError> {
    let file = cur.file();
    let unsupported = |msg: String| MeshError::Unsupported {
        file: file.to_string(),
        msg,
    };
    match cur.token() {
        Some(b"$MeshFormat") => {}
        Some(b"$NOD") => return Err(unsupported("MSH version 1 ($NOD) is not supported".into())),
        Some(t) => {
            return Err(cur.err(format_args!(
                "not an MSH file: expected $MeshFormat, found {:?}",
                show(t)
            )));
        }
        None => return Err(cur.eof("$MeshFormat")),
    }
    cur.section = "$MeshFormat";
    let vtok = cur.expect_token(&"version")?;
    let version = match vtok {
        b"4.1" => Version::V41,
        v if v.starts_with(b"2") => Version::V2,
        v => {
            return Err(unsupported(format!(
                "MSH version {} (supported: 2.x, 4.1)",
                show(v)
            )));
        }
    };
    let ftype: i64 = cur.parse(&"file-type")?;
    let dsize: i64 = cur.parse(&"data-size")?;
    let binary = match ftype {
        0 => false,
        1 => true,
        _ => return Err(cur.err(format_args!("file-type {ftype} (expected 0 or 1)"))),
    };
    let size_t = match dsize {
        4 => 4,
        8 => 8,
        _ => return Err(cur.err(format_args!("data-size {dsize} (expected 8)"))),
    };
    let mut big = false;
    if binary {
        cur.skip_line();
        let one = cur.bytes(4, &"endianness marker")?;
        big = match one {
            [1, 0, 0, 0] => false,
            [0, 0, 0, 1] => true,
            _ => return Err(cur.err("bad endianness marker (expected the integer 1)")),
        };
    }
    expect_end(cur, b"$EndMeshFormat")?;
    Ok(Header {
        version,
        binary,
        big,
        size_t,
    })
}

/// A count read as ASCII.
fn count(cur: &mut Cursor<'_>, what: &str) -> Result<usize, MeshError> {
    cur.parse::<usize>(&what)
}

fn nodes_v2(cur: &mut Cursor<'_>, h: &Header, acc: &mut Acc) -> Result<(), MeshError> {
    let n = count(cur, "number of nodes")?;
    acc.positions.reserve(cap(n, cur.len()));
    acc.node_ids.reserve(cap(n, cur.len()));
    if h.binary {
        cur.skip_line();
    }
    for i in 0..n {
        let what = format_args!("node {i}");
        let (id, p) = if h.binary {
            let id = i64::from(cur.i32(h.big, &what)?);
            let mut p = [0.0; 3];
            for x in &mut p {
                *x = cur.f64(h.big, &what)?;
            }
            (id, p)
        } else {
            let id = cur.parse::<i64>(&what)?;
            let mut p = [0.0; 3];
            for x in &mut p {
                *x = cur.parse::<f64>(&what)?;
            }
            (id, p)
        };
        acc.node_ids.push(id);
        acc.positions.push(p);
    }
    Ok(())
}

fn elements_v2(cur: &mut Cursor<'_>, h: &Header, acc: &mut Acc) -> Result<(), MeshError> {
    let n = count(cur, "number of elements")?;
    acc.tets.reserve(cap(n, cur.len()));
    if !h.binary {
        for i in 0..n {
            let line = cur
                .nonempty_line()
                .ok_or_else(|| cur.eof(format_args!("element {i}")))?;
            if cur.at_end() {
                // `$EndElements` must follow: this line was cut.
                return Err(cur.eof(format_args!("element {i}")));
            }
            let mut nums = Vec::with_capacity(16);
            for tok in line
                .split(|c| c.is_ascii_whitespace())
                .filter(|t| !t.is_empty())
            {
                let v: i64 = parse_tok(tok).ok_or_else(|| {
                    cur.err(format_args!(
                        "element {i}: expected an integer, found {:?}",
                        show(tok)
                    ))
                })?;
                nums.push(v);
            }
            let (id, ty, ntags) = match nums.as_slice() {
                [id, ty, ntags, ..] => (*id, *ty, *ntags),
                _ => return Err(cur.err(format_args!("element {i}: short line"))),
            };
            let tags = usize::try_from(ntags).map_err(|_| {
                cur.err(format_args!("element {i} (id {id}): bad tag count {ntags}"))
            })?;
            let nodes = nums.get(3..).and_then(|r| r.get(tags..)).unwrap_or(&[]);
            let physical = if tags > 0 { nums.get(3).copied() } else { None };
            if ty == TET4 || ty == TET10 {
                let want = nodes_per_element(ty).unwrap_or(4);
                if nodes.len() != want {
                    return Err(cur.err(format_args!(
                        "element {i} (id {id}): tet has {} node ids, expected {want}",
                        nodes.len()
                    )));
                }
            }
            acc.element(ty, id, nodes, physical.unwrap_or(0));
        }
        return Ok(());
    }
    cur.skip_line();
    let mut done = 0usize;
    let mut nodes = Vec::new();
    while done < n {
        let what = format_args!("element block after {done} elements");
        let ty = i64::from(cur.i32(h.big, &what)?);
        let cnt = cur.i32(h.big, &what)?;
        let ntags = cur.i32(h.big, &what)?;
        let cnt = usize::try_from(cnt)
            .ok()
            .filter(|&c| c > 0 && c <= n - done)
            .ok_or_else(|| cur.err(format_args!("element block: bad element count {cnt}")))?;
        let ntags = usize::try_from(ntags)
            .map_err(|_| cur.err(format_args!("element block: bad tag count {ntags}")))?;
        let nn = nodes_per_element(ty)
            .ok_or_else(|| cur.err(format_args!("unknown element type {ty}")))?;
        for _ in 0..cnt {
            let what = format_args!("element {done}");
            let id = i64::from(cur.i32(h.big, &what)?);
            let mut physical = 0;
            for k in 0..ntags {
                let tag = cur.i32(h.big, &what)?;
                if k == 0 {
                    physical = i64::from(tag);
                }
            }
            nodes.clear();
            for _ in 0..nn {
                nodes.push(i64::from(cur.i32(h.big, &what)?));
            }
            acc.element(ty, id, &nodes, physical);
            done += 1;
        }
    }
    Ok(())
}

/// A 4.1 `size_t` (binary) or unsigned ASCII integer.
fn size(cur: &mut Cursor<'_>, h: &Header, what: &dyn core::fmt::Display) -> Result<u64, MeshError> {
    if h.binary {
        cur.uint(h.size_t, h.big, what)
    } else {
        cur.parse::<u64>(what)
    }
}

/// A 4.1 `int` (binary) or ASCII integer.
fn int(cur: &mut Cursor<'_>, h: &Header, what: &dyn core::fmt::Display) -> Result<i64, MeshError> {
    if h.binary {
        Ok(i64::from(cur.i32(h.big, what)?))
    } else {
        cur.parse::<i64>(what)
    }
}

fn to_usize(cur: &Cursor<'_>, v: u64, what: &str) -> Result<usize, MeshError> {
    usize::try_from(v).map_err(|_| cur.err(format_args!("{what} {v} too large")))
}

fn nodes_v41(cur: &mut Cursor<'_>, h: &Header, acc: &mut Acc) -> Result<(), MeshError> {
    if h.binary {
        cur.skip_line();
    }
    let nblocks = size(cur, h, &"number of entity blocks")?;
    let total = size(cur, h, &"number of nodes")?;
    let total = to_usize(cur, total, "number of nodes")?;
    size(cur, h, &"min node tag")?;
    size(cur, h, &"max node tag")?;
    acc.positions.reserve(cap(total, cur.len()));
    acc.node_ids.reserve(cap(total, cur.len()));
    for b in 0..nblocks {
        let what = format_args!("node block {b}");
        let dim = int(cur, h, &what)?;
        int(cur, h, &what)?;
        let parametric = int(cur, h, &what)?;
        let nb = size(cur, h, &what)?;
        let nb = to_usize(cur, nb, "node count")?;
        if nb > total - acc.node_ids.len().min(total) {
            return Err(cur.err(format_args!(
                "node block {b}: {nb} nodes exceed the declared total {total}"
            )));
        }
        let nparam = match (parametric, dim) {
            (0, _) => 0,
            (1, d @ 0..=3) => d as usize,
            _ => {
                return Err(cur.err(format_args!(
                    "node block {b}: bad entity dim {dim} / parametric {parametric}"
                )));
            }
        };
        let start = acc.node_ids.len();
        for i in 0..nb {
            let what = format_args!("node {}", start + i);
            let tag = size(cur, h, &what)?;
            acc.node_ids.push(i64::try_from(tag).unwrap_or(i64::MAX));
        }
        for i in 0..nb {
            let what = format_args!("node {}", start + i);
            let mut p = [0.0; 3];
            for x in &mut p {
                *x = if h.binary {
                    cur.f64(h.big, &what)?
                } else {
                    cur.parse::<f64>(&what)?
                };
            }
            for _ in 0..nparam {
                if h.binary {
                    cur.f64(h.big, &what)?;
                } else {
                    cur.parse::<f64>(&what)?;
                }
            }
            acc.positions.push(p);
        }
    }
    if acc.node_ids.len() != total {
        return Err(cur.err(format_args!(
            "{} nodes in blocks, header declares {total}",
            acc.node_ids.len()
        )));
    }
    Ok(())
}

fn elements_v41(cur: &mut Cursor<'_>, h: &Header, acc: &mut Acc) -> Result<(), MeshError> {
    if h.binary {
        cur.skip_line();
    }
    let nblocks = size(cur, h, &"number of entity blocks")?;
    let total = size(cur, h, &"number of elements")?;
    let total = to_usize(cur, total, "number of elements")?;
    size(cur, h, &"min element tag")?;
    size(cur, h, &"max element tag")?;
    acc.tets.reserve(cap(total, cur.len()));
    let mut done = 0usize;
    let mut nodes: Vec<i64> = Vec::new();
    for b in 0..nblocks {
        let what = format_args!("element block {b}");
        int(cur, h, &what)?;
        let entity = int(cur, h, &what)?;
        let ty = int(cur, h, &what)?;
        let nb = size(cur, h, &what)?;
        let nb = to_usize(cur, nb, "element count")?;
        if nb > total - done {
            return Err(cur.err(format_args!(
                "element block {b}: {nb} elements exceed the declared total {total}"
            )));
        }
        let nn = nodes_per_element(ty);
        for _ in 0..nb {
            let what = format_args!("element {done}");
            if h.binary {
                let nn = nn.ok_or_else(|| cur.err(format_args!("unknown element type {ty}")))?;
                let id = size(cur, h, &what)?;
                nodes.clear();
                for _ in 0..nn {
                    let v = size(cur, h, &what)?;
                    nodes.push(i64::try_from(v).unwrap_or(i64::MAX));
                }
                acc.element(ty, i64::try_from(id).unwrap_or(i64::MAX), &nodes, entity);
            } else {
                let line = cur.nonempty_line().ok_or_else(|| cur.eof(what))?;
                if cur.at_end() {
                    return Err(cur.eof(what));
                }
                nodes.clear();
                for tok in line
                    .split(|c| c.is_ascii_whitespace())
                    .filter(|t| !t.is_empty())
                {
                    let v: i64 = parse_tok(tok).ok_or_else(|| {
                        cur.err(format_args!(
                            "element {done}: expected an integer, found {:?}",
                            show(tok)
                        ))
                    })?;
                    nodes.push(v);
                }
                let Some((&id, rest)) = nodes.split_first() else {
                    return Err(cur.err(format_args!("element {done}: empty line")));
                };
                if let Some(want) = nn
                    && rest.len() != want
                {
                    return Err(cur.err(format_args!(
                        "element {done} (id {id}): {} node ids, type {ty} needs {want}",
                        rest.len()
                    )));
                }
                let rest = rest.to_vec();
                acc.element(ty, id, &rest, entity);
            }
            done += 1;
        }
    }
    if done != total {
        return Err(cur.err(format_args!(
            "{done} elements in blocks, header declares {total}"
        )));
    }
    Ok(())
}

/// A 4.1 `double` (binary) or ASCII real.
fn real(cur: &mut Cursor<'_>, h: &Header, what: &dyn core::fmt::Display) -> Result<f64, MeshError> {
    if h.binary {
        cur.f64(h.big, what)
    } else {
        cur.parse::<f64>(what)
    }
}

/// The 4.1 `$Entities` section: every volume's tag → its first physical tag (0 without one).
/// Points, curves and surfaces are read past. Every count is read from the input, and each
/// entry consumes input, so a huge count ends at the end of the file.
fn entities_v41(cur: &mut Cursor<'_>, h: &Header) -> Result<HashMap<i64, i64>, MeshError> {
    if h.binary {
        cur.skip_line();
    }
    let mut counts = [0u64; 4];
    for (dim, n) in counts.iter_mut().enumerate() {
        *n = size(
            cur,
            h,
            &format_args!("number of entities of dimension {dim}"),
        )?;
    }
    let mut volumes = HashMap::new();
    for (dim, &n) in counts.iter().enumerate() {
        for e in 0..n {
            let what = format_args!("entity {e} of dimension {dim}");
            let tag = int(cur, h, &what)?;
            // A point has its coordinates, any other entity its bounding box.
            let reals = if dim == 0 { 3 } else { 6 };
            for _ in 0..reals {
                real(cur, h, &what)?;
            }
            let physical_count = size(cur, h, &what)?;
            let mut first = 0;
            for k in 0..physical_count {
                let physical = int(cur, h, &what)?;
                if k == 0 {
                    first = physical;
                }
            }
            if dim > 0 {
                let bounding = size(cur, h, &what)?;
                for _ in 0..bounding {
                    int(cur, h, &what)?;
                }
            }
            if dim == 3 {
                volumes.insert(tag, first);
            }
        }
    }
    Ok(volumes)
}
