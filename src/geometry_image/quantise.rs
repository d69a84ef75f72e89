//! Residual quantisation: each coordinate's residuals map linearly onto `0..=255` over a stored range.
//!
//! Intra (JPEG) frames use a range per frame and coordinate, the tightest possible. MPEG-4 P-frames
//! predict a frame's pixels from the previous frame's, which only works if a pixel value means the same
//! residual in both: there the range is shared by a whole group of pictures.

use crate::error::{Error, Result};
use crate::stream::bytes::{ByteReader, ByteWriter};

/// Largest quantised value (8-bit images).
pub const LEVELS: f32 = 255.0;

/// The interval one coordinate's residuals are quantised over.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisRange {
    /// Residual that maps to 0.
    pub min: f32,
    /// Residual that maps to 255.
    pub max: f32,
}

impl AxisRange {
    /// The range spanning `values` (a zero-width range at 0 for no values).
    pub fn spanning(values: impl Iterator<Item = f32>) -> Self {
        let (mut min, mut max) = (f32::INFINITY, f32::NEG_INFINITY);
        for v in values {
            min = min.min(v);
            max = max.max(v);
        }
        if min > max {
            Self { min: 0.0, max: 0.0 }
        } else {
            Self { min, max }
        }
    }

    /// The smallest range covering both.
    pub fn union(self, other: Self) -> Self {
        Self {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// `value` as a real number in `0..=255` (rounding is left to the caller, after padding).
    pub fn quantise(self, value: f32) -> f32 {
        let width = self.max - self.min;
        if width <= 0.0 {
            0.0
        } else {
            ((value - self.min) / width * LEVELS).clamp(0.0, LEVELS)
        }
    }

    /// The residual a pixel value stands for.
    pub fn dequantise(self, level: f32) -> f32 {
        self.min + (self.max - self.min) * (level / LEVELS)
    }
}

/// The ranges of the x, y and z residual images of one frame.
pub type FrameRanges = [AxisRange; 3];

/// How residual ranges are shared between frames.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RangeMode {
    /// A range per frame and coordinate (intra coding).
    PerFrame,
    /// One range per group of `n` frames and coordinate (P-frame coding).
    PerGroup(usize),
}

/// The ranges of every frame's residuals (`residuals[f][v]`), shared as `mode` says.
pub fn frame_ranges(residuals: &[Vec<[f32; 3]>], mode: RangeMode) -> Vec<FrameRanges> {
    let own: Vec<FrameRanges> = residuals
        .iter()
        .map(|frame| std::array::from_fn(|a| AxisRange::spanning(frame.iter().map(|r| r[a]))))
        .collect();
    match mode {
        RangeMode::PerFrame => own,
        RangeMode::PerGroup(n) => {
            let n = n.max(1);
            let mut out = Vec::with_capacity(own.len());
            for group in own.chunks(n) {
                let shared: FrameRanges = std::array::from_fn(|a| {
                    group.iter().skip(1).fold(group[0][a], |r, g| r.union(g[a]))
                });
                out.extend(std::iter::repeat_n(shared, group.len()));
            }
            out
        }
    }
}

/// Widens every range narrower than `floor` × the widest range of its coordinate over the sequence
/// to that width, about its own midpoint (`floor` 0 leaves them all).
///
/// A tight range spends all 256 levels on small residuals, so the image codec's error in levels
/// becomes a small geometric error bought with many bits, while frames with wide ranges carry the
/// large errors. A common floor evens the step across frames, which is where a fixed rate buys the
/// lowest mean error (reverse water-filling).
pub fn widen(ranges: &mut [FrameRanges], floor: f32) {
    if floor <= 0.0 {
        return;
    }
    for a in 0..3 {
        let widest = ranges
            .iter()
            .map(|r| r[a].max - r[a].min)
            .fold(0.0f32, f32::max);
        let min_width = floor.min(1.0) * widest;
        for r in ranges.iter_mut() {
            let width = r[a].max - r[a].min;
            if width < min_width {
                let mid = 0.5 * (r[a].max + r[a].min);
                r[a] = AxisRange {
                    min: mid - 0.5 * min_width,
                    max: mid + 0.5 * min_width,
                };
            }
        }
    }
}

/// Serialises ranges (6 floats per frame).
pub fn write_ranges(ranges: &[FrameRanges], w: &mut ByteWriter) {
    w.u32(ranges.len() as u32);
    for r in ranges.iter().flatten() {
        w.f32(r.min).f32(r.max);
    }
}

/// Reads ranges written by [`write_ranges`]; `frames` is the count the header promised.
pub fn read_ranges(r: &mut ByteReader, frames: usize) -> Result<Vec<FrameRanges>> {
    let n = r.u32()? as usize;
    if n != frames {
        return Err(Error::Stream(format!(
            "{n} residual ranges for {frames} frames"
        )));
    }
    if n.saturating_mul(24) > r.remaining() {
        return Err(Error::Stream("residual ranges are truncated".into()));
    }
    (0..n)
        .map(|_| {
            let mut fr = [AxisRange { min: 0.0, max: 0.0 }; 3];
            for a in fr.iter_mut() {
                let (min, max) = (r.f32()?, r.f32()?);
                if min > max {
                    return Err(Error::Stream("a residual range has min above max".into()));
                }
                *a = AxisRange { min, max };
            }
            Ok(fr)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantise_round_trip_within_half_a_step() {
        let r = AxisRange {
            min: -0.5,
            max: 1.5,
        };
        for i in 0..=100 {
            let v = -0.5 + 2.0 * i as f32 / 100.0;
            let back = r.dequantise(r.quantise(v).round());
            assert!(
                (back - v).abs() <= 0.5 * 2.0 / 255.0 + 1e-6,
                "{v} -> {back}"
            );
        }
        let flat = AxisRange { min: 3.0, max: 3.0 };
        assert_eq!(flat.dequantise(flat.quantise(3.0)), 3.0);
    }

    #[test]
    fn widening_keeps_each_range_covering_its_values() {
        let narrow = AxisRange { min: 0.9, max: 1.1 };
        let wide = AxisRange {
            min: -2.0,
            max: 2.0,
        };
        let mut ranges = vec![[narrow; 3], [wide; 3]];
        widen(&mut ranges, 0.0);
        assert_eq!(ranges[0][0], narrow);
        widen(&mut ranges, 0.5);
        assert_eq!(ranges[1][0], wide, "the widest range is left as it is");
        let r = ranges[0][2];
        assert!((r.max - r.min - 2.0).abs() < 1e-6, "{r:?}");
        assert!(r.min <= narrow.min && r.max >= narrow.max, "{r:?}");
    }

    #[test]
    fn group_ranges_cover_each_member() {
        let res = vec![
            vec![[0.0, 1.0, 2.0]],
            vec![[-1.0, 5.0, 2.0]],
            vec![[4.0, 0.0, 0.0]],
        ];
        let g = frame_ranges(&res, RangeMode::PerGroup(2));
        assert_eq!(g[0], g[1]);
        assert_eq!(
            g[0][0],
            AxisRange {
                min: -1.0,
                max: 0.0
            }
        );
        assert_eq!(g[2][0], AxisRange { min: 4.0, max: 4.0 });
        let mut w = ByteWriter::new();
        write_ranges(&g, &mut w);
        let bytes = w.into_bytes();
        let back = read_ranges(&mut ByteReader::new(&bytes, "ranges"), 3).unwrap();
        assert_eq!(back, g);
        assert!(read_ranges(&mut ByteReader::new(&bytes, "ranges"), 4).is_err());
    }
}
