//! HEVC (H.265) at 10 or 12 bits a sample: FFmpeg's `libx265` encoder and its native `hevc`
//! decoder, through `ffmpeg-next` (cargo feature `ffmpeg`); the encoder,
//! decoder and set-up part are [`super::deep`]'s, shared with AV1.
//!
//! The x | y | z picture is coded as the three planes of a 4:4:4 picture (`yuv444p10le`,
//! `yuv444p12le`), which shares block modes and motion vectors between the coordinates: fewer bits
//! at equal error than the three side by side in one monochrome (4:0:0) picture (`gray10le`,
//! `gray12le`; `Planes::Mono`, which the decoder also reads; docs/design.md, "HEVC settings").
//! The quantiser is a fixed QP (`qp=`, no rate control, `tune=psnr`: no psycho-visual tricks, which
//! spend bits on what looks sharp rather than on the error). No B-frames, no scene cuts, no open
//! GOPs: an IDR every `gop` frames (every frame with `gop` 1: all-intra), P-frames between, so each
//! frame gives exactly one packet, in order, and decoding can start at any IDR. Headers are
//! in-band (`repeat-headers`: VPS/SPS/PPS on every IDR). x265 runs without its thread pool and with
//! one frame thread, so its output does not depend on scheduling (the geometry-video coder runs
//! groups of pictures on several threads instead), and codes trees of 32 pixels, not 64, whose
//! path reads memory x265 never wrote (docs/design.md, "HEVC settings").
//!
//! The stream's codec set-up part holds the sample depth and the planes (one byte each), which the
//! decoder needs before any picture (the depth to read the residual ranges).

use super::deep::DeepConfig;
use super::depth::DeepLaws;
use crate::codec::rate::{ijg_scale_percent, PictureLaw, Rate, RatePlan};
use crate::codec::Codec;
use crate::error::Result;
use super::AFFINE_PRECISION;

#[cfg(feature = "ffmpeg")]
pub(crate) use coder::PICTURES;

/// The largest QP x265 takes.
pub const MAX_QP: u8 = 51;

/// Fails, naming the option, when one of `config` is out of range for HEVC.
pub(crate) fn check(config: &DeepConfig) -> Result<()> {
    config.check(Codec::Hevc, MAX_QP)
}

/// The plan of `rate` on a first frame of bounding-box diagonal `diagonal`: [`hevc_law`], affine
/// maps at [`AFFINE_PRECISION`] of the residual step in P-frame groups too
/// (docs/design.md, "Affine precision per codec").
pub(crate) fn plan(config: &DeepConfig, rate: &Rate, diagonal: f64) -> Result<RatePlan> {
    let laws = DeepLaws {
        law: hevc_law_at,
        coarser_12: None,
        affine_precision: AFFINE_PRECISION,
    };
    config.plan(Codec::Hevc, laws, rate, diagonal)
}

/// HEVC's law at 10 bits a sample: a pixel step of [`HEVC_STEP_FACTOR`] × the target step and the
/// QP that follows the target step, 6 per halving ([`HEVC_QP_AT_50`] at quality 50), between
/// [`HEVC_MIN_QP`] and 51; beyond them the pixel step takes the rest. At equal error the rate
/// hardly depends on how pixel step and QP share it, except that QPs under 10 cost more than a
/// finer pixel step; quality 50 lands on MPEG-4's error at quality 50
/// (docs/design.md, "Quality laws (JPEG, MPEG-4, HEVC, AV1)").
pub const HEVC_STEP_FACTOR: f64 = 0.02;
/// The QP of quality 50 at 10 bits a sample.
pub const HEVC_QP_AT_50: f64 = 28.0;
/// The lowest QP the law uses at 10 bits a sample.
pub const HEVC_MIN_QP: f64 = 10.0;

/// HEVC's pixel step factor and QP for a user quality 1..100 at `depth` bits a sample. A deeper
/// sample takes the same pixel step and a QP 6 lower per bit over 10: HEVC's QP is relative to the
/// sample range, so this is the same quantiser step in model units; what 12 bits add is a finer
/// rounding of the samples. The QP stops at 0.
#[cfg_attr(not(any(test, feature = "internals")), allow(dead_code))]
pub fn hevc_law(quality: u8, depth: u8) -> PictureLaw {
    hevc_law_at(f64::from(ijg_scale_percent(quality).max(1)), depth)
}

