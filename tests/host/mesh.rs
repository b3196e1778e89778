//! Host mesh input: every reader against the reference meshes, small hand-written files, test-side
//! binary writers, every validation error, the boundary surface, the procedural generators (box,
//! cylinder, voxel carving, organ), and a mutation fuzz test.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use palpate::mesh::{
    MeshError, MeshFormat, MeshReport, TetMesh, boundary_surface, generate, read_mesh,
    read_mesh_bytes, read_tetgen,
};
use palpate_tests::{data_dir, reference_dir};

fn meshes_dir() -> PathBuf {
    reference_dir().join("meshes")
}

fn mesh_data(name: &str) -> PathBuf {
    data_dir().join("mesh").join(name)
}

fn read(path: &Path) -> (TetMesh, MeshReport) {
    match read_mesh(path) {
        Ok(m) => m,
        Err(e) => panic!("{}: {e}", path.display()),
    }
}

/// Run `f`, expect an error, return its message.
fn err_msg(r: Result<(TetMesh, MeshReport), MeshError>) -> String {
    match r {
        Ok((m, _)) => panic!("expected an error, got a mesh with {} tets", m.tets.len()),
        Err(e) => e.to_string(),
    }
}

fn assert_contains(msg: &str, parts: &[&str]) {
    for p in parts {
        assert!(msg.contains(p), "message {msg:?} lacks {p:?}");
    }
}

// ---------------------------------------------------------------------------------------------
// Test-side writers. An element is (gmsh type, 0-based vertex indices).

type Elem = (i32, Vec<u32>);

/// Gmsh type → VTK cell type.
fn vtk_type(gmsh: i32) -> i32 {
    match gmsh {
        4 => 10,
        2 => 5,
        1 => 3,
        15 => 1,
        _ => panic!("no vtk type for {gmsh}"),
    }
}

fn gmsh_dim(ty: i32) -> i32 {
    match ty {
        4 => 3,
        2 => 2,
        1 => 1,
        _ => 0,
    }
}

fn tets_as_elems(mesh: &TetMesh) -> Vec<Elem> {
    mesh.tets.iter().map(|t| (4, t.to_vec())).collect()
}

fn fmt_f(x: f64) -> String {
    format!("{x:?}")
}

fn msh22_ascii(pos: &[[f64; 3]], ids: &[i64], elems: &[Elem], elem_id0: i64) -> Vec<u8> {
    let mut s = String::from("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n");
    s += &format!("{}\n", pos.len());
    for (p, id) in pos.iter().zip(ids) {
        s += &format!("{id} {} {} {}\n", fmt_f(p[0]), fmt_f(p[1]), fmt_f(p[2]));
    }
    s += &format!("$EndNodes\n$Elements\n{}\n", elems.len());
    for (i, (ty, nodes)) in elems.iter().enumerate() {
        s += &format!("{} {ty} 2 1 1", elem_id0 + i as i64);
        for &n in nodes {
            s += &format!(" {}", ids[n as usize]);
        }
        s += "\n";
    }
    s += "$EndElements\n";
    s.into_bytes()
}

fn msh22_binary(pos: &[[f64; 3]], ids: &[i64], elems: &[Elem]) -> Vec<u8> {
    let mut b = b"$MeshFormat\n2.2 1 8\n".to_vec();
    b.extend_from_slice(&1i32.to_le_bytes());
    b.extend_from_slice(b"\n$EndMeshFormat\n$Nodes\n");
    b.extend_from_slice(format!("{}\n", pos.len()).as_bytes());
    for (p, &id) in pos.iter().zip(ids) {
        b.extend_from_slice(&(id as i32).to_le_bytes());
        for x in p {
            b.extend_from_slice(&x.to_le_bytes());
        }
    }
    b.extend_from_slice(b"\n$EndNodes\n$Elements\n");
    b.extend_from_slice(format!("{}\n", elems.len()).as_bytes());
    // Blocks of consecutive elements of the same type.
    let mut i = 0;
    while i < elems.len() {
        let ty = elems[i].0;
        let j = elems[i..]
            .iter()
            .position(|e| e.0 != ty)
            .map_or(elems.len(), |k| i + k);
        for v in [ty, (j - i) as i32, 2] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        for (k, e) in elems[i..j].iter().enumerate() {
            for v in [(i + k + 1) as i32, 1, 1] {
                b.extend_from_slice(&v.to_le_bytes());
            }
            for &n in &e.1 {
                b.extend_from_slice(&(ids[n as usize] as i32).to_le_bytes());
            }
        }
        i = j;
    }
    b.extend_from_slice(b"\n$EndElements\n");
    b
}

/// Groups elements into blocks of consecutive same type.
fn blocks(elems: &[Elem]) -> Vec<(i32, &[Elem])> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < elems.len() {
        let ty = elems[i].0;
        let j = elems[i..]
            .iter()
            .position(|e| e.0 != ty)
            .map_or(elems.len(), |k| i + k);
        out.push((ty, &elems[i..j]));
        i = j;
    }
    out
}

/// MSH 4.1 ASCII; nodes split into two blocks (the second parametric on a surface).
fn msh41_ascii(pos: &[[f64; 3]], ids: &[i64], elems: &[Elem]) -> Vec<u8> {
    let n = pos.len();
    let half = n / 2;
    let mut s = String::from(
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 0 1\n1 0 0 0 1 1 1 0 0\n$EndEntities\n",
    );
    s += &format!("$Nodes\n2 {n} 1 {n}\n");
    for (dim, param, range) in [(3, 0, 0..half), (2, 1, half..n)] {
        s += &format!("{dim} 1 {param} {}\n", range.len());
        for i in range.clone() {
            s += &format!("{}\n", ids[i]);
        }
        for i in range {
            let p = pos[i];
            s += &format!("{} {} {}", fmt_f(p[0]), fmt_f(p[1]), fmt_f(p[2]));
            s += if param == 1 { " 0.25 0.75\n" } else { "\n" };
        }
    }
    s += "$EndNodes\n";
    let bl = blocks(elems);
    s += &format!(
        "$Elements\n{} {} 1 {}\n",
        bl.len(),
        elems.len(),
        elems.len()
    );
    let mut id = 1;
    for (ty, es) in bl {
        s += &format!("{} 1 {ty} {}\n", gmsh_dim(ty), es.len());
        for e in es {
            s += &format!("{id}");
            id += 1;
            for &v in &e.1 {
                s += &format!(" {}", ids[v as usize]);
            }
            s += "\n";
        }
    }
    s += "$EndElements\n";
    s.into_bytes()
}

fn msh41_binary(pos: &[[f64; 3]], ids: &[i64], elems: &[Elem]) -> Vec<u8> {
    let n = pos.len();
    let mut b = b"$MeshFormat\n4.1 1 8\n".to_vec();
    b.extend_from_slice(&1i32.to_le_bytes());
    b.extend_from_slice(b"\n$EndMeshFormat\n$Entities\n");
    b.extend_from_slice(&[0u8, 1, 2, 3, 255, 36, 10, 7]); // opaque binary entities
    b.extend_from_slice(b"\n$EndEntities\n$Nodes\n");
    for v in [1u64, n as u64, 1, n as u64] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    for v in [3i32, 1, 0] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b.extend_from_slice(&(n as u64).to_le_bytes());
    for &id in ids {
        b.extend_from_slice(&(id as u64).to_le_bytes());
    }
    for p in pos {
        for x in p {
            b.extend_from_slice(&x.to_le_bytes());
        }
    }
    b.extend_from_slice(b"\n$EndNodes\n$Elements\n");
    let bl = blocks(elems);
    for v in [bl.len() as u64, elems.len() as u64, 1, elems.len() as u64] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    let mut id = 1u64;
    for (ty, es) in bl {
        for v in [gmsh_dim(ty), 1, ty] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        b.extend_from_slice(&(es.len() as u64).to_le_bytes());
        for e in es {
            b.extend_from_slice(&id.to_le_bytes());
            id += 1;
            for &v in &e.1 {
                b.extend_from_slice(&(ids[v as usize] as u64).to_le_bytes());
            }
        }
    }
    b.extend_from_slice(b"\n$EndElements\n");
    b
}

