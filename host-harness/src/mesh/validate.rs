//! Shared validation: raw reader output → [`TetMesh`] + [`MeshReport`].

use std::collections::HashMap;
use std::collections::hash_map::Entry;

use super::{MeshError, MeshReport, TetMesh, surface};

/// How a reader's vertex references map to 0-based vertex indices.
pub(crate) enum Numbering {
    /// index = reference − base.
    Base(i64),
    /// Arbitrary file ids (MSH node tags) → index.
    Ids(HashMap<i64, u32>),
}

impl Numbering {
    /// Ids in order of appearance → `Base(first)` if consecutive, else a map. Err on a repeated id:
    /// `(id, first vertex, second vertex)`.
    pub(crate) fn from_ids(ids: &[i64]) -> Result<Self, (i64, usize, usize)> {
        let first = ids.first().copied().unwrap_or(0);
        let consecutive = ids
            .iter()
            .enumerate()
            .all(|(i, &id)| i64::try_from(i).ok().and_then(|i| first.checked_add(i)) == Some(id));
        if consecutive {
            return Ok(Self::Base(first));
        }
        let mut map = HashMap::with_capacity(ids.len());
        for (i, &id) in ids.iter().enumerate() {
            match map.entry(id) {
                Entry::Occupied(e) => return Err((id, *e.get() as usize, i)),
                Entry::Vacant(e) => {
                    e.insert(u32::try_from(i).unwrap_or(u32::MAX));
                }
            }
        }
        Ok(Self::Ids(map))
    }
}

/// A reader's output before validation.
pub(crate) struct RawMesh {
    pub positions: Vec<[f64; 3]>,
    /// File id per vertex, for messages (MSH).
    pub node_ids: Option<Vec<i64>>,
    /// Tets as file vertex references (see `numbering`).
    pub tets: Vec<[i64; 4]>,
    /// File id per tet, for messages (MSH).
    pub elem_ids: Option<Vec<i64>>,
    pub numbering: Numbering,
    /// Non-tet elements skipped.
    pub skipped: usize,
    /// Region id per tet, in `tets` order, where the file has them
    /// ([`MeshReport::tet_regions`]).
    pub tet_regions: Option<Vec<u32>>,
}

/// `det[b-a, c-a, d-a] / 6`.
pub(crate) fn signed_volume(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> f64 {
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let w = [d[0] - a[0], d[1] - a[1], d[2] - a[2]];
    let det = u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
        + u[2] * (v[0] * w[1] - v[1] * w[0]);
    det / 6.0
}

/// Validate `raw`. `vertex_file` names vertex errors, `tet_file` tet errors, `source` the report.
///
/// Stages: the vertices ([`check_vertices`]), the tets' references resolved
/// to vertex indices ([`resolve_tets`]), their volumes and orientation
/// ([`orient`]), no tet twice ([`check_duplicates`]), then the report.
pub(crate) fn validate(
    raw: RawMesh,
    vertex_file: &str,
    tet_file: &str,
    source: &str,
) -> Result<(TetMesh, MeshReport), MeshError> {
    let RawMesh {
        positions,
        node_ids,
        tets: raw_tets,
        elem_ids,
        numbering,
        skipped,
        tet_regions,
    } = raw;
    check_vertices(&positions, node_ids.as_deref(), vertex_file)?;
    if raw_tets.is_empty() {
        return Err(MeshError::NoTets {
            file: tet_file.to_string(),
            skipped,
        });
    }
    let names = TetNames {
        file: tet_file,
        elem_ids: elem_ids.as_deref(),
    };
    let vertices = Vertices {
        count: positions.len(),
        numbering: &numbering,
        has_node_ids: node_ids.is_some(),
    };
    let tets = resolve_tets(raw_tets, &vertices, &names)?;
    let mut mesh = TetMesh { positions, tets };
    let reoriented = orient(&mut mesh, &names)?;
    check_duplicates(&mesh, &names)?;

    let unreferenced_vertices: Vec<u32> = mesh
        .referenced()
        .iter()
        .enumerate()
        .filter(|(_, r)| !**r)
        .filter_map(|(i, _)| u32::try_from(i).ok())
        .collect();

    let warnings = surface::check(&mesh);
    let report = MeshReport {
        source: source.to_string(),
        skipped_elements: skipped,
        reoriented_tets: reoriented,
        unreferenced_vertices,
        warnings,
        tet_regions,
    };
    Ok((mesh, report))
}

/// What names a tet in an error: its file and, where the file has them
/// (MSH), its element id.
struct TetNames<'a> {
    file: &'a str,
    elem_ids: Option<&'a [i64]>,
}

impl TetNames<'_> {
    /// The file id of tet `t`, if the file has ids.
    fn elem_id(&self, t: usize) -> Option<i64> {
        self.elem_ids.and_then(|ids| ids.get(t).copied())
    }
}

/// The vertices a tet's references resolve to.
struct Vertices<'a> {
    /// Vertices read.
    count: usize,
    /// How a reference maps to a vertex index.
    numbering: &'a Numbering,
    /// The file has node ids (MSH): a reference below the first id is named
    /// as the id written.
    has_node_ids: bool,
}

