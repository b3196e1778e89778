//! The haptic loop refuses more than `MAX_CONTACTS` tool points `P`.

use palpate_kernel::haptic::{LoopConfig, PrecomputedLoop, SafetyLimits};
use palpate_kernel::precomputed::PrecomputedTissue;
use palpate_kernel::{MAX_CONTACTS, PrecomputedTable};

fn main() {
    let Ok(table) = PrecomputedTable::<f32>::load(&[]) else {
        return;
    };
    let config = LoopConfig {
        radius_m: 1e-3,
        dt_s: 1e-3,
        limits: SafetyLimits {
            max_force_n: 1.0,
            max_slew_n_per_s: 1.0,
        },
    };
    let tissue = PrecomputedTissue::new(&table);
    let _ = PrecomputedLoop::<f32, { MAX_CONTACTS + 1 }, MAX_CONTACTS>::new(tissue, config);
}
