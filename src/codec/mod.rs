//! Residual coders: how the motion the predictor leaves over is stored.
//!
//! Every codec implements one interface, [`ResidualEncoder`] and [`ResidualDecoder`], owns its
//! options (a variant of [`CodecConfig`], its type in the codec's own file) and its quality law
//! (turning the caller's rate into a [`RatePlan`]), and writes its own parts. The places that know
//! which codecs exist are [`Codec`] and [`CodecConfig`]: a new codec is one new module and one
//! variant of each (docs/design.md, "The codec interface").
//!
//! - [`pictures`] is the papers' geometry video: the residuals are splatted onto a multi-chart
//!   atlas, padded, and coded as pictures — one JPEG per frame (any frame decodes alone), or
//!   through FFmpeg (cargo feature `ffmpeg`) MPEG-4 Part 2 I- and P-frames and HEVC and AV1 at 10
//!   or 12 bits a sample.
//! - [`tdct`] is the follow-up paper's temporal DCT: each vertex's residual trajectory transformed
//!   over all frames and coded band by band, no images.

mod interface;
pub mod pictures;
mod rate;
pub mod tdct;

pub use interface::{BandsDescription, Description, PicturesDescription};
pub(crate) use interface::{
    CodedResiduals, ResidualDecoder, ResidualEncoder, ResidualInput, StreamLayout,
};
pub use pictures::deep::DeepConfig;
pub use pictures::jpeg::JpegConfig;
pub use pictures::mpeg4::Mpeg4Config;
pub use pictures::{abbreviated, geometry_video, jpeg, PictureOptions, Plane};
#[cfg(feature = "ffmpeg")]
pub use pictures::{av1, deep, hevc, mpeg4};
pub(crate) use rate::Rate;
pub use rate::{ijg_scale_percent, target_step, PictureLaw, RatePlan};
pub use tdct::TdctConfig;

use crate::error::{Error, Result};
use crate::stream::container::{ContainerReader, Tag};
use pictures::PictureCodec;
use rate::CoderPlan;
use std::io::{Read, Seek};

/// The residual codec recorded in the stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Codec {
    /// One JPEG picture per frame: every frame decodes on its own.
    Jpeg,
    /// MPEG-4 Part 2: I-frames every `gop` frames, P-frames between.
    Mpeg4,
    /// No images: each vertex's residuals as a temporal DCT over all frames, coded from low to high
    /// frequency, so that a truncated stream still decodes a coarser animation.
    Tdct,
    /// HEVC at 10 or 12 bits a sample (libx265): IDR frames every `gop` frames, P-frames between
    /// (`gop` 1: all-intra, every frame decodes alone).
    Hevc,
    /// AV1 at 10 or 12 bits a sample (libaom): key frames every `gop` frames, P-frames between
    /// (`gop` 1: all-intra, every frame decodes alone).
    Av1,
}

impl Codec {
    /// Every codec, in the order of their stream ids.
    pub const ALL: [Codec; 5] = [
        Codec::Jpeg,
        Codec::Mpeg4,
        Codec::Tdct,
        Codec::Hevc,
        Codec::Av1,
    ];

    /// The codec's id in the stream header.
    pub fn id(self) -> u8 {
        match self {
            Codec::Jpeg => 0,
            Codec::Mpeg4 => 1,
            Codec::Tdct => 3,
            Codec::Hevc => 4,
            Codec::Av1 => 5,
        }
    }

    /// The codec of a stream id.
    pub fn from_id(id: u8) -> Result<Self> {
        Codec::ALL
            .into_iter()
            .find(|c| c.id() == id)
            .ok_or_else(|| Error::Stream(format!("unknown codec id {id}")))
    }

