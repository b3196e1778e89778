//! Region ids from the mesh readers (`palpate::mesh`, `MeshReport::tet_regions`): small files
//! written here in each format, their ids known by construction.

use palpate::mesh::{MeshFormat, read_mesh_bytes, read_tetgen};

/// Two tets sharing the face (1, 2, 3): regions 1 and 2 in every file below.
const POINTS: &str = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 1 1\n";

fn msh22(first_tags: [&str; 2]) -> String {
    let mut nodes = String::new();
    for (i, p) in POINTS.lines().enumerate() {
        nodes += &format!("{} {p}\n", i + 1);
    }
    format!(
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n5\n{nodes}$EndNodes\n$Elements\n3\n\
         1 2 2 7 7 1 2 3\n2 4 2 {} 1 1 2 3 4\n3 4 {} 2 3 4 5\n$EndElements\n",
        first_tags[0], first_tags[1]
    )
}

#[test]
fn msh_2_2_region_is_the_first_tag() {
    let (mesh, report) =
        read_mesh_bytes(msh22(["1", "1 2"]).as_bytes(), MeshFormat::Msh, "a.msh").expect("valid");
    assert_eq!(mesh.tets.len(), 2);
    assert_eq!(report.tet_regions, Some(vec![1, 2]));
    // No tags: region 0.
    let file = msh22(["1", "0"]);
    let (_, report) = read_mesh_bytes(file.as_bytes(), MeshFormat::Msh, "a.msh").expect("valid");
    assert_eq!(report.tet_regions, Some(vec![1, 0]));
    let err = read_mesh_bytes(msh22(["-3", "1 2"]).as_bytes(), MeshFormat::Msh, "a.msh")
        .unwrap_err()
        .to_string();
    assert!(
        err.starts_with("a.msh: tet 0 (element id 2): physical tag -3 is not a region id"),
        "{err}"
    );
}

fn msh41(entities: &str) -> String {
    format!(
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n{entities}$Nodes\n1 5 1 5\n3 1 0 5\n1\n2\n3\n4\n5\n\
         {POINTS}$EndNodes\n$Elements\n3 3 1 3\n2 1 2 1\n1 1 2 3\n3 1 4 1\n2 1 2 3 4\n\
         3 2 4 1\n3 2 3 4 5\n$EndElements\n"
    )
}

#[test]
fn msh_4_1_region_is_the_physical_tag_of_the_tets_entity() {
    // A point with a physical tag, a surface, volume 1 with physical tags 7 and 8, volume 2 with
    // none (region 0).
    let entities = "$Entities\n1 0 1 2\n1 0 0 0 1 9\n1 0 0 0 1 1 0 0 0\n\
        1 0 0 0 1 1 1 2 7 8 1 1\n2 0 0 0 1 1 1 0 0\n$EndEntities\n";
    let (mesh, report) =
        read_mesh_bytes(msh41(entities).as_bytes(), MeshFormat::Msh, "b.msh").expect("valid");
    assert_eq!(mesh.tets.len(), 2);
    assert_eq!(report.tet_regions, Some(vec![7, 0]));
    // Without $Entities: no region ids.
    let (_, report) = read_mesh_bytes(msh41("").as_bytes(), MeshFormat::Msh, "b.msh").unwrap();
    assert_eq!(report.tet_regions, None);
    // A truncated $Entities gives no region ids; the mesh reads as before.
    let cut = "$Entities\n1 0 1 2\n1 0 0\n$EndEntities\n";
    let (_, report) = read_mesh_bytes(msh41(cut).as_bytes(), MeshFormat::Msh, "b.msh").unwrap();
    assert_eq!(report.tet_regions, None);
}

fn vtk(data: &str) -> String {
    format!(
        "# vtk DataFile Version 3.0\nregions\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 5 double\n\
         {POINTS}CELLS 3 14\n3 0 1 2\n4 0 1 2 3\n4 1 2 3 4\nCELL_TYPES 3\n5\n10\n10\n{data}"
    )
}

#[test]
fn vtk_region_is_the_cell_field_named_region() {
    let scalars = "POINT_DATA 5\nSCALARS t float 1\nLOOKUP_TABLE default\n1 2 3 4 5\n\
        CELL_DATA 3\nSCALARS other float\nLOOKUP_TABLE default\n0.5 1.5 2.5\n\
        VECTORS v double\n0 0 0 1 1 1 2 2 2\nSCALARS region int 1\nLOOKUP_TABLE default\n9 1 2\n";
    let (mesh, report) =
        read_mesh_bytes(vtk(scalars).as_bytes(), MeshFormat::Vtk, "c.vtk").expect("valid");
    assert_eq!(mesh.tets.len(), 2);
    assert_eq!(report.tet_regions, Some(vec![1, 2]));
    let field =
        "CELL_DATA 3\nFIELD FieldData 2\nother 1 3 float\n0.5 1.5 2.5\nregion 1 3 double\n9 1 2\n";
    let (_, report) = read_mesh_bytes(vtk(field).as_bytes(), MeshFormat::Vtk, "c.vtk").unwrap();
    assert_eq!(report.tet_regions, Some(vec![1, 2]));
    let (_, report) = read_mesh_bytes(vtk("").as_bytes(), MeshFormat::Vtk, "c.vtk").unwrap();
    assert_eq!(report.tet_regions, None);
    let err = read_mesh_bytes(
        vtk("CELL_DATA 3\nSCALARS region float\nLOOKUP_TABLE default\n1 1.5 2\n").as_bytes(),
        MeshFormat::Vtk,
        "c.vtk",
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("cell 1: region 1.5 is not a region id"),
        "{err}"
    );
    let short = vtk("CELL_DATA 2\nSCALARS region int\nLOOKUP_TABLE default\n1 2\n");
    let err = read_mesh_bytes(short.as_bytes(), MeshFormat::Vtk, "c.vtk").unwrap_err();
    assert!(err.to_string().contains("for 3 cells"), "{err}");
}

