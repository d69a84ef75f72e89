//! Residual quantisation: one step for the whole sequence, set by the target error, not by each
//! frame's range (docs/design.md, "One error law: a step per quality (stream version 2)").
//!
//! A residual `r` of one coordinate becomes the level `r / step − offset + mid`, mid-grey being
//! 2^(depth − 1) at the picture codec's sample depth (128 for the 8-bit JPEG and MPEG-4, 512 or 2048
//! for HEVC at 10 or 12 bits): mid-grey is the offset, one grey level one step. The step is the encoding's pixel step (a fraction of the first
//! frame's bounding-box diagonal that `quality` sets, `crate::codec::quality`), so a frame whose
//! residuals are small makes a near-flat picture that costs almost nothing, and a better predictor
//! buys fewer bits rather than finer levels. The offset (an integer number of steps) centres the
//! 2^depth levels on the frame's residuals.
//!
//! Intra (JPEG) frames take an offset per frame and coordinate. MPEG-4 P-frames predict a frame's
//! pixels from the previous frame's, which only works if a pixel value means the same residual in
//! both: there step and offset are shared by a whole group of pictures.
//!
//! Residuals that do not fit the 2^depth levels around the offset: if only a few do (at most
//! [`CORRECTION_SHARE`] of the group's values), they are clipped in the picture and sent exactly
//! (at the pixel step) in a sparse correction list ([`super::corrections`]); if more, the group's
//! step is widened just enough that that holds (stored per frame and coordinate), so such a group
//! costs precision, never a wrong frame. The widened step is the smallest that works rather than a
//! power of two, so that a finer pixel step never ends in a coarser frame step: a higher quality
//! never gives a higher error.

use super::corrections::Corrections;

/// The share of a group's values that may be clipped and corrected before its step is widened.
pub const CORRECTION_SHARE: f64 = 1.0 / 256.0;

/// Largest level at `depth` bits a sample (255 at 8 bits).
pub fn max_level(depth: u8) -> f32 {
    ((1u32 << depth) - 1) as f32
}

/// Mid-grey at `depth` bits a sample (128 at 8 bits).
pub fn mid_level(depth: u8) -> f32 {
    (1u32 << (depth - 1)) as f32
}

/// Levels a group's kept values may span: one less than the largest level leaves room for
/// rounding at both ends (254 at 8 bits).
fn span(depth: u8) -> f64 {
    f64::from(max_level(depth)) - 1.0
}

/// How one coordinate's residuals of one frame map to levels:
/// residual = (level − mid-grey + offset) × step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisRange {
    /// One grey level, in model units: the pixel step, or more for a group whose residuals span
    /// more than 2^depth of them.
    pub step: f32,
    /// The residual at mid-grey, in steps.
    pub offset: i32,
    /// Bits a sample of the picture (8 for JPEG and MPEG-4); not stored per range: the stream
    /// has one depth.
    pub depth: u8,
}

impl AxisRange {
    /// The range of one grey level `step` of 8-bit pictures, centred on `offset` steps.
    pub fn new(step: f32, offset: i32) -> Self {
        Self::at_depth(step, offset, 8)
    }

    /// The range of one grey level `step` of `depth`-bit pictures, centred on `offset` steps.
    pub fn at_depth(step: f32, offset: i32, depth: u8) -> Self {
        Self {
            step,
            offset,
            depth,
        }
    }

    /// `value` as a real level, not clamped (rounding is left to the caller, after padding).
    fn level(self, value: f32) -> f32 {
        value / self.step - self.offset as f32 + mid_level(self.depth)
    }

    /// `value` as a real number in `0..=max level`: values beyond the range are clipped.
    pub fn quantise(self, value: f32) -> f32 {
        let level = self.level(value);
        if level.is_nan() {
            mid_level(self.depth)
        } else {
            level.clamp(0.0, max_level(self.depth))
        }
    }

    /// Whether `value` rounds to a level in `0..=max level`.
    pub fn fits(self, value: f32) -> bool {
        let level = self.level(value).round();
        (0.0..=max_level(self.depth)).contains(&level)
    }

    /// The residual a pixel value stands for.
    pub fn dequantise(self, level: f32) -> f32 {
        (level - mid_level(self.depth) + self.offset as f32) * self.step
    }

