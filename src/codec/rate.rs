//! The rate plan: what one `quality` means for one encoding.
//!
//! A codec configuration turns the caller's rate (the quality, or an explicit step) and the first
//! frame's bounding-box diagonal into one [`RatePlan`] when an encoding starts: the residual step,
//! the affine coefficients' step, and the codec's own settings (quantiser, sample depth, padding).
//! Every later stage reads the plan; none reads `quality` again. Each codec's law — how its
//! quantiser and step follow the quality — sits in that codec's file; what the laws share is
//! here: the target step of a quality, and the reading of a law given by anchors.

use super::pictures::PicturePlan;
use super::Codec;
use crate::error::{Error, Result};
use crate::motion;

/// What the caller asked of the rate, before any codec reads it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Rate {
    /// The rate knob 1..100.
    pub quality: u8,
    /// A quality between the integers (1.0..=100.0) read instead of `quality` by every law.
    pub fine_quality: Option<f64>,
    /// An explicit residual step as a fraction of the bounding-box diagonal (overrides the law).
    pub step: Option<f64>,
    /// An explicit affine precision `k` (affine step = k × residual step fraction).
    pub affine_precision: Option<f64>,
}

/// The IJG quality law (libjpeg's `jpeg_quality_scaling`): the quantiser scale in percent for a
/// quality 1..100 (clamped), 5000/q below 50 and 200 − 2q from 50 up (0 at 100).
pub fn ijg_scale_percent(quality: u8) -> u32 {
    let q = u32::from(quality.clamp(1, 100));
    if q < 50 {
        5000 / q
    } else {
        200 - 2 * q
    }
}

/// The IJG scale in percent at a quality between the integers (1.0..=100.0, clamped): log-linear
/// between the scales of the integers around it, so that it meets the integers' IJG scale (at least
/// 1) at every integer and falls strictly between them.
pub fn fine_scale_percent(quality: f64) -> f64 {
    let q = quality.clamp(1.0, 100.0);
    let (below, above) = (q.floor(), q.ceil());
    let at = |q: f64| f64::from(ijg_scale_percent(q as u8).max(1));
    if below == above {
        return at(below);
    }
    at(below) * (at(above) / at(below)).powf(q - below)
}

/// The target step of `quality` in model units, for a first frame of bounding-box diagonal
/// `diagonal`: 1e-3 × diagonal × the IJG scale (1 % at quality 99 and 100, so never 0).
pub fn target_step(quality: u8, diagonal: f64) -> f64 {
    let s = ijg_scale_percent(quality).max(1);
    diagonal * 1e-3 * f64::from(s) / 100.0
}

impl Rate {
    /// The residual step as a fraction of the bounding-box diagonal: the explicit one, else the
    /// quality's.
    pub fn step_fraction(&self) -> f64 {
        self.step.unwrap_or_else(|| self.target_step(1.0))
    }

    /// The quality every law reads: the fine one when given.
    pub fn level(&self) -> f64 {
        self.fine_quality.unwrap_or(f64::from(self.quality))
    }

    /// The IJG scale in percent of [`Rate::level`] (at least 1).
    pub fn scale_percent(&self) -> f64 {
        match self.fine_quality {
            Some(q) => fine_scale_percent(q),
            None => f64::from(ijg_scale_percent(self.quality).max(1)),
        }
    }

    /// The target step in model units on a first frame of diagonal `diagonal` ([`target_step`]
    /// at [`Rate::level`]).
    pub fn target_step(&self, diagonal: f64) -> f64 {
        diagonal * 1e-3 * self.scale_percent() / 100.0
    }

    /// The quality the stream header records: the fine one rounded.
    fn label(&self) -> u8 {
        match self.fine_quality {
            Some(q) => q.round().clamp(1.0, 100.0) as u8,
            None => self.quality,
        }
    }

    /// The residual step in model units: the explicit `step` × `diagonal`, else `factor` × the
    /// quality's target step; rounded to the `f32` the stream stores, so that the encoder
    /// quantises with exactly the step the decoder reads. `what` names the step in the error a
    /// degenerate first frame gives.
    pub fn stored_step(&self, what: &str, diagonal: f64, factor: f64) -> Result<f32> {
        let step = match self.step {
            Some(fraction) => diagonal * fraction,
            None => factor * self.target_step(diagonal),
        };
        let stored = step as f32;
        if !(stored.is_normal() && stored > 0.0) {
            return Err(Error::Mesh(format!(
                "the {what} is {step} (first frame's bounding-box diagonal {diagonal}): \
                 a degenerate first frame gives no scale to quantise against"
            )));
        }
        Ok(stored)
    }

    /// The affine precision in sixteenths as the header stores it (1..=255): the explicit one,
    /// else the codec's `default`.
    fn affine_precision_code(&self, default: f64) -> u8 {
        let k = self.affine_precision.unwrap_or(default);
        (k * 16.0).round().clamp(1.0, 255.0) as u8
    }

