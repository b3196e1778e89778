//! The kernel's hybrid model over heap buffers, for the harness's runs and
//! tests (firmware keeps the same buffers in static arrays).

use anyhow::{Context, anyhow};
use palpate_kernel::hybrid::{HybridBuffers, HybridModel};
use palpate_kernel::table::{InterfaceTable, TensorMassTable};
use palpate_kernel::tensor_mass::{DynamicParams, TensorMassModel};
use palpate_kernel::{PrecomputedTable, Real};

use super::build::HybridTables;
use crate::tensor_mass::OwnedState;

/// Loads `tables` in precision `T`, builds the hybrid model with `params`
/// for its tensor-mass region over heap buffers, and runs `run` on it.
pub fn with_hybrid<T: Real, R>(
    tables: &HybridTables,
    params: DynamicParams<T>,
    run: impl FnOnce(&mut HybridModel<'_, '_, T>) -> R,
) -> anyhow::Result<R> {
    let precomputed =
        PrecomputedTable::<T>::load(tables.precomputed.bytes()).context("pre-computed region")?;
    let dynamic =
        TensorMassTable::<T>::load(tables.dynamic.bytes()).context("tensor-mass region")?;
    let interface = InterfaceTable::<T>::load(tables.interface.bytes()).context("interface")?;
    let mut state = OwnedState::for_table(&dynamic);
    let mut passed = vec![[T::zero(); 3]; interface.connection_count()];
    let mut background = vec![[T::zero(); 3]; interface.free_count()];
    let model = TensorMassModel::new(dynamic, state.buffers(), params)
        .map_err(|e| anyhow!("tensor-mass region: {e}"))?;
    let buffers = HybridBuffers {
        passed_force_n: &mut passed,
        background_m: &mut background,
    };
    let mut hybrid = HybridModel::new(model, precomputed, interface, buffers)?;
    Ok(run(&mut hybrid))
}