    /// The residual at level 0.
    pub fn min(self) -> f32 {
        self.dequantise(0.0)
    }

    /// The residual at the largest level.
    pub fn max(self) -> f32 {
        self.dequantise(max_level(self.depth))
    }
}

/// The ranges of the x, y and z residual images of one frame.
pub type FrameRanges = [AxisRange; 3];

/// How steps and offsets are shared between frames.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RangeMode {
    /// An offset per frame and coordinate (intra coding).
    PerFrame,
    /// One step and offset per group of `n` frames and coordinate (P-frame coding).
    PerGroup(usize),
}

impl RangeMode {
    /// Frames per group (1 for intra coding).
    pub fn group(self) -> usize {
        match self {
            RangeMode::PerFrame => 1,
            RangeMode::PerGroup(n) => n.max(1),
        }
    }
}

/// Every frame's ranges at pixel step `pixel_step` and `depth` bits a sample (`residuals[f][v]`,
/// grouped as `mode` says), the corrections of the values they clip, and the residuals'
/// [`spread`](Chosen::spread).
pub fn choose(
    residuals: &[Vec<[f32; 3]>],
    mode: RangeMode,
    pixel_step: f32,
    depth: u8,
) -> Chosen {
    let n = mode.group();
    let mut ranges = Vec::with_capacity(residuals.len());
    let mut spread = 0.0f64;
    for group in residuals.chunks(n) {
        let shared: FrameRanges = std::array::from_fn(|a| {
            let (range, width) = group_range(group, a, pixel_step, depth);
            spread = spread.max(width);
            range
        });
        ranges.extend(std::iter::repeat_n(shared, group.len()));
    }
    let corrections = Corrections::of_clipped(residuals, &ranges, pixel_step);
    Chosen {
        ranges,
        corrections,
        spread,
    }
}

/// What [`choose`] found.
pub struct Chosen {
    /// Every frame's ranges.
    pub ranges: Vec<FrameRanges>,
    /// The residuals the ranges clip.
    pub corrections: Corrections,
    /// The widest of the narrowest windows that hold all but [`CORRECTION_SHARE`] of a group's
    /// values of one coordinate, in model units: below [`unwidened_step`] of it no group's step
    /// is widened. The depth a sample needs is read off it (a budget search's, `encoder::budget`).
    pub spread: f64,
}

/// The finest pixel step at which `depth`-bit samples hold residuals of [`Chosen::spread`]
/// `spread` without widening any group's step.
pub fn unwidened_step(spread: f64, depth: u8) -> f64 {
    spread / span(depth)
}

/// The step and offset of axis `a` over a group: at the pixel step, centred on the [`span`]-level
/// window that holds most of the group's values, if it leaves out at most [`CORRECTION_SHARE`] of
/// them; else centred on the narrowest window that does, at the step that makes it [`span`] levels.
/// With it, the width of that narrowest window in model units.
fn group_range(
    group: &[Vec<[f32; 3]>],
    a: usize,
    pixel_step: f32,
    depth: u8,
) -> (AxisRange, f64) {
    let values = sorted_levels(group, a, pixel_step);
    if values.is_empty() {
        return (AxisRange::at_depth(pixel_step, 0, depth), 0.0);
    }
    let (keep, narrowest) = narrowest_window(&values);
    let (held, lo, hi) = fullest_window(&values, span(depth));
    let width = (narrowest.1 - narrowest.0) * f64::from(pixel_step);
    let (lo, hi) = if held >= keep { (lo, hi) } else { narrowest };
    let scale = ((hi - lo) / span(depth)).max(1.0);
    // f32 rounding must not narrow the step below what the window needs.
    let mut step = (f64::from(pixel_step) * scale) as f32;
    if f64::from(step) < f64::from(pixel_step) * scale {
        step = f32::from_bits(step.to_bits() + 1);
    }
    let mid = 0.5 * (lo + hi) * f64::from(pixel_step) / f64::from(step);
    let offset = mid.round().clamp(f64::from(i32::MIN), f64::from(i32::MAX)) as i32;
    (AxisRange::at_depth(step, offset, depth), width)
}