    /// The name used in reports (and on the command line).
    pub fn name(self) -> &'static str {
        match self {
            Codec::Jpeg => "jpeg",
            Codec::Mpeg4 => "mpeg4",
            Codec::Tdct => "tdct",
            Codec::Hevc => "hevc",
            Codec::Av1 => "av1",
        }
    }

    /// The codec's options with every default.
    pub fn default_config(self) -> CodecConfig {
        match self {
            Codec::Jpeg => CodecConfig::Jpeg(JpegConfig::default()),
            Codec::Mpeg4 => CodecConfig::Mpeg4(Mpeg4Config::default()),
            Codec::Tdct => CodecConfig::Tdct(TdctConfig::default()),
            Codec::Hevc => CodecConfig::Hevc(DeepConfig::default()),
            Codec::Av1 => CodecConfig::Av1(DeepConfig::default()),
        }
    }

    /// Whether the codec codes geometry images on a lattice (and so has an atlas).
    pub fn has_images(self) -> bool {
        !matches!(self, Codec::Tdct)
    }

    /// Whether the codec codes frequency bands, so that a stream cut short, or decoded up to a
    /// band, still gives every frame (coarser).
    pub fn has_bands(self) -> bool {
        matches!(self, Codec::Tdct)
    }

    /// Whether its residual coder is cheap next to the segmentation and codes at exactly the
    /// plan's step: the automatic choice may then try more candidates (a k-means ladder, coarser
    /// first frames) and compare them by bytes alone.
    pub(crate) fn cheap_exact_trials(self) -> bool {
        matches!(self, Codec::Tdct)
    }

    /// Whether the automatic choice may estimate a candidate from a sample of frames: the frames
    /// are coded each on its own (measured on JPEG; spread frames misrank P-frames).
    pub(crate) fn sampled_trials(self) -> bool {
        matches!(self, Codec::Jpeg)
    }

    /// Whether this build can code the codec (MPEG-4, HEVC and AV1 need the `ffmpeg` feature).
    pub fn available(self) -> bool {
        !matches!(self, Codec::Mpeg4 | Codec::Hevc | Codec::Av1) || cfg!(feature = "ffmpeg")
    }

    /// The picture codec of a geometry-video codec (`None` for codecs without images).
    pub(crate) fn pictures(self) -> Result<Option<&'static dyn PictureCodec>> {
        Ok(match self {
            Codec::Jpeg => Some(&pictures::jpeg::Pictures),
            #[cfg(feature = "ffmpeg")]
            Codec::Mpeg4 => Some(&pictures::mpeg4::Pictures),
            #[cfg(feature = "ffmpeg")]
            Codec::Hevc => Some(&pictures::hevc::PICTURES),
            #[cfg(feature = "ffmpeg")]
            Codec::Av1 => Some(&pictures::av1::PICTURES),
            #[cfg(not(feature = "ffmpeg"))]
            Codec::Mpeg4 | Codec::Hevc | Codec::Av1 => return Err(unavailable(self)),
            Codec::Tdct => None,
        })
    }

    /// Reads the codec's parts of a stream (everything but the coded residuals themselves, which
    /// a decoder reads on demand, or for tdct the bands, read here) and returns its decoder.
    pub(crate) fn open_decoder<R: Read + Seek>(
        self,
        stream: &StreamLayout,
        reader: &mut ContainerReader<R>,
        max_bands: Option<usize>,
    ) -> Result<Box<dyn ResidualDecoder<R>>> {
        let setup = reader.part(Tag::CODEC_SETUP)?;
        Ok(match self.pictures()? {
            Some(pictures) => Box::new(geometry_video::Decoder::open(
                (self, pictures),
                &setup,
                stream,
                reader,
            )?),
            None => Box::new(tdct::Decoder::open(&setup, stream, reader, max_bands)?),
        })
    }
}

#[cfg(not(feature = "ffmpeg"))]
fn unavailable(codec: Codec) -> Error {
    Error::Codec(format!(
        "this build has no {} codec (built without the `ffmpeg` feature)",
        codec.name()
    ))
}

