//! The picture path: residuals as geometry images coded by a picture codec.
//!
//! [`geometry_video`] splats each frame's residuals onto a multi-chart atlas, pads and tiles them
//! into one picture per frame and hands the pictures to a `PictureCodec`: JPEG ([`jpeg`], every
//! frame alone), or through FFmpeg (cargo feature `ffmpeg`) MPEG-4 Part 2 ([`mpeg4`]) and HEVC and
//! AV1 at 10 or 12 bits a sample ([`hevc`], [`av1`], sharing [`deep`]). Each codec's file holds its
//! configuration, its quality law and its coder; what they share — the lattice and padding options
//! and the resolved `PicturePlan` — is here.

pub mod abbreviated;
pub mod av1;
pub mod deep;
mod depth;
pub mod geometry_video;
pub mod hevc;
pub mod jpeg;
#[cfg(feature = "ffmpeg")]
mod libav;
pub mod mpeg4;
mod setup;

use super::rate::{PictureLaw, Rate, RatePlan};
use super::Codec;
use crate::error::{Error, Result};
pub use crate::geometry_image::Plane;
use crate::geometry_image::{lattice, Lattice, RangeMode};
use crate::stream::frame_index::FrameChunk;
pub(crate) use depth::Deeper;
pub(crate) use setup::PictureSetup;

/// The affine precision of JPEG and HEVC: 3/16 of the residual step, as tdct's (a quarter until
/// the maps followed a nearby cluster, which made them cheaper: 3/16 then coded CesiumMan,
/// chickenCrossing and pdance 0.4-3.5 % smaller at equal error, horse-gallop about the same,
/// pcow and walking_cat 0.3-1.8 % larger; docs/design.md, "Affine precision per codec").
pub(crate) const AFFINE_PRECISION: f64 = 3.0 / 16.0;

/// The residual step (a fraction of the diagonal) at and below which P-frame groups (MPEG-4, AV1)
/// take their affine maps at 1/16 of the step instead of 1/8: between quality 84 (3.2e-4) and 85
/// (3e-4).
const FINE_P_FRAME_STEP: f64 = 3.1e-4;

/// The affine precision of MPEG-4's and AV1's P-frame groups: 1/8 of the residual step, 1/16 from
/// quality 85 (or an explicit step that fine), where the maps' white quantisation noise spoils the
/// prediction between frames more than finer maps cost (docs/design.md, "Affine precision per
/// codec").
pub(crate) fn p_frame_affine_precision(rate: &Rate) -> f64 {
    if rate.step_fraction() > FINE_P_FRAME_STEP {
        1.0 / 8.0
    } else {
        1.0 / 16.0
    }
}

/// Frames per group of pictures of the video codecs unless asked otherwise.
pub const DEFAULT_GOP: usize = 50;

/// The options every picture codec's configuration holds: the lattice its geometry images are
/// laid on and how their free pixels are filled.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PictureOptions {
    /// Lattice width and height, or chosen from the mesh (the smallest the charts fit).
    pub lattice: Lattice,
    /// How free pixels are filled; `None` takes the codec's measured best.
    pub padding: Option<padding::Method>,
}

impl PictureOptions {
    /// Fails, naming the option, on a lattice the stream cannot carry, or on `snap` padding for a
    /// codec that is not JPEG (it models JPEG's quantiser at the picture's quality).
    pub(crate) fn check(&self, codec: Codec) -> Result<()> {
        if let Lattice::Fixed(w, h) = self.lattice {
            lattice::check(w, h)?;
        }
        if self.padding == Some(padding::Method::Snap) && codec != Codec::Jpeg {
            return Err(Error::option(
                "padding",
                format!(
                    "snap models JPEG's quantiser and applies to the jpeg codec only, not {}",
                    codec.name()
                ),
            ));
        }
        Ok(())
    }
}

