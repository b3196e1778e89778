//! What one model's static run measures ([`Outcome`]) and how a step is
//! timed ([`median_s`]).

use crate::bench::measure::{Sampling, time};

/// How a run's time per step is measured ([`crate::bench::measure`], the
/// library of `palpate bench`): one warm-up and 7 kept samples of 2 ms,
/// the median reported. Short, as the matrix times some 300 steps; the
/// spread is `palpate bench`'s to show.
const STEP_SAMPLING: Sampling = Sampling {
    warmup: 1,
    samples: 7,
    sample_s: 2e-3,
};

/// What a model's run gives.
pub(super) struct Outcome {
    /// Displacement of every vertex at the equilibrium, m.
    pub(super) u: Vec<[f64; 3]>,
    /// `None`, or why the run has no equilibrium.
    pub(super) fault: Option<String>,
    /// Median time of one f64 step, s.
    pub(super) step_s: f64,
    /// The same in f32, s (`None` when not measured).
    pub(super) step_f32_s: Option<f64>,
    /// Steps to reach the equilibrium (1 for the pre-computed models).
    pub(super) steps: usize,
}

/// Median time of one call of `call`, s, sampled as [`STEP_SAMPLING`].
pub(crate) fn median_s(call: impl FnMut()) -> f64 {
    time(&STEP_SAMPLING, call).median_s
}
