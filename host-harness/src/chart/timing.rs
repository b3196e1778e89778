//! The chart's own time-per-step measurement: warm-up, then the median of
//! repeated samples. Kept alone so it can be replaced by the shared timing
//! library of `palpate bench` when that lands.

use std::time::Instant;

/// Calls of `f` in warm-up before sampling.
const WARM_UP_CALLS: usize = 3;
/// Samples (the median is reported).
const SAMPLES: usize = 7;
/// Each sample repeats `f` until it lasts at least this long, s.
const MIN_SAMPLE_S: f64 = 2e-3;
/// Repetitions per sample at most.
const MAX_REPEATS: usize = 100_000;

/// Median time of one call of `f`, s: after [`WARM_UP_CALLS`] calls, the
/// repetition count is doubled until a sample lasts [`MIN_SAMPLE_S`], then
/// [`SAMPLES`] samples are taken and their median per-call time returned.
pub fn median_time_s(mut f: impl FnMut()) -> f64 {
    for _ in 0..WARM_UP_CALLS {
        f();
    }
    let sample = |f: &mut dyn FnMut(), repeats: usize| {
        let start = Instant::now();
        for _ in 0..repeats {
            f();
        }
        start.elapsed().as_secs_f64()
    };
    let mut repeats = 1;
    while repeats < MAX_REPEATS && sample(&mut f, repeats) < MIN_SAMPLE_S {
        repeats *= 2;
    }
    let mut times: Vec<f64> = (0..SAMPLES)
        .map(|_| sample(&mut f, repeats) / repeats as f64)
        .collect();
    times.sort_by(f64::total_cmp);
    times[SAMPLES / 2]
}
