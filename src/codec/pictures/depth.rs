//! The sample depth of HEVC's and AV1's pictures: 10 or 12 bits, from the quality and, below
//! the codec's threshold, from the residuals — a plan carries its 12-bit laws ([`Deeper`]): the
//! encoder takes them where the clip's residuals would widen a group's step in 10-bit samples,
//! and codes AV1's second split where they leave room (docs/design.md, "Sample depth").

use super::setup::PictureSetup;
use crate::codec::rate::{PictureLaw, RatePlan};
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

/// What a quality means for one deep-sample codec.
pub(crate) struct DeepLaws {
    /// Its pixel step factor and quantiser at a quality's IJG scale (percent) and a sample depth.
    pub law: fn(f64, u8) -> PictureLaw,
    /// Its other 12-bit laws beside `law`'s own at 12 bits, made from that one, which the coder
    /// may take instead where the residuals leave room ([`Deeper`]); `None`: the own alone.
    pub coarser_12: Option<fn(PictureLaw) -> Vec<PictureLaw>>,
    /// The affine maps' precision (over the residual step) it measured best.
    pub affine_precision: f64,
}

/// The 12-bit pictures a plan may code, decided on its residuals ([`RatePlan::depth_choices`]):
/// at the automatic depth's 10 bits (HEVC and AV1 at the law's quantiser), the pictures the
/// geometry-video coder takes where its residuals outgrow 10-bit samples at the pixel step, since
/// a widened step is error the quality did not ask for and costs more bits at equal error than
/// 12-bit samples do; and the codec's other 12-bit laws, which the encoder tries where the
/// residuals leave room for them (AV1's, `av1::av1_coarser_laws_12`; docs/design.md, "Sample depth").
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Deeper {
    /// The codec's quantiser and pixel step at 12 bits: the law's own first, then coarser
    /// quantisers at finer pixel steps (the same quantiser step in model units).
    pub rungs: Vec<(u8, f32)>,
}

impl Deeper {
    /// The law's own rung.
    fn own(&self) -> (u8, f32) {
        self.rungs.first().copied().unwrap_or_default()
    }

    /// The rung of the coarsest quantiser whose pixel step is not finer than `unwidened` (the
    /// finest step at which the residuals fit 12-bit samples), where that is not the law's own.
    fn roomiest(&self, unwidened: f64) -> Option<(u8, f32)> {
        let fits = |&&(_, step): &&(u8, f32)| f64::from(step) >= unwidened;
        let rung = self.rungs.iter().skip(1).rev().find(fits);
        rung.copied()
    }
}

impl RatePlan {
    /// This plan at the depth its pictures of `residuals` want ([`Self::depth_choices`]).
    pub(crate) fn at_depth_for(self, residuals: &[Vec<[f32; 3]>]) -> Self {
        self.depth_choices(residuals).0
    }

    /// This plan at the depth its pictures of `residuals` want, and the other 12-bit plan the
    /// encoder may code beside it. At the automatic depth's 10 bits with a 12-bit alternative
    /// ([`Deeper`]), the 12-bit plan where 10-bit samples would widen a group's step at the pixel
    /// step, else the 10-bit one; other plans as they are. At 12 bits with the law's quantiser,
    /// also the codec's coarsest other 12-bit law the residuals leave room for (AV1's): the
    /// encoder codes both and keeps the fewer bits at equal error. The encoder decides on the
    /// clip's residuals, every frame of them, before coding any.
    pub(crate) fn depth_choices(mut self, residuals: &[Vec<[f32; 3]>]) -> (Self, Option<Self>) {
        let Some(pictures) = self.pictures.as_mut() else {
            return (self, None);
        };
        let Some(deeper) = pictures.deeper.take() else {
            return (self, None);
        };
        let spread = quantise::spread(residuals, pictures.ranges(), self.step);
        let widens = f64::from(self.step) < quantise::unwidened_step(spread, pictures.depth);
        if pictures.depth < 12 && !widens {
            return (self, None);
        }
        self.deepen(deeper.own());
        let roomiest = deeper.roomiest(quantise::unwidened_step(spread, 12));
        let other = roomiest.map(|rung| {
            let mut other = self.clone();
            other.deepen(rung);
            other
        });
        (self, other)
    }

    /// 12-bit pictures at `quantiser` and pixel step `step` in place of this plan's.
    fn deepen(&mut self, (quantiser, step): (u8, f32)) {
        if let Some(pictures) = self.pictures.as_mut() {
            pictures.depth = 12;
            pictures.quantiser = quantiser;
            self.step = step;
        }
    }

    /// This plan as the set-up part `setup` of a stream of `vertices` vertices says its pictures
    /// were coded: where the residuals decide ([`Deeper`]), at the depth and quantiser that
    /// stream took (the law's own at 12 bits where no law has that quantiser), so that the
    /// segments of a stream code what its analysis clip chose. Other plans stay as they are.
    pub(crate) fn pinned_to(mut self, setup: &[u8], vertices: u32) -> Result<Self> {
        let Some(pictures) = self.pictures.as_mut() else {
            return Ok(self);
        };
        let Some(deeper) = pictures.deeper.take() else {
            return Ok(self);
        };
        let setup = PictureSetup::from_bytes(setup, vertices)?;
        let taken = deeper.rungs.iter().find(|rung| rung.0 == setup.quantiser);
        if setup.depth == 12 {
            self.deepen(taken.copied().unwrap_or(deeper.own()));
        }
        Ok(self)
    }
}

