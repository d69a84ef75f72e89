//! Temporal prediction of a trajectory of integer levels (one stored coefficient of a cluster's
//! affine map over the frames): the extrapolation orders the affine coder predicts with
//! (`stream/affine_coding.rs`), the reference cluster's innovation it may add, and the encoder's
//! estimate of the bits a trajectory costs, by which it picks each trajectory's [`Choice`] and
//! each cluster's [`super::LinearForm`].
//!
//! A trajectory's *innovation* at frame f is its level there less its own extrapolation: what its
//! past did not foretell. Clusters of one body share much of it (the body walks, turns or jumps
//! as a whole), so a trajectory may also add the innovation of the same coefficient of an earlier
//! coded cluster nearby, in its own units (container version 8), or, for a translation, the
//! innovation of that cluster's whole map at its own centroid (version 11: a turning thigh moves
//! the shin's centroid by the turn times the lever between them). The reference is any of the
//! [`REFERENCES`] nearest, and its innovation is taken at the follower's own order (version 14).

/// Predictor orders a trajectory may use (1..=ORDERS).
pub const ORDERS: usize = 3;

/// What a trajectory's prediction may add from its reference cluster.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Follow {
    /// Nothing: its own extrapolation alone.
    No = 0,
    /// The innovation of the reference's same coefficient, scaled to this trajectory's step.
    Coefficient = 1,
    /// Translations only: the innovation of the reference's whole map (linear part included) at
    /// this cluster's centroid.
    Map = 2,
}

/// Symbols of a translation's [`Choice`]: every order with every [`Follow`].
pub const CHOICES: usize = 3 * ORDERS;

/// Symbols of a linear coefficient's [`Choice`], which never follows a [`Follow::Map`].
pub const LINEAR_CHOICES: usize = 2 * ORDERS;

/// Earlier clusters a trajectory may follow: the nearest few (by centroid on the decoded frame 0),
/// nearest first; a following trajectory names its reference by this rank (container version 14).
pub const REFERENCES: usize = 4;

/// How a trajectory is predicted: its extrapolation order, and what it adds from which reference
/// cluster.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Choice {
    /// 1: the previous level, 2: linear, 3: quadratic extrapolation.
    pub order: usize,
    /// What the reference cluster adds.
    pub follows: Follow,
    /// Which of the nearest earlier clusters it follows (0: the nearest; 0 when not following).
    pub reference: usize,
}

impl Choice {
    /// The plain previous-level predictor.
    pub const FIRST: Choice = Choice {
        order: 1,
        follows: Follow::No,
        reference: 0,
    };

    /// The coded symbol of the order and what it follows, `0..CHOICES` (`0..LINEAR_CHOICES`
    /// unless it follows a map); the reference is coded apart.
    pub fn symbol(self) -> usize {
        (self.order.clamp(1, ORDERS) - 1) + ORDERS * self.follows as usize
    }

    /// The choice of symbol `s` (`s % CHOICES`), following the nearest reference if any: a
    /// following trajectory's rank is coded after its symbol.
    pub fn of_symbol(s: usize) -> Self {
        let s = s % CHOICES;
        Choice {
            order: 1 + s % ORDERS,
            follows: [Follow::No, Follow::Coefficient, Follow::Map][s / ORDERS],
            reference: 0,
        }
    }
}

/// One way a trajectory may follow a reference: what it adds at each frame, in this trajectory's
/// levels, when the reference's innovation is taken under `order` — the trajectory's own order, so
/// that what the two do not share is extrapolated as one smooth difference.
#[derive(Debug, Clone)]
pub struct Way {
    /// How it follows.
    pub follows: Follow,
    /// Rank of the reference among the nearest earlier clusters.
    pub reference: usize,
    /// The trajectory's order this lift was computed for.
    pub order: usize,
    /// What it adds at each frame.
    pub lift: Vec<i64>,
}

/// The level `order` predicts from `history` (most recent last; shorter histories lower the
/// order): 1 the previous level, 2 a linear, 3 a quadratic extrapolation.
pub fn extrapolate(order: usize, history: &[i64]) -> i64 {
    let n = history.len();
    let at = |back: usize| history[n - back];
    match order.min(n) {
        0 => 0,
        1 => at(1),
        2 => (2 * at(1)).wrapping_sub(at(2)),
        _ => (3 * at(1)).wrapping_sub(3 * at(2)).wrapping_add(at(3)),
    }
}

/// `innovation` (a reference trajectory's, in its step) in levels of a trajectory whose step is
/// `ratio` times smaller: rounded half away from zero, saturating; IEEE-exact, so the same on
/// every machine. Translations share one step (`ratio` 1): the innovation itself.
pub fn scaled(innovation: i64, ratio: f64) -> i64 {
    if ratio == 1.0 {
        innovation
    } else {
        (innovation as f64 * ratio).round() as i64
    }
}

/// Rough cost in bits of coding `residual`.
fn cost(residual: i64) -> f64 {
    2.0 * (1.0 + residual.unsigned_abs() as f64).log2() + 1.0
}

