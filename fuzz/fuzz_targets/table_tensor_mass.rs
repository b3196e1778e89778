//! Tensor-mass table loader, `TensorMassTable::<f32>::load` and `::<f64>::load`: no input
//! panics; a loaded table keeps the invariants `load` documents (CSR edge list, tets, edge
//! references, neighbours, mesh triangles, masses) and its accessors answer without panicking.
//!
//! Each input is loaded as given (16-byte aligned), then with its declared length and CRC-32
//! repaired (so that mutations of a valid table reach the directory and content checks), and
//! that repaired copy once more at an address 4 bytes past a 16-byte boundary.
#![no_main]

use libfuzzer_sys::fuzz_target;
use palpate_fuzz::table_layouts;
use palpate_kernel::Real;
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::table::format::{NO_NEIGHBOUR, tet_edge_vertices, tet_face_vertices};

fuzz_target!(|data: &[u8]| table_layouts(data, load_both));

fn load_both(bytes: &[u8]) {
    if let Ok(table) = TensorMassTable::<f32>::load(bytes) {
        check(&table);
    }
    if let Ok(table) = TensorMassTable::<f64>::load(bytes) {
        check(&table);
    }
}

fn check<T: Real>(table: &TensorMassTable<'_, T>) {
    let (n, e, m) = (table.vertex_count(), table.edge_count(), table.tet_count());
    let header = table.header();
    assert_eq!(n, header.vertex_count as usize);
    assert_eq!(e, header.edge_count as usize);
    assert_eq!(m, header.tet_count as usize);
    let fixed = (0..n as u32).filter(|&v| table.is_fixed(v)).count();
    assert_eq!(n - fixed, header.free_count as usize);
    assert!(!table.is_fixed(n as u32));
    let _ = (table.tet_materials(), table.density_kg_m3());

    // Per-vertex data.
    assert_eq!(table.rest_positions().len(), n);
    assert_eq!(table.masses_kg().len(), n);
    assert_eq!(table.vertex_tensors().len(), n);
    assert_eq!(table.vertex_terms().len(), n);
    assert!(table.rest_positions().iter().flatten().all(|x| x.finite()));
    assert!(
        table
            .masses_kg()
            .iter()
            .all(|&x| x.finite() && x >= T::zero())
    );
    assert!(
        table
            .surface_triangles()
            .iter()
            .flatten()
            .all(|&v| (v as usize) < n)
    );

    // The CSR edge list of the pairs i < j.
    let (starts, columns) = (table.edge_row_starts(), table.edge_columns());
    assert_eq!(starts.len(), n + 1);
    assert_eq!(starts.first(), Some(&0));
    assert_eq!(starts.last().map(|&s| s as usize), Some(e));
    assert_eq!(table.edge_tensors().len(), e);
    assert_eq!(table.edge_terms().len(), e);
    for (i, row) in starts.windows(2).enumerate() {
        let (i, first) = (i as u32, row[0]);
        let mut previous = i;
        for (k, &j) in columns[first as usize..row[1] as usize].iter().enumerate() {
            assert!(j > previous && (j as usize) < n, "row {i}: column {j}");
            let edge = first + k as u32;
            assert_eq!(table.edge_index(i, j), Some(edge));
            assert_eq!(table.edge_index(j, i), Some(edge));
            previous = j;
        }
    }
    assert_eq!(table.edge_index(n as u32, 0), None);
    assert_eq!(table.edge_index(u32::MAX, u32::MAX), None);

    // Tets: vertices, edge references, rest shapes, neighbours, faces.
    let tets = table.tets();
    let mesh_triangles = table.mesh_triangles();
    assert_eq!(table.tet_edges().len(), m);
    assert_eq!(table.tet_neighbours().len(), m);
    assert_eq!(table.tet_triangles().len(), m);
    assert_eq!(table.tet_shapes().len(), m);
    assert_eq!(table.tet_terms().len(), m);
    assert_eq!(mesh_triangles.len() as u64, header.mesh_triangle_count);
    assert_eq!(table.triangle_terms().len(), mesh_triangles.len());
    assert!(mesh_triangles.windows(2).all(|w| w[0] < w[1]));
    assert!(
        mesh_triangles
            .iter()
            .all(|&[p, q, r]| p < q && q < r && (r as usize) < n)
    );
    for (t, &tet) in tets.iter().enumerate() {
        assert!(tet.iter().all(|&v| (v as usize) < n), "tet {t}: {tet:?}");
        for ([a, b], &edge) in tet_edge_vertices(tet)
            .into_iter()
            .zip(&table.tet_edges()[t])
        {
            assert_ne!(a, b, "tet {t}: repeated vertex");
            assert_eq!(table.edge_index(a, b), Some(edge), "tet {t}");
        }
        let (_, volume) = table.tet_shape(t).expect("tet shape");
        assert!(volume > T::zero(), "tet {t}: volume {volume:?}");
        for &o in &table.tet_neighbours()[t] {
            assert!(
                o == NO_NEIGHBOUR || (o as usize) < m,
                "tet {t}: neighbour {o}"
            );
        }
        let faces = tet_face_vertices(tet).into_iter();
        for (mut face, &triangle) in faces.zip(&table.tet_triangles()[t]) {
            face.sort_unstable();
            assert_eq!(
                mesh_triangles.get(triangle as usize),
                Some(&face),
                "tet {t}"
            );
        }
    }
    assert!(table.tet_shape(m).is_none());
}
