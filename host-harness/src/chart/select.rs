//! The report's selections: the Pareto front of (cost, error) points and
//! the cheapest point within an error bound.

/// For each point `(cost, error)`, whether it is on the Pareto front: no
/// other point is at most as costly and at most as wrong and strictly
/// better in one. Points with a non-finite coordinate are never on it (and
/// dominate nothing). Ties (equal points) are all kept.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<bool> {
    let finite = |p: &(f64, f64)| p.0.is_finite() && p.1.is_finite();
    points
        .iter()
        .map(|p| {
            finite(p)
                && !points
                    .iter()
                    .any(|q| finite(q) && q.0 <= p.0 && q.1 <= p.1 && (q.0 < p.0 || q.1 < p.1))
        })
        .collect()
}

/// Index of the cheapest point whose error is at most `bound` (finite
/// points only); the first of equally cheap ones; `None` if none is within.
pub fn cheapest_within(points: &[(f64, f64)], bound: f64) -> Option<usize> {
    points
        .iter()
        .enumerate()
        .filter(|(_, p)| p.0.is_finite() && p.1.is_finite() && p.1 <= bound)
        .min_by(|a, b| a.1.0.total_cmp(&b.1.0))
        .map(|(i, _)| i)
}
