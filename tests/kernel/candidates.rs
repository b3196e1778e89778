//! The collision index's per-cell candidate lists (table format 6;
//! `palpate_kernel::table::SurfaceIndex::candidates`, used by
//! `SurfaceGeometry::detect`): checked against an exact projection on each
//! triangle (every triangle a tool can be found on is in its cell's list) and
//! against the walk over 27 cells they replace (the same contacts), on the
//! reference cube (1 m, 0.2 m cells of 6 tets).

use nalgebra::Vector3;
use palpate::table::build::{BuildOptions, build};
use palpate::table::compliance::Solver;
use palpate::table::file::Precision;
use palpate::table::load::TableFile;
use palpate_kernel::PrecomputedTable;
use palpate_kernel::contact::{ContactWork, SurfaceGeometry};
use palpate_kernel::table::{CANDIDATE_MARGIN_RADII, TriangleIndex};
use palpate_tests::Lcg;

/// A tool a quarter of the surface's edge (0.2 m): its lists span a few
/// cells' triangles, not all.
const RADIUS_M: f64 = 0.05;

/// The reference cube's pre-computed table (f64) with candidate lists for
/// tools of radius up to `tool_radius_m` (m).
fn cube_table(tool_radius_m: f64) -> TableFile {
    let (mesh, report) =
        palpate::mesh::read_mesh(&palpate_tests::reference_dir().join("meshes/cube.msh"))
            .expect("cube.msh");
    let options = BuildOptions::precomputed(
        palpate::fem::material::Material::new(5000.0, 0.45).expect("material"),
        vec!["z<0.001".parse().expect("predicate")],
        Solver::Cholesky,
        Precision::F64,
    )
    .with_tool_radius(tool_radius_m);
    TableFile::from_bytes(&build(&mesh, &report, &options).expect("build").bytes)
}

/// A vector of uniform components in `[−half_m, half_m)`, m.
fn vector(rng: &mut Lcg, half_m: f64) -> Vector3<f64> {
    Vector3::new(rng.signed(), rng.signed(), rng.signed()) * half_m
}

/// The signed distance (m) of `p` from the plane of triangle `[a, b, c]`
/// (along its right-hand unit normal), and whether `p` projects into the
/// triangle (edges included): by cross products, independent of the
/// table's stored frames.
fn over_triangle(p: &Vector3<f64>, [a, b, c]: &[Vector3<f64>; 3]) -> (f64, bool) {
    let n = (b - a).cross(&(c - a)).normalize();
    let distance = n.dot(&(p - a));
    let q = p - n * distance;
    let inside = [(a, b), (b, c), (c, a)]
        .iter()
        .all(|(u, v)| (*v - *u).cross(&(q - *u)).dot(&n) >= 0.0);
    (distance, inside)
}

/// A point `at_m` metres off the surface (along the normal, either side)
/// over a random point of a random surface triangle.
fn near_surface(rng: &mut Lcg, table: &PrecomputedTable<'_, f64>, at_m: f64) -> Vector3<f64> {
    let triangles = table.surface_triangles();
    let t = ((rng.unit() * triangles.len() as f64) as usize).min(triangles.len() - 1);
    let [a, b, c] = triangles[t].map(|v| Vector3::from(table.rest_positions()[v as usize]));
    let (u, v) = (rng.unit(), rng.unit());
    let (u, v) = if u + v > 1.0 {
        (1.0 - u, 1.0 - v)
    } else {
        (u, v)
    };
    let n = (b - a).cross(&(c - a)).normalize();
    a + (b - a) * u + (c - a) * v + n * ((2.0 * rng.unit() - 1.0) * at_m)
}

/// Every triangle a tool can be found on from a point (the point projects
/// into it and lies within 2.25 radii of its plane: the penetration test's
/// depth of 2 radii, and slack) is in the list of the point's cell, for
/// 4000 points within 3 radii of the surface and beyond the grid's box;
/// and the lists are short: the longest holds at most a fortieth of the
/// triangles the walk over 27 cells visits (measured: 8 of the 300 surface
/// triangles on the lists' grid of 8 × 8 × 8 cells, against 366 triangle
/// visits; 32 when the lists filed every triangle within 2.25 radii of a
/// grid cell, whatever its normal).
#[test]
fn every_triangle_within_reach_is_in_the_cell_list() {
    let file = cube_table(RADIUS_M);
    let table = PrecomputedTable::<f64>::load(file.bytes()).unwrap();
    let index = table.surface_index();
    assert_eq!(index.candidate_radius_m(), Some(RADIUS_M));
    let depth_m = RADIUS_M * CANDIDATE_MARGIN_RADII;
    let corners: Vec<[Vector3<f64>; 3]> = table
        .surface_triangles()
        .iter()
        .map(|tri| tri.map(|v| Vector3::from(table.rest_positions()[v as usize])))
        .collect();
    let mut rng = Lcg(7);
    let mut checked = 0usize;
    for k in 0..4000 {
        let p = if k % 10 == 9 {
            // Outside the grid's box, near a face.
            near_surface(&mut rng, &table, 2.0 * RADIUS_M) * 1.02
        } else {
            near_surface(&mut rng, &table, 3.0 * RADIUS_M)
        };
        let list = index
            .candidates(&p, RADIUS_M)
            .expect("lists serve the radius");
        let listed: Vec<TriangleIndex> = list.iter().collect();
        for (t, c) in corners.iter().enumerate() {
            let (distance_m, inside) = over_triangle(&p, c);
            if inside && distance_m.abs() <= depth_m {
                checked += 1;
                let id = TriangleIndex::new(t as u32, corners.len()).unwrap();
                assert!(listed.contains(&id), "triangle {t} not listed at {p:?}");
            }
        }
    }
    assert!(checked > 3000, "{checked}");
    let longest = index.max_cell_triangles();
    println!(
        "longest list {longest} of {} triangles; walk {}",
        corners.len(),
        index.max_query_triangles()
    );
    assert!(40 * longest <= index.max_query_triangles(), "{longest}");
    assert_eq!(index.list_grid().dims, [8, 8, 8]);
    // A larger tool than the lists serve walks the grid.
    assert!(
        index
            .candidates(&Vector3::zeros(), 1.01 * RADIUS_M)
            .is_none()
    );
}

