//! The sparse correction list: residuals that fell outside their frame's 256 levels (see
//! [`super::quantise`]), sent as (vertex, axis, residual in pixel steps) so that a clipped vertex
//! still decodes within half a pixel step. The picture keeps the clipped level there; the decoder
//! replaces what it reads at that vertex by the correction.
//!
//! Stored with the ranges, entropy-coded ([`super::range_coding`]).

use super::quantise::FrameRanges;

/// One clipped coordinate of one vertex.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Correction {
    /// The vertex.
    pub vertex: u32,
    /// The coordinate: 0, 1, 2 for x, y, z.
    pub axis: u8,
    /// Its residual in pixel steps, rounded.
    pub value: i64,
}

impl Correction {
    /// The residual it stands for at pixel step `step`.
    pub fn residual(&self, step: f32) -> f32 {
        (self.value as f64 * f64::from(step)) as f32
    }
}

/// Every frame's corrections, sorted by vertex then axis.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Corrections(Vec<Vec<Correction>>);

impl Corrections {
    /// How many corrections in all.
    #[cfg(any(test, feature = "internals"))]
    pub fn len(&self) -> usize {
        self.0.iter().map(Vec::len).sum()
    }

    /// Whether there are none.
    #[cfg(any(test, feature = "internals"))]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The corrections of every residual that does not fit its frame's range.
    pub fn of_clipped(residuals: &[Vec<[f32; 3]>], ranges: &[FrameRanges], step: f32) -> Self {
        let frames = residuals
            .iter()
            .zip(ranges)
            .map(|(frame, range)| {
                let mut list = Vec::new();
                for (v, r) in frame.iter().enumerate() {
                    for a in 0..3 {
                        if !range[a].fits(r[a]) {
                            let value = (f64::from(r[a]) / f64::from(step)).round();
                            list.push(Correction {
                                vertex: v as u32,
                                axis: a as u8,
                                // Saturating: a residual beyond ±2^63 steps is not a motion.
                                value: value as i64,
                            });
                        }
                    }
                }
                list
            })
            .collect();
        Self(frames)
    }

    /// The list of each frame's corrections (each sorted by vertex then axis).
    pub fn from_frames(frames: Vec<Vec<Correction>>) -> Self {
        Self(frames)
    }

    /// Frame `f`'s corrections (none past the last frame).
    pub fn frame(&self, f: usize) -> &[Correction] {
        self.0.get(f).map_or(&[], Vec::as_slice)
    }
}