fn vtk_ascii(pos: &[[f64; 3]], elems: &[Elem]) -> Vec<u8> {
    let mut s =
        String::from("# vtk DataFile Version 3.0\ntest\nASCII\nDATASET UNSTRUCTURED_GRID\n");
    s += &format!("POINTS {} double\n", pos.len());
    for p in pos {
        s += &format!("{} {} {}\n", fmt_f(p[0]), fmt_f(p[1]), fmt_f(p[2]));
    }
    let size: usize = elems.iter().map(|e| e.1.len() + 1).sum();
    s += &format!("CELLS {} {size}\n", elems.len());
    for e in elems {
        s += &format!("{}", e.1.len());
        for v in &e.1 {
            s += &format!(" {v}");
        }
        s += "\n";
    }
    s += &format!("CELL_TYPES {}\n", elems.len());
    for e in elems {
        s += &format!("{}\n", vtk_type(e.0));
    }
    s.into_bytes()
}

fn vtk_binary(pos: &[[f64; 3]], elems: &[Elem]) -> Vec<u8> {
    let mut b = b"# vtk DataFile Version 3.0\ntest\nBINARY\nDATASET UNSTRUCTURED_GRID\n".to_vec();
    b.extend_from_slice(format!("POINTS {} double\n", pos.len()).as_bytes());
    for p in pos {
        for x in p {
            b.extend_from_slice(&x.to_be_bytes());
        }
    }
    let size: usize = elems.iter().map(|e| e.1.len() + 1).sum();
    b.extend_from_slice(format!("\nCELLS {} {size}\n", elems.len()).as_bytes());
    for e in elems {
        b.extend_from_slice(&(e.1.len() as i32).to_be_bytes());
        for &v in &e.1 {
            b.extend_from_slice(&(v as i32).to_be_bytes());
        }
    }
    b.extend_from_slice(format!("\nCELL_TYPES {}\n", elems.len()).as_bytes());
    for e in elems {
        b.extend_from_slice(&vtk_type(e.0).to_be_bytes());
    }
    b.extend_from_slice(b"\nCELL_DATA 1\n");
    b
}

fn tetgen(pos: &[[f64; 3]], tets: &[[u32; 4]], base: u32) -> (Vec<u8>, Vec<u8>) {
    let mut node = format!("# generated\n{} 3 0 0\n", pos.len());
    for (i, p) in pos.iter().enumerate() {
        node += &format!(
            "{} {} {} {}\n",
            i as u32 + base,
            fmt_f(p[0]),
            fmt_f(p[1]),
            fmt_f(p[2])
        );
    }
    let mut ele = format!("{} 4 0\n", tets.len());
    for (i, t) in tets.iter().enumerate() {
        ele += &format!(
            "{} {} {} {} {}\n",
            i as u32 + base,
            t[0] + base,
            t[1] + base,
            t[2] + base,
            t[3] + base
        );
    }
    (node.into_bytes(), ele.into_bytes())
}

fn one_based(n: usize) -> Vec<i64> {
    (1..=n as i64).collect()
}

/// A small mesh: 2×1×1 box (12 vertices, 12 tets) plus an unused vertex, with non-tet elements.
fn small_input() -> (Vec<[f64; 3]>, Vec<Elem>, TetMesh) {
    let mesh = generate::box_mesh([2, 1, 1], [2.0, 1.0, 1.0]);
    let mut pos = mesh.positions.clone();
    pos.push([9.0, 9.0, 9.0]);
    let mut elems = vec![(15, vec![0]), (1, vec![0, 1])];
    elems.extend(tets_as_elems(&mesh));
    elems.push((2, vec![0, 1, 3]));
    let expected = TetMesh {
        positions: pos.clone(),
        tets: mesh.tets.clone(),
    };
    (pos, elems, expected)
}

fn check_small(r: Result<(TetMesh, MeshReport), MeshError>, expected: &TetMesh, skipped: usize) {
    let (m, rep) = r.unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(&m, expected);
    assert_eq!(rep.skipped_elements, skipped);
    assert_eq!(rep.reoriented_tets, 0);
    assert_eq!(rep.unreferenced_vertices, vec![12]);
    assert!(rep.warnings.is_empty(), "{:?}", rep.warnings);
}

// ---------------------------------------------------------------------------------------------
// Reference meshes.

#[test]
fn reference_formats_agree() {
    for (name, nv, nt) in [("cube", 216, 750), ("liver", 181, 596)] {
        let dir = meshes_dir();
        let (msh, rm) = read(&dir.join(format!("{name}.msh")));
        let (node, rn) = read(&dir.join(format!("{name}.node")));
        let (ele, _) = read(&dir.join(format!("{name}.ele")));
        let (vtk, rv) = read(&dir.join(format!("{name}.vtk")));
        assert_eq!(msh.positions.len(), nv);
        assert_eq!(msh.tets.len(), nt);
        assert_eq!(msh, node);
        assert_eq!(msh, ele);
        assert_eq!(msh, vtk);
        let h = msh.content_hash();
        assert_eq!(h, node.content_hash());
        assert_eq!(h, vtk.content_hash());
        for r in [&rm, &rn, &rv] {
            assert_eq!(r.skipped_elements, 0, "{name}");
            assert_eq!(r.reoriented_tets, 0, "{name}");
            assert!(r.unreferenced_vertices.is_empty(), "{name}");
            assert!(r.warnings.is_empty(), "{name}: {:?}", r.warnings);
        }
        assert!(rm.source.contains(&format!("{name}.msh")));
        assert!(msh.referenced().iter().all(|&r| r));
        for t in 0..msh.tets.len() {
            assert!(msh.tet_volume(t) > 0.0);
        }
    }
    let (cube, _) = read(&meshes_dir().join("cube.msh"));
    let (liver, _) = read(&meshes_dir().join("liver.msh"));
    assert_ne!(cube.content_hash(), liver.content_hash());
    let vol: f64 = (0..liver.tets.len()).map(|t| liver.tet_volume(t)).sum();
    assert!((vol - 36.56).abs() < 0.01, "liver volume {vol}");
}

#[test]
fn box_mesh_equals_reference_cube() {
    let (cube, _) = read(&meshes_dir().join("cube.msh"));
    let gen_mesh = generate::box_mesh([5, 5, 5], [1.0, 1.0, 1.0]);
    assert_eq!(gen_mesh.positions, cube.positions);
    assert_eq!(gen_mesh.tets, cube.tets);
    assert_eq!(gen_mesh.content_hash(), cube.content_hash());
    for t in 0..gen_mesh.tets.len() {
        assert!((gen_mesh.tet_volume(t) - 1.0 / 750.0).abs() < 1e-15);
    }
    // And it validates unchanged.
    let (m, r) = TetMesh::new_validated(gen_mesh.positions.clone(), gen_mesh.tets.clone(), "gen")
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m, gen_mesh);
    assert_eq!(r.reoriented_tets, 0);
    // Anisotropic box: all positive, total volume right.
    let b = generate::box_mesh([3, 2, 4], [0.3, 0.1, 0.2]);
    assert_eq!(b.positions.len(), 4 * 3 * 5);
    assert_eq!(b.tets.len(), 3 * 2 * 4 * 6);
    let vol: f64 = (0..b.tets.len()).map(|t| b.tet_volume(t)).sum();
    assert!((vol - 0.006).abs() < 1e-15);
    assert!((0..b.tets.len()).all(|t| b.tet_volume(t) > 0.0));
}