/// A picture codec's settings for one encoding, resolved from its configuration and the quality.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PicturePlan {
    /// Which picture codec.
    pub codec: Codec,
    /// The codec's own quantiser: JPEG quality, MPEG-4 qscale, HEVC QP or AV1 `crf`.
    pub quantiser: u8,
    /// Frames per group of pictures: a key frame, then P-frames (1: every frame alone).
    pub gop: usize,
    /// Bits a sample of the pictures.
    pub depth: u8,
    /// How free pixels are filled.
    pub padding: padding::Method,
    /// The lattice option.
    pub lattice: Lattice,
    /// The 12-bit pictures the coder takes by the residuals ([`Deeper`]): at the automatic depth
    /// at 10 bits, where 10-bit samples would widen a group's step; at 12 bits, the law the
    /// residuals leave room for.
    pub deeper: Option<Deeper>,
}

impl PicturePlan {
    /// How residual ranges are shared: by the frames of a group of pictures, so that P-frames
    /// predict like from like (one frame a group for intra coding).
    pub fn ranges(&self) -> RangeMode {
        match self.gop {
            0 | 1 => RangeMode::PerFrame,
            n => RangeMode::PerGroup(n),
        }
    }
}

/// What a picture codec's configuration resolves of an encoding by its law: the rest of its plan
/// (lattice, padding) is the caller's [`PictureOptions`].
pub(crate) struct Resolved {
    /// Which picture codec.
    pub codec: Codec,
    /// The pixel step as a multiple of the quality's target step.
    pub step_factor: f64,
    /// The codec's own quantiser.
    pub quantiser: u8,
    /// Frames per group of pictures.
    pub gop: usize,
    /// Bits a sample.
    pub depth: u8,
    /// The padding the codec measured best, unless the caller asks another.
    pub padding: padding::Method,
    /// The affine precision the codec measured best, unless the caller asks another.
    pub affine_precision: f64,
    /// The 12-bit laws the residuals choose from ([`Deeper`]), the law's own first; none where
    /// the plan is fixed.
    pub deeper: Vec<PictureLaw>,
}

/// The rate plan of a picture codec: its pixel step from the law's factor, the lattice and
/// padding of `options` (the padding: the caller's or the codec's default).
pub(crate) fn plan(
    rate: &Rate,
    diagonal: f64,
    options: &PictureOptions,
    resolved: Resolved,
) -> Result<RatePlan> {
    let step = rate.stored_step("pixel step", diagonal, resolved.step_factor)?;
    let rungs = resolved.deeper.iter().map(|law| {
        let step = rate.stored_step("pixel step", diagonal, law.step_factor)?;
        Ok((law.quantiser, step))
    });
    let rungs = rungs.collect::<Result<Vec<_>>>()?;
    let deeper = (!rungs.is_empty()).then_some(Deeper { rungs });
    let plan = PicturePlan {
        codec: resolved.codec,
        quantiser: resolved.quantiser,
        gop: resolved.gop,
        depth: resolved.depth,
        padding: options.padding.unwrap_or(resolved.padding),
        lattice: options.lattice,
        deeper,
    };
    Ok(rate.plan(step, resolved.affine_precision, resolved.codec, Some(plan)))
}

/// What a picture codec (one file per codec) tells the geometry-video coder. `Sync`: groups of
/// pictures are coded on several threads at once.
pub(crate) trait PictureCodec: Sync {
    /// The padding options of the pictures `plan` codes: a method that models the codec's
    /// quantiser is given it.
    fn padding(&self, plan: &PicturePlan) -> padding::PaddingOptions {
        padding::PaddingOptions::with_method(plan.padding)
    }
    /// The codec's settings as reports name them (its options' names), from its quantiser, its
    /// frames per group and its bits a sample.
    fn settings(&self, quantiser: u8, gop: u32, depth: u8) -> Vec<(&'static str, u32)>;
    /// An encoder for `width`×`height` pictures whose first picture is frame `first_frame` of the
    /// sequence (a key frame: every group of pictures gets its own encoder).
    #[cfg(feature = "encode")]
    fn encoder(
        &self,
        width: u32,
        height: u32,
        first_frame: usize,
        plan: &PicturePlan,
    ) -> Result<Box<dyn PictureEncoder>>;
    /// A decoder for `width`×`height` pictures of a stream with set-up `setup`.
    fn decoder(
        &self,
        width: u32,
        height: u32,
        setup: &PictureSetup,
    ) -> Result<Box<dyn PictureDecoder>>;
}

/// A picture codec this build cannot decode (MPEG-4, HEVC and AV1 without the `ffmpeg` feature):
/// its streams open all the same, and their pictures, decoded outside (a browser's WebCodecs),
/// come back through `Decoder::decode_frame_from_picture`.
#[cfg(not(feature = "ffmpeg"))]
pub(crate) struct Outside(pub Codec);

#[cfg(not(feature = "ffmpeg"))]
impl PictureCodec for Outside {
    fn settings(&self, quantiser: u8, gop: u32, depth: u8) -> Vec<(&'static str, u32)> {
        match self.0 {
            Codec::Mpeg4 => vec![("qscale", quantiser.into()), ("gop", gop)],
            _ => vec![
                ("qp", quantiser.into()),
                ("gop", gop),
                ("bit_depth", depth.into()),
            ],
        }
    }

