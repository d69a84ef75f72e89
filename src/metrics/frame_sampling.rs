//! Surface RMSE of a run of frames from a sample of them, refined until it has converged.
//!
//! Measuring a frame in full costs an exact nearest-surface query per sample (a grid built per
//! frame, some twenty boxes and two exact distances per query); bounding it costs a distance or
//! two per sample, to the faces on the same vertices as the one or two faces the sample lies on.
//! That bound follows the measured RMS from frame to frame (measured / bound 0.94 on
//! chickenCrossing's tdct stream, 1.5 % spread), so one frame in eight measured in full, at a
//! pseudo-random place in each block of eight, scales the bounds of the others (see [`estimate`]).
//! While the estimate's standard error exceeds the tolerance, one frame in four, in two, then
//! every frame, is measured. The Hausdorff distance stays exact: a bounded frame measures every
//! sample whose bound exceeds the largest distance found.

/// Which frames of a comparison have their surface distances measured in full.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FrameSampling {
    /// Every frame: the RMSE to the last bit.
    Every,
    /// One frame in eight (one per block of eight frames of the animation), then in four, in
    /// two, then every frame, until the estimated RMSE's standard error is at most
    /// `relative_error` of it; the others are bounded only and their RMS estimated. Runs of
    /// fewer than 32 frames, and surfaces whose faces do not all pair up, are measured in full.
    Converged {
        /// Largest standard error accepted, as a fraction of the estimated RMSE.
        relative_error: f64,
    },
}

/// The tolerance `eval` uses: a standard error of 0.2 % leaves 1 % at five standard errors.
pub const DEFAULT_RELATIVE_ERROR: f64 = 0.002;

/// Runs shorter than this are measured in full: too few sampled frames for a standard error.
pub const MIN_SAMPLED_RUN: usize = 32;

/// The sample's strides, coarsest first: one frame in every block of `stride` frames.
pub const STRIDES: [usize; 4] = [8, 4, 2, 1];

/// The frames of a run (numbers `first..first + n` in the animation, given as indexes into the
/// run) sampled at `stride`: in each block of `stride` frames, the one of lowest [`rank`]. A
/// frame sampled at one stride stays sampled at the finer ones, and its place within the block
/// varies from block to block, so that a period in the error (a group of pictures, a walk cycle)
/// cannot line up with the sample as it could with every `stride`-th frame.
pub fn sampled_at(stride: usize, first: usize, n: usize) -> Vec<usize> {
    let stride = stride.max(1);
    let mut chosen: Vec<usize> = Vec::new();
    let mut block = None;
    for i in 0..n {
        let b = (first + i) / stride;
        match chosen.last_mut() {
            Some(c) if block == Some(b) => {
                if rank(first + i) < rank(first + *c) {
                    *c = i;
                }
            }
            _ => {
                chosen.push(i);
                block = Some(b);
            }
        }
    }
    chosen
}

/// A fixed pseudo-random order of frame numbers (SplitMix64's finaliser): the same frames are
/// sampled on every run and machine.
fn rank(frame: usize) -> u64 {
    let mut z = (frame as u64).wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// One frame of a run: measured in full, or bounded only.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameValue {
    /// The frame's symmetric RMS, when measured in full.
    pub measured: Option<f64>,
    /// Its bound (see `surface::FrameBound::bound_rms`).
    pub bound: f64,
}

/// Each frame's RMS, measured or estimated, and the standard error of their sum as a fraction
/// of it (0 when every frame is measured; infinite when the sample cannot tell).
///
/// A frame not measured gets its bound times the ratio measured / bound interpolated between the
/// nearest measured frames on either side (the ratio drifts over a clip: chickenCrossing's JPEG
/// stream from 0.80 to 0.91; one ratio for the whole clip was 1.2 % off). The error comes from
/// predicting each measured frame's ratio from its measured neighbours (leave one out, over twice
/// the gap an estimate spans), and counts the frames of one gap as erring together.
pub fn estimate(frames: &[FrameValue]) -> (Vec<f64>, f64) {
    // (frame, ratio) of the measured frames with a bound to scale.
    let known: Vec<(usize, f64)> = frames
        .iter()
        .enumerate()
        .filter_map(|(i, f)| match f.measured {
            Some(m) if f.bound > 0.0 => Some((i, m / f.bound)),
            _ => None,
        })
        .collect();
    let ratio_at = |i: usize| -> f64 {
        let after = known.partition_point(|&(k, _)| k < i);
        match (
            after.checked_sub(1).and_then(|b| known.get(b)),
            known.get(after),
        ) {
            (Some(&a), Some(&b)) if b.0 > a.0 => between(a, b, i),
            (Some(&(_, r)), _) | (None, Some(&(_, r))) => r,
            (None, None) => 0.0,
        }
    };
    let values: Vec<f64> = frames
        .iter()
        .enumerate()
        .map(|(i, f)| f.measured.unwrap_or_else(|| ratio_at(i) * f.bound))
        .collect();
    let total: f64 = values.iter().sum();
    // Bounds of the frames left unmeasured, summed per gap between measured frames.
    let mut gaps: Vec<f64> = vec![0.0];
    for f in frames {
        match f.measured {
            Some(_) if f.bound > 0.0 => gaps.push(0.0),
            Some(_) => {}
            None => {
                if let Some(g) = gaps.last_mut() {
                    *g += f.bound;
                }
            }
        }
    }
    if gaps.iter().all(|&g| g == 0.0) {
        return (values, 0.0);
    }
    let residuals: Vec<f64> = known
        .windows(3)
        .map(|w| w[1].1 - between(w[0], w[2], w[1].0))
        .collect();
    if residuals.len() < MIN_RESIDUALS || total.is_nan() || total <= 0.0 {
        return (values, f64::INFINITY);
    }
    let variance = residuals.iter().map(|r| r * r).sum::<f64>() / residuals.len() as f64;
    let spread: f64 = gaps.iter().map(|g| g * g).sum();
    (values, (spread * variance).sqrt() / total)
}