#[test]
fn reference_cube_through_all_writers() {
    let (cube, _) = read(&meshes_dir().join("cube.msh"));
    let h = cube.content_hash();
    let pos = &cube.positions;
    let ids = one_based(pos.len());
    let elems = tets_as_elems(&cube);
    let inputs: Vec<(&str, Vec<u8>, MeshFormat)> = vec![
        ("msh22a", msh22_ascii(pos, &ids, &elems, 1), MeshFormat::Msh),
        ("msh22b", msh22_binary(pos, &ids, &elems), MeshFormat::Msh),
        ("msh41a", msh41_ascii(pos, &ids, &elems), MeshFormat::Msh),
        ("msh41b", msh41_binary(pos, &ids, &elems), MeshFormat::Msh),
        ("vtka", vtk_ascii(pos, &elems), MeshFormat::Vtk),
        ("vtkb", vtk_binary(pos, &elems), MeshFormat::Vtk),
    ];
    for (name, bytes, fmt) in inputs {
        let (m, _) = read_mesh_bytes(&bytes, fmt, name).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(m, cube, "{name}");
        assert_eq!(m.content_hash(), h, "{name}");
    }
    let (node, ele) = tetgen(pos, &cube.tets, 1);
    let (m, _) = read_tetgen(&node, &ele, "cube1").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.content_hash(), h);
}

// ---------------------------------------------------------------------------------------------
// One small test per format.

#[test]
fn msh22_ascii_small() {
    let (pos, elems, expected) = small_input();
    // Non-consecutive node ids: 1-based ×3.
    let ids: Vec<i64> = (0..pos.len() as i64).map(|i| 3 * i + 5).collect();
    let b = msh22_ascii(&pos, &ids, &elems, 100);
    check_small(read_mesh_bytes(&b, MeshFormat::Msh, "s.msh"), &expected, 3);
}

#[test]
fn msh22_binary_small() {
    let (pos, elems, expected) = small_input();
    let ids = one_based(pos.len());
    let b = msh22_binary(&pos, &ids, &elems);
    check_small(read_mesh_bytes(&b, MeshFormat::Msh, "s.msh"), &expected, 3);
}

#[test]
fn msh41_ascii_small() {
    let (pos, elems, expected) = small_input();
    let ids: Vec<i64> = (0..pos.len() as i64).rev().map(|i| i + 1).collect();
    let b = msh41_ascii(&pos, &ids, &elems);
    check_small(read_mesh_bytes(&b, MeshFormat::Msh, "s.msh"), &expected, 3);
}

#[test]
fn msh41_binary_small() {
    let (pos, elems, expected) = small_input();
    let ids = one_based(pos.len());
    let b = msh41_binary(&pos, &ids, &elems);
    check_small(read_mesh_bytes(&b, MeshFormat::Msh, "s.msh"), &expected, 3);
}

#[test]
fn vtk_ascii_small() {
    let (pos, elems, expected) = small_input();
    let b = vtk_ascii(&pos, &elems);
    check_small(read_mesh_bytes(&b, MeshFormat::Vtk, "s.vtk"), &expected, 3);
}

#[test]
fn vtk_binary_small() {
    let (pos, elems, expected) = small_input();
    let b = vtk_binary(&pos, &elems);
    check_small(read_mesh_bytes(&b, MeshFormat::Vtk, "s.vtk"), &expected, 3);
}

#[test]
fn vtk_51_offsets_connectivity() {
    let s = "# vtk DataFile Version 5.1\nt\nASCII\nDATASET UNSTRUCTURED_GRID\n\
             POINTS 5 double\n0 0 0 1 0 0 0 1 0 0 0 1 1 1 1\n\
             CELLS 3 7\nOFFSETS vtktypeint64\n0 4 7\nCONNECTIVITY vtktypeint64\n0 1 2 3 1 2 3\n\
             CELL_TYPES 2\n10\n5\n";
    let (m, r) =
        read_mesh_bytes(s.as_bytes(), MeshFormat::Vtk, "v51.vtk").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.tets, vec![[0, 1, 2, 3]]);
    assert_eq!(r.skipped_elements, 1);
    assert_eq!(r.unreferenced_vertices, vec![4]);
}

#[test]
fn tetgen_small() {
    let (pos, _, expected) = small_input();
    for base in [0, 1] {
        let (node, ele) = tetgen(&pos, &expected.tets, base);
        check_small(read_tetgen(&node, &ele, "s"), &expected, 0);
    }
}

#[test]
fn hand_written_files() {
    let unit = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    // MSH 2.2 ASCII: node ids 10..50, a point, a line and a triangle, vertex 4 unused.
    let (m, r) = read(&mesh_data("single_tet.msh"));
    assert_eq!(&m.positions[..4], &unit[..]);
    assert_eq!(m.tets, vec![[0, 1, 2, 3]]);
    assert_eq!(r.skipped_elements, 3);
    assert_eq!(r.unreferenced_vertices, vec![4]);
    assert_eq!(r.reoriented_tets, 0);
    // MSH 4.1 ASCII: two node blocks (one parametric), a triangle, an inverted tet.
    let (m, r) = read(&mesh_data("single_tet41.msh"));
    assert_eq!(m.positions, unit);
    assert_eq!(m.tets, vec![[0, 1, 2, 3]]);
    assert_eq!(r.skipped_elements, 1);
    assert_eq!(r.reoriented_tets, 1);
    // TetGen, 1-based with comments, attributes and markers; the tet is given inverted.
    // Read via the .ele path: the sibling .node is found.
    let (m, r) = read(&mesh_data("single_tet.ele"));
    assert_eq!(m.positions, unit);
    assert_eq!(m.tets, vec![[0, 1, 2, 3]]);
    assert_eq!(r.reoriented_tets, 1);
    // VTK ASCII float points, vertex + triangle cells, POINT_DATA ignored.
    let (m, r) = read(&mesh_data("single_tet.vtk"));
    assert_eq!(m.positions, unit);
    assert_eq!(m.tets, vec![[0, 1, 2, 3]]);
    assert_eq!(r.skipped_elements, 2);
    assert!(r.warnings.is_empty());
}

#[test]
fn read_mesh_file_errors() {
    let msg = read_mesh(&mesh_data("nope.msh"))
        .map(|_| ())
        .unwrap_err()
        .to_string();
    assert_contains(&msg, &["nope.msh", "cannot read"]);
    let msg = read_mesh(&mesh_data("single_tet.obj"))
        .map(|_| ())
        .unwrap_err()
        .to_string();
    assert_contains(&msg, &["single_tet.obj", "extension"]);
}

// ---------------------------------------------------------------------------------------------
// Validation: errors name the file and the element or vertex.

fn unit_tet_msh(nodes: &str, elements: &str) -> Vec<u8> {
    format!(
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n{}\n{nodes}$EndNodes\n$Elements\n{}\n{elements}$EndElements\n",
        nodes.lines().count(),
        elements.lines().count()
    )
    .into_bytes()
}

const NODES5: &str = "1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 1 1 1\n";

