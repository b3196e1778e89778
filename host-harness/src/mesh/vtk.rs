//! VTK legacy `UNSTRUCTURED_GRID` reader (ASCII and big-endian binary; classic `CELLS n size`
//! layout and the 5.1 `OFFSETS`/`CONNECTIVITY` layout).
//!
//! Region ids ([`super::MeshReport::tet_regions`]): the `CELL_DATA` array named `region`, a
//! `SCALARS` or a `FIELD` array of one component, each value an integer from 0 to `u32::MAX`
//! (of any numeric type). The attribute arrays before it are read past (`SCALARS`, `FIELD`,
//! `VECTORS`, `NORMALS`, `TENSORS`); the search ends at any other keyword, without regions.

use super::MeshError;
use super::cursor::{Cursor, NOT_A_REGION, cap, parse_tok, region_id, show};
use super::validate::{Numbering, RawMesh};

/// VTK cell type of the linear tet.
const VTK_TETRA: i64 = 10;
/// VTK cell type of the quadratic tet (first 4 points are the corners).
const VTK_QUADRATIC_TETRA: i64 = 24;

struct Reader<'a> {
    cur: Cursor<'a>,
    binary: bool,
}

impl Reader<'_> {
    /// After a keyword line: binary data starts on the next line.
    fn start_data(&mut self) {
        if self.binary {
            self.cur.skip_line();
        }
    }

    fn float(&mut self, double: bool, what: &dyn core::fmt::Display) -> Result<f64, MeshError> {
        match (self.binary, double) {
            (false, _) => self.cur.parse::<f64>(what),
            (true, true) => self.cur.f64(true, what),
            (true, false) => self.cur.f32(true, what),
        }
    }

    /// Integer of `size` bytes in binary (4 or 8), any integer in ASCII.
    fn int(&mut self, size: usize, what: &dyn core::fmt::Display) -> Result<i64, MeshError> {
        match (self.binary, size) {
            (false, _) => self.cur.parse::<i64>(what),
            (true, 8) => self.cur.i64(true, what),
            (true, _) => Ok(i64::from(self.cur.i32(true, what)?)),
        }
    }

    fn count(&mut self, what: &str) -> Result<usize, MeshError> {
        self.cur.parse::<usize>(&what)
    }
}

/// Bytes of an integer data type name in binary files.
fn int_size(ty: &[u8]) -> Option<usize> {
    match ty.to_ascii_lowercase().as_slice() {
        b"int" | b"unsigned_int" | b"vtktypeint32" | b"vtktypeuint32" => Some(4),
        b"long" | b"unsigned_long" | b"vtktypeint64" | b"vtktypeuint64" | b"vtkidtype" => Some(8),
        _ => None,
    }
}

/// Parse a VTK legacy file into unvalidated arrays.
///
/// Stages: the header ([`header`]), the geometry ([`geometry`]), the cells'
/// region ids ([`regions`]), the tet cells kept ([`keep_tets`]).
pub(crate) fn parse(bytes: &[u8], file: &str) -> Result<RawMesh, MeshError> {
    let mut r = header(bytes, file)?;
    let geometry = geometry(&mut r, file)?;
    let cell_regions = regions(&mut r, geometry.attributes, geometry.cells.len())?;
    keep_tets(geometry, cell_regions, file)
}

/// The dataset as read up to its attribute data.
struct Geometry<'a> {
    /// Point coordinates.
    positions: Vec<[f64; 3]>,
    /// Per cell: (npts, first 4 point ids).
    cells: Vec<(usize, [i64; 4])>,
    /// VTK cell type per cell.
    types: Vec<i64>,
    /// The attribute keyword that ended the geometry, if any.
    attributes: Option<&'a [u8]>,
}

/// The three header lines: the `# vtk DataFile Version` line, the title and
/// `ASCII` or `BINARY`; a reader placed after them.
fn header<'a>(bytes: &'a [u8], file: &'a str) -> Result<Reader<'a>, MeshError> {
    let mut cur = Cursor::new(bytes, file);
    let l1 = cur
        .line()
        .ok_or_else(|| cur.eof("`# vtk DataFile Version`"))?;
    if !l1.trim_ascii().starts_with(b"# vtk DataFile") {
        return Err(cur.err(format_args!(
            "not a VTK legacy file: first line {:?}",
            show(l1)
        )));
    }
    cur.line().ok_or_else(|| cur.eof("title line"))?;
    let enc = cur
        .nonempty_line()
        .ok_or_else(|| cur.eof("ASCII or BINARY"))?;
    let binary = match enc.to_ascii_uppercase().as_slice() {
        b"ASCII" => false,
        b"BINARY" => true,
        _ => {
            return Err(cur.err(format_args!(
                "expected ASCII or BINARY, found {:?}",
                show(enc)
            )));
        }
    };
    Ok(Reader { cur, binary })
}

