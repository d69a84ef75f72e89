//! Time: a channel's value at any time (step, linear, spherical-linear and cubic-spline
//! interpolation), the clip's keyframe rate, and the times at which frames are baked.

use super::channels::Channel;
use crate::error::Result;
use crate::limits::{check_bake, Bake};
use gltf::animation::{Interpolation, Property};
use nalgebra::{Quaternion, UnitQuaternion};
use std::path::Path;

/// Frame rate used when the clip's own keyframe rate cannot be told: the one glTF output falls
/// back on too.
const FALLBACK_FPS: f64 = crate::mesh::DEFAULT_FPS;
/// Estimated keyframe rates outside this range are not trusted (sparse or dense keys).
const PLAUSIBLE_FPS: std::ops::RangeInclusive<f64> = 10.0..=240.0;

/// The times of the baked frames: from the first key to the last at the frame rate, the last
/// clamped to the clip's end.
pub(super) struct FrameTimes {
    start: f64,
    end: f64,
    rate: f64,
    next: usize,
    count: usize,
}

impl FrameTimes {
    /// The frames of the clip at `fps` (default: its keyframe rate if plausible, else 30); an error
    /// when frames of `vertex_count` positions would be more than `max_positions` (`path` names the
    /// file).
    pub(super) fn new(
        channels: &[Channel],
        fps: Option<f64>,
        vertex_count: usize,
        max_positions: u64,
        path: &Path,
    ) -> Result<Self> {
        let (start, end) = channels
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(s, e), c| {
                let first = c.times.first().copied().unwrap_or(0.0) as f64;
                let last = c.times.last().copied().unwrap_or(0.0) as f64;
                (s.min(first), e.max(last))
            });
        let rate = fps.unwrap_or_else(|| keyframe_rate(channels).unwrap_or(FALLBACK_FPS));
        let count = ((end - start).max(0.0) * rate + 1e-6).floor() + 1.0;
        let bake = Bake {
            file: &path.display().to_string(),
            seconds: end - start,
            rate,
            frames: count,
            vertices: vertex_count,
        };
        check_bake(&bake, max_positions)?;
        Ok(Self {
            start,
            end,
            rate,
            next: 0,
            count: count as usize,
        })
    }
}

impl FrameTimes {
    /// The frame rate the frames are baked at.
    pub(super) fn rate(&self) -> f64 {
        self.rate
    }

    /// Seconds from the first key to the last.
    pub(super) fn seconds(&self) -> f64 {
        self.end - self.start
    }

    /// How many frames the clip bakes to.
    pub(super) fn frame_count(&self) -> usize {
        self.count
    }
}

impl Iterator for FrameTimes {
    type Item = f64;

    fn next(&mut self) -> Option<f64> {
        if self.next >= self.count {
            return None;
        }
        let time = (self.start + self.next as f64 / self.rate).min(self.end);
        self.next += 1;
        Some(time)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = self.count - self.next;
        (left, Some(left))
    }
}

/// The clip's keyframe rate: 1 / the median step between distinct key times, rounded to a whole
/// rate when within 0.1 % of one (key times are stored rounded); `None` when there are too few keys
/// or the rate is implausible for keys to interpolate between (sparse poses, dense keys). Keys
/// that all STEP hold nothing between them: they are the frames (a baked animation, as glTF
/// output writes it), trusted at any rate, so that a clip baked at 5 fps reads back at 5 fps.
fn keyframe_rate(channels: &[Channel]) -> Option<f64> {
    let mut times: Vec<f64> = channels
        .iter()
        .flat_map(|c| c.times.iter().map(|&t| t as f64))
        .collect();
    times.sort_by(f64::total_cmp);
    times.dedup_by(|a, b| (*a - *b).abs() < 1e-4);
    let mut steps: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
    if steps.len() < 2 {
        return None;
    }
    steps.sort_by(f64::total_cmp);
    let rate = 1.0 / steps[steps.len() / 2];
    let rate = if (rate - rate.round()).abs() < 0.001 * rate {
        rate.round()
    } else {
        rate
    };
    let stepped = channels
        .iter()
        .all(|c| c.interpolation == Interpolation::Step);
    (rate.is_finite() && (stepped || PLAUSIBLE_FPS.contains(&rate))).then_some(rate)
}

impl Channel {
    /// The (interpolated) value at `time`, clamped to the first and last keys.
    pub(super) fn sample(&self, time: f64) -> Vec<f64> {
        let last = self.times.len() - 1;
        // STEP keys are compared at f32, the precision key times are stored in: a sample at a key's
        // time (f / fps computed in f64) shows that key even when the stored time rounded up.
        let next = match self.interpolation {
            Interpolation::Step => self.times.partition_point(|&t| t <= time as f32),
            _ => self.times.partition_point(|&t| (t as f64) <= time),
        };
        if next == 0 {
            return self.key_value(0);
        }
        if next > last {
            return self.key_value(last);
        }
        let k = next - 1;
        let (t0, t1) = (self.times[k] as f64, self.times[next] as f64);
        let dt = t1 - t0;
        let s = if dt > 0.0 { (time - t0) / dt } else { 0.0 };
        let mut out = match self.interpolation {
            Interpolation::Step => return self.key_value(k),
            Interpolation::Linear if self.property == Property::Rotation => {
                return slerp(&self.key_value(k), &self.key_value(next), s);
            }
            Interpolation::Linear => {
                let (a, b) = (self.key_value(k), self.key_value(next));
                a.iter()
                    .zip(&b)
                    .map(|(a, b)| a + (b - a) * s)
                    .collect::<Vec<f64>>()
            }
            Interpolation::CubicSpline => self.hermite(k, next, s, dt),
        };
        if self.property == Property::Rotation {
            normalize(&mut out);
        }
        out
    }