/// [`hevc_law`] at the IJG scale `scale_percent` of a quality (between the integers too).
pub(crate) fn hevc_law_at(scale_percent: f64, depth: u8) -> PictureLaw {
    let scale = scale_percent / 100.0;
    let deeper = 6.0 * (f64::from(depth) - 10.0);
    let exact = HEVC_QP_AT_50 + 6.0 * scale.log2() - deeper;
    let qp = exact.round().clamp((HEVC_MIN_QP - deeper).max(0.0), 51.0);
    // The pixel step takes what the integer QP cannot: the rest beyond its bounds, and within
    // them the rounding, so that the step follows a fine quality between two QPs.
    let rest = exact - qp;
    PictureLaw {
        step_factor: HEVC_STEP_FACTOR * 2f64.powf(rest / 6.0),
        quantiser: qp as u8,
    }
}

/// libx265 as a [`deep::Flavour`].
#[cfg(feature = "ffmpeg")]
mod coder {
    use super::super::deep::{self, Flavour};
    use super::MAX_QP;
    use ffmpeg_next::{codec, Dictionary};

    /// libx265 and FFmpeg's `hevc` decoder.
    #[derive(Debug, Clone, Copy)]
    pub struct X265;

    /// HEVC as the geometry-video picture codec.
    pub(crate) const PICTURES: deep::Pictures<X265> = deep::Pictures(X265);

    impl Flavour for X265 {
        fn name(&self) -> &'static str {
            "hevc"
        }

        fn encoder_name(&self) -> &'static str {
            "libx265"
        }

        fn decoder_id(&self) -> codec::Id {
            codec::Id::HEVC
        }

        fn max_qp(&self) -> u8 {
            MAX_QP
        }

        /// `x265-params` of a fixed QP, IDR frames every `gop` frames, no B-frames, scene cuts or open
        /// GOPs, headers on every IDR, and nothing whose result can depend on timing or on memory
        /// x265 leaves unwritten: no thread pool (hence no wavefront, parallel mode or motion
        /// analysis, lookahead slices or threads, each also turned off by name), one frame thread,
        /// and coding tree units of 32 pixels: with x265 3.5's 64, its reference limits and its
        /// motion compensation read memory it never wrote, so the same pictures came out as
        /// different bytes from one encoder to the next (docs/design.md, "HEVC settings"). A
        /// picture narrower or lower than 32 takes 16-pixel units: x265 refuses a picture smaller
        /// than one unit ("Picture size must be at least one CTU").
        fn settings(
            &self,
            options: &deep::Options,
            gop: u32,
            (width, height): (u32, u32),
        ) -> Dictionary<'static> {
            let mut dict = Dictionary::new();
            dict.set("preset", "medium");
            dict.set("tune", "psnr");
            let ctu = if width.min(height) >= 32 { 32 } else { 16 };
            let params = format!(
                "qp={qp}:keyint={gop}:min-keyint={gop}:scenecut=0:open-gop=0:bframes=0:\
                 repeat-headers=1:info=0:pools=none:frame-threads=1:wpp=0:pmode=0:pme=0:\
                 lookahead-slices=0:lookahead-threads=0:ctu={ctu}:log-level=error",
                qp = options.qp
            );
            dict.set("x265-params", &params);
            dict
        }
    }
}

#[cfg(all(test, feature = "ffmpeg"))]
mod tests {
    use super::coder::*;
    use crate::codec::pictures::deep;

    #[test]
    fn deep_planes_round_trip_with_idr_frames_every_gop() {
        // QP 4 is a step of about one level of an 8-bit picture.
        deep::testing::round_trip(&X265, 4, 4);
    }

    #[test]
    fn bad_settings_are_errors() {
        deep::testing::bad_settings_are_errors(X265, 22);
    }

    /// With x265's 64-pixel coding trees, 10 runs of this gave 4 to 9 different streams.
    #[test]
    fn the_same_pictures_give_the_same_bytes_every_run() {
        deep::testing::same_bytes_every_run(&X265, 60, 50, 6);
    }
}
