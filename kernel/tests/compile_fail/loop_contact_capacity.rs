//! The haptic loop refuses a contact capacity `M` above its tool points `P`.

use palpate_kernel::PrecomputedTable;
use palpate_kernel::haptic::{LoopConfig, PrecomputedLoop, SafetyLimits};
use palpate_kernel::precomputed::PrecomputedTissue;

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
    let _ = PrecomputedLoop::<f32, 1, 2>::new(PrecomputedTissue::new(&table), config);
}