#[test]
fn error_nan_coordinate() {
    let b = unit_tet_msh(
        "1 0 0 0\n2 1 0 0\n3 0 nan 0\n4 0 0 1\n",
        "1 4 2 1 1 1 2 3 4\n",
    );
    let msg = err_msg(read_mesh_bytes(&b, MeshFormat::Msh, "nan.msh"));
    assert_contains(&msg, &["nan.msh", "vertex 2", "node id 3", "non-finite"]);
    let node = b"4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 inf\n";
    let ele = b"1 4 0\n0 0 1 2 3\n";
    let msg = err_msg(read_tetgen(node, ele, "nan"));
    assert_contains(&msg, &["nan.node", "vertex 3", "non-finite"]);
    let msg = err_msg(TetMesh::new_validated(
        vec![
            [0.0; 3],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [f64::NAN, 0.0, 1.0],
        ],
        vec![[0, 1, 2, 3]],
        "direct",
    ));
    assert_contains(&msg, &["direct", "vertex 3"]);
}

#[test]
fn error_index_out_of_range() {
    let b = unit_tet_msh(NODES5, "17 4 2 1 1 1 2 3 4\n18 4 2 1 1 1 2 3 901\n");
    let msg = err_msg(read_mesh_bytes(&b, MeshFormat::Msh, "cube.msh"));
    assert_eq!(
        msg,
        "cube.msh: tet 1 (element id 18): vertex index 900 out of range (5 vertices)"
    );
    // Non-consecutive ids: names the undefined node id.
    let b = unit_tet_msh(
        "10 0 0 0\n20 1 0 0\n30 0 1 0\n40 0 0 1\n",
        "5 4 2 1 1 10 20 30 44\n",
    );
    let msg = err_msg(read_mesh_bytes(&b, MeshFormat::Msh, "ids.msh"));
    assert_contains(&msg, &["ids.msh", "tet 0 (element id 5)", "node id 44"]);
    let node = b"4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n";
    let msg = err_msg(read_tetgen(node, b"2 4 0\n0 0 1 2 3\n1 0 1 2 -1\n", "oor"));
    assert_contains(&msg, &["oor.ele", "tet 1", "vertex index -1", "4 vertices"]);
    let msg = err_msg(TetMesh::new_validated(
        vec![[0.0; 3]; 4],
        vec![[0, 1, 2, 4]],
        "d",
    ));
    assert_contains(&msg, &["d: tet 0", "vertex index 4"]);
    let vtk = b"# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 4 double\n0 0 0 1 0 0 0 1 0 0 0 1\nCELLS 1 5\n4 0 1 2 7\nCELL_TYPES 1\n10\n";
    let msg = err_msg(read_mesh_bytes(vtk, MeshFormat::Vtk, "o.vtk"));
    assert_contains(&msg, &["o.vtk", "tet 0", "vertex index 7"]);
}

#[test]
fn error_repeated_vertex() {
    let b = unit_tet_msh(NODES5, "1 4 2 1 1 1 2 3 4\n2 4 2 1 1 2 3 5 3\n");
    let msg = err_msg(read_mesh_bytes(&b, MeshFormat::Msh, "rep.msh"));
    assert_contains(
        &msg,
        &["rep.msh", "tet 1 (element id 2)", "vertex 2 repeated"],
    );
}

#[test]
fn error_degenerate_tet() {
    // Tet 1 is flat (all four in the z=0 plane).
    let b = unit_tet_msh(
        "1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 1 1 0\n",
        "1 4 2 1 1 1 2 3 4\n9 4 2 1 1 1 2 3 5\n",
    );
    let msg = err_msg(read_mesh_bytes(&b, MeshFormat::Msh, "flat.msh"));
    assert_contains(&msg, &["flat.msh", "tet 1 (element id 9)", "degenerate"]);
    // Nearly flat relative to the mean: 1e-12 of the others.
    let mut pos = generate::box_mesh([1, 1, 1], [1.0; 3]).positions;
    let mut tets = generate::box_mesh([1, 1, 1], [1.0; 3]).tets;
    pos.extend([
        [5.0, 5.0, 5.0],
        [6.0, 5.0, 5.0],
        [5.0, 6.0, 5.0],
        [5.0, 5.0, 5.0 + 1e-11],
    ]);
    tets.push([8, 9, 10, 11]);
    let msg = err_msg(TetMesh::new_validated(pos, tets, "thin"));
    assert_contains(&msg, &["thin: tet 6", "degenerate"]);
}

#[test]
fn error_duplicate_tets() {
    let b = unit_tet_msh(
        NODES5,
        "1 4 2 1 1 1 2 3 4\n2 4 2 1 1 2 3 4 5\n3 4 2 1 1 4 3 2 1\n",
    );
    let msg = err_msg(read_mesh_bytes(&b, MeshFormat::Msh, "dup.msh"));
    assert_contains(
        &msg,
        &[
            "dup.msh",
            "tets 0 (element id 1) and 2 (element id 3)",
            "same vertices",
        ],
    );
    let (cube, _) = read(&meshes_dir().join("cube.msh"));
    let mut tets = cube.tets.clone();
    let t = tets[3];
    tets.push([t[1], t[0], t[3], t[2]]);
    let msg = err_msg(TetMesh::new_validated(
        cube.positions.clone(),
        tets,
        "cube+",
    ));
    assert_contains(&msg, &["cube+", "tets 3 and 750"]);
}

#[test]
fn error_no_tets() {
    let b = unit_tet_msh(NODES5, "1 2 2 1 1 1 2 3\n");
    let msg = err_msg(read_mesh_bytes(&b, MeshFormat::Msh, "tri.msh"));
    assert_contains(&msg, &["tri.msh", "no tetrahedra", "1 other"]);
    let msg = err_msg(TetMesh::new_validated(vec![[0.0; 3]], vec![], "empty"));
    assert_contains(&msg, &["empty", "no tetrahedra"]);
}

#[test]
fn error_truncated_files() {
    let dir = meshes_dir();
    let (cube, _) = read(&dir.join("cube.msh"));
    let ids = one_based(cube.positions.len());
    let elems = tets_as_elems(&cube);
    let mut inputs: Vec<(&str, Vec<u8>, MeshFormat)> = vec![
        (
            "t.msh",
            std::fs::read(dir.join("cube.msh")).unwrap_or_default(),
            MeshFormat::Msh,
        ),
        (
            "t.vtk",
            std::fs::read(dir.join("cube.vtk")).unwrap_or_default(),
            MeshFormat::Vtk,
        ),
        (
            "t22b.msh",
            msh22_binary(&cube.positions, &ids, &elems),
            MeshFormat::Msh,
        ),
        (
            "t41a.msh",
            msh41_ascii(&cube.positions, &ids, &elems),
            MeshFormat::Msh,
        ),
        (
            "t41b.msh",
            msh41_binary(&cube.positions, &ids, &elems),
            MeshFormat::Msh,
        ),
        (
            "tb.vtk",
            vtk_binary(&cube.positions, &elems),
            MeshFormat::Vtk,
        ),
    ];
    // VTK binary ends with a harmless CELL_DATA line: cut before it.
    if let Some(last) = inputs.last_mut() {
        last.1.truncate(last.1.len() - b"\nCELL_DATA 1\n".len());
    }
    for (name, bytes, fmt) in &inputs {
        assert!(bytes.len() > 1000, "{name}");
        // Cuts everywhere except inside the trailing end marker / final newline.
        let tail = if name.ends_with(".vtk") { 1 } else { 14 };
        for frac in 1..40 {
            let cut = bytes.len() * frac / 40;
            if cut >= bytes.len() - tail {
                continue;
            }
            let r = read_mesh_bytes(&bytes[..cut], *fmt, name);
            let msg = err_msg(r);
            assert!(msg.starts_with(&format!("{name}: ")), "{msg}");
        }
    }
    let msg = err_msg(read_mesh_bytes(
        &inputs[0].1[..20000],
        MeshFormat::Msh,
        "cut.msh",
    ));
    assert_contains(&msg, &["cut.msh", "$Elements", "end of file"]);
    let node = std::fs::read(dir.join("cube.node")).unwrap_or_default();
    let ele = std::fs::read(dir.join("cube.ele")).unwrap_or_default();
    let msg = err_msg(read_tetgen(&node, &ele[..ele.len() / 2], "cube"));
    // Cut mid-line or between lines: either way the tet is named.
    assert_contains(&msg, &["cube.ele: line ", "tet "]);
    let msg = err_msg(read_tetgen(&node, b"750 4 0\n0 0 1 7 43\n", "cube"));
    assert_contains(&msg, &["cube.ele", "end of file", "tet 1 of 750"]);
    let msg = err_msg(read_tetgen(&node[..node.len() / 2], &ele, "cube"));
    assert_contains(&msg, &["cube.node: line ", "vertex "]);
}