/// A detection reads the lists when they serve its radius and walks the
/// 27 cells otherwise; over 3000 short motions near the surface (up to
/// 1.5 radii per tick, from up to 3 radii off it) both find the same
/// contact (point, normal and gap to 1e-12 m: the same triangle but where
/// the point lies on an edge between coplanar ones) or none, while the
/// lists test at most a sixth of the triangles (measured: 1386 contacts,
/// 28 286 triangle tests against 260 477; 90 218 when the lists filed
/// every triangle within 2.25 radii of a grid cell, whatever its normal).
#[test]
fn detection_with_lists_finds_what_the_walk_finds() {
    let (listed_file, walked_file) = (cube_table(RADIUS_M), cube_table(0.0));
    let listed = PrecomputedTable::<f64>::load(listed_file.bytes()).unwrap();
    let walked = PrecomputedTable::<f64>::load(walked_file.bytes()).unwrap();
    assert!(
        walked
            .surface_index()
            .candidates(&Vector3::zeros(), RADIUS_M)
            .is_none()
    );
    let (with_lists, with_walk) = (SurfaceGeometry::new(&listed), SurfaceGeometry::new(&walked));
    let mut rng = Lcg(11);
    let (mut contacts, mut tests_listed, mut tests_walked) = (0, 0u64, 0u64);
    for _ in 0..3000 {
        let to = near_surface(&mut rng, &listed, 3.0 * RADIUS_M);
        let from = to + vector(&mut rng, 0.9 * RADIUS_M);
        let (mut w1, mut w2) = (ContactWork::default(), ContactWork::default());
        let a = with_lists.detect(0, Some(&from), &to, RADIUS_M, &mut w1);
        let b = with_walk.detect(0, Some(&from), &to, RADIUS_M, &mut w2);
        tests_listed += u64::from(w1.triangles_tested);
        tests_walked += u64::from(w2.triangles_tested);
        match (a, b) {
            (None, None) => {}
            (Some(a), Some(b)) => {
                contacts += 1;
                let close = |x: &Vector3<f64>, y: &Vector3<f64>| (x - y).norm() < 1e-12;
                assert!(
                    close(&a.point_m, &b.point_m)
                        && close(&a.normal, &b.normal)
                        && (a.gap_m - b.gap_m).abs() < 1e-12,
                    "{from:?} → {to:?}: {a:?} vs {b:?}"
                );
            }
            (a, b) => panic!("{from:?} → {to:?}: lists {a:?}, walk {b:?}"),
        }
    }
    println!("{contacts} contacts; triangles tested: lists {tests_listed}, walk {tests_walked}");
    assert!(contacts > 500, "{contacts}");
    assert!(
        6 * tests_listed <= tests_walked,
        "{tests_listed} vs {tests_walked}"
    );
}

/// The loader files every triangle again and refuses, naming the cell, a
/// list out of order, one that misses a triangle the grid files there, and
/// one that holds a triangle it does not.
#[test]
fn a_wrong_candidate_list_is_refused_naming_its_cell() {
    use palpate_kernel::LoadError;
    use palpate_kernel::table::format::SectionKind;
    let file = cube_table(RADIUS_M);
    let bytes = file.bytes();
    let load = |bytes: &[u8]| {
        let file = TableFile::from_bytes(bytes);
        PrecomputedTable::<f64>::load(file.bytes()).map(|_| ())
    };
    assert_eq!(load(bytes), Ok(()));
    let words = |kind| {
        let (offset, elem, count) = palpate_tests::section_span(bytes, kind);
        bytes[offset..offset + elem * count]
            .chunks_exact(4)
            .map(|w| u32::from_le_bytes(w.try_into().unwrap()))
            .collect::<Vec<u32>>()
    };
    let (starts, list) = (
        words(SectionKind::CellTriangleStart),
        words(SectionKind::CellTriangle),
    );
    let triangles = PrecomputedTable::<f64>::load(bytes)
        .unwrap()
        .surface_triangles()
        .len() as u32;
    // A cell past the first with at least two triangles, and a triangle
    // it does not list, above its last.
    let cell = (1..starts.len() - 1)
        .find(|&c| {
            starts[c + 1] - starts[c] >= 2 && list[starts[c + 1] as usize - 1] + 1 < triangles
        })
        .expect("a cell with two triangles");
    let (first, last) = (starts[cell] as usize, starts[cell + 1] as usize - 1);
    let unlisted = (list[last] + 1..triangles)
        .find(|t| !list[first..=last].contains(t))
        .expect("a triangle the cell does not list");
    let set = |at: usize, value: u32| {
        palpate_tests::patch_section(bytes, SectionKind::CellTriangle, |payload| {
            payload[4 * at..4 * at + 4].copy_from_slice(&value.to_le_bytes());
        })
    };
    let bad = Err(LoadError::BadCellTriangles { cell: cell as u32 });
    // Out of order: the first entry repeats the second.
    assert_eq!(load(&set(first, list[first + 1])), bad);
    // The last entry replaced by a triangle filed elsewhere: one too many
    // (and one missing), found in this cell.
    assert_eq!(load(&set(last, unlisted)), bad);
    // Past the last triangle.
    assert_eq!(load(&set(last, triangles)), bad);
}
