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

#[cfg(test)]
mod tests {
    use super::*;

    /// Hand-made points: (1, 0.5) and (2, 0.1) and (4, 0.01) are each
    /// best at their cost; (3, 0.2) is dominated by (2, 0.1); (5, 0.01)
    /// by (4, 0.01) (costlier, no better); (0.5, NaN) has no error and is
    /// off the front without dominating anything; the duplicate of (2, 0.1)
    /// stays on it.
    #[test]
    fn pareto_front_of_hand_made_points() {
        let points = [
            (1.0, 0.5),
            (3.0, 0.2),
            (2.0, 0.1),
            (4.0, 0.01),
            (5.0, 0.01),
            (0.5, f64::NAN),
            (2.0, 0.1),
        ];
        assert_eq!(
            pareto_front(&points),
            [true, false, true, true, false, false, true]
        );
    }

    /// Within 20 %: (1, 0.15) is cheapest; within 5 %: (2, 0.04) beats the
    /// costlier (4, 0.001); within 0.05 %: none; the bound is inclusive;
    /// equal costs give the first.
    #[test]
    fn cheapest_within_bounds() {
        let points = [(4.0, 0.001), (1.0, 0.15), (2.0, 0.04), (2.0, 0.03)];
        assert_eq!(cheapest_within(&points, 0.20), Some(1));
        assert_eq!(cheapest_within(&points, 0.05), Some(2));
        assert_eq!(cheapest_within(&points, 0.15), Some(1));
        assert_eq!(cheapest_within(&points, 0.002), Some(0));
        assert_eq!(cheapest_within(&points, 0.0005), None);
        assert_eq!(cheapest_within(&[(1.0, f64::NAN)], 1.0), None);
    }
}
