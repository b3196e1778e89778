//! Wall-clock timing of one call: calibrated batches, warm-up, repeated
//! samples, median and spread; and the memory-copy roofline a pass is
//! compared with.

use core::hint::black_box;
use std::time::Instant;

use serde::Serialize;

/// How a call is timed: `warmup` samples discarded, then `samples` samples,
/// each a batch of calls lasting about `sample_s` (the batch size is
/// calibrated once per call, doubling from one call).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sampling {
    /// Samples run and discarded first (caches, branch predictors, CPU
    /// frequency), ≥ 0.
    pub warmup: usize,
    /// Samples kept, ≥ 1.
    pub samples: usize,
    /// Target duration of one sample, s (a call longer than that makes a
    /// sample of one call).
    pub sample_s: f64,
}

impl Default for Sampling {
    /// 3 warm-up and 21 kept samples of 10 ms: about 0.25 s per
    /// measurement of a fast call.
    fn default() -> Self {
        Self {
            warmup: 3,
            samples: 21,
            sample_s: 0.01,
        }
    }
}

/// Largest batch of one sample: a call of 1 ns fills a 10 ms sample with
/// 10⁷ calls; beyond this the loop overhead, not the call, is timed.
const MAX_BATCH: u64 = 1 << 24;

/// Time per call over the kept samples, s: median, extremes and quartiles
/// (nearest rank), and how they were sampled.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Timing {
    /// Median time per call, s.
    pub median_s: f64,
    /// Fastest sample's time per call, s.
    pub min_s: f64,
    /// Slowest sample's time per call, s.
    pub max_s: f64,
    /// First quartile, s.
    pub q1_s: f64,
    /// Third quartile, s.
    pub q3_s: f64,
    /// Samples kept.
    pub samples: usize,
    /// Calls per sample.
    pub iterations: u64,
}

/// Times `call` as `sampling` says. `call` must do the same work each time
/// (its result is passed through [`black_box`] by the caller as needed).
pub fn time(sampling: &Sampling, mut call: impl FnMut()) -> Timing {
    let batch = |n: u64, call: &mut dyn FnMut()| {
        let start = Instant::now();
        for _ in 0..n {
            call();
        }
        start.elapsed().as_secs_f64()
    };
    // Calibrate: double the batch until it lasts half a sample.
    let mut iterations = 1;
    let mut elapsed = batch(iterations, &mut call);
    while elapsed < sampling.sample_s / 2.0 && iterations < MAX_BATCH {
        iterations *= 2;
        elapsed = batch(iterations, &mut call);
    }
    let per_call = elapsed / iterations as f64;
    if per_call > 0.0 {
        let fit = (sampling.sample_s / per_call).round() as u64;
        iterations = fit.clamp(1, MAX_BATCH);
    }
    for _ in 0..sampling.warmup {
        batch(iterations, &mut call);
    }
    let mut times: Vec<f64> = (0..sampling.samples.max(1))
        .map(|_| batch(iterations, &mut call) / iterations as f64)
        .collect();
    times.sort_by(f64::total_cmp);
    let rank = |p: f64| times[((times.len() - 1) as f64 * p).round() as usize];
    Timing {
        median_s: rank(0.5),
        min_s: rank(0.0),
        max_s: rank(1.0),
        q1_s: rank(0.25),
        q3_s: rank(0.75),
        samples: times.len(),
        iterations,
    }
}

/// The roofline of a pass that reads `bytes` bytes: one `copy_from_slice`
/// of that many bytes between two buffers allocated here (the same
/// convention as the criterion benches, `benches/benches/*.rs`), timed as
/// `sampling` says.
pub fn time_copy(bytes: usize, sampling: &Sampling) -> Timing {
    let source = vec![1u8; bytes];
    let mut target = vec![0u8; bytes];
    time(sampling, || {
        target.copy_from_slice(black_box(&source));
        black_box(&mut target);
    })
}

/// The wall time of one measurement of a call lasting `call_s` (s), for
/// the run's estimate: calibration (at most one sample and the calls
/// doubling up to it), warm-up and kept samples, each at least one call.
pub fn estimated_seconds(sampling: &Sampling, call_s: f64) -> f64 {
    let sample = sampling.sample_s.max(call_s);
    let calibration = sampling.sample_s + 2.0 * call_s;
    calibration + (sampling.warmup + sampling.samples.max(1)) as f64 * sample
}
