//! Where a budget search's next encode goes: a curve through the encodes so far, in the modelled
//! measure (the log of an error, or of a size's bytes beyond its fixed ones) against the log of
//! the target step — the prior's slope after one encode, then the secant of the last two (bent by
//! the codec's prior curvature where it has one), and inside a bracket that curve through its two
//! ends, the secant nearest the aim, or regula falsi (docs/design.md, "Budgets").

use crate::codec::{fine_scale_percent, ijg_scale_percent};

/// The log of the target step's scale at a quality: what the search's model is linear in.
pub(super) fn log_scale(quality: f64) -> f64 {
    fine_scale_percent(quality).ln()
}

/// The quality (rounded to hundredths, so that a report's figure codes the same stream) whose
/// log scale is `u`, within 1..=100.
pub(super) fn quality_of(u: f64) -> f64 {
    let scale = |q: u8| f64::from(ijg_scale_percent(q).max(1)).ln();
    let q = (1..100u8).find(|&q| scale(q + 1) <= u).unwrap_or(99);
    let (a, b) = (scale(q), scale(q + 1));
    let t = if a > b { (a - u) / (a - b) } else { 0.0 };
    let x = f64::from(q) + t.clamp(0.0, 1.0);
    ((x * 100.0).round() / 100.0).clamp(1.0, 100.0)
}

/// A codec's prior curvature of the modelled measure: its second derivative against the log
/// step over a range of log steps (JPEG's bytes flatten below quality 50 as its pictures near
/// their floor of block headers; AV1's error falls faster and faster above quality 50).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Bend {
    /// d² measure / d(log step)².
    pub curvature: f64,
    /// The log steps it holds between (lowest, highest).
    pub over: (f64, f64),
    /// Whether the search follows it from its first encode (the parabola of the prior's slope
    /// there), or from its second on, as JPEG's was fitted.
    pub from_first: bool,
}

impl Bend {
    /// The curvature between log steps `a` and `b`: the prior's when both lie in its range.
    fn between(bend: Option<Bend>, a: f64, b: f64) -> f64 {
        bend.filter(|k| a.min(b) >= k.over.0 && a.max(b) <= k.over.1)
            .map_or(0.0, |k| k.curvature)
    }

    /// From one encode `p`: where the parabola of this curvature with the `prior` slope at `p`
    /// meets `aim` (the root nearest `p` on the side the slope says), if the bend holds over the
    /// whole way there.
    fn first_step(self, p: (f64, f64), aim: f64, prior: f64) -> Option<f64> {
        let straight = (aim - p.1) / prior;
        let (a, b, c) = (0.5 * self.curvature, prior, p.1 - aim);
        let disc = b * b - 4.0 * a * c;
        // A curvature of 0 (roots of 0/0 and ±∞) or a parabola that never meets the aim (a
        // negative discriminant's NaN roots) has no bent step.
        let roots = [
            (-b + disc.sqrt()) / (2.0 * a),
            (-b - disc.sqrt()) / (2.0 * a),
        ];
        let d = (roots.into_iter())
            .filter(|d| d.is_finite() && d * straight > 0.0)
            .min_by(|x, y| x.abs().total_cmp(&y.abs()))?;
        (Bend::between(Some(self), p.0, p.0 + d) != 0.0).then_some(p.0 + d)
    }
}