    #[cfg(feature = "encode")]
    fn encoder(
        &self,
        _width: u32,
        _height: u32,
        _first_frame: usize,
        _plan: &PicturePlan,
    ) -> Result<Box<dyn PictureEncoder>> {
        Err(super::unavailable(self.0))
    }

    fn decoder(
        &self,
        _width: u32,
        _height: u32,
        _setup: &PictureSetup,
    ) -> Result<Box<dyn PictureDecoder>> {
        Err(Error::Codec(format!(
            "this build has no {} decoder (built without the `ffmpeg` feature): decode the \
             pictures outside (Decoder::coded_picture) and hand them to \
             Decoder::decode_frame_from_picture",
            self.0.name()
        )))
    }
}

/// Codes pictures in frame order.
#[cfg(feature = "encode")]
pub(crate) trait PictureEncoder {
    /// Codes the next frame's picture (samples of the codec's depth).
    fn push(&mut self, plane: &Plane<u16>) -> Result<()>;
    /// Ends the sequence: the codec's own bytes of the set-up part, and one chunk per frame.
    fn finish(self: Box<Self>) -> Result<(Vec<u8>, Vec<FrameChunk>)>;
}

/// Decodes pictures, starting at a key frame and continuing in order (`Send`: see
/// [`ResidualDecoder`](crate::codec::ResidualDecoder)).
pub(crate) trait PictureDecoder: Send {
    /// Decodes frame `f` from its chunk.
    fn decode(&mut self, f: usize, chunk: &[u8]) -> Result<Plane<u16>>;
}

#[cfg(test)]
mod tests {
    use super::av1::{av1_law, av1_law_at, av1_log2_step, AV1_MAX_QP, AV1_QP_AT_50, AV1_STEP_FACTOR};
    use super::hevc::{hevc_law, hevc_law_at, HEVC_QP_AT_50, HEVC_STEP_FACTOR};
    use super::jpeg::{jpeg_law, jpeg_law_at, jpeg_quantiser_step};
    use super::mpeg4::{mpeg4_law, mpeg4_law_at, mpeg4_quantiser_step};
    use crate::codec::rate::{fine_scale_percent, target_step, PictureLaw};

    /// Fails unless log2 of pixel step × quantiser step, read at each of `points` in turn (finer
    /// and finer), falls at every one and by less than 0.01 (no jump for a budget search to meet).
    fn falls_without_jumps(
        mut points: impl Iterator<Item = f64>,
        log2_steps: impl Fn(f64) -> f64,
        what: &str,
    ) {
        let Some(first) = points.next() else { return };
        let mut last = log2_steps(first);
        for x in points {
            let now = log2_steps(x);
            let fall = last - now;
            assert!(fall > 0.0 && fall < 0.01, "{what}: {fall} at {x}");
            last = now;
        }
    }

    /// IJG scales from 200 % down to 1 %, 0.1 % apart.
    fn scales() -> impl Iterator<Item = f64> {
        std::iter::successors(Some(200.0f64), |s| Some(s * 0.999)).take_while(|s| *s > 1.0)
    }