/// The `DATASET UNSTRUCTURED_GRID` with its `POINTS`, `CELLS` and
/// `CELL_TYPES`, in any order, up to the first attribute keyword
/// (`POINT_DATA`, `CELL_DATA`) or once all three are read: each present,
/// one type per cell.
fn geometry<'a>(r: &mut Reader<'a>, file: &str) -> Result<Geometry<'a>, MeshError> {
    let mut positions: Option<Vec<[f64; 3]>> = None;
    let mut cells: Option<Vec<(usize, [i64; 4])>> = None;
    let mut types: Option<Vec<i64>> = None;
    let mut have_dataset = false;
    let mut attributes: Option<&[u8]> = None;
    while let Some(tok) = r.cur.token() {
        match tok.to_ascii_uppercase().as_slice() {
            b"DATASET" => {
                r.cur.section = "DATASET";
                let ty = r.cur.expect_token(&"dataset type")?;
                if !ty.eq_ignore_ascii_case(b"UNSTRUCTURED_GRID") {
                    return Err(MeshError::Unsupported {
                        file: file.to_string(),
                        msg: format!("VTK DATASET {} (expected UNSTRUCTURED_GRID)", show(ty)),
                    });
                }
                have_dataset = true;
            }
            b"POINTS" => {
                r.cur.section = "POINTS";
                positions = Some(read_points(r)?);
            }
            b"CELLS" => {
                r.cur.section = "CELLS";
                let n = r.count("number of cells")?;
                let size = r.count("cell list size")?;
                r.start_data();
                cells = Some(read_cells(r, n, size)?);
            }
            b"CELL_TYPES" => {
                r.cur.section = "CELL_TYPES";
                types = Some(read_cell_types(r)?);
            }
            b"POINT_DATA" | b"CELL_DATA" => {
                attributes = Some(tok);
                break;
            }
            b"METADATA" | b"FIELD" => {
                return Err(r.cur.err(format_args!(
                    "{} blocks are not supported before the cells",
                    show(tok)
                )));
            }
            _ => {
                return Err(r
                    .cur
                    .err(format_args!("unexpected keyword {:?}", show(tok))));
            }
        }
        if positions.is_some() && cells.is_some() && types.is_some() {
            break;
        }
    }
    r.cur.section = "file";
    if !have_dataset {
        return Err(r.cur.err("missing DATASET UNSTRUCTURED_GRID"));
    }
    let positions = positions.ok_or_else(|| r.cur.err("missing POINTS"))?;
    let cells = cells.ok_or_else(|| r.cur.err("missing CELLS"))?;
    let types = types.ok_or_else(|| r.cur.err("missing CELL_TYPES"))?;
    if cells.len() != types.len() {
        return Err(r.cur.err(format_args!(
            "{} cells but {} cell types",
            cells.len(),
            types.len()
        )));
    }
    Ok(Geometry {
        positions,
        cells,
        types,
        attributes,
    })
}

/// The `POINTS n type` block after its keyword: `n` points of `float` or
/// `double` (any number in ASCII).
fn read_points(r: &mut Reader<'_>) -> Result<Vec<[f64; 3]>, MeshError> {
    let n = r.count("number of points")?;
    let ty = r.cur.expect_token(&"point data type")?;
    let double = match ty.to_ascii_lowercase().as_slice() {
        b"double" => true,
        b"float" => false,
        _ if !r.binary => true,
        _ => {
            return Err(r.cur.err(format_args!(
                "point type {:?} (expected float or double)",
                show(ty)
            )));
        }
    };
    r.start_data();
    let mut pts = Vec::with_capacity(cap(n, r.cur.len()));
    for i in 0..n {
        let what = format_args!("point {i}");
        let mut p = [0.0; 3];
        for x in &mut p {
            *x = r.float(double, &what)?;
        }
        pts.push(p);
    }
    Ok(pts)
}

