//! `PrecomputedModel::contact_forces::<M>` refuses `M = 0` and
//! `M > MAX_CONTACT_CAPACITY` (its `3M × 3M` system lives on the stack).

use palpate_kernel::{Constraint, MAX_CONTACT_CAPACITY, PrecomputedModel, PrecomputedTable};

fn main() {
    let Ok(table) = PrecomputedTable::<f32>::load(&[]) else {
        return;
    };
    let model = PrecomputedModel::new(table);
    let none: [Constraint<f32>; 0] = [];
    let _ = model.contact_forces::<0>(&none);
    let _ = model.contact_forces::<{ MAX_CONTACT_CAPACITY + 1 }>(&none);
}
