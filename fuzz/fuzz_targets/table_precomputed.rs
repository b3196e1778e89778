//! Pre-computed table loader, `PrecomputedTable::<f32>::load` and `::<f64>::load`: no input
//! panics; a loaded table keeps the invariants `load` documents (a compressed one's blocks
//! decode finite, its diagonal blocks stored), its accessors and collision index answer
//! without panicking, and the contact solve on it does not panic. Seeds: f32 and f64 tables,
//! and the firmware box compressed (f16, q16, blocks dropped in both parts).
//!
//! Each input is loaded as given (16-byte aligned), then with its declared length and CRC-32
//! repaired (so that mutations of a valid table reach the directory and content checks), and
//! that repaired copy once more at an address 4 bytes past a 16-byte boundary.
#![no_main]

use libfuzzer_sys::fuzz_target;
use nalgebra::Vector3;
use palpate_fuzz::table_layouts;
use palpate_kernel::table::format::surface_block_index;
use palpate_kernel::table::{VertexSlot, within};
use palpate_kernel::{Constraint, PrecomputedModel, PrecomputedTable, Real};

fuzz_target!(|data: &[u8]| table_layouts(data, load_both));

fn load_both(bytes: &[u8]) {
    if let Ok(table) = PrecomputedTable::<f32>::load(bytes) {
        check(&table);
    }
    if let Ok(table) = PrecomputedTable::<f64>::load(bytes) {
        check(&table);
    }
}

fn check<T: Real>(table: &PrecomputedTable<'_, T>) {
    let (n, f, s) = (
        table.vertex_count(),
        table.free_count(),
        table.touchable_count(),
    );
    assert_eq!(n, table.header().vertex_count as usize);
    assert!(s <= f && f <= n, "S {s} F {f} N {n}");
    assert_eq!(table.rest_positions().len(), n);
    assert!(table.rest_positions().iter().flatten().all(|x| x.finite()));
    assert_eq!(table.surface_blocks().len(), s * (s + 1) / 2);
    assert_eq!(table.interior_blocks().len(), (f - s) * s);
    let _ = (table.young_pa(), table.poisson());

    // Compressed compliance: the record's values in range, every block (stored or dropped)
    // decodes to finite values, every diagonal block is stored.
    if let Some(r) = table.compression() {
        assert!((0.0..1.0).contains(&r.drop_below));
        assert!(r.max_force_error >= 0.0 && r.max_displacement_error.is_finite());
    }
    let (surface, interior) = (table.surface_blocks(), table.interior_blocks());
    assert!(surface.stored_len() <= surface.len() && interior.stored_len() <= interior.len());
    for k in 0..s {
        for n in 0..=k {
            let j = surface_block_index(n, k);
            let block = surface.block(j, k).expect("block in the layout");
            assert!(block.iter().all(|x| x.finite()));
            assert!(n != k || surface.is_stored(j));
        }
        for i in 0..f - s {
            let block = interior.block(k * (f - s) + i, k).expect("block in the layout");
            assert!(block.iter().all(|x| x.finite()));
        }
    }

    // The vertex maps are inverse; the touchable vertices come first, ascending.
    let free = table.free_vertices();
    for (i, &v) in free.iter().enumerate() {
        assert!(matches!(table.slot(v), Some(VertexSlot::Free(f)) if f.get() == i));
        assert!(!table.is_fixed(v));
    }
    let fixed = (0..n as u32).filter(|&v| table.is_fixed(v)).count();
    assert_eq!(fixed + f, n);
    assert_eq!(table.slot(n as u32), None);
    assert!(!table.is_fixed(u32::MAX));
    assert!(free[..s].windows(2).all(|w| w[0] < w[1]));

    // Diagonal blocks exist, off-diagonal ones are transposes, out of range gives None.
    for k in 0..s as u32 {
        let c = table.touchable_block(k, k).expect("diagonal block");
        assert!((0..3).all(|i| c[(i, i)] > T::zero()), "C_kk not SPD: {c:?}");
    }
    if s >= 2 {
        let (a, b) = (0, s as u32 - 1);
        let (ab, ba) = (table.touchable_block(a, b), table.touchable_block(b, a));
        assert_eq!(ab.map(|m| m.transpose()), ba);
    }
    assert!(table.touchable_block(s as u32, 0).is_none());
    assert!(table.touchable_block(0, u32::MAX).is_none());

    // Surface triangles and the collision index.
    let triangles = table.surface_triangles();
    assert!(triangles.iter().flatten().all(|&v| (v as usize) < n));
    let index = table.surface_index();
    assert!(index.dims().iter().all(|&d| d > 0));
    assert!(index.cell_m() > T::zero());
    assert!(table.vertex(n as u32).is_none());
    for v in (0..n as u32).filter_map(|v| table.vertex(v)) {
        let around = index.triangles_of(v);
        assert!(around.len() <= index.max_valence() as usize);
        for t in around {
            let tri = triangles.get(t.get()).expect("triangle in range");
            assert!(tri.contains(&v.as_u32()));
        }
    }
    let origin = index.origin_m();
    let mut probes = vec![
        origin,
        origin.add_scalar(T::of_f64(1e30)),
        Vector3::repeat(T::of_f64(f64::NAN)),
        Vector3::repeat(T::of_f64(f64::NEG_INFINITY)),
    ];
    probes.extend(
        table
            .rest_positions()
            .iter()
            .take(4)
            .map(|p| Vector3::from(*p)),
    );
    for p in &probes {
        let cell = index.cell_of(p);
        assert!(cell.iter().zip(index.dims()).all(|(&c, d)| c < d));
        let _ = within(p, &index.reach(T::of_f64(1e-3)));
        let mut near = 0usize;
        for v in index.vertices_near(p) {
            assert!(v.get() < n);
            near += 1;
        }
        assert!(near <= 27 * index.max_bucket() as usize);
    }

    // The step path on the loaded table: contact forces, then displacements.
    let model = PrecomputedModel::new(*table);
    let d = Vector3::new(T::zero(), T::zero(), T::of_f64(-1e-3));
    let mut contacts = Vec::new();
    if let Some(&v) = free.first().filter(|_| s > 0) {
        contacts.push(Constraint::at_vertex(v, d));
    }
    if let Some(&tri) = triangles.first() {
        let third = T::of_f64(1.0 / 3.0);
        contacts.push(Constraint::on_triangle(tri, [third; 3], d));
    }
    for k in 0..=contacts.len() {
        solve(&model, &contacts[..k], f, n);
    }
    let out_of_range = Constraint::at_vertex(n as u32, d);
    assert!(model.contact_forces::<4>(&[out_of_range]).is_err());
}

fn solve<T: Real>(model: &PrecomputedModel<'_, T>, contacts: &[Constraint<T>], f: usize, n: usize) {
    let Ok(solution) = model.contact_forces::<4>(contacts) else {
        return;
    };
    assert_eq!(solution.len(), contacts.len());
    assert!(
        solution
            .contact_forces_n()
            .iter()
            .flatten()
            .all(|x| x.finite())
    );
    let _ = solution.device_force_n();
    let mut out = vec![[T::zero(); 3]; f];
    assert!(model.free_displacements(&solution, &mut out).is_ok());
    let mut out = vec![[T::zero(); 3]; n];
    assert!(model.displacements(&solution, &mut out).is_ok());
    let mut short = vec![[T::zero(); 3]; n.saturating_sub(1)];
    assert!(n == 0 || model.displacements(&solution, &mut short).is_err());
}