/// The `CELL_TYPES n` block after its keyword: `n` cell types.
fn read_cell_types(r: &mut Reader<'_>) -> Result<Vec<i64>, MeshError> {
    let n = r.count("number of cell types")?;
    r.start_data();
    let mut ts = Vec::with_capacity(cap(n, r.cur.len()));
    for i in 0..n {
        ts.push(r.int(4, &format_args!("cell type {i}"))?);
    }
    Ok(ts)
}

/// The tet cells of `geometry` (linear, or the corners of a quadratic tet),
/// each with its point count checked, and their regions from
/// `cell_regions`; other cells are counted as skipped.
fn keep_tets(
    geometry: Geometry<'_>,
    cell_regions: Option<Vec<u32>>,
    file: &str,
) -> Result<RawMesh, MeshError> {
    let Geometry {
        positions,
        cells,
        types,
        ..
    } = geometry;
    let mut tets = Vec::new();
    let mut tet_regions = Vec::new();
    let mut skipped = 0;
    for (i, (&(npts, ids), &ty)) in cells.iter().zip(&types).enumerate() {
        let want = match ty {
            VTK_TETRA => 4,
            VTK_QUADRATIC_TETRA => 10,
            _ => {
                skipped += 1;
                continue;
            }
        };
        if npts != want {
            return Err(MeshError::Parse {
                file: file.to_string(),
                msg: format!(
                    "cell {i} (tet {}): type {ty} needs {want} points, has {npts}",
                    tets.len()
                ),
            });
        }
        tets.push(ids);
        if let Some(region) = cell_regions.as_ref().and_then(|all| all.get(i)) {
            tet_regions.push(*region);
        }
    }
    Ok(RawMesh {
        positions,
        node_ids: None,
        tets,
        elem_ids: None,
        numbering: Numbering::Base(0),
        skipped,
        tet_regions: cell_regions.map(|_| tet_regions),
    })
}

/// A numeric type of an attribute array.
#[derive(Clone, Copy)]
enum DataType {
    Float,
    Double,
    /// An integer of `bytes` bytes.
    Int {
        bytes: usize,
        signed: bool,
    },
}

impl DataType {
    fn of(name: &[u8]) -> Option<DataType> {
        let int = |bytes, signed| Some(DataType::Int { bytes, signed });
        match name.to_ascii_lowercase().as_slice() {
            b"float" => Some(DataType::Float),
            b"double" => Some(DataType::Double),
            b"char" => int(1, true),
            b"unsigned_char" => int(1, false),
            b"short" => int(2, true),
            b"unsigned_short" => int(2, false),
            b"int" | b"vtktypeint32" => int(4, true),
            b"unsigned_int" | b"vtktypeuint32" => int(4, false),
            b"long" | b"vtktypeint64" | b"vtkidtype" => int(8, true),
            b"unsigned_long" | b"vtktypeuint64" => int(8, false),
            _ => None,
        }
    }
}

impl Reader<'_> {
    /// One attribute value of type `ty`, as a real (ASCII: any number).
    fn value(&mut self, ty: DataType, what: &dyn core::fmt::Display) -> Result<f64, MeshError> {
        match (self.binary, ty) {
            (false, _) => self.cur.parse::<f64>(what),
            (true, DataType::Float) => self.cur.f32(true, what),
            (true, DataType::Double) => self.cur.f64(true, what),
            (true, DataType::Int { bytes, signed }) => {
                let raw = self.cur.bytes(bytes, what)?;
                let unsigned = raw.iter().fold(0u64, |v, &b| (v << 8) | u64::from(b));
                let bits = 8 * bytes as u32;
                Ok(if signed && bits < 64 && unsigned >> (bits - 1) == 1 {
                    (unsigned as i64 - (1i64 << bits)) as f64
                } else if signed {
                    unsigned as i64 as f64
                } else {
                    unsigned as f64
                })
            }
        }
    }

    /// Reads past `n` values of type `ty`; `None` if they are not there.
    fn skip_values(&mut self, ty: DataType, n: Option<usize>) -> Option<()> {
        for _ in 0..n? {
            self.value(ty, &"").ok()?;
        }
        Some(())
    }
}