/// Axis `a` of a group's residuals in pixel steps, finite ones, sorted.
fn sorted_levels(group: &[Vec<[f32; 3]>], a: usize, pixel_step: f32) -> Vec<f64> {
    let mut values: Vec<f64> = group
        .iter()
        .flatten()
        .map(|r| f64::from(r[a]) / f64::from(pixel_step))
        .filter(|v| v.is_finite())
        .collect();
    values.sort_by(f64::total_cmp);
    values
}

/// How many of the sorted, non-empty `values` a range must hold (all but [`CORRECTION_SHARE`]),
/// and the narrowest window that holds that many: its lowest and highest value.
fn narrowest_window(values: &[f64]) -> (usize, (f64, f64)) {
    let n = values.len();
    let keep = n - (n as f64 * CORRECTION_SHARE).floor() as usize;
    let narrowest = (0..=n - keep)
        .map(|i| (values[i], values[i + keep - 1]))
        .min_by(|x, y| (x.1 - x.0).total_cmp(&(y.1 - y.0)))
        .unwrap_or((values[0], values[n - 1]));
    (keep, narrowest)
}

/// The residuals' [`spread`](Chosen::spread) alone, as [`choose`] finds it (it does not depend on
/// the depth): what deciding a depth needs, without building ranges and corrections.
pub fn spread(residuals: &[Vec<[f32; 3]>], mode: RangeMode, pixel_step: f32) -> f64 {
    let mut spread = 0.0f64;
    for group in residuals.chunks(mode.group()) {
        for a in 0..3 {
            let values = sorted_levels(group, a, pixel_step);
            if !values.is_empty() {
                let (_, (lo, hi)) = narrowest_window(&values);
                spread = spread.max((hi - lo) * f64::from(pixel_step));
            }
        }
    }
    spread
}