/// A residual codec and its own options: what an encoding codes its residuals with.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum CodecConfig {
    /// The temporal DCT (the default: the fewest bits at equal error).
    Tdct(TdctConfig),
    /// One JPEG picture per frame.
    Jpeg(JpegConfig),
    /// MPEG-4 Part 2 pictures.
    Mpeg4(Mpeg4Config),
    /// HEVC pictures at 10 or 12 bits a sample.
    Hevc(DeepConfig),
    /// AV1 pictures at 10 or 12 bits a sample.
    Av1(DeepConfig),
}

impl Default for CodecConfig {
    fn default() -> Self {
        CodecConfig::Tdct(TdctConfig::default())
    }
}

impl From<Codec> for CodecConfig {
    fn from(codec: Codec) -> Self {
        codec.default_config()
    }
}

impl CodecConfig {
    /// Which codec.
    pub fn codec(&self) -> Codec {
        match self {
            CodecConfig::Tdct(_) => Codec::Tdct,
            CodecConfig::Jpeg(_) => Codec::Jpeg,
            CodecConfig::Mpeg4(_) => Codec::Mpeg4,
            CodecConfig::Hevc(_) => Codec::Hevc,
            CodecConfig::Av1(_) => Codec::Av1,
        }
    }

    /// The lattice and padding options of a picture codec (`None` for codecs without pictures).
    pub fn pictures_mut(&mut self) -> Option<&mut PictureOptions> {
        match self {
            CodecConfig::Tdct(_) => None,
            CodecConfig::Jpeg(c) => Some(&mut c.pictures),
            CodecConfig::Mpeg4(c) => Some(&mut c.pictures),
            CodecConfig::Hevc(c) | CodecConfig::Av1(c) => Some(&mut c.pictures),
        }
    }

    /// The frames per group of pictures of a video codec (`None` for codecs that code every frame
    /// alone or no pictures).
    pub fn gop_mut(&mut self) -> Option<&mut usize> {
        match self {
            CodecConfig::Tdct(_) | CodecConfig::Jpeg(_) => None,
            CodecConfig::Mpeg4(c) => Some(&mut c.gop),
            CodecConfig::Hevc(c) | CodecConfig::Av1(c) => Some(&mut c.gop),
        }
    }

    /// Fails, naming the option, when one is out of range.
    pub(crate) fn check(&self) -> Result<()> {
        match self {
            CodecConfig::Tdct(_) => Ok(()),
            CodecConfig::Jpeg(c) => c.check(),
            CodecConfig::Mpeg4(c) => c.check(),
            CodecConfig::Hevc(c) => pictures::hevc::check(c),
            CodecConfig::Av1(c) => pictures::av1::check(c),
        }
    }

    /// The plan of `rate` on a first frame of bounding-box diagonal `diagonal`, by the codec's law.
    pub(crate) fn plan(&self, rate: &Rate, diagonal: f64) -> Result<RatePlan> {
        match self {
            CodecConfig::Tdct(c) => c.plan(rate, diagonal),
            CodecConfig::Jpeg(c) => c.plan(rate, diagonal),
            CodecConfig::Mpeg4(c) => c.plan(rate, diagonal),
            CodecConfig::Hevc(c) => pictures::hevc::plan(c, rate, diagonal),
            CodecConfig::Av1(c) => pictures::av1::plan(c, rate, diagonal),
        }
    }
}

impl RatePlan {
    /// The residual encoder with this plan's settings.
    pub(crate) fn encoder(&self) -> Result<Box<dyn ResidualEncoder>> {
        Ok(match &self.coder {
            CoderPlan::Tdct => Box::new(tdct::Encoder { step: self.step }),
            CoderPlan::Pictures(plan) => {
                let codec = plan.codec.pictures()?.ok_or_else(|| {
                    Error::Codec(format!("{} codes no pictures", plan.codec.name()))
                })?;
                Box::new(geometry_video::Encoder::new(codec, plan.clone(), self.step))
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stream_ids_round_trip() {
        for codec in Codec::ALL {
            assert_eq!(Codec::from_id(codec.id()).unwrap(), codec);
            assert_eq!(codec.default_config().codec(), codec);
        }
        assert!(Codec::from_id(2).is_err());
        assert!(Codec::from_id(6).is_err());
    }
}