/// Estimated bits of `trajectory` (its first level aside) under predictor `order`, adding
/// `reference` (already in this trajectory's levels) at each frame when given.
fn bits_with(order: usize, trajectory: &[i64], reference: Option<&[i64]>) -> f64 {
    (1..trajectory.len())
        .map(|f| {
            let guess = extrapolate(order, &trajectory[f.saturating_sub(ORDERS)..f]);
            let lift = reference.and_then(|r| r.get(f)).copied().unwrap_or(0);
            cost(trajectory[f].wrapping_sub(guess.saturating_add(lift)))
        })
        .sum()
}

/// The order (1..=ORDERS) that codes `trajectory` smallest by the estimate, and its bits.
pub fn best_order(trajectory: &[i64]) -> (usize, f64) {
    let (choice, bits) = best_choice(trajectory, &[]);
    (choice.order, bits)
}

/// Estimated bits of naming a reference other than the nearest (a rough price for its symbol).
const FARTHER_REFERENCE_BITS: f64 = 2.0;

/// The [`Choice`] that codes `trajectory` smallest by the estimate, and its bits: its own
/// extrapolation at every order, or one of `ways` of following a reference (each at its own
/// order). Ties keep the lower order, and the earlier way (not following first).
pub fn best_choice(trajectory: &[i64], ways: &[Way]) -> (Choice, f64) {
    let mut best = (Choice::FIRST, f64::INFINITY);
    for order in 1..=ORDERS {
        let bits = bits_with(order, trajectory, None);
        if bits < best.1 {
            best = (
                Choice {
                    order,
                    ..Choice::FIRST
                },
                bits,
            );
        }
    }
    for way in ways {
        let price = if way.reference > 0 {
            FARTHER_REFERENCE_BITS
        } else {
            0.0
        };
        let bits = bits_with(way.order, trajectory, Some(&way.lift)) + price;
        if bits < best.1 {
            let choice = Choice {
                order: way.order,
                follows: way.follows,
                reference: way.reference,
            };
            best = (choice, bits);
        }
    }
    best
}

/// The innovation of `level` under `order` after `before`, the trajectory's earlier levels (the
/// last [`ORDERS`] are read): `level` less their extrapolation; 0 with nothing before (the first
/// frame, predicted by the identity).
pub fn innovation(order: usize, before: &[i64], level: i64) -> i64 {
    if before.is_empty() {
        return 0;
    }
    level.wrapping_sub(extrapolate(order, &before[before.len().saturating_sub(ORDERS)..]))
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

    #[test]
    fn a_trajectory_that_moves_as_its_reference_follows_it() {
        // A jerky common motion, and a trajectory that is that motion plus a steady drift.
        let common = [0i64, 5, 3, 11, 2, 9, 14, 1, 7];
        let own: Vec<i64> = common.iter().enumerate().map(|(f, c)| c + 2 * f as i64).collect();
        let reference: Vec<i64> = (0..common.len())
            .map(|f| innovation(1, &common[..f], common[f]))
            .collect();
        assert_eq!(reference[0], 0);
        assert_eq!(reference[3], 8);
        let way = |follows, lift: &[i64]| Way {
            follows,
            reference: 0,
            order: 1,
            lift: lift.to_vec(),
        };
        let (choice, bits) = best_choice(&own, &[way(Follow::Coefficient, &reference[..])]);
        assert_eq!(choice.follows, Follow::Coefficient, "{choice:?}");
        assert!(bits < best_choice(&own, &[]).1);
        // Without a reference, or one that does not help, it does not follow.
        assert_eq!(best_choice(&own, &[]).0.follows, Follow::No);
        let noise = [0, 9, -9, 9];
        let (still, _) = best_choice(&[4, 4, 4, 4], &[way(Follow::Coefficient, &noise)]);
        assert_eq!(still, Choice::FIRST);
        // Of two ways, the one that predicts; a farther reference when it predicts better.
        let worse = vec![1; own.len()];
        let both = [way(Follow::Coefficient, &worse[..]), way(Follow::Map, &reference[..])];
        assert_eq!(best_choice(&own, &both).0.follows, Follow::Map);
        let farther = Way {
            reference: 2,
            ..way(Follow::Coefficient, &reference[..])
        };
        let picked = best_choice(&own, &[way(Follow::Coefficient, &worse[..]), farther]).0;
        assert_eq!((picked.follows, picked.reference), (Follow::Coefficient, 2));
        for s in 0..CHOICES {
            assert_eq!(Choice::of_symbol(s).symbol(), s);
        }
        assert_eq!(Choice::of_symbol(4).reference, 0, "the rank is coded apart");
        assert_eq!(scaled(-7, 1.0), -7);
        assert_eq!(scaled(5, 0.5), 3);
        assert_eq!(scaled(-5, 0.5), -3);
        assert_eq!(scaled(i64::MAX, 4.0), i64::MAX);
    }
}