    /// Key `k`'s value (the middle of the three cubic-spline entries).
    fn key_value(&self, k: usize) -> Vec<f64> {
        let w = self.width;
        let cubic = self.interpolation == Interpolation::CubicSpline;
        let at = if cubic { (3 * k + 1) * w } else { k * w };
        self.values[at..at + w].iter().map(|&v| v as f64).collect()
    }

    /// The cubic Hermite spline between keys `k` and `next`, `dt` seconds apart, at fraction `s`.
    fn hermite(&self, k: usize, next: usize, s: f64, dt: f64) -> Vec<f64> {
        let w = self.width;
        let part =
            |key: usize, which: usize, i: usize| self.values[(3 * key + which) * w + i] as f64;
        let (s2, s3) = (s * s, s * s * s);
        (0..w)
            .map(|i| {
                (2.0 * s3 - 3.0 * s2 + 1.0) * part(k, 1, i)
                    + (s3 - 2.0 * s2 + s) * dt * part(k, 2, i)
                    + (-2.0 * s3 + 3.0 * s2) * part(next, 1, i)
                    + (s3 - s2) * dt * part(next, 0, i)
            })
            .collect()
    }
}

/// Spherical interpolation of two `[x, y, z, w]` quaternions along the shorter arc.
fn slerp(a: &[f64], b: &[f64], s: f64) -> Vec<f64> {
    let q = |v: &[f64]| UnitQuaternion::new_normalize(Quaternion::new(v[3], v[0], v[1], v[2]));
    let (qa, mut qb) = (q(a), q(b));
    if qa.coords.dot(&qb.coords) < 0.0 {
        qb = UnitQuaternion::new_unchecked(-qb.into_inner());
    }
    let r = qa.try_slerp(&qb, s, 1e-9).unwrap_or_else(|| {
        UnitQuaternion::new_normalize(qa.into_inner().lerp(&qb.into_inner(), s))
    });
    vec![r.i, r.j, r.k, r.w]
}

fn normalize(v: &mut [f64]) {
    let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    if n > 0.0 {
        v.iter_mut().for_each(|x| *x /= n);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn channel(
        property: Property,
        interpolation: Interpolation,
        times: &[f32],
        values: &[f32],
        width: usize,
    ) -> Channel {
        Channel {
            node: 0,
            property,
            interpolation,
            times: times.to_vec(),
            values: values.to_vec(),
            width,
        }
    }

    #[test]
    fn step_linear_and_cubic_sampling() {
        let step = channel(
            Property::Translation,
            Interpolation::Step,
            &[0.0, 1.0],
            &[0., 0., 0., 2., 4., 6.],
            3,
        );
        assert_eq!(step.sample(0.99), vec![0.0; 3]);
        assert_eq!(step.sample(1.0), vec![2.0, 4.0, 6.0]);
        let linear = channel(
            Property::Translation,
            Interpolation::Linear,
            &[1.0, 2.0],
            &[0., 0., 0., 2., 4., 6.],
            3,
        );
        assert_eq!(
            linear.sample(0.0),
            vec![0.0; 3],
            "clamped before the first key"
        );
        assert_eq!(linear.sample(1.25), vec![0.5, 1.0, 1.5]);
        assert_eq!(
            linear.sample(9.0),
            vec![2.0, 4.0, 6.0],
            "clamped after the last key"
        );
        // Tangents chosen so the Hermite curve is the straight line v = 3t (tangent 3 per second).
        let cubic = channel(
            Property::MorphTargetWeights,
            Interpolation::CubicSpline,
            &[0.0, 2.0],
            &[3.0, 0.0, 3.0, 3.0, 6.0, 3.0],
            1,
        );
        for t in [0.0, 0.5, 1.0, 1.7, 2.0] {
            assert!((cubic.sample(t)[0] - 3.0 * t).abs() < 1e-9, "t = {t}");
        }
    }

    #[test]
    fn rotations_take_the_short_way() {
        let h = std::f32::consts::FRAC_1_SQRT_2;
        // Identity, then a quarter turn about z written with a negated (equivalent) quaternion.
        let rotation = channel(
            Property::Rotation,
            Interpolation::Linear,
            &[0.0, 1.0],
            &[0., 0., 0., 1., 0., 0., -h, -h],
            4,
        );
        let half = rotation.sample(0.5);
        let expected = [
            0.0,
            0.0,
            (std::f64::consts::PI / 8.0).sin(),
            (std::f64::consts::PI / 8.0).cos(),
        ];
        let same = half.iter().zip(expected).all(|(a, b)| (a - b).abs() < 1e-6);
        let opposite = half.iter().zip(expected).all(|(a, b)| (a + b).abs() < 1e-6);
        assert!(same || opposite, "{half:?}");
    }
}