#[test]
fn error_garbage_files() {
    let garbage: &[&[u8]] = &[
        b"",
        b"hello world",
        b"\x00\x01\x02\xff\xfe",
        b"$MeshFormat\n9.9 0 8\n$EndMeshFormat\n",
        b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\nmany\n",
        b"$MeshFormat\n2.2 1 8\n\x07\x00\x00\x00\n$EndMeshFormat\n",
        b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n1000000000000\n1 0 0 0\n$EndNodes\n",
        b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 99999999999 1 2\n3 1 0 99999999999\n",
        b"# vtk DataFile Version 3.0\nt\nBINARY\nDATASET POLYDATA\n",
        b"# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 1000000000000 double\n0 0 0\n",
    ];
    for (i, g) in garbage.iter().enumerate() {
        for fmt in [MeshFormat::Msh, MeshFormat::Vtk] {
            let msg = err_msg(read_mesh_bytes(g, fmt, "junk"));
            assert!(msg.starts_with("junk: "), "case {i}: {msg}");
        }
        let msg = err_msg(read_tetgen(g, g, "junk"));
        assert!(
            msg.starts_with("junk.node: ") || msg.starts_with("junk.ele: "),
            "{msg}"
        );
    }
    let msg = err_msg(read_mesh_bytes(
        b"$MeshFormat\n4.0 0 8\n",
        MeshFormat::Msh,
        "v40.msh",
    ));
    assert_contains(&msg, &["v40.msh", "unsupported", "4.0"]);
}

// ---------------------------------------------------------------------------------------------
// Fixes and reports.

#[test]
fn inverted_tets_fixed_and_counted() {
    let (cube, _) = read(&meshes_dir().join("cube.msh"));
    let mut tets = cube.tets.clone();
    for t in tets.iter_mut().step_by(7) {
        t.swap(0, 1);
    }
    let n_inv = cube.tets.len().div_ceil(7);
    let (m, r) = TetMesh::new_validated(cube.positions.clone(), tets.clone(), "inv")
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(r.reoriented_tets, n_inv);
    for (t, (fixed, given)) in m.tets.iter().zip(&tets).enumerate() {
        assert!(m.tet_volume(t) > 0.0);
        if t % 7 == 0 {
            assert_eq!(*fixed, [given[0], given[1], given[3], given[2]]);
        } else {
            assert_eq!(fixed, given);
        }
    }
    assert!(r.warnings.is_empty());
}

#[test]
fn non_tet_elements_skipped_and_unreferenced_reported() {
    let b = unit_tet_msh(
        "1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 7 7 7\n6 8 8 8\n",
        "1 15 2 0 1 1\n2 1 2 0 1 1 2\n3 2 2 0 1 1 2 3\n4 3 2 0 1 1 2 3 5\n5 4 2 1 1 1 2 3 4\n",
    );
    let (m, r) =
        read_mesh_bytes(&b, MeshFormat::Msh, "mixed.msh").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.tets, vec![[0, 1, 2, 3]]);
    assert_eq!(m.positions.len(), 6);
    assert_eq!(r.skipped_elements, 4);
    assert_eq!(r.unreferenced_vertices, vec![4, 5]);
    assert_eq!(m.referenced(), vec![true, true, true, true, false, false]);
    assert_eq!(r.source, "mixed.msh");
}

#[test]
fn non_manifold_surface_warned() {
    // Two tets sharing only an edge (0-1): boundary edge 0-1 is in 4 boundary triangles.
    let pos = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, -1.0],
    ];
    let (_, r) = TetMesh::new_validated(pos.clone(), vec![[0, 1, 2, 3], [0, 1, 4, 5]], "bow")
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(r.warnings.len(), 1, "{:?}", r.warnings);
    assert_contains(&r.warnings[0], &["not closed", "[0, 1]"]);
    // Three tets on one face: non-manifold face and open boundary edges.
    let pos = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
        [0.2, 0.2, 2.0],
    ];
    let (_, r) = TetMesh::new_validated(pos, vec![[0, 1, 2, 3], [0, 2, 1, 4], [0, 1, 2, 5]], "fan")
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(
        r.warnings.iter().any(|w| w.contains("more than 2 tets")),
        "{:?}",
        r.warnings
    );
    assert!(
        r.warnings.iter().any(|w| w.contains("open edges")),
        "{:?}",
        r.warnings
    );
}

// ---------------------------------------------------------------------------------------------
// Surface.

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn check_surface(mesh: &TetMesh) -> usize {
    let s = boundary_surface(mesh);
    // Face → owning tet's 4th vertex.
    let mut opposite: HashMap<[u32; 3], Vec<u32>> = HashMap::new();
    for t in &mesh.tets {
        for k in 0..4 {
            let mut f: Vec<u32> = (0..4).filter(|&j| j != k).map(|j| t[j]).collect();
            f.sort_unstable();
            opposite.entry([f[0], f[1], f[2]]).or_default().push(t[k]);
        }
    }
    let p = |v: u32| mesh.positions[v as usize];
    let mut flux = 0.0;
    for tri in &s.triangles {
        let mut key = *tri;
        key.sort_unstable();
        let opp = &opposite[&key];
        assert_eq!(opp.len(), 1, "boundary face {tri:?} in {} tets", opp.len());
        let n = cross(sub(p(tri[1]), p(tri[0])), sub(p(tri[2]), p(tri[0])));
        assert!(
            dot(n, sub(p(opp[0]), p(tri[0]))) < 0.0,
            "{tri:?} points inward"
        );
        let c = [0, 1, 2].map(|k| (p(tri[0])[k] + p(tri[1])[k] + p(tri[2])[k]) / 3.0);
        flux += dot(c, n) / 2.0; // n has length 2·area
    }
    let vol: f64 = (0..mesh.tets.len()).map(|t| mesh.tet_volume(t)).sum();
    assert!(
        (flux - 3.0 * vol).abs() < 1e-9 * vol.max(1.0),
        "flux {flux} vs 3V {}",
        3.0 * vol
    );
    let mut expect: Vec<u32> = s.triangles.iter().flatten().copied().collect();
    expect.sort_unstable();
    expect.dedup();
    assert_eq!(s.vertices, expect);
    s.triangles.len()
}

