//! `PrecomputedTissue<_, M>` refuses `M > MAX_CONTACTS`.

use palpate_kernel::precomputed::PrecomputedTissue;
use palpate_kernel::{MAX_CONTACTS, PrecomputedTable};

fn main() {
    let Ok(table) = PrecomputedTable::<f32>::load(&[]) else {
        return;
    };
    let _ = PrecomputedTissue::<f32, { MAX_CONTACTS + 1 }>::new(&table);
}