    /// The plan of `codec`, whose step is `step`, whose affine precision is
    /// `default_affine_precision` unless asked otherwise, and whose pictures (a picture codec's)
    /// are `pictures`. The affine step is a fraction of the diagonal: the residual step's fraction
    /// (explicit, or the quality's) times the precision.
    pub fn plan(
        &self,
        step: f32,
        default_affine_precision: f64,
        codec: Codec,
        pictures: Option<PicturePlan>,
    ) -> RatePlan {
        let affine_precision = self.affine_precision_code(default_affine_precision);
        let fraction = self.step_fraction();
        let k = f64::from(affine_precision) / 16.0;
        RatePlan {
            quality: self.label(),
            step,
            affine_step: (fraction * k).clamp(motion::MIN_AFFINE_STEP, motion::MAX_AFFINE_STEP),
            affine_precision,
            codec,
            pictures,
        }
    }
}

/// Every step and setting an encoding uses, resolved once from the caller's options and the
/// first frame's bounding-box diagonal ([`crate::EncodeOptions::plan`]).
#[derive(Debug, Clone, PartialEq)]
pub struct RatePlan {
    /// The quality it was resolved from (recorded in the stream header).
    pub quality: u8,
    /// The residual step in model units, as the stream stores it: the temporal DCT's quantiser
    /// step, or the pictures' pixel step (one grey level).
    pub step: f32,
    /// The affine coefficients' base step, as a fraction of the bounding-box diagonal.
    pub affine_step: f64,
    /// The affine precision (affine step over the residual step) in sixteenths.
    pub affine_precision: u8,
    /// The codec.
    pub codec: Codec,
    /// A picture codec's quantiser, groups, depth, padding and lattice.
    pub(crate) pictures: Option<PicturePlan>,
}

/// What one quality means for a picture codec.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PictureLaw {
    /// Pixel step (one grey level) as a multiple of the target step.
    pub step_factor: f64,
    /// The picture codec's own quantiser.
    pub quantiser: u8,
}

/// One anchor of a law: from `quality` up (until the next anchor), the codec's quantiser, and the
/// step factor at `quality` (towards the next anchor, the pixel step × the quantiser's step is
/// interpolated log-linearly: [`read_law`]).
pub(crate) struct Anchor {
    pub quality: u8,
    pub step_factor: f64,
    pub quantiser: u8,
}

/// An anchor of a law (for the laws' tables).
pub(crate) const fn anchor(quality: u8, step_factor: f64, quantiser: u8) -> Anchor {
    Anchor {
        quality,
        step_factor,
        quantiser,
    }
}

/// The law given by `anchors` (in rising quality, the first at quality 1) read at `quality`
/// (between the integers too), for a codec whose quantiser `q` quantises at a step proportional
/// to `quantiser_step(q)`. Between two anchors the pixel step × that step is interpolated, not
/// the pixel step alone, so that where the next anchor changes the quantiser the two together
/// meet it without a jump (JPEG's error halved at quality 75, MPEG-4's at 90, and no error
/// budget between could be met: docs/design.md, "Quality laws").
pub(crate) fn read_law(
    anchors: &[Anchor],
    quantiser_step: fn(u8) -> f64,
    quality: f64,
) -> PictureLaw {
    let q = quality.clamp(1.0, 100.0);
    let i = anchors
        .iter()
        .rposition(|a| f64::from(a.quality) <= q)
        .unwrap_or(0);
    let here = &anchors[i];
    let step_factor = match anchors.get(i + 1) {
        Some(next) => {
            let t = (q - f64::from(here.quality)) / f64::from(next.quality - here.quality);
            let (from, to) = (
                quantiser_step(here.quantiser),
                quantiser_step(next.quantiser),
            );
            here.step_factor * (next.step_factor * to / (here.step_factor * from)).powf(t)
        }
        None => here.step_factor,
    };
    PictureLaw {
        step_factor,
        quantiser: here.quantiser,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_target_step_is_anchored_and_falls_with_quality() {
        assert!((target_step(50, 2.0) - 2e-3).abs() < 1e-12);
        assert!((target_step(75, 1.0) - 0.5e-3).abs() < 1e-12);
        assert!(target_step(100, 1.0) > 0.0);
        for q in 1..100u8 {
            assert!(target_step(q + 1, 1.0) <= target_step(q, 1.0), "{q}");
        }
    }

    #[test]
    fn the_affine_step_follows_the_residual_step_and_the_precision() {
        let rate = |step, affine_precision| Rate {
            quality: 50,
            fine_quality: None,
            step,
            affine_precision,
        };
        let plan = rate(None, None).plan(1.0, 0.25, Codec::Tdct, None);
        assert_eq!(plan.affine_precision, 4);
        assert!((plan.affine_step - 0.25e-3).abs() < 1e-15);
        let plan = rate(Some(2e-3), Some(0.5)).plan(1.0, 0.25, Codec::Tdct, None);
        assert_eq!(plan.affine_precision, 8);
        assert!((plan.affine_step - 1e-3).abs() < 1e-15);
        let degenerate = rate(None, None).stored_step("step", 0.0, 1.0);
        assert!(degenerate.is_err());
    }
}
