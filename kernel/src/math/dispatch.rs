//! Where the step's hot loops run: a hook through which a host compiles
//! them for more of its CPU's instruction set than the build's baseline
//! (run-time CPU-feature dispatch), while the kernel's code stays the same
//! on every target.
//!
//! Each hot pass (the tensor-mass force passes and integrator updates, the
//! pre-computed model's displacement update) hands its loop to
//! [`Dispatch::run`] as a closure marked `#[inline(always)]`. The firmware,
//! the replays and every caller that does not ask otherwise use
//! [`Portable`], which calls the closure in place: the same machine code as
//! a direct loop. A host may implement [`Dispatch`] by calling the closure
//! from a function compiled for more features (`#[target_feature(enable =
//! "avx2,fma")]` on x86-64 after `is_x86_feature_detected!`); because the
//! closure is always inlined, its loop is then compiled for those features.
//! The kernel contains no target-specific code and no `unsafe`.
//!
//! Rust never contracts `a * b + c` into a fused multiply-add, so a pass
//! compiled for AVX2 and FMA does the same IEEE-754 operations in the same
//! order as the portable one (wider vectors, not other arithmetic): the
//! results are the same bits.

/// Most parts a split pass is cut into ([`Dispatch::parts`]): the length
/// of the item arrays of [`Dispatch::each`].
pub const MAX_PARTS: usize = 8;

/// Runs a hot pass of the step path (see the module documentation).
pub trait Dispatch: Copy {
    /// Calls `pass` once and returns its result. An implementation may only
    /// change where the code of `pass` is compiled for, never what it
    /// computes or how often it runs.
    fn run<R>(self, pass: impl FnOnce() -> R) -> R;

    /// How many parts a pass that can be split is cut into, `1..=`
    /// [`MAX_PARTS`] (a larger value counts as [`MAX_PARTS`]). 1, the
    /// default: no pass is split, and the kernel runs the passes as it
    /// always has.
    fn parts(self) -> usize {
        1
    }

    /// Calls `job` once on every item of `items`, each inside
    /// [`Self::run`], and returns when all have returned. The default calls
    /// them in order on this thread; a host may call them on several
    /// threads at once. Each item owns the data its job writes (disjoint
    /// parts of an array), so what is computed never depends on how the
    /// items are run.
    fn each<I: Send>(self, items: [Option<I>; MAX_PARTS], job: impl Fn(I) + Sync) {
        for item in items.into_iter().flatten() {
            self.run(
                #[inline(always)]
                || job(item),
            );
        }
    }
}

/// The build's own instruction set: `pass` is called in place.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Portable;

impl Dispatch for Portable {
    #[inline(always)]
    fn run<R>(self, pass: impl FnOnce() -> R) -> R {
        pass()
    }
}