/// Where the model puts the aim, from the encodes' (log scale, modelled measure) `points`
/// (`None` without one: nothing to model from). Inside a bracket (encodes on either side of the
/// aim): when it is the only two encodes and the prior `bend` applies, the curve of that
/// curvature through them; else the secant through the two encodes nearest the aim if it falls
/// well inside, else the secant through the bracket's ends, pulled towards the middle if it
/// would land at an end (regula falsi's fix). Without a bracket:
/// along the slope at the last encode of the curve through the last two (its slope kept within a
/// factor of 4 of the `prior`, and of its sign), or after one encode the prior's slope — bent
/// by the `bend` if it is followed from the first encode ([`Bend::from_first`]).
pub(super) fn next_log_scale(
    points: &[(f64, f64)],
    aim: f64,
    prior: f64,
    bend: Option<Bend>,
) -> Option<f64> {
    if let Some((below, above)) = bracket(points, aim) {
        let (lo, hi) = (below.0.min(above.0), below.0.max(above.0));
        let inside = |u: &f64| *u > lo + 0.02 * (hi - lo) && *u < hi - 0.02 * (hi - lo);
        let c = Bend::between(bend, lo, hi);
        if points.len() == 2 && c != 0.0 {
            if let Some(u) = bent_root(below, above, aim, c).filter(inside) {
                return Some(u);
            }
        }
        // A bracket's far end may lie where the curve bends (pdance AV1's error, quality 50
        // against 77), and regula falsi between its ends then lands off.
        if let Some(u) = nearest_secant(points, aim, prior).filter(inside) {
            return Some(u);
        }
        let t = ((aim - below.1) / (above.1 - below.1)).clamp(0.1, 0.9);
        return Some(below.0 + t * (above.0 - below.0));
    }
    let &last = points.last()?;
    let slope = match points.len() {
        n if n >= 2 => {
            let before = points[n - 2];
            let secant = (last.1 - before.1) / (last.0 - before.0);
            // The parabola of the prior curvature through both has this slope at the last.
            let c = Bend::between(bend, last.0, before.0);
            let s = secant + 0.5 * c * (last.0 - before.0);
            if s.is_finite() && s * prior > 0.0 {
                prior.signum() * s.abs().clamp(prior.abs() / 4.0, prior.abs() * 4.0)
            } else {
                prior
            }
        }
        _ => {
            let bent = bend.filter(|k| k.from_first);
            if let Some(u) = bent.and_then(|k| k.first_step(last, aim, prior)) {
                return Some(u);
            }
            prior
        }
    };
    Some(last.0 + (aim - last.1) / slope)
}

/// Whether the measure jumps across the aim: the two encodes next to each other in the step that
/// straddle it lie less than `JUMP_WIDTH` apart in log scale, yet the measure changes across them
/// more than `JUMP_FACTOR` times as fast as the `prior` slope says. No quality between them lands
/// then (chickenCrossing HEVC's vertex RMSE: 3.03e-4 at quality 73.49, 2.79e-4 at 73.52, the
/// budget 3e-4), and narrowing the bracket further only spends encodes.
pub(super) fn jumps(points: &[(f64, f64)], aim: f64, prior: f64) -> bool {
    bracket(points, aim).is_some_and(|(below, above)| {
        let width = (above.0 - below.0).abs();
        let rise = (above.1 - below.1).abs();
        width > 0.0 && width < JUMP_WIDTH && rise > JUMP_FACTOR * prior.abs() * width
    })
}

/// A bracket this narrow in log scale (about one quality point at 75, two at 50) that still jumps
/// ([`jumps`]) ends a search.
const JUMP_WIDTH: f64 = 0.04;
/// How many times the prior's slope the measure must change by across it.
const JUMP_FACTOR: f64 = 3.0;

/// Where `f`, of opposite signs at `lo` and `hi`, is zero (bisection to the last bits);
/// `None` without a change of sign.
fn root(f: impl Fn(f64) -> f64, lo: f64, hi: f64) -> Option<f64> {
    let (mut a, mut b) = (lo, hi);
    let fa = f(a);
    // NaN is no change of sign either.
    (fa * f(b) < 0.0).then_some(())?;
    for _ in 0..100 {
        let m = 0.5 * (a + b);
        if (f(m) < 0.0) == (fa < 0.0) {
            a = m;
        } else {
            b = m;
        }
    }
    Some(0.5 * (a + b))
}

/// Where the parabola of curvature `c` through `p` and `q` meets `aim` between them.
fn bent_root(p: (f64, f64), q: (f64, f64), aim: f64, c: f64) -> Option<f64> {
    let slope = (q.1 - p.1) / (q.0 - p.0);
    let (lo, hi) = (p.0.min(q.0), p.0.max(q.0));
    root(
        |u| p.1 + slope * (u - p.0) + 0.5 * c * (u - p.0) * (u - q.0) - aim,
        lo,
        hi,
    )
}

/// Where the secant through the two encodes whose modelled measures are nearest `aim` meets it;
/// `None` when the secant is flat, not finite, or slopes against the `prior`.
fn nearest_secant(points: &[(f64, f64)], aim: f64, prior: f64) -> Option<f64> {
    let mut by_distance = points.to_vec();
    by_distance.sort_by(|a, b| (a.1 - aim).abs().total_cmp(&(b.1 - aim).abs()));
    let (p, q) = (by_distance.first()?, by_distance.get(1)?);
    let slope = (q.1 - p.1) / (q.0 - p.0);
    let u = p.0 + (aim - p.1) / slope;
    (slope * prior > 0.0 && u.is_finite()).then_some(u)
}