/// The ratio at frame `at` on the line through the (frame, ratio) points `a` and `b`
/// (`a.0 <= at`, `a.0 < b.0`).
fn between(a: (usize, f64), b: (usize, f64), at: usize) -> f64 {
    a.1 + (b.1 - a.1) * (at - a.0) as f64 / (b.0 - a.0) as f64
}

/// Fewest leave-one-out residuals a standard error is computed from.
const MIN_RESIDUALS: usize = 4;

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(measured: Option<f64>, bound: f64) -> FrameValue {
        FrameValue { measured, bound }
    }

    #[test]
    fn each_block_gives_one_frame_and_finer_samples_hold_coarser_ones() {
        for (first, n) in [(0, 100), (128, 73), (5, 3)] {
            let mut coarser: Vec<usize> = Vec::new();
            for stride in STRIDES {
                let s = sampled_at(stride, first, n);
                let blocks = (first + n - 1) / stride - first / stride + 1;
                assert_eq!(s.len(), blocks, "stride {stride}");
                assert!(s
                    .windows(2)
                    .all(|w| (first + w[0]) / stride < (first + w[1]) / stride));
                assert!(coarser.iter().all(|c| s.contains(c)), "stride {stride}");
                coarser = s;
            }
            assert_eq!(coarser, (0..n).collect::<Vec<_>>());
        }
        // Not every eighth frame at the same place in its block.
        let offsets: std::collections::BTreeSet<usize> =
            sampled_at(8, 0, 800).iter().map(|i| i % 8).collect();
        assert!(offsets.len() > 4, "{offsets:?}");
    }

    #[test]
    fn every_frame_measured_is_exact() {
        let f = [frame(Some(1.0), 2.0), frame(Some(3.0), 4.0)];
        assert_eq!(estimate(&f), (vec![1.0, 3.0], 0.0));
    }

    #[test]
    fn a_constant_ratio_scales_the_bounds_with_no_error() {
        let f: Vec<FrameValue> = (0..40)
            .map(|i| {
                let bound = 1.0 + (i as f64 * 0.3).sin() * 0.5;
                let sampled = i % 4 == 0;
                frame(sampled.then_some(0.8 * bound), bound)
            })
            .collect();
        let (values, error) = estimate(&f);
        for (v, f) in values.iter().zip(&f) {
            assert!((v - 0.8 * f.bound).abs() < 1e-12);
        }
        assert!(error < 1e-12, "{error}");
    }

    #[test]
    fn a_drifting_ratio_is_followed() {
        let f: Vec<FrameValue> = (0..40)
            .map(|i| {
                let sampled = i % 4 == 0;
                let ratio = 0.5 + 0.01 * i as f64;
                frame(sampled.then_some(ratio * 2.0), 2.0)
            })
            .collect();
        let (values, error) = estimate(&f);
        for (i, v) in values.iter().enumerate().take(37) {
            assert!((v - (1.0 + 0.02 * i as f64)).abs() < 1e-12, "{i}: {v}");
        }
        assert!(error < 1e-12, "{error}");
    }

    #[test]
    fn a_jumping_ratio_shows_in_the_error() {
        let f: Vec<FrameValue> = (0..40)
            .map(|i| {
                let sampled = i % 4 == 0;
                let ratio = if i % 8 == 0 { 0.5 } else { 0.9 };
                frame(sampled.then_some(ratio), 1.0)
            })
            .collect();
        let (_, error) = estimate(&f);
        assert!(error > 0.05, "{error}");
    }

    #[test]
    fn too_few_sampled_frames_cannot_tell() {
        let mut f = vec![frame(None, 1.0); 20];
        for i in [0, 5, 10, 15, 19] {
            f[i] = frame(Some(0.5), 1.0);
        }
        assert!(estimate(&f).1.is_infinite(), "three residuals");
        f[2] = frame(Some(0.5), 1.0);
        assert_eq!(estimate(&f).1, 0.0, "a constant ratio, four residuals");
    }
}