    #[test]
    fn pixel_step_and_quantiser_together_follow_a_fine_quality_without_jumps() {
        // JPEG and MPEG-4 read qualities (1 to 100, 0.005 apart), HEVC and AV1 IJG scales.
        let qualities = || (0..=19_800).map(|i| 1.0 + f64::from(i) * 0.005);
        let log2_scale = |q: f64| (fine_scale_percent(q) / 100.0).log2();
        type Law = (fn(f64) -> PictureLaw, fn(u8) -> f64, &'static str);
        let anchored: [Law; 2] = [
            (jpeg_law_at, jpeg_quantiser_step, "JPEG"),
            (mpeg4_law_at, mpeg4_quantiser_step, "MPEG-4"),
        ];
        for (law_at, quantiser_step, name) in anchored {
            let log2_steps = |q: f64| {
                let law = law_at(q);
                log2_scale(q) + (law.step_factor * quantiser_step(law.quantiser)).log2()
            };
            falls_without_jumps(qualities(), log2_steps, name);
        }
        for depth in [10, 12] {
            falls_without_jumps(
                scales(),
                |s| {
                    let law = hevc_law_at(s, depth);
                    let qp = f64::from(law.quantiser);
                    (s / 100.0).log2() + law.step_factor.log2() + qp / 6.0
                },
                &format!("HEVC at {depth} bits"),
            );
            falls_without_jumps(
                scales(),
                |s| {
                    let law = av1_law_at(s, depth);
                    let crf = f64::from(law.quantiser);
                    (s / 100.0).log2() + law.step_factor.log2() + av1_log2_step(crf, depth)
                },
                &format!("AV1 at {depth} bits"),
            );
        }
        // Quality 50 sits on its quantisers: the pixel steps are the laws' factors.
        assert!((hevc_law(50, 10).step_factor - HEVC_STEP_FACTOR).abs() < 1e-12);
        assert!((av1_law(50, 10).step_factor - AV1_STEP_FACTOR).abs() < 1e-12);
    }

    #[test]
    fn pixel_steps_fall_and_quantisers_do_not_coarsen_with_quality() {
        // The pixel step may rise where the quantiser falls (HEVC's and AV1's take their integer
        // quantisers' rounding, JPEG's and MPEG-4's meet a finer quantiser at an anchor): the
        // two together fall (above). Where the quantiser holds, the pixel step falls.
        let hevc10 = |q| hevc_law(q, 10);
        let hevc12 = |q| hevc_law(q, 12);
        let av1_10 = |q| av1_law(q, 10);
        let av1_12 = |q| av1_law(q, 12);
        for law in [jpeg_law, mpeg4_law, hevc10, hevc12, av1_10, av1_12] {
            for q in 1..100u8 {
                let (a, b) = (law(q), law(q + 1));
                let step = |l: PictureLaw, q| l.step_factor * target_step(q, 1.0);
                let held = a.quantiser == b.quantiser;
                assert!(!held || step(b, q + 1) <= step(a, q), "pixel step grows at {q}");
            }
        }
        for q in 1..100u8 {
            assert!(jpeg_law(q + 1).quantiser >= jpeg_law(q).quantiser);
            assert!(mpeg4_law(q + 1).quantiser <= mpeg4_law(q).quantiser);
            assert!((1..=31).contains(&mpeg4_law(q).quantiser));
            assert!(hevc_law(q + 1, 10).quantiser <= hevc_law(q, 10).quantiser);
            assert!(hevc_law(q, 12).quantiser <= 51);
            assert!(av1_law(q + 1, 10).quantiser <= av1_law(q, 10).quantiser);
            assert!(av1_law(q, 10).quantiser <= 63);
        }
        assert_eq!(hevc_law(50, 10).quantiser, HEVC_QP_AT_50 as u8);
        assert_eq!(hevc_law(50, 12).quantiser, HEVC_QP_AT_50 as u8 - 12);
        assert_eq!(av1_law(50, 10).quantiser, AV1_QP_AT_50);
        // The 12-bit crf of quality 50 has a quarter of the 10-bit step (700 / 4 = 175: crf 11).
        assert_eq!(av1_law(50, 12).quantiser, 11);
        assert_eq!(av1_law(10, 10).quantiser, AV1_MAX_QP);
        assert!(av1_law(10, 10).step_factor > AV1_STEP_FACTOR);
    }
}