/// Every vertex of `positions` has an index that fits `u32` and finite
/// coordinates; `node_ids` name them where the file has ids.
fn check_vertices(
    positions: &[[f64; 3]],
    node_ids: Option<&[i64]>,
    vertex_file: &str,
) -> Result<(), MeshError> {
    let n = positions.len();
    if u32::try_from(n).is_err() {
        return Err(MeshError::TooManyVertices {
            file: vertex_file.to_string(),
            count: n,
        });
    }
    for (i, p) in positions.iter().enumerate() {
        if let Some((c, &x)) = p.iter().enumerate().find(|(_, x)| !x.is_finite()) {
            return Err(MeshError::NonFiniteCoordinate {
                file: vertex_file.to_string(),
                vertex: i,
                node_id: node_ids.and_then(|ids| ids.get(i).copied()),
                component: c,
                value: x,
            });
        }
    }
    Ok(())
}

/// Each tet of `raw_tets` as four distinct vertex indices: every reference
/// resolved ([`resolve_reference`]), no vertex twice in a tet.
fn resolve_tets(
    raw_tets: Vec<[i64; 4]>,
    vertices: &Vertices<'_>,
    names: &TetNames<'_>,
) -> Result<Vec<[u32; 4]>, MeshError> {
    let mut tets = Vec::with_capacity(raw_tets.len());
    for (t, raw_t) in raw_tets.iter().enumerate() {
        let mut tet = [0u32; 4];
        for (slot, &r) in tet.iter_mut().zip(raw_t) {
            *slot = resolve_reference(r, t, vertices, names)?;
        }
        for i in 0..4 {
            for j in (i + 1)..4 {
                if tet[i] == tet[j] {
                    return Err(MeshError::RepeatedVertex {
                        file: names.file.to_string(),
                        tet: t,
                        elem_id: names.elem_id(t),
                        vertex: tet[i],
                        vertices: tet,
                    });
                }
            }
        }
        tets.push(tet);
    }
    Ok(tets)
}

/// The vertex index of reference `r` of tet `t`: an index out of range, or
/// an id the file does not define, is an error naming the tet.
fn resolve_reference(
    r: i64,
    t: usize,
    vertices: &Vertices<'_>,
    names: &TetNames<'_>,
) -> Result<u32, MeshError> {
    let n = vertices.count;
    let unknown_node = || MeshError::UnknownNode {
        file: names.file.to_string(),
        tet: t,
        elem_id: names.elem_id(t),
        node_id: r,
        n_vertices: n,
    };
    match vertices.numbering {
        Numbering::Base(base) => {
            let idx = i128::from(r) - i128::from(*base);
            match u32::try_from(idx) {
                Ok(i) if (i as usize) < n => Ok(i),
                // Below the file's first id (an MSH node id of 0):
                // name the id as written, not a negative index.
                Err(_) if vertices.has_node_ids => Err(unknown_node()),
                _ => Err(MeshError::IndexOutOfRange {
                    file: names.file.to_string(),
                    tet: t,
                    elem_id: names.elem_id(t),
                    index: i64::try_from(idx).unwrap_or(i64::MAX),
                    n_vertices: n,
                }),
            }
        }
        Numbering::Ids(map) => map.get(&r).copied().ok_or_else(unknown_node),
    }
}

/// Refuses a degenerate tet (volume not finite, zero, or below `1e-9` of
/// the mean absolute finite volume), then swaps two corners of each
/// negatively oriented tet: returns how many.
fn orient(mesh: &mut TetMesh, names: &TetNames<'_>) -> Result<usize, MeshError> {
    let vols: Vec<f64> = (0..mesh.tets.len()).map(|t| mesh.tet_volume(t)).collect();
    let finite: Vec<f64> = vols
        .iter()
        .filter(|v| v.is_finite())
        .map(|v| v.abs())
        .collect();
    let mean = if finite.is_empty() {
        0.0
    } else {
        finite.iter().sum::<f64>() / finite.len() as f64
    };
    for (t, &v) in vols.iter().enumerate() {
        if !v.is_finite() || v == 0.0 || v.abs() < 1e-9 * mean {
            return Err(MeshError::DegenerateTet {
                file: names.file.to_string(),
                tet: t,
                elem_id: names.elem_id(t),
                volume: v,
                mean,
            });
        }
    }
    let mut reoriented = 0;
    for (tet, &v) in mesh.tets.iter_mut().zip(&vols) {
        if v < 0.0 {
            tet.swap(2, 3);
            reoriented += 1;
        }
    }
    Ok(reoriented)
}

/// Refuses two tets on the same four vertices, naming both.
fn check_duplicates(mesh: &TetMesh, names: &TetNames<'_>) -> Result<(), MeshError> {
    let mut seen: HashMap<[u32; 4], usize> = HashMap::with_capacity(mesh.tets.len());
    for (t, tet) in mesh.tets.iter().enumerate() {
        let mut key = *tet;
        key.sort_unstable();
        match seen.entry(key) {
            Entry::Occupied(e) => {
                let first = *e.get();
                return Err(MeshError::DuplicateTet {
                    file: names.file.to_string(),
                    first,
                    first_id: names.elem_id(first),
                    second: t,
                    second_id: names.elem_id(t),
                    vertices: key,
                });
            }
            Entry::Vacant(e) => {
                e.insert(t);
            }
        }
    }
    Ok(())
}