impl<'a> Reader<'a> {
    /// The header line of an array: its whitespace-separated words.
    fn words(&mut self) -> Vec<&'a [u8]> {
        self.cur
            .nonempty_line()
            .map(|l| {
                l.split(|c| c.is_ascii_whitespace())
                    .filter(|w| !w.is_empty())
                    .collect()
            })
            .unwrap_or_default()
    }
}

/// One attribute array's header.
struct Array {
    /// The cells' array named `region`.
    is_region: bool,
    ty: DataType,
    components: usize,
    tuples: usize,
}

/// The region id of every cell: the `CELL_DATA` array named `region` among the attribute data
/// that starts at `keyword` (`POINT_DATA` or `CELL_DATA`, already read), `None` without one.
/// Errors only on the `region` array itself: not one value per cell, not one component, or a
/// value that is not a region id.
///
/// Each array's header is read by [`Reader::scalars_header`] or
/// [`Reader::field_region`], the arrays that are not the region read past,
/// the region's values by [`Reader::region_ids`].
fn regions(
    r: &mut Reader<'_>,
    mut keyword: Option<&[u8]>,
    cells: usize,
) -> Result<Option<Vec<u32>>, MeshError> {
    r.cur.section = "CELL_DATA";
    let mut on_cells = false;
    let mut count = 0usize;
    loop {
        let Some(tok) = keyword.take().or_else(|| r.cur.token()) else {
            return Ok(None);
        };
        let array = match tok.to_ascii_uppercase().as_slice() {
            b"POINT_DATA" | b"CELL_DATA" => {
                on_cells = tok.eq_ignore_ascii_case(b"CELL_DATA");
                let Ok(n) = r.count("attribute count") else {
                    return Ok(None);
                };
                count = n;
                continue;
            }
            b"SCALARS" => {
                let Some(array) = r.scalars_header(on_cells, count) else {
                    return Ok(None);
                };
                array
            }
            b"FIELD" => match r.field_region(on_cells) {
                None => return Ok(None),
                Some(None) => continue,
                Some(Some(region)) => region,
            },
            b"VECTORS" | b"NORMALS" | b"TENSORS" => {
                let per = if tok.eq_ignore_ascii_case(b"TENSORS") {
                    9
                } else {
                    3
                };
                let Some(ty) = data_type(r.words().get(1)) else {
                    return Ok(None);
                };
                if r.skip_values(ty, count.checked_mul(per)).is_none() {
                    return Ok(None);
                }
                continue;
            }
            _ => return Ok(None),
        };
        if !array.is_region {
            if r.skip_values(array.ty, array.components.checked_mul(array.tuples))
                .is_none()
            {
                return Ok(None);
            }
            continue;
        }
        return r.region_ids(array, cells).map(Some);
    }
}

/// A count word of an array header, if it is one.
fn number(w: Option<&&[u8]>) -> Option<usize> {
    w.and_then(|w| parse_tok::<usize>(w))
}

/// A data type word of an array header, if it is one.
fn data_type(w: Option<&&[u8]>) -> Option<DataType> {
    w.and_then(|w| DataType::of(w))
}