/// The window of at most `span` pixel steps that holds most of the sorted `values` (in pixel
/// steps): how many it holds, its lowest and its highest value.
fn fullest_window(sorted: &[f64], span: f64) -> (usize, f64, f64) {
    let (mut best, mut best_at, mut j) = (0usize, 0usize, 0usize);
    for i in 0..sorted.len() {
        j = j.max(i);
        while j + 1 < sorted.len() && sorted[j + 1] - sorted[i] <= span {
            j += 1;
        }
        if j + 1 - i > best {
            (best, best_at) = (j + 1 - i, i);
        }
    }
    match best {
        0 => (0, 0.0, 0.0),
        _ => (best, sorted[best_at], sorted[best_at + best - 1]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_round_trip_within_half_a_step_and_mid_grey_is_the_offset() {
        let r = AxisRange::new(0.01, 7);
        assert_eq!(r.quantise(0.07), mid_level(8));
        for i in -127..=127 {
            let v = 0.07 + i as f32 * 0.0099;
            assert!(r.fits(v), "{v}");
            let back = r.dequantise(r.quantise(v).round());
            assert!((back - v).abs() <= 0.005 + 1e-6, "{v} -> {back}");
        }
        assert!(!r.fits(0.07 + 1.3) && r.quantise(0.07 + 1.3) == max_level(8));
    }

    #[test]
    fn the_spread_alone_is_the_one_choose_finds() {
        let residuals: Vec<Vec<[f32; 3]>> = (0..7)
            .map(|f| {
                (0..300)
                    .map(|i| {
                        let x = ((i * 37 + f * 11) % 101) as f32 / 50.0 - 1.0;
                        [x * (f + 1) as f32, 0.01 * x, if i == 7 { 40.0 } else { 0.0 }]
                    })
                    .collect()
            })
            .collect();
        for mode in [RangeMode::PerFrame, RangeMode::PerGroup(3)] {
            for depth in [8, 10, 12] {
                let chosen = choose(&residuals, mode, 0.001, depth);
                assert_eq!(spread(&residuals, mode, 0.001), chosen.spread, "{depth}");
            }
        }
        assert_eq!(spread(&[], RangeMode::PerFrame, 0.001), 0.0);
    }

    #[test]
    fn a_few_outliers_are_clipped_many_widen_the_step() {
        let step = 0.01;
        // 1000 values within ±1, i.e. ±100 steps: they fit at step 0.01.
        let mut frame: Vec<[f32; 3]> = (0..1000)
            .map(|i| [(i as f32 / 500.0 - 1.0), 0.0, 0.5])
            .collect();
        frame[3][0] = 50.0;
        let Chosen {
            ranges,
            corrections,
            spread,
        } = choose(&[frame.clone()], RangeMode::PerFrame, step, 8);
        assert_eq!(ranges[0][0].step, step, "{:?}", ranges[0][0]);
        // x's narrowest window of all but 3 values (1/256 of 1000: the outlier and two at an
        // end) is 997 of its steps of 0.002 wide; y and z spread nowhere.
        assert!((spread - 1.994).abs() < 1e-5, "{spread}");
        assert!(unwidened_step(spread, 8) < f64::from(step));
        assert_eq!(ranges[0][2].offset, 50);
        assert_eq!(corrections.frame(0).len(), 1);
        assert_eq!(corrections.frame(0)[0].vertex, 3);
        // Values over ±300 steps: the step widens to fit them in 254 levels, one outlier aside.
        let wide: Vec<[f32; 3]> = frame.iter().map(|r| [3.0 * r[0], 0.0, 0.0]).collect();
        let Chosen {
            ranges,
            corrections,
            spread,
        } = choose(std::slice::from_ref(&wide), RangeMode::PerFrame, step, 8);
        let r = ranges[0][0];
        assert!(r.step > 2.3 * step && r.step < 2.4 * step, "{r:?}");
        // The widened step is the one that holds the spread, whatever the pixel step asked.
        assert!((unwidened_step(spread, 8) - f64::from(r.step)).abs() < 1e-6 * spread);
        let coarse = choose(std::slice::from_ref(&wide), RangeMode::PerFrame, 1.0, 8);
        assert_eq!(coarse.spread, spread);
        let corrected = corrections.frame(0);
        assert!(corrected.len() <= 3 && corrected.iter().any(|c| c.vertex == 3));
        assert!(wide.iter().skip(4).take(900).all(|v| r.fits(v[0])));
    }

    #[test]
    fn groups_share_a_range_and_ranges_round_trip() {
        let res = vec![
            vec![[0.0, 1.0, 2.0]],
            vec![[-1.0, 1.5, 2.0]],
            vec![[4.0, 0.0, 0.0]],
        ];
        let g = choose(&res, RangeMode::PerGroup(2), 0.25, 8).ranges;
        assert_eq!(g[0], g[1]);
        assert_eq!(g[0][0].offset, -2);
        assert_eq!(g[2][0].offset, 16);
        let none = Corrections::from_frames(vec![Vec::new(); 3]);
        let bytes = super::super::range_coding::encode_ranges(0.25, &g, &none, 1).unwrap();
        let back = super::super::range_coding::decode_ranges(&bytes, 3, 1, 8).unwrap();
        assert_eq!(back, (0.25, g, none));
        assert!(super::super::range_coding::decode_ranges(&bytes, 4, 1, 8).is_err());
    }

    #[test]
    fn deeper_samples_hold_wider_residuals_at_the_same_step() {
        let step = 0.01;
        // ±3 = ±300 steps: beyond 8 bits' 254 levels, within 10 bits' 1022.
        let frame: Vec<[f32; 3]> = (0..1000)
            .map(|i| [i as f32 * 0.006 - 3.0, 0.0, 0.0])
            .collect();
        let eight = choose(std::slice::from_ref(&frame), RangeMode::PerFrame, step, 8).ranges;
        let Chosen {
            ranges: ten,
            corrections,
            spread,
        } = choose(std::slice::from_ref(&frame), RangeMode::PerFrame, step, 10);
        // 10 bits hold the whole ±3 at this step, 8 bits from a step a quarter coarser on.
        let step64 = f64::from(step);
        assert!(unwidened_step(spread, 10) < step64 && unwidened_step(spread, 8) > 2.0 * step64);
        assert!(eight[0][0].step > 2.0 * step);
        assert_eq!(ten[0][0].step, step);
        assert!(corrections.is_empty());
        assert_eq!(mid_level(10), 512.0);
        assert_eq!(max_level(12), 4095.0);
        let r = ten[0][0];
        for v in &frame {
            assert!(r.fits(v[0]));
            assert!((r.dequantise(r.quantise(v[0]).round()) - v[0]).abs() <= 0.005 + 1e-5);
        }
    }
}