#[test]
fn reference_cube_surface() {
    let (cube, r) = read(&meshes_dir().join("cube.msh"));
    assert_eq!(check_surface(&cube), 300);
    assert!(r.warnings.is_empty());
    let s = boundary_surface(&cube);
    // The boundary vertices are exactly those on the faces of [0,1]^3: 216 - 4^3.
    assert_eq!(s.vertices.len(), 216 - 64);
    let (liver, r) = read(&meshes_dir().join("liver.vtk"));
    check_surface(&liver);
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
    let single = TetMesh {
        positions: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        tets: vec![[0, 1, 2, 3]],
    };
    assert_eq!(check_surface(&single), 4);
}

// ---------------------------------------------------------------------------------------------
// Procedural meshes: cylinder, voxel carving, organ.

/// Boundary-surface checks beyond [`check_surface`] for a mesh meant to be a solid: every tet
/// positive, every vertex used, validation silent, every boundary edge in exactly two boundary
/// triangles, the triangles around each boundary vertex forming a single fan (no vertex-only
/// contacts), and the tets face-connected. Returns the boundary surface.
fn assert_manifold_solid(mesh: &TetMesh) -> palpate::mesh::Surface {
    assert!((0..mesh.tets.len()).all(|t| mesh.tet_volume(t) > 0.0));
    assert!(mesh.referenced().iter().all(|&u| u));
    let (m, r) = TetMesh::new_validated(mesh.positions.clone(), mesh.tets.clone(), "gen")
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(&m, mesh);
    assert_eq!(r.reoriented_tets, 0);
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
    check_surface(mesh);
    let s = boundary_surface(mesh);
    let mut edges: HashMap<[u32; 2], u32> = HashMap::new();
    let mut link: HashMap<u32, Vec<[u32; 2]>> = HashMap::new();
    for tri in &s.triangles {
        for k in 0..3 {
            let (a, b, c) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
            *edges.entry([a.min(b), a.max(b)]).or_insert(0) += 1;
            link.entry(a).or_default().push([b, c]);
        }
    }
    for (e, n) in &edges {
        assert_eq!(*n, 2, "boundary edge {e:?} in {n} boundary triangles");
    }
    // Around a vertex, each triangle links its two other vertices; one fan = one cycle.
    for (v, segs) in &link {
        let mut reached = vec![segs[0][0]];
        let mut grew = true;
        while grew {
            grew = false;
            for [a, b] in segs {
                for (x, y) in [(a, b), (b, a)] {
                    if reached.contains(x) && !reached.contains(y) {
                        reached.push(*y);
                        grew = true;
                    }
                }
            }
        }
        assert_eq!(reached.len(), segs.len(), "vertex {v}: more than one fan");
    }
    // Face connectivity of the tets.
    let mut by_face: HashMap<[u32; 3], Vec<usize>> = HashMap::new();
    for (t, tet) in mesh.tets.iter().enumerate() {
        for k in 0..4 {
            let mut f = [0; 3];
            for (slot, j) in f.iter_mut().zip((0..4).filter(|&j| j != k)) {
                *slot = tet[j];
            }
            f.sort_unstable();
            by_face.entry(f).or_default().push(t);
        }
    }
    let mut seen = vec![false; mesh.tets.len()];
    let mut stack = vec![0];
    seen[0] = true;
    while let Some(t) = stack.pop() {
        for k in 0..4 {
            let mut f = [0; 3];
            for (slot, j) in f.iter_mut().zip((0..4).filter(|&j| j != k)) {
                *slot = mesh.tets[t][j];
            }
            f.sort_unstable();
            for &u in &by_face[&f] {
                if !seen[u] {
                    seen[u] = true;
                    stack.push(u);
                }
            }
        }
    }
    assert!(seen.iter().all(|&s| s), "tets not face-connected");
    s
}

/// Tet shape quality `6√2·V / l_rms³`: 1 for a regular tet, 0.657 for a Kuhn tet of a cube.
fn tet_quality(mesh: &TetMesh, t: usize) -> f64 {
    let p = mesh.tets[t].map(|v| mesh.positions[v as usize]);
    let mut sum = 0.0;
    for (a, b) in [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)] {
        let d = sub(p[a], p[b]);
        sum += dot(d, d);
    }
    6.0 * 2f64.sqrt() * mesh.tet_volume(t) / (sum / 6.0).powf(1.5)
}

#[test]
fn cylinder_mesh_default() {
    use core::f64::consts::PI;
    let (h, r) = (0.1, 0.02);
    let (nr, nz) = (
        generate::CYLINDER_RADIAL_CELLS,
        generate::CYLINDER_HEIGHT_CELLS,
    );
    let m = generate::cylinder_mesh(h, nr, nz);
    let side = 2 * nr + 1;
    assert_eq!(m.positions.len(), side * side * (nz + 1));
    assert_eq!((m.positions.len(), m.tets.len()), (784, 3240));
    let s = assert_manifold_solid(&m);

    // Not nearly degenerate: smallest tet 0.567 of the mean volume, worst shape 0.436 (an
    // undistorted Kuhn tet: 0.657); the rim cells, squeezed by the mapping near the square's
    // corners, are the worst. (Without the per-quadrant reflection the smallest tet is 0.29 of the
    // mean: three rim vertices in one triangle.)
    let vols: Vec<f64> = (0..m.tets.len()).map(|t| m.tet_volume(t)).collect();
    let vol: f64 = vols.iter().sum();
    let min_ratio = vols.iter().copied().fold(f64::INFINITY, f64::min) / (vol / vols.len() as f64);
    let min_q = (0..m.tets.len())
        .map(|t| tet_quality(&m, t))
        .fold(f64::INFINITY, f64::min);
    assert!(
        (0.566..0.568).contains(&min_ratio),
        "min V / mean V {min_ratio}"
    );
    assert!((0.436..0.437).contains(&min_q), "min quality {min_q}");

    // The bottom and top faces: exactly z = 0 and z = H, (2·nr+1)² vertices each, nothing else
    // within a tiny distance of them.
    let near = |z0: f64| -> Vec<[f64; 3]> {
        m.positions
            .iter()
            .copied()
            .filter(|p| (p[2] - z0).abs() < 1e-9)
            .collect()
    };
    let (bottom, top) = (near(0.0), near(h));
    assert_eq!((bottom.len(), top.len()), (side * side, side * side));
    assert!(bottom.iter().all(|p| p[2] == 0.0) && top.iter().all(|p| p[2] == h));

    // Every other boundary vertex is on the circle of radius R.
    let radius = |v: u32| m.positions[v as usize][0].hypot(m.positions[v as usize][1]);
    let caps = |v: u32| m.positions[v as usize][2] == 0.0 || m.positions[v as usize][2] == h;
    for &v in s.vertices.iter().filter(|&&v| !caps(v)) {
        assert!(
            (radius(v) - r).abs() < 1e-15,
            "vertex {v} at radius {}",
            radius(v)
        );
    }

    // Volume: the cross-section is the polygon inscribed in the circle through the 8·nr rim
    // vertices, of area Σ R²/2·sin Δθ_i; its deficit from πR² is (1/2π)·Σ (Δθ_i − sin Δθ_i) of
    // πR², at most Δθ_max²/6 (Δθ − sin Δθ ≤ Δθ³/6 and Σ Δθ_i = 2π).
    let mut angles: Vec<f64> = (0..side * side)
        .filter(|&v| (radius(v as u32) - r).abs() < 1e-15)
        .map(|v| m.positions[v][1].atan2(m.positions[v][0]))
        .collect();
    assert_eq!(angles.len(), 8 * nr);
    angles.sort_by(f64::total_cmp);
    let steps: Vec<f64> = (0..angles.len())
        .map(|i| (angles[(i + 1) % angles.len()] - angles[i]).rem_euclid(2.0 * PI))
        .collect();
    let polygon: f64 = steps.iter().map(|d| r * r / 2.0 * d.sin()).sum();
    assert!(
        (vol - polygon * h).abs() < 1e-12 * vol,
        "{vol} vs {}",
        polygon * h
    );
    let deficit = 1.0 - vol / (PI * r * r * h);
    let step_max = steps.iter().copied().fold(0.0, f64::max);
    // Here Δθ ranges from 13.6° to 16.9°: deficit 1.167 %, bound 1.445 %.
    assert!((0.01166..0.01168).contains(&deficit), "deficit {deficit}");
    assert!(deficit <= step_max * step_max / 6.0);
    assert!((step_max.to_degrees() - 16.87).abs() < 0.01);
}

