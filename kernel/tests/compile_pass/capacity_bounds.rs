//! Every compile-time capacity check accepts both ends of its range:
//! `contact_forces::<M>` for `M` in `1..=MAX_CONTACT_CAPACITY`,
//! `PrecomputedTissue<_, M>` for `M` in `1..=MAX_CONTACTS`, and the haptic
//! loop for `P` in `1..=MAX_CONTACTS`, `M` in `1..=P`.

use palpate_kernel::haptic::{LoopConfig, PrecomputedLoop, SafetyLimits};
use palpate_kernel::precomputed::PrecomputedTissue;
use palpate_kernel::{
    Constraint, MAX_CONTACT_CAPACITY, MAX_CONTACTS, PrecomputedModel, PrecomputedTable,
};

fn main() {
    // An empty buffer is no table: what follows is compiled (so each
    // capacity check is instantiated) but never runs.
    let Ok(table) = PrecomputedTable::<f32>::load(&[]) else {
        return;
    };
    let model = PrecomputedModel::new(table);
    let none: [Constraint<f32>; 0] = [];
    let _ = model.contact_forces::<1>(&none);
    let _ = model.contact_forces::<MAX_CONTACT_CAPACITY>(&none);
    let config = LoopConfig {
        radius_m: 1e-3,
        dt_s: 1e-3,
        limits: SafetyLimits {
            max_force_n: 1.0,
            max_slew_n_per_s: 1.0,
        },
    };
    let _ = PrecomputedLoop::<f32, 1, 1>::new(PrecomputedTissue::new(&table), config);
    let _ = PrecomputedLoop::<f32, MAX_CONTACTS, MAX_CONTACTS>::new(
        PrecomputedTissue::new(&table),
        config,
    );
}
