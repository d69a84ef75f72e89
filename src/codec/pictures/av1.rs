//! AV1 at 10 or 12 bits a sample: FFmpeg's `libaom-av1` encoder and its preferred AV1 decoder
//! (`libdav1d` in Debian's libavcodec 59), through `ffmpeg-next` (cargo feature `mpeg4`, which
//! brings FFmpeg); the encoder, decoder and set-up part are [`super::deep`]'s, shared with HEVC.
//!
//! The x | y | z picture is the three planes of a 4:4:4 picture, as for HEVC: profile 1 at 10 bits,
//! profile 2 at 12 (libaom picks the profile from the pixel format). The quantiser is libaom's
//! constant-quality level (`crf` 0..63, end usage `q`: no rate control), `tune=psnr`. A key frame
//! every `gop` frames (every frame with `gop` 1: all-intra), P-frames between, which look ahead
//! [`LAG_IN_FRAMES`] frames for hidden alternate-reference frames; one packet per frame (a hidden
//! frame rides in the packet of a shown one), in order, the sequence header in-band on every key
//! frame. One thread and no row multi-threading, so the output does not depend on scheduling.
//!
//! `cpu-used` [`CPU_USED`] trades compression for speed (docs/results.md, "AV1").

use super::deep::{self, Flavour};
use super::{Codec, PictureLaw};
use ffmpeg_next::{codec, Dictionary};

/// The largest quantiser (`crf`) libaom takes.
pub const MAX_QP: u8 = 63;
/// libaom's speed preset: 0 (slowest, smallest) ..= 6 in its "good" usage. 4 measured 2 % lower
/// RMSE at equal rate on CesiumMan (quality 50 / 75) for 50 % / 42 % more encode CPU time.
pub const CPU_USED: u8 = 6;
/// Frames libaom looks ahead in a P-frame group (`--gop` above 1), which lets it code hidden
/// alternate-reference frames (`auto-alt-ref`): a future frame coded first, shown later, that the
/// frames between predict from. The hidden frame travels in the packet of a shown frame (AV1's
/// temporal unit), so the stream keeps one packet per frame, in order. Measured against no look-ahead
/// (docs/results.md, "AV1 tuning"): 13–20 % fewer bits at equal RMSE on walking_cat and pcow, and
/// less encode time.
pub const LAG_IN_FRAMES: u8 = 19;
/// Strength of the temporal filter libaom runs over the frames an alternate reference stands for:
/// 0, no filtering (docs/results.md, "AV1 tuning").
pub const ARNR_STRENGTH: u8 = 0;

/// libaom's encoder and FFmpeg's AV1 decoder.
#[derive(Debug, Clone, Copy)]
pub struct Libaom;

/// AV1 as the geometry-video picture codec.
pub const PICTURES: deep::Pictures<Libaom> = deep::Pictures(Libaom);

impl Flavour for Libaom {
    fn name(&self) -> &'static str {
        "av1"
    }

    fn codec(&self) -> Codec {
        Codec::Av1
    }

    fn encoder_name(&self) -> &'static str {
        "libaom-av1"
    }

    fn decoder_id(&self) -> codec::Id {
        codec::Id::AV1
    }

    fn max_qp(&self) -> u8 {
        MAX_QP
    }

    fn law(&self, quality: u8, depth: u8) -> PictureLaw {
        super::av1_law(quality, depth)
    }

    /// Constant quality at `crf` = the quantiser, key frames exactly every `gop` frames
    /// (`keyint_min` = `g`), one tile, no row threads; P-frame groups look ahead and code hidden
    /// alternate-reference frames, all-intra streams do not.
    fn settings(&self, options: &deep::Options, gop: u32) -> Dictionary<'static> {
        let mut dict = Dictionary::new();
        dict.set("usage", "good");
        dict.set("cpu-used", &CPU_USED.to_string());
        dict.set("crf", &options.qp.to_string());
        // libaom's constant-quality mode gives key frames a finer quantiser than `crf`, as x265's
        // fixed QP does (its I/P ratio); pinning every frame to `crf` (`qmin` = `qmax`) measured
        // 30 % more bits at equal error (CesiumMan, pixel step 5e-5: 5.06 bpvf at RMSE 2.43e-4
        // with `crf` 12 pinned, 3.82 at 2.45e-4 with `crf` 32 free). These are libaom's own
        // bounds: FFmpeg's generic defaults (2..31, MPEG-4's qscale range) would clamp every `crf`
        // above 31 to 31 (measured: CesiumMan's rate and error stop changing from `crf` 32 up).
        dict.set("qmin", "0");
        dict.set("qmax", &MAX_QP.to_string());
        dict.set("keyint_min", &gop.to_string());
        let (lag, alt_ref) = if gop > 1 {
            (LAG_IN_FRAMES, "1")
        } else {
            (0, "0")
        };
        dict.set("lag-in-frames", &lag.to_string());
        dict.set("auto-alt-ref", alt_ref);
        dict.set("arnr-strength", &ARNR_STRENGTH.to_string());
        dict.set("row-mt", "0");
        dict.set("tune", "psnr");
        dict.set("aq-mode", "none");
        dict
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn deep_planes_round_trip_with_key_frames_every_gop() {
        // crf 4 (qindex 16) is a step of about one level of an 8-bit picture.
        deep::testing::round_trip(&Libaom, 4, 4);
    }

    #[test]
    fn the_automatic_depth_is_12_bits_from_quality_90() {
        use crate::codec::geometry_video::PictureCodec;
        use crate::encoder::EncodeOptions;
        let at = |quality, bit_depth| {
            let opts = EncodeOptions {
                codec: Codec::Av1,
                quality,
                bit_depth,
                ..EncodeOptions::default()
            };
            (
                PICTURES.depth(&opts),
                super::super::hevc::PICTURES.depth(&opts),
            )
        };
        assert_eq!(at(89, None), (10, 10));
        assert_eq!(at(90, None), (12, 12));
        assert_eq!(at(97, Some(10)), (10, 10));
        assert_eq!(at(50, Some(12)), (12, 12));
    }

    #[test]
    fn bad_settings_are_errors() {
        deep::testing::bad_settings_are_errors(Libaom, 32);
    }
}