#[test]
fn cylinder_mesh_other_resolutions() {
    // Including the coarsest (one cell from axis to rim: every cell is a corner cell).
    for (h, nr, nz) in [(1.0, 1, 1), (0.3, 2, 5), (0.05, 6, 4), (0.1, 0, 0)] {
        let m = generate::cylinder_mesh(h, nr, nz);
        let (nr, nz) = (nr.max(1), nz.max(1));
        assert_eq!(m.tets.len(), 24 * nr * nr * nz);
        assert_manifold_solid(&m);
        let vol: f64 = (0..m.tets.len()).map(|t| m.tet_volume(t)).sum();
        let exact = core::f64::consts::PI * (h / 5.0) * (h / 5.0) * h;
        // Coarsest: the inscribed square, 2/π of the disk.
        let expect_min = if nr == 1 {
            2.0 / core::f64::consts::PI
        } else {
            0.95
        };
        assert!(
            vol < exact && vol / exact >= expect_min - 1e-12,
            "{vol} vs {exact}"
        );
        assert!(
            m.positions
                .iter()
                .all(|p| p[2] == 0.0 || p[2] >= h / nz as f64 * 0.999)
        );
        assert_eq!(
            m.positions.iter().filter(|p| p[2] == h).count(),
            (2 * nr + 1).pow(2)
        );
    }
}

#[test]
fn organ_mesh_default() {
    let cube = generate::ORGAN_CUBE_M;
    let m = generate::organ_mesh(cube);
    assert!(
        (5000..=7000).contains(&m.tets.len()),
        "{} tets",
        m.tets.len()
    );
    assert_eq!(m.tets.len() % 6, 0);
    assert_eq!((m.positions.len(), m.tets.len()), (1386, 5868));
    assert_manifold_solid(&m);
    // Every tet h³/6 and the volume the kept cubes' exactly (h = 3·2⁻⁸: no rounding anywhere).
    let cubes = (m.tets.len() / 6) as f64;
    assert!((0..m.tets.len()).all(|t| m.tet_volume(t) == cube * cube * cube / 6.0));
    let vol: f64 = (0..m.tets.len()).map(|t| m.tet_volume(t)).sum();
    assert_eq!(vol, cubes * cube * cube * cube);
    assert!((vol - 1.574e-3).abs() < 1e-6, "volume {vol} m³");
    // Liver-sized: about 0.2 m × 0.14 m × 0.1 m.
    let extent = |a: usize| {
        let (lo, hi) = m
            .positions
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
                (l.min(p[a]), h.max(p[a]))
            });
        hi - lo
    };
    assert_eq!([0, 1, 2].map(extent), [17.0, 12.0, 9.0].map(|n| n * cube));
    // The two vertex sets: small, non-empty, disjoint, where they should be.
    let patch = generate::organ_underside_patch(&m, generate::ORGAN_PATCH_RADIUS_M);
    let lobe = generate::organ_left_lobe_tip(&m, generate::ORGAN_LOBE_TIP_DEPTH_M);
    assert_eq!((patch.len(), lobe.len()), (8, 83));
    assert!(patch.iter().all(|v| !lobe.contains(v)));
    let z_min = m
        .positions
        .iter()
        .map(|p| p[2])
        .fold(f64::INFINITY, f64::min);
    let x_min = m
        .positions
        .iter()
        .map(|p| p[0])
        .fold(f64::INFINITY, f64::min);
    for &v in &patch {
        let p = m.positions[v as usize];
        assert!(p[2] == z_min && (p[0] - 0.03).hypot(p[1]) <= 0.02);
    }
    let surface = boundary_surface(&m).vertices;
    for &v in &lobe {
        assert!(surface.binary_search(&v).is_ok());
        assert!(m.positions[v as usize][0] <= x_min + 0.03);
    }
    assert!(lobe.iter().all(|&v| m.positions[v as usize][0] < -0.06));
}

#[test]
fn organ_mesh_other_resolutions() {
    for cube in [0.008, 0.01, 0.015, 0.02] {
        let m = generate::organ_mesh(cube);
        assert_manifold_solid(&m);
        let vol: f64 = (0..m.tets.len()).map(|t| m.tet_volume(t)).sum();
        let kept = (m.tets.len() / 6) as f64 * cube * cube * cube;
        assert!((vol - kept).abs() < 1e-12 * vol);
        assert!((vol - 1.55e-3).abs() < 0.1e-3, "{cube}: {vol} m³");
        assert!(!generate::organ_underside_patch(&m, generate::ORGAN_PATCH_RADIUS_M).is_empty());
        assert!(!generate::organ_left_lobe_tip(&m, generate::ORGAN_LOBE_TIP_DEPTH_M).is_empty());
    }
}

/// The built-in organ (`palpate::mesh::organ`, the gmsh mesh of `tools/meshes/organ.py`): it
/// reads cleanly (nothing skipped, reoriented, unreferenced or warned about), is a manifold
/// solid, and its tets fill exactly what its boundary encloses: the sum of the tet volumes
/// equals the divergence-theorem volume of the boundary triangles, `Σ (a × b)·c / 6` (to
/// 1e-12 relative: rounding of some 10⁴ terms). Its size is the script's shape (half-length
/// 0.085 m: the x extent within 1 mm of 0.17 m, the surface remeshed by gmsh) and its lowest
/// vertices are the flat underside, exactly at `ORGAN_FLOOR_Z_M`, a few dozen of them. Counts
/// describe the committed file.
#[test]
fn built_in_organ() {
    use palpate::mesh::organ::{ORGAN_FLOOR_Z_M, ORGAN_SOURCE, organ};
    let (m, report) = organ().expect("organ");
    assert_eq!(report.source, ORGAN_SOURCE);
    assert_eq!(
        (report.skipped_elements, report.reoriented_tets),
        (0, 0),
        "{report:?}"
    );
    assert!(report.unreferenced_vertices.is_empty() && report.warnings.is_empty());
    assert_eq!((m.positions.len(), m.tets.len()), (1118, 3947));
    let surface = assert_manifold_solid(&m);
    let tets: f64 = (0..m.tets.len()).map(|t| m.tet_volume(t)).sum();
    let enclosed: f64 = surface
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| m.positions[v as usize]);
            (a[1] * b[2] - a[2] * b[1]) * c[0]
                + (a[2] * b[0] - a[0] * b[2]) * c[1]
                + (a[0] * b[1] - a[1] * b[0]) * c[2]
        })
        .sum::<f64>()
        / 6.0;
    assert!(
        (tets - enclosed).abs() <= 1e-12 * tets,
        "{tets} vs {enclosed} m³"
    );
    assert!((0.4e-3..0.55e-3).contains(&tets), "{tets} m³");
    let (lo, hi) =
        m.positions
            .iter()
            .fold(([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]), |(l, h), p| {
                (
                    [0, 1, 2].map(|a| l[a].min(p[a])),
                    [0, 1, 2].map(|a| h[a].max(p[a])),
                )
            });
    assert!((hi[0] - lo[0] - 0.17).abs() < 0.001, "{lo:?} {hi:?}");
    assert_eq!(lo[2], ORGAN_FLOOR_Z_M);
    let floor = m
        .positions
        .iter()
        .filter(|p| p[2] == ORGAN_FLOOR_Z_M)
        .count();
    assert!((10..100).contains(&floor), "{floor} underside vertices");
}

