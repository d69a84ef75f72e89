//! HEVC (H.265) at 10 or 12 bits a sample: FFmpeg's `libx265` encoder and its native `hevc`
//! decoder, through `ffmpeg-next` (cargo feature `mpeg4`, which brings FFmpeg); the encoder,
//! decoder and set-up part are [`super::deep`]'s, shared with AV1.
//!
//! The x | y | z picture is coded as the three planes of a 4:4:4 picture (`yuv444p10le`,
//! `yuv444p12le`), which shares block modes and motion vectors between the coordinates: measured
//! 3–9 % smaller at equal error than the three side by side in one monochrome (4:0:0) picture
//! (`gray10le`, `gray12le`; [`Planes::Mono`], which the decoder also reads) on CesiumMan and the
//! walking cat at quality 30/50/75 (docs/results.md).
//! The quantiser is a fixed QP (`qp=`, no rate control, `tune=psnr`: no psycho-visual tricks, which
//! spend bits on what looks sharp rather than on the error). No B-frames, no scene cuts, no open
//! GOPs: an IDR every `gop` frames (every frame with `gop` 1: all-intra), P-frames between, so each
//! frame gives exactly one packet, in order, and decoding can start at any IDR. Headers are
//! in-band (`repeat-headers`: VPS/SPS/PPS on every IDR). x265 runs without its thread pool and with
//! one frame thread, so its output does not depend on scheduling: the geometry-video coder runs
//! groups of pictures on several threads instead.
//!
//! The stream's codec set-up part holds the sample depth and the planes (one byte each), which the
//! decoder needs before any picture (the depth to read the residual ranges).

use super::deep::{self, Flavour};
use super::{Codec, PictureLaw};
use ffmpeg_next::{codec, Dictionary};

pub use super::deep::{Packet, Planes, DEFAULT_PLANES, DEPTHS};

/// The largest QP x265 takes.
pub const MAX_QP: u8 = 51;

/// Encoder settings.
pub type HevcOptions = deep::Options;

/// libx265 and FFmpeg's `hevc` decoder.
#[derive(Debug, Clone, Copy)]
pub struct X265;

/// HEVC as the geometry-video picture codec.
pub const PICTURES: deep::Pictures<X265> = deep::Pictures(X265);

impl Flavour for X265 {
    fn name(&self) -> &'static str {
        "hevc"
    }

    fn codec(&self) -> Codec {
        Codec::Hevc
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

    fn law(&self, quality: u8, depth: u8) -> PictureLaw {
        super::hevc_law(quality, depth)
    }

    /// `x265-params` of a fixed QP, IDR frames every `gop` frames, no B-frames, scene cuts or open
    /// GOPs, headers on every IDR, no thread pool and one frame thread.
    fn settings(&self, options: &deep::Options, gop: u32) -> Dictionary<'static> {
        let mut dict = Dictionary::new();
        dict.set("preset", "medium");
        dict.set("tune", "psnr");
        let params = format!(
            "qp={qp}:keyint={gop}:min-keyint={gop}:scenecut=0:open-gop=0:bframes=0:\
             repeat-headers=1:info=0:pools=none:frame-threads=1:log-level=error",
            qp = options.qp
        );
        dict.set("x265-params", &params);
        dict
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn deep_planes_round_trip_with_idr_frames_every_gop() {
        // QP 4 is a step of about one level of an 8-bit picture.
        deep::testing::round_trip(&X265, 4, 4);
    }

    #[test]
    fn bad_settings_are_errors() {
        deep::testing::bad_settings_are_errors(X265, 22);
    }
}
