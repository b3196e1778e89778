//! Interface table loader (the hybrid model, RR-3510 §6.2),
//! `InterfaceTable::<f32>::load` and `::<f64>::load`: no input panics; a
//! loaded table keeps the invariants `load` documents (connection nodes
//! ascending, numbered first in the tensor-mass region and mapped, positive
//! condensed diagonal, section lengths) and its accessors answer without
//! panicking, in range or not.
//!
//! Each input is loaded as given (16-byte aligned), then with its declared
//! length and CRC-32 repaired, and that repaired copy once more at an
//! address 4 bytes past a 16-byte boundary (`table_layouts`).
#![no_main]

use libfuzzer_sys::fuzz_target;
use palpate_fuzz::table_layouts;
use palpate_kernel::Real;
use palpate_kernel::table::InterfaceTable;

fuzz_target!(|data: &[u8]| table_layouts(data, load_both));

fn load_both(bytes: &[u8]) {
    if let Ok(table) = InterfaceTable::<f32>::load(bytes) {
        check(&table);
    }
    if let Ok(table) = InterfaceTable::<f64>::load(bytes) {
        check(&table);
    }
}

fn check<T: Real>(table: &InterfaceTable<'_, T>) {
    let (n, c, f) = (
        table.vertex_count(),
        table.connection_count(),
        table.free_count(),
    );
    let header = table.header();
    assert_eq!(n, header.vertex_count as usize);
    assert_eq!(c, header.connection_count as usize);
    assert_eq!(f, header.free_count as usize);
    assert!(c >= 1);
    for (j, &[vertex, dynamic]) in table.connections().iter().enumerate() {
        assert_eq!(dynamic as usize, j);
        assert_eq!(table.dynamic_vertex(vertex), Some(dynamic));
        let d = table.condensed_block(j, j).expect("diagonal block");
        assert!(d[0] > T::zero() && d[4] > T::zero() && d[8] > T::zero());
    }
    assert!(table.connections().windows(2).all(|w| w[0][0] < w[1][0]));
    assert!(table.condensed_block(c, 0).is_none());
    assert!(table.condensed_block(0, c).is_none());
    // The product and the quadratic form over the blocks, in bounded time.
    let u = vec![[T::one(); 3]; c];
    let mut out = vec![[T::zero(); 3]; c];
    table.add_condensed_product(&u, T::one(), &mut out);
    let _ = table.condensed_quadratic(&u);
    // The response's rows: every free vertex's, or the touchable ones'.
    let rows = table.response_rows();
    assert!(rows == f || rows == header.touchable_count as usize);
    for r in 0..3 * rows {
        assert_eq!(table.response_row(r).len(), c);
    }
    assert!(table.response_row(3 * rows).is_empty());
    assert_eq!(table.load_displacement_m().len(), f);
    assert_eq!(table.load_force_n().len(), c);
    assert_eq!(table.dynamic_vertices().len(), n);
    assert_eq!(table.dynamic_vertex(n as u32), None);
    let _ = (table.region_checksums(), table.checksum());
}