/// [`generate::voxel_mesh`] of the unit cubes listed in `cells` (on the lattice ℤ³).
fn voxels_of(cells: &[[i32; 3]], hi: i32) -> TetMesh {
    generate::voxel_mesh(1.0, [[0.0; 3], [f64::from(hi); 3]], |p| {
        cells.contains(&p.map(|x| x.floor() as i32))
    })
}

#[test]
fn voxel_mesh_removes_non_manifold_contacts() {
    // Two cubes sharing only an edge, or only a vertex: one is left.
    for other in [[1, 1, 0], [1, 1, 1]] {
        let m = voxels_of(&[[0, 0, 0], other], 2);
        assert_eq!((m.positions.len(), m.tets.len()), (8, 6));
        assert_eq!(m.positions[0], [0.0; 3]);
    }
    // A bar of three with a fourth cube touching its middle by an edge: the bar stays.
    let m = voxels_of(&[[0, 0, 0], [1, 0, 0], [2, 0, 0], [1, 1, 1]], 3);
    assert_eq!(m.tets.len(), 18);
    assert_manifold_solid(&m);
    // A 2×2×2 block without two opposite corners: the empty corners touch at the centre (a pinch);
    // cubes go until the centre vertex is manifold.
    let block: Vec<[i32; 3]> = (0..8)
        .map(|b| [b & 1, b >> 1 & 1, b >> 2 & 1])
        .filter(|c| *c != [0, 0, 0] && *c != [1, 1, 1])
        .collect();
    let m = voxels_of(&block, 2);
    assert_eq!(m.tets.len(), 4 * 6);
    assert_manifold_solid(&m);
    // A ring of 7 cubes around an empty one, closed only across an edge: a cube of the contact
    // goes, leaving a C of 6.
    let m = voxels_of(
        &[
            [0, 0, 0],
            [1, 0, 0],
            [0, 1, 0],
            [0, 2, 0],
            [1, 2, 0],
            [2, 1, 0],
            [2, 0, 0],
        ],
        3,
    );
    assert_eq!(m.tets.len(), 6 * 6);
    assert_manifold_solid(&m);
    // Random blobs (55 % of a 6×6×6 box, full of edge and vertex contacts): whatever survives is
    // a manifold solid.
    let mut rng = XorShift(0x2545_F491_4F6C_DD1D);
    let mut removed = 0;
    for _ in 0..40 {
        let cells: Vec<[i32; 3]> = (0..216)
            .map(|c| [c % 6, c / 6 % 6, c / 36])
            .filter(|_| rng.below(100) < 55)
            .collect();
        let m = voxels_of(&cells, 6);
        assert!(!m.tets.is_empty());
        assert_manifold_solid(&m);
        removed += cells.len() - m.tets.len() / 6;
    }
    assert!(removed > 0);
}

// ---------------------------------------------------------------------------------------------
// Fuzz: seeded byte mutations never panic.

struct XorShift(u64);
impl XorShift {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

fn mutate(rng: &mut XorShift, src: &[u8]) -> Vec<u8> {
    let mut b = src.to_vec();
    const INTERESTING: &[&[u8]] = &[
        b"0",
        b"-1",
        b"4294967296",
        b"99999999999999999999",
        b"nan",
        b"inf",
        b"\n",
        b" ",
        b"$",
        b"$EndNodes",
        b"1e308",
        b"\xff\xff\xff\x7f",
    ];
    for _ in 0..1 + rng.below(4) {
        if b.is_empty() {
            break;
        }
        let i = rng.below(b.len());
        match rng.below(6) {
            0 => b[i] = rng.next() as u8,
            1 => b[i] = b"0123456789 \n.-e$"[rng.below(16)],
            2 => {
                b.remove(i);
            }
            3 => b.truncate(i),
            4 => {
                let s = INTERESTING[rng.below(INTERESTING.len())];
                b.splice(i..i, s.iter().copied());
            }
            _ => {
                // Duplicate a chunk.
                let len = rng.below(64).min(b.len() - i);
                let chunk: Vec<u8> = b[i..i + len].to_vec();
                let j = rng.below(b.len());
                b.splice(j..j, chunk);
            }
        }
    }
    b
}

#[test]
fn fuzz_mutations_never_panic() {
    let dir = meshes_dir();
    let rd = |n: &str| std::fs::read(dir.join(n)).unwrap_or_default();
    let (cube, _) = read(&dir.join("cube.msh"));
    let small = generate::box_mesh([2, 2, 1], [1.0, 1.0, 0.5]);
    let ids = one_based(small.positions.len());
    let elems = tets_as_elems(&small);
    let sources: Vec<(Vec<u8>, MeshFormat)> = vec![
        (rd("cube.msh"), MeshFormat::Msh),
        (rd("liver.msh"), MeshFormat::Msh),
        (rd("cube.vtk"), MeshFormat::Vtk),
        (rd("liver.vtk"), MeshFormat::Vtk),
        (
            msh22_binary(&small.positions, &ids, &elems),
            MeshFormat::Msh,
        ),
        (msh41_ascii(&small.positions, &ids, &elems), MeshFormat::Msh),
        (
            msh41_binary(&small.positions, &ids, &elems),
            MeshFormat::Msh,
        ),
        (vtk_binary(&small.positions, &elems), MeshFormat::Vtk),
    ];
    let (node, ele) = (rd("liver.node"), rd("liver.ele"));
    assert!(sources.iter().all(|(s, _)| !s.is_empty()) && !node.is_empty());
    let mut rng = XorShift(0x9E37_79B9_7F4A_7C15);
    let mut ok = 0usize;
    let rounds = 3000;
    for round in 0..rounds {
        let k = round % (sources.len() + 1);
        let r = if k == sources.len() {
            if rng.below(2) == 0 {
                read_tetgen(&mutate(&mut rng, &node), &ele, "f")
            } else {
                read_tetgen(&node, &mutate(&mut rng, &ele), "f")
            }
        } else {
            let (src, fmt) = &sources[k];
            let m = mutate(&mut rng, src);
            // Also feed each mutant to the other reader.
            let other = if *fmt == MeshFormat::Msh {
                MeshFormat::Vtk
            } else {
                MeshFormat::Msh
            };
            let _ = read_mesh_bytes(&m, other, "f");
            read_mesh_bytes(&m, *fmt, "f")
        };
        match r {
            Ok((m, _)) => {
                ok += 1;
                // Whatever came through satisfies the invariants.
                for (t, tet) in m.tets.iter().enumerate() {
                    assert!(tet.iter().all(|&v| (v as usize) < m.positions.len()));
                    assert!(m.tet_volume(t) > 0.0);
                }
                assert!(m.positions.iter().flatten().all(|x| x.is_finite()));
            }
            Err(e) => assert!(e.to_string().starts_with("f"), "{e}"),
        }
    }
    assert!(ok > 0 && ok < rounds, "{ok} of {rounds} mutants parsed");
    assert_eq!(cube.tets.len(), 750);
}
