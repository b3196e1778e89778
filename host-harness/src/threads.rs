//! The tensor-mass step's split force pass on several threads: a
//! [`Dispatch`] whose [`Dispatch::each`] runs the items of a split pass on
//! scoped threads (`std::thread::scope`), each inside the wrapped dispatch
//! (the CPU-feature level). The kernel cuts the pass so that the results
//! are the same bits for any thread count
//! ([`palpate_kernel::tensor_mass::SplitBuffers`]); a model without split
//! buffers, or one thread, runs the pass in one piece as before.
//!
//! Threads are started per pass (two scoped spawns per force evaluation)
//! rather than kept in a pool: no `unsafe`, nothing left running, at a
//! cost of some 10–30 µs per pass and thread that `palpate bench --scene`
//! shows in the physics update.

use palpate_kernel::Real;
use palpate_kernel::math::{Dispatch, MAX_PARTS};
use palpate_kernel::table::TensorMassTable;
use palpate_kernel::tensor_mass::{SplitBuffers, StateError, TensorMassModel};

/// The default thread count: 1. With threads started per pass, two threads
/// cost more than they save on a 13k-tet organ (St Venant-Kirchhoff per
/// tet, f32: 3.65 M instructions a step on one thread; 2.84 M on the
/// calling thread and 2.17 M on the other with two, docs/bench.md), so a
/// split pays only once a persistent pool replaces the per-pass spawns;
/// `--threads N` asks for it.
pub fn default_threads() -> usize {
    1
}

/// `dispatch`'s passes with the split ones on `threads` threads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Threaded<D> {
    dispatch: D,
    threads: usize,
}

impl<D: Dispatch> Threaded<D> {
    /// `dispatch` with the split passes cut into `threads` parts, clamped
    /// to `1..=`[`MAX_PARTS`] (1: not split).
    pub fn new(dispatch: D, threads: usize) -> Self {
        Self {
            dispatch,
            threads: threads.clamp(1, MAX_PARTS),
        }
    }

    /// The thread count.
    pub fn threads(&self) -> usize {
        self.threads
    }
}

impl<D: Dispatch + Send + Sync> Dispatch for Threaded<D> {
    #[inline(always)]
    fn run<R>(self, pass: impl FnOnce() -> R) -> R {
        self.dispatch.run(pass)
    }

    fn parts(self) -> usize {
        self.threads
    }

    /// The first item on this thread, every other on a scoped thread of
    /// its own; returns when all have returned.
    fn each<I: Send>(self, items: [Option<I>; MAX_PARTS], job: impl Fn(I) + Sync) {
        let mut items = items.into_iter().flatten();
        let Some(own) = items.next() else {
            return;
        };
        let (dispatch, job) = (self.dispatch, &job);
        std::thread::scope(|scope| {
            for item in items {
                scope.spawn(move || dispatch.run(|| job(item)));
            }
            dispatch.run(|| job(own));
        });
    }
}

/// Heap storage for a model's [`SplitBuffers`].
pub struct OwnedSplit<T> {
    corner_starts: Vec<u32>,
    corners: Vec<u32>,
    gradients: Vec<[T; 3]>,
}

impl<T: Real> OwnedSplit<T> {
    /// Buffers of the right lengths for `table`
    /// ([`SplitBuffers::lengths`]).
    pub fn for_table(table: &TensorMassTable<'_, T>) -> Self {
        let (starts, corners, gradients) = SplitBuffers::lengths(table);
        Self {
            corner_starts: vec![0; starts],
            corners: vec![0; corners],
            gradients: vec![[T::zero(); 3]; gradients],
        }
    }

    /// The buffers, borrowed.
    pub fn buffers(&mut self) -> SplitBuffers<'_, T> {
        SplitBuffers {
            corner_starts: &mut self.corner_starts,
            corners: &mut self.corners,
            gradients: &mut self.gradients,
        }
    }
}

/// `model` with its per-tet pass split on `split`'s buffers when more
/// than one thread runs it, unchanged otherwise (one thread runs the pass
/// in one piece, as a model without split buffers always does).
pub fn split_model<'a, 's, T: Real>(
    model: TensorMassModel<'a, 's, T>,
    split: &'s mut Option<OwnedSplit<T>>,
    threads: usize,
) -> Result<TensorMassModel<'a, 's, T>, StateError> {
    if threads <= 1 {
        return Ok(model);
    }
    let owned = split.insert(OwnedSplit::for_table(model.table()));
    model.with_split(owned.buffers())
}
