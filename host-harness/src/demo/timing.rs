//! What the demo measures of a model's steps: the wall time of each
//! haptic-rate step and of each physics update, and the frames written.

use core::time::Duration;

/// A model's step costs in one demo run.
#[derive(Clone, Debug, Default)]
pub struct Costs {
    /// Each haptic-rate step: the force path.
    pub ticks: Vec<Duration>,
    /// Each physics update: the deformation field (pre-computed) or the
    /// tensor-mass steps, cuts and coupling (hybrid).
    pub physics: Vec<Duration>,
    /// VTK frames written.
    pub frames: usize,
}

/// Mean and maximum of `samples`, µs (0 for none).
pub fn mean_max(samples: &[Duration]) -> (f64, f64) {
    let us = micros(samples);
    let mean = us.iter().sum::<f64>() / us.len().max(1) as f64;
    (mean, us.iter().copied().fold(0.0, f64::max))
}

/// Median and maximum (the worst) of `samples`, µs (0 for none); the
/// median of an even count is the upper of the middle two.
pub fn median_max(samples: &[Duration]) -> (f64, f64) {
    let mut us = micros(samples);
    us.sort_by(f64::total_cmp);
    let median = us.get(us.len() / 2).copied().unwrap_or(0.0);
    (median, us.last().copied().unwrap_or(0.0))
}

fn micros(samples: &[Duration]) -> Vec<f64> {
    samples.iter().map(|d| d.as_secs_f64() * 1e6).collect()
}