/// The binary VTK layout: the same file, big-endian `int` regions.
#[test]
fn binary_vtk_region_field() {
    let mut file = "# vtk DataFile Version 3.0\nregions\nBINARY\nDATASET UNSTRUCTURED_GRID\n\
        POINTS 5 double\n"
        .as_bytes()
        .to_vec();
    for p in POINTS.lines() {
        for x in p.split(' ') {
            file.extend_from_slice(&x.parse::<f64>().unwrap().to_be_bytes());
        }
    }
    file.extend_from_slice(b"\nCELLS 2 10\n");
    for cell in [[4i32, 0, 1, 2, 3], [4, 1, 2, 3, 4]] {
        for v in cell {
            file.extend_from_slice(&v.to_be_bytes());
        }
    }
    file.extend_from_slice(b"\nCELL_TYPES 2\n");
    for _ in 0..2 {
        file.extend_from_slice(&10i32.to_be_bytes());
    }
    file.extend_from_slice(
        b"\nCELL_DATA 2\nSCALARS region unsigned_short 1\nLOOKUP_TABLE default\n",
    );
    for r in [3u16, 4] {
        file.extend_from_slice(&r.to_be_bytes());
    }
    file.push(b'\n');
    let (_, report) = read_mesh_bytes(&file, MeshFormat::Vtk, "d.vtk").expect("valid");
    assert_eq!(report.tet_regions, Some(vec![3, 4]));
}

#[test]
fn tetgen_region_is_the_first_attribute() {
    let node = "5 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n4 1 1 1\n";
    let ele = "2 4 2\n0 0 1 2 3 1 5.5\n1 1 2 3 4 2 6.5\n";
    let (mesh, report) = read_tetgen(node.as_bytes(), ele.as_bytes(), "e").expect("valid");
    assert_eq!(mesh.tets.len(), 2);
    assert_eq!(report.tet_regions, Some(vec![1, 2]));
    let (_, report) = read_tetgen(
        node.as_bytes(),
        "2 4 0\n0 0 1 2 3\n1 1 2 3 4\n".as_bytes(),
        "e",
    )
    .unwrap();
    assert_eq!(report.tet_regions, None);
    let err = read_tetgen(
        node.as_bytes(),
        "2 4 1\n0 0 1 2 3 -1\n1 1 2 3 4 2\n".as_bytes(),
        "e",
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.starts_with("e.ele: line 2: tet 0: region attribute -1 is not a region id"),
        "{err}"
    );
}

/// The binary 4.1 layout of `$Entities` (tags `int`, bounds `double`, counts `size_t`).
#[test]
fn binary_msh_4_1_region() {
    let mut b = b"$MeshFormat\n4.1 1 8\n".to_vec();
    b.extend_from_slice(&1i32.to_le_bytes());
    b.extend_from_slice(b"\n$EndMeshFormat\n$Entities\n");
    let size = |b: &mut Vec<u8>, v: u64| b.extend_from_slice(&v.to_le_bytes());
    let int = |b: &mut Vec<u8>, v: i32| b.extend_from_slice(&v.to_le_bytes());
    for n in [0u64, 0, 0, 2] {
        size(&mut b, n);
    }
    for (tag, physical) in [(1, Some(4)), (2, None)] {
        int(&mut b, tag);
        for x in [0.0f64, 0.0, 0.0, 1.0, 1.0, 1.0] {
            b.extend_from_slice(&x.to_le_bytes());
        }
        size(&mut b, u64::from(physical.is_some()));
        if let Some(p) = physical {
            int(&mut b, p);
        }
        size(&mut b, 1);
        int(&mut b, 3);
    }
    b.extend_from_slice(b"\n$EndEntities\n$Nodes\n");
    for v in [1u64, 5, 1, 5] {
        size(&mut b, v);
    }
    for v in [3i32, 1, 0] {
        int(&mut b, v);
    }
    size(&mut b, 5);
    for id in 1..=5u64 {
        size(&mut b, id);
    }
    for p in POINTS.lines() {
        for x in p.split(' ') {
            b.extend_from_slice(&x.parse::<f64>().unwrap().to_le_bytes());
        }
    }
    b.extend_from_slice(b"\n$EndNodes\n$Elements\n");
    for v in [2u64, 2, 1, 2] {
        size(&mut b, v);
    }
    for (entity, id, nodes) in [(2, 1u64, [1u64, 2, 3, 4]), (1, 2, [2, 3, 4, 5])] {
        for v in [3i32, entity, 4] {
            int(&mut b, v);
        }
        size(&mut b, 1);
        size(&mut b, id);
        for n in nodes {
            size(&mut b, n);
        }
    }
    b.extend_from_slice(b"\n$EndElements\n");
    let (mesh, report) = read_mesh_bytes(&b, MeshFormat::Msh, "f.msh").expect("valid");
    assert_eq!(mesh.tets.len(), 2);
    assert_eq!(report.tet_regions, Some(vec![0, 4]));
}