impl Reader<'_> {
    /// After `SCALARS`: `name type [components]`, then an optional
    /// `LOOKUP_TABLE` line; the array of `count` tuples, the region if it is
    /// `region` on the cells. `None` if the header is not one.
    fn scalars_header(&mut self, on_cells: bool, count: usize) -> Option<Array> {
        let words = self.words();
        let components = if words.len() > 2 {
            number(words.get(2))
        } else {
            Some(1)
        };
        if matches!(self.cur.peek_token(), Some(t) if t.eq_ignore_ascii_case(b"LOOKUP_TABLE")) {
            self.cur.line();
        }
        let (Some(&name), Some(ty), Some(components)) =
            (words.first(), data_type(words.get(1)), components)
        else {
            return None;
        };
        Some(Array {
            is_region: on_cells && name == b"region",
            ty,
            components,
            tuples: count,
        })
    }

    /// After `FIELD`: `name arrays`, then per array `name components tuples
    /// type` and its values. Reads past the arrays up to the region array
    /// on the cells, whose header it returns (`Some(None)` when the field
    /// has none, its arrays all read past); `None` if a header is not one or
    /// values are missing.
    fn field_region(&mut self, on_cells: bool) -> Option<Option<Array>> {
        let arrays = number(self.words().get(1))?;
        for _ in 0..arrays {
            let words = self.words();
            let (Some(&name), Some(components), Some(tuples), Some(ty)) = (
                words.first(),
                number(words.get(1)),
                number(words.get(2)),
                data_type(words.get(3)),
            ) else {
                return None;
            };
            let array = Array {
                is_region: on_cells && name == b"region",
                ty,
                components,
                tuples,
            };
            if array.is_region {
                return Some(Some(array));
            }
            self.skip_values(ty, components.checked_mul(tuples))?;
        }
        Some(None)
    }

    /// The values of the region `array`: one component per cell of
    /// `cells`, each a region id.
    fn region_ids(&mut self, array: Array, cells: usize) -> Result<Vec<u32>, MeshError> {
        let Array {
            ty,
            components,
            tuples,
            ..
        } = array;
        if components != 1 || tuples != cells {
            return Err(self.cur.err(format_args!(
                "the region array has {tuples} values of {components} components for {cells} cells (expected one integer per cell)"
            )));
        }
        let mut ids = Vec::with_capacity(cap(cells, self.cur.len()));
        for i in 0..cells {
            let v = self.value(ty, &format_args!("region of cell {i}"))?;
            let id = region_id(v).ok_or_else(|| {
                self.cur
                    .err(format_args!("cell {i}: region {v} {NOT_A_REGION}"))
            })?;
            ids.push(id);
        }
        Ok(ids)
    }
}

fn read_cells(
    r: &mut Reader<'_>,
    n: usize,
    size: usize,
) -> Result<Vec<(usize, [i64; 4])>, MeshError> {
    // VTK 5.1: `CELLS nOffsets nConn` then `OFFSETS type` and `CONNECTIVITY type`.
    let mut cells = Vec::with_capacity(cap(n, r.cur.len()));
    let is_51 = matches!(r.cur.peek_token(), Some(t) if t.eq_ignore_ascii_case(b"OFFSETS"));
    if is_51 {
        r.cur.token();
        let ty = r.cur.expect_token(&"offsets type")?;
        let osz = int_size(ty).unwrap_or(8);
        r.start_data();
        let mut offsets = Vec::with_capacity(cap(n, r.cur.len()));
        for i in 0..n {
            offsets.push(r.int(osz, &format_args!("offset {i}"))?);
        }
        match r.cur.token() {
            Some(t) if t.eq_ignore_ascii_case(b"CONNECTIVITY") => {}
            _ => return Err(r.cur.err("expected CONNECTIVITY after OFFSETS")),
        }
        let ty = r.cur.expect_token(&"connectivity type")?;
        let csz = int_size(ty).unwrap_or(8);
        r.start_data();
        let mut conn = Vec::with_capacity(cap(size, r.cur.len()));
        for i in 0..size {
            conn.push(r.int(csz, &format_args!("connectivity entry {i}"))?);
        }
        for (i, w) in offsets.windows(2).enumerate() {
            let (a, b) = (w[0], w[1]);
            let range = usize::try_from(a)
                .ok()
                .zip(usize::try_from(b).ok())
                .filter(|(a, b)| a <= b && *b <= conn.len())
                .ok_or_else(|| r.cur.err(format_args!("cell {i}: bad offsets {a}..{b}")))?;
            let ids = conn.get(range.0..range.1).unwrap_or(&[]);
            let mut t = [0i64; 4];
            for (s, v) in t.iter_mut().zip(ids) {
                *s = *v;
            }
            cells.push((ids.len(), t));
        }
        return Ok(cells);
    }
    let mut used = 0usize;
    for i in 0..n {
        let what = format_args!("cell {i}");
        let npts = r.int(4, &what)?;
        let npts = usize::try_from(npts)
            .ok()
            .filter(|&k| k <= size.saturating_sub(used + 1))
            .ok_or_else(|| r.cur.err(format_args!("cell {i}: bad point count {npts}")))?;
        let mut t = [0i64; 4];
        for k in 0..npts {
            let v = r.int(4, &what)?;
            if let Some(s) = t.get_mut(k) {
                *s = v;
            }
        }
        used += 1 + npts;
        cells.push((npts, t));
    }
    if used != size {
        return Err(r.cur.err(format_args!(
            "cell list holds {used} integers, header declares {size}"
        )));
    }
    Ok(cells)
}
