//! Temporal prediction of a trajectory of integer levels (one stored coefficient of a cluster's
//! affine map over the frames): the extrapolation orders the affine coder predicts with
//! (`stream/affine_coding.rs`), and the encoder's estimate of the bits a trajectory costs, by
//! which it picks each trajectory's order and each cluster's [`super::LinearForm`].

/// Predictor orders a trajectory may use (1..=ORDERS).
pub const ORDERS: usize = 3;

/// The level `order` predicts from `history` (most recent last; shorter histories lower the
/// order): 1 the previous level, 2 a linear, 3 a quadratic extrapolation.
pub fn extrapolate(order: usize, history: &[i64]) -> i64 {
    let n = history.len();
    let at = |back: usize| history[n - back];
    match order.min(n) {
        0 => 0,
        1 => at(1),
        2 => 2 * at(1) - at(2),
        _ => 3 * at(1) - 3 * at(2) + at(3),
    }
}

/// Rough cost in bits of coding `residual`.
fn cost(residual: i64) -> f64 {
    2.0 * (1.0 + residual.unsigned_abs() as f64).log2() + 1.0
}

/// Estimated bits of `trajectory` (its first level aside) under predictor `order`.
fn bits_with(order: usize, trajectory: &[i64]) -> f64 {
    (1..trajectory.len())
        .map(|f| cost(trajectory[f].wrapping_sub(extrapolate(order, &trajectory[..f]))))
        .sum()
}

/// The order (1..=ORDERS) that codes `trajectory` smallest by the estimate, and its bits.
pub fn best_order(trajectory: &[i64]) -> (usize, f64) {
    (1..=ORDERS)
        .map(|order| (order, bits_with(order, trajectory)))
        .fold((1, f64::INFINITY), |best, c| if c.1 < best.1 { c } else { best })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extrapolation_follows_polynomials() {
        let line = [3, 5, 7, 9];
        assert_eq!(extrapolate(2, &line), 11);
        assert_eq!(extrapolate(1, &line), 9);
        let square = [0, 1, 4, 9];
        assert_eq!(extrapolate(3, &square), 16);
        // What the coder passes: the last three levels at most.
        assert_eq!(extrapolate(3, &square[1..]), 16);
        assert_eq!(extrapolate(3, &square[..1]), 0);
        assert_eq!(best_order(&[0, 1, 4, 9, 16, 25, 36]).0, 3);
        assert_eq!(best_order(&[4, 4, 4, 4]), (1, 3.0));
    }
}
