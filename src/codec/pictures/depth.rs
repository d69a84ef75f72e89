//! The sample depth of HEVC's and AV1's pictures: 10 or 12 bits, from the quality and, below
//! the codec's threshold, from the residuals — a plan carries its 12-bit alternative ([`Deeper`]),
//! which the encoder takes where the clip's residuals would widen a group's step in 10-bit
//! samples (docs/design.md, "Sample depth").

use super::setup::PictureSetup;
use crate::codec::rate::RatePlan;
use crate::codec::Codec;
use crate::error::Result;
use crate::geometry_image::quantise;

/// Sample depths the codecs take, in bits.
pub const DEPTHS: [u8; 2] = [10, 12];
/// The quality from which `codec`'s automatic depth is 12 bits whatever the residuals
/// ([`auto_depth`]): HEVC from 65, the first quality measured at which 12-bit pictures cost less
/// on average at equal error on the media sequences and none more than 5 % (with P-frames and
/// all-intra); AV1 from 90, as until 2026-12-05 (its 12-bit pictures
/// cost up to 2× the bytes at quality 75 on the small glTF characters, though less on the
/// captured and simulated sequences; docs/design.md, "Sample depth").
pub fn deeper_from_quality(codec: Codec) -> u8 {
    match codec {
        Codec::Hevc => 65,
        _ => 90,
    }
}

/// The sample depth of `codec`'s encoding at `quality` with no `bit_depth`, before its residuals
/// are known: 12 bits from [`deeper_from_quality`], else 10, which the encoder turns to 12 where
/// its residuals would widen a group's step at 10 (docs/design.md, "Sample depth"). At equal
/// error the finer rounding of 12 bits buys nothing at coarse steps; at fine ones it costs less,
/// and reaches errors 10 bits cannot where large residuals outgrow 1024 levels.
#[cfg_attr(not(any(test, feature = "internals")), allow(dead_code))]
pub fn auto_depth(codec: Codec, quality: u8) -> u8 {
    auto_depth_at(codec, f64::from(quality))
}

/// [`auto_depth`] at a quality between the integers too.
pub(crate) fn auto_depth_at(codec: Codec, quality: f64) -> u8 {
    if quality >= f64::from(deeper_from_quality(codec)) {
        12
    } else {
        10
    }
}

/// The 12-bit plan of an encoding whose automatic depth is 10 bits (HEVC and AV1 at the law's
/// quantiser): the geometry-video coder codes these pictures when its residuals outgrow 10-bit
/// samples at the pixel step, since a widened step is error the quality did not ask for and
/// costs more bits at equal error than 12-bit samples do (docs/design.md, "Sample depth").
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Deeper {
    /// The codec's quantiser at 12 bits.
    pub quantiser: u8,
    /// The pixel step at 12 bits (the law's rest of the integer quantiser differs by depth).
    pub step: f32,
}

impl RatePlan {
    /// This plan at the depth its pictures of `residuals` want: at the automatic depth's 10 bits
    /// with a 12-bit alternative ([`Deeper`]), the 12-bit plan where 10-bit samples would widen a
    /// group's step at the pixel step, else the 10-bit one; other plans as they are. The encoder
    /// decides on the clip's residuals, every frame of them, before coding any.
    pub(crate) fn at_depth_for(mut self, residuals: &[Vec<[f32; 3]>]) -> Self {
        let Some(pictures) = self.pictures.as_mut() else {
            return self;
        };
        let Some(deeper) = pictures.deeper.take() else {
            return self;
        };
        let spread = quantise::spread(residuals, pictures.ranges(), self.step);
        if f64::from(self.step) < quantise::unwidened_step(spread, pictures.depth) {
            self.deepen(deeper);
        }
        self
    }

    /// `deeper`'s 12-bit pictures in place of this plan's.
    fn deepen(&mut self, deeper: Deeper) {
        if let Some(pictures) = self.pictures.as_mut() {
            pictures.depth = 12;
            pictures.quantiser = deeper.quantiser;
            self.step = deeper.step;
        }
    }

    /// This plan as the set-up part `setup` of a stream of `vertices` vertices says its pictures
    /// were coded: at the automatic depth, at the depth that stream took ([`Deeper`]), so that
    /// the segments of a stream code what its analysis clip chose. Other plans stay as they are.
    pub(crate) fn pinned_to(mut self, setup: &[u8], vertices: u32) -> Result<Self> {
        let Some(pictures) = self.pictures.as_mut() else {
            return Ok(self);
        };
        let Some(deeper) = pictures.deeper.take() else {
            return Ok(self);
        };
        if PictureSetup::from_bytes(setup, vertices)?.depth == 12 {
            self.deepen(deeper);
        }
        Ok(self)
    }
}