/// Two encodes next to each other in log scale whose measures lie on either side of the aim
/// (below, above): of such pairs, the one with an end nearest the aim. Adjacent in the step,
/// not nearest in the measure, so that a measure that is not monotone (the largest vertex
/// error jumps from one quality to the next) still narrows the bracket at each encode.
fn bracket(points: &[(f64, f64)], aim: f64) -> Option<((f64, f64), (f64, f64))> {
    let mut sorted = points.to_vec();
    sorted.sort_by(|a, b| a.0.total_cmp(&b.0));
    sorted
        .windows(2)
        .filter(|w| (w[0].1 > aim) != (w[1].1 > aim))
        .map(|w| match w[0].1 > aim {
            true => (w[1], w[0]),
            false => (w[0], w[1]),
        })
        .min_by(|x, y| {
            let near =
                |p: &((f64, f64), (f64, f64))| (p.0 .1 - aim).abs().min((p.1 .1 - aim).abs());
            near(x).total_cmp(&near(y))
        })
}

/// The value at `u` of the piecewise-linear curve through `points` (x, y), in any order: linear
/// between the two points around `u`, the nearest end's value beyond them; `None` without points.
pub(super) fn interpolated(points: &[(f64, f64)], u: f64) -> Option<f64> {
    let mut sorted = points.to_vec();
    sorted.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (first, last) = (*sorted.first()?, *sorted.last()?);
    if u <= first.0 {
        return Some(first.1);
    }
    if u >= last.0 {
        return Some(last.1);
    }
    let w = sorted.windows(2).find(|w| w[0].0 <= u && u <= w[1].0)?;
    let span = w[1].0 - w[0].0;
    let t = if span > 0.0 { (u - w[0].0) / span } else { 0.0 };
    Some(w[0].1 + t * (w[1].1 - w[0].1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bracket_with_a_bent_far_end_is_searched_along_the_nearest_secant() {
        // pdance AV1's vertex RMSE against ln(IJG scale): quality 50 (scale 100), 86.22 and
        // 77.01; the aim (1.97e-4, mid-window under 2e-4) lies just above the last encode.
        let point = |scale: f64, rmse: f64| (scale.ln(), rmse.ln());
        let points = [
            point(100.0, 4.27e-4),
            point(27.56, 1.1825e-4),
            point(45.98, 1.9234e-4),
        ];
        let aim = 1.97e-4f64.ln();
        let u = next_log_scale(&points, aim, 1.0, None).unwrap_or(f64::NAN);
        // The secant through 77.01 and 86.22 (slope 0.95) puts it at scale 47.1 (quality 76.4,
        // which codes 1.97e-4); regula falsi's tenth towards quality 50 put it at 49.7 (75.15,
        // 2.10e-4: over the budget).
        assert!((u.exp() - 47.1).abs() < 0.3, "scale {}", u.exp());
        // Without a bracket: the secant of the last two encodes, then the prior alone.
        let u = next_log_scale(&points[..2], aim, 1.0, None).unwrap_or(f64::NAN);
        assert!(u.exp() > 27.56 && u.exp() < 100.0, "scale {}", u.exp());
        let u = next_log_scale(&points[..1], aim, 1.0, None).unwrap_or(f64::NAN);
        assert!((u - (100f64.ln() + aim - 4.27e-4f64.ln())).abs() < 1e-12);
        assert_eq!(
            next_log_scale(&[], aim, 1.0, None),
            None,
            "nothing to model from"
        );
    }

    #[test]
    fn a_bend_follows_jpegs_flattening_bytes() {
        // pdance JPEG (skinning, K 20), ln(bytes beyond the fixed ones) against ln(IJG scale):
        // quality 50 and 15 coded; quality 12 (ln scale 6.032) codes 11.198.
        let points = [(4.605, 12.772), (5.809, 11.282)];
        let jpeg = Some(Bend {
            curvature: 1.5,
            over: (4.605, f64::INFINITY),
            from_first: false,
        });
        let straight = next_log_scale(&points, 11.198, -1.3, None).unwrap_or(f64::NAN);
        let bent = next_log_scale(&points, 11.198, -1.3, jpeg).unwrap_or(f64::NAN);
        assert!((straight - 6.032).abs() > 0.1, "{straight}");
        assert!((bent - 6.032).abs() < 0.05, "{bent}");
        // Before the bend's start the curve is the straight one.
        let early = [(3.0, 14.0), (3.5, 13.4)];
        assert_eq!(
            next_log_scale(&early, 13.0, -1.3, jpeg),
            next_log_scale(&early, 13.0, -1.3, None)
        );
        // A bracket of two encodes: the bent curve through them, between them.
        let u = next_log_scale(&[(4.605, 12.772), (6.032, 11.198)], 11.282, -1.3, jpeg);
        let u = u.unwrap_or(f64::NAN);
        assert!(u > 5.7 && u < 6.032, "{u}");
    }

    #[test]
    fn av1_errors_bend_from_the_first_encode() {
        // horse-gallop AV1's vertex RMSE, ln against ln(IJG scale): quality 50 codes 5.926e-4;
        // 1.97e-4 (mid-window under 2e-4) lies near quality 78.4 (ln scale 3.77): the error
        // fell as the step to the power 1.3 on average, faster as the quality rose.
        let first = (100f64.ln(), 5.926e-4f64.ln());
        let aim = 1.97e-4f64.ln();
        let av1 = Bend {
            curvature: -1.0,
            over: (f64::NEG_INFINITY, 100f64.ln()),
            from_first: true,
        };
        let straight = next_log_scale(&[first], aim, 1.0, None).unwrap_or(f64::NAN);
        let bent = next_log_scale(&[first], aim, 1.0, Some(av1)).unwrap_or(f64::NAN);
        // The straight line overshoots to quality 83.0 (ln scale 3.50); the parabola stops short
        // of the aim's quality by less.
        assert!((straight - 3.504).abs() < 0.01, "{straight}");
        assert!(bent > 3.70 && bent < 3.90, "{bent}");
        // On the parabola of the prior slope at the first encode: the aim there.
        let d = bent - first.0;
        assert!((first.1 + d - 0.5 * d * d - aim).abs() < 1e-9);
        // A bend followed from the second encode only, or an aim outside its range (a coarser
        // step than the first encode's), leaves the first step straight.
        let later = Some(Bend {
            from_first: false,
            ..av1
        });
        assert_eq!(next_log_scale(&[first], aim, 1.0, later), Some(straight));
        let coarser = 8e-4f64.ln();
        assert_eq!(
            next_log_scale(&[first], coarser, 1.0, Some(av1)),
            next_log_scale(&[first], coarser, 1.0, None)
        );
    }

    #[test]
    fn a_measure_that_jumps_across_a_narrow_bracket_ends_the_search() {
        // chickenCrossing HEVC's vertex RMSE against ln(IJG scale), the budget 3e-4 (aim
        // 2.955e-4): qualities 50, 68.56, 72.38 and 73.7 coded; 72.87 codes 3.03e-4, and every
        // quality up to 73.49 stays over the budget, 73.52 under (2.79e-4).
        let point = |quality: f64, rmse: f64| {
            let scale = crate::codec::fine_scale_percent(quality);
            (scale.ln(), f64::ln(rmse))
        };
        let aim = 2.955e-4f64.ln();
        let mut points = vec![
            point(50.0, 5.402e-4),
            point(68.56, 3.371e-4),
            point(72.38, 3.064e-4),
            point(73.7, 2.775e-4),
        ];
        // 1.3 quality points apart: a steep stretch, not yet a jump.
        assert!(!jumps(&points, aim, 1.3));
        points.push(point(72.87, 3.032e-4));
        points.push(point(73.12, 3.049e-4));
        assert!(jumps(&points, aim, 1.3));
        // The same bracket with the measure changing as the prior says is searched on.
        let smooth = [point(73.12, 3.0e-4), point(73.7, 2.98e-4)];
        assert!(!jumps(&smooth, 2.99e-4f64.ln(), 1.3));
        assert!(!jumps(&points[..1], aim, 1.3), "no bracket");
    }

    #[test]
    fn fixed_bytes_between_encodes_are_interpolated_and_held_beyond() {
        // pdance AV1's fixed bytes at quality 50 (ln scale 4.605) and 29.53 (5.132).
        let known = [(5.132, 29_953.0), (4.605, 31_881.0)];
        let at = |u| interpolated(&known, u).unwrap_or(f64::NAN);
        assert!((at(5.044) - 30_275.0).abs() < 2.0, "{}", at(5.044));
        assert_eq!(at(6.0), 29_953.0);
        assert_eq!(at(4.0), 31_881.0);
        assert_eq!(interpolated(&[], 5.0), None);
    }
}
