//! Residual codecs: how the motion the predictor leaves over is stored, and each codec's own
//! options.
//!
//! Pick a codec with a [`CodecConfig`] in [`crate::EncodeOptions::codec`]; `Codec::X.into()` gives
//! codec X with every default, and each variant's type holds the codec's own options:
//!
//! - [`CodecConfig::Tdct`] ([`TdctConfig`], the default): the follow-up paper's temporal DCT.
//!   Each vertex's residual trajectory is transformed over all frames and coded band by band,
//!   low to high frequency: the fewest bits, and a stream cut short still decodes, coarser.
//! - [`CodecConfig::Jpeg`] ([`JpegConfig`]): the papers' geometry video, the residuals splatted
//!   onto a multi-chart atlas and coded as one JPEG picture per frame: any frame decodes alone.
//! - [`CodecConfig::Mpeg4`] ([`Mpeg4Config`]), [`CodecConfig::Hevc`] and [`CodecConfig::Av1`]
//!   ([`DeepConfig`], 10 or 12 bits a sample): the same pictures as video through FFmpeg (cargo
//!   feature `ffmpeg`), a key frame then P-frames (or all-intra).
//!
//! The picture codecs share [`PictureOptions`] (the lattice and padding). The rate is not a codec
//! option: [`crate::EncodeOptions::quality`] (or `step`) is, and each codec's law turns it into a
//! [`RatePlan`] — its step and quantiser — when an encoding starts. A decoded stream says what its
//! codec stored with a [`Description`].
//!
//! Inside the crate every codec implements one interface (a residual encoder and decoder, its own
//! set-up part); adding one is a module and a variant of [`Codec`] and [`CodecConfig`]
//! (docs/design.md, "The codec interface").

mod interface;
mod rate;
#[cfg(test)]
mod raw;
internal! {
    pictures;
    tdct;
}

pub use interface::{BandsDescription, Description, PicturesDescription};
#[cfg(feature = "encode")]
pub(crate) use interface::{CodedResiduals, Estimate, Limit, ResidualEncoder, ResidualInput};
pub(crate) use interface::{ResidualDecoder, StreamLayout};
pub use pictures::deep::DeepConfig;
pub(crate) use pictures::geometry_video;
pub use pictures::jpeg::JpegConfig;
pub use pictures::mpeg4::Mpeg4Config;
pub use pictures::{PictureOptions, Plane, DEFAULT_GOP};
pub(crate) use rate::ijg_scale_percent;
pub(crate) use rate::Rate;
pub use rate::{fine_scale_percent, target_step, RatePlan};
pub use tdct::TdctConfig;

use crate::error::{Error, Result};
use crate::stream::container::{ContainerReader, Tag};
use pictures::PictureCodec;
use std::io::{Read, Seek};

/// The residual codec recorded in the stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Codec {
    /// One JPEG picture per frame: every frame decodes on its own.
    Jpeg,
    /// MPEG-4 Part 2: I-frames every `gop` frames, P-frames between.
    Mpeg4,
    /// No images: each vertex's residuals as a temporal DCT over all frames, coded from low to high
    /// frequency, so that a truncated stream still decodes a coarser animation. The default: the
    /// fewest bits at equal error.
    #[default]
    Tdct,
    /// HEVC at 10 or 12 bits a sample (libx265): IDR frames every `gop` frames, P-frames between
    /// (`gop` 1: all-intra, every frame decodes alone).
    Hevc,
    /// AV1 at 10 or 12 bits a sample (libaom): key frames every `gop` frames, P-frames between
    /// (`gop` 1: all-intra, every frame decodes alone).
    Av1,
    /// Rounded residuals, one chunk a frame: the interface's test codec ([`raw`]).
    #[cfg(test)]
    Raw,
}

impl Codec {
    /// Every codec, in the order of their stream ids.
    #[cfg(not(test))]
    pub const ALL: [Codec; 5] = [
        Codec::Jpeg,
        Codec::Mpeg4,
        Codec::Tdct,
        Codec::Hevc,
        Codec::Av1,
    ];
    /// Every codec, in the order of their stream ids (with the test codec).
    #[cfg(test)]
    pub const ALL: [Codec; 6] = [
        Codec::Jpeg,
        Codec::Mpeg4,
        Codec::Tdct,
        Codec::Hevc,
        Codec::Av1,
        Codec::Raw,
    ];

    /// The codec's id in the stream header.
    pub fn id(self) -> u8 {
        match self {
            Codec::Jpeg => 0,
            Codec::Mpeg4 => 1,
            Codec::Tdct => 3,
            Codec::Hevc => 4,
            Codec::Av1 => 5,
            #[cfg(test)]
            Codec::Raw => 255,
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
            #[cfg(test)]
            Codec::Raw => "raw",
        }
    }

    /// The codec of a name (as [`Codec::name`] gives it).
    pub fn from_name(name: &str) -> Option<Self> {
        Codec::ALL.into_iter().find(|c| c.name() == name)
    }

    /// What the codec is for, in a line (for help texts).
    pub fn summary(self) -> &'static str {
        match self {
            Codec::Jpeg => "JPEG pictures, one per frame: every frame decodes on its own",
            Codec::Mpeg4 => "MPEG-4 Part 2 pictures: an I-frame, then P-frames",
            Codec::Tdct => {
                "temporal DCT of each vertex's residuals, coded low to high frequency: the \
                 fewest bits; a truncated stream decodes coarser"
            }
            Codec::Hevc => {
                "HEVC (libx265) pictures at 10 or 12 bits: an IDR frame, then P-frames (--gop 1: \
                 all-intra)"
            }
            Codec::Av1 => {
                "AV1 (libaom) pictures at 10 or 12 bits: a key frame, then P-frames (--gop 1: \
                 all-intra)"
            }
            #[cfg(test)]
            Codec::Raw => "rounded residuals, one chunk a frame (tests only)",
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
            #[cfg(test)]
            Codec::Raw => CodecConfig::Raw(raw::RawConfig),
        }
    }

    /// Whether the codec codes geometry images on a lattice (and so has an atlas).
    pub fn has_images(self) -> bool {
        matches!(self, Codec::Jpeg | Codec::Mpeg4 | Codec::Hevc | Codec::Av1)
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

    /// Whether the automatic choice estimates each candidate's residual bytes with the codec's
    /// own cheap estimate ([`ResidualEncoder::estimate_bytes`]) and codes only the winner.
    pub(crate) fn estimated_trials(self) -> bool {
        matches!(self, Codec::Tdct)
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
            #[cfg(test)]
            Codec::Raw => None,
        })
    }

    /// The picture codec a stream's decoder reads pictures with: [`Codec::pictures`], or without
    /// the `ffmpeg` feature for MPEG-4, HEVC and AV1 one whose pictures are decoded outside.
    fn decoded_pictures(self) -> Result<Option<&'static dyn PictureCodec>> {
        #[cfg(not(feature = "ffmpeg"))]
        {
            static OUTSIDE: [pictures::Outside; 3] = [
                pictures::Outside(Codec::Mpeg4),
                pictures::Outside(Codec::Hevc),
                pictures::Outside(Codec::Av1),
            ];
            if let Some(outside) = OUTSIDE.iter().find(|o| o.0 == self) {
                return Ok(Some(outside));
            }
        }
        self.pictures()
    }

    /// The residual encoder of `plan` (a plan of this codec).
    #[cfg(feature = "encode")]
    pub(crate) fn encoder(self, plan: &RatePlan) -> Result<Box<dyn ResidualEncoder>> {
        // The depth and 12-bit law are decided before coding (`RatePlan::depth_choices`,
        // `pinned_to`): a plan still open here would code its first choice unasked.
        debug_assert!(
            plan.pictures.as_ref().is_none_or(|p| p.deeper.is_none()),
            "a picture plan whose depth is still open"
        );
        let step = plan.step;
        Ok(match (self.pictures()?, &plan.pictures) {
            (Some(pictures), Some(settings)) => Box::new(geometry_video::Encoder::new(
                pictures,
                settings.clone(),
                step,
            )),
            (Some(_), None) => return Err(Error::Codec(format!("a {self} plan without pictures"))),
            (None, _) => match self {
                #[cfg(test)]
                Codec::Raw => Box::new(raw::Encoder { step }),
                _ => Box::new(tdct::Encoder { step }),
            },
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
        Ok(match self.decoded_pictures()? {
            Some(pictures) => Box::new(geometry_video::Decoder::open(
                (self, pictures),
                &setup,
                stream,
                reader,
            )?),
            None => match self {
                #[cfg(test)]
                Codec::Raw => Box::new(raw::Decoder::open(&setup, stream, reader)?),
                _ => Box::new(tdct::Decoder::open(&setup, stream, reader, max_bands)?),
            },
        })
    }
}

impl std::fmt::Display for Codec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(not(feature = "ffmpeg"))]
pub(crate) fn unavailable(codec: Codec) -> Error {
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
    /// The interface's test codec.
    #[cfg(test)]
    Raw(raw::RawConfig),
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
            #[cfg(test)]
            CodecConfig::Raw(_) => Codec::Raw,
        }
    }

    /// The lattice and padding options of a picture codec (`None` for codecs without pictures).
    pub fn pictures_mut(&mut self) -> Option<&mut PictureOptions> {
        match self {
            #[cfg(test)]
            CodecConfig::Raw(_) => None,
            CodecConfig::Tdct(_) => None,
            CodecConfig::Jpeg(c) => Some(&mut c.pictures),
            CodecConfig::Mpeg4(c) => Some(&mut c.pictures),
            CodecConfig::Hevc(c) | CodecConfig::Av1(c) => Some(&mut c.pictures),
        }
    }

    /// The codec's own quantiser and its option's name (`jpeg_quality`, `qscale`, `qp`); `None`
    /// for a codec whose step is its only quantiser (tdct).
    pub fn quantiser_mut(&mut self) -> Option<(&'static str, &mut Option<u8>)> {
        match self {
            #[cfg(test)]
            CodecConfig::Raw(_) => None,
            CodecConfig::Tdct(_) => None,
            CodecConfig::Jpeg(c) => Some(("jpeg_quality", &mut c.quality)),
            CodecConfig::Mpeg4(c) => Some(("qscale", &mut c.qscale)),
            CodecConfig::Hevc(c) | CodecConfig::Av1(c) => Some(("qp", &mut c.qp)),
        }
    }

    /// The bits a sample of a codec that codes deeper pictures (`None` for 8-bit codecs).
    pub fn bit_depth_mut(&mut self) -> Option<&mut Option<u8>> {
        match self {
            CodecConfig::Hevc(c) | CodecConfig::Av1(c) => Some(&mut c.bit_depth),
            _ => None,
        }
    }

    /// The bits a sample of the pictures an encoding at `quality` plans: the option's, else the
    /// automatic depth before the residuals turn it ([`pictures::deep::auto_depth`]; `None` for
    /// codecs without deeper pictures).
    pub(crate) fn picture_depth(&self, quality: f64) -> Option<u8> {
        match self {
            CodecConfig::Hevc(c) | CodecConfig::Av1(c) => Some(c.depth_at(self.codec(), quality)),
            _ => None,
        }
    }

    /// The frames per group of pictures of a video codec (`None` for codecs that code every frame
    /// alone or no pictures).
    pub fn gop_mut(&mut self) -> Option<&mut usize> {
        match self {
            #[cfg(test)]
            CodecConfig::Raw(_) => None,
            CodecConfig::Tdct(_) | CodecConfig::Jpeg(_) => None,
            CodecConfig::Mpeg4(c) => Some(&mut c.gop),
            CodecConfig::Hevc(c) | CodecConfig::Av1(c) => Some(&mut c.gop),
        }
    }

    /// Fails, naming the option, when one is out of range.
    pub(crate) fn check(&self) -> Result<()> {
        match self {
            #[cfg(test)]
            CodecConfig::Raw(_) => Ok(()),
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
            #[cfg(test)]
            CodecConfig::Raw(c) => c.plan(rate, diagonal),
        }
    }
}

impl RatePlan {
    /// A picture codec's own quantiser (JPEG quality, MPEG-4 qscale, HEVC QP or AV1 `crf`);
    /// `None` for the temporal DCT.
    pub fn quantiser(&self) -> Option<u8> {
        self.pictures.as_ref().map(|p| p.quantiser)
    }
}

#[cfg(feature = "encode")]
impl RatePlan {
    /// The residual encoder with this plan's settings.
    pub(crate) fn encoder(&self) -> Result<Box<dyn ResidualEncoder>> {
        self.codec.encoder(self)
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
        for codec in Codec::ALL {
            assert_eq!(Codec::from_name(codec.name()), Some(codec));
        }
    }

    #[test]
    fn affine_precision_is_finest_for_p_frames_and_finer_for_the_temporal_dct() {
        let rate = |affine_precision| Rate {
            quality: 50,
            fine_quality: None,
            step: None,
            affine_precision,
        };
        let code = |codec: Codec, gop| {
            let mut config = codec.default_config();
            match &mut config {
                CodecConfig::Mpeg4(c) => c.gop = gop,
                CodecConfig::Hevc(c) | CodecConfig::Av1(c) => c.gop = gop,
                _ => {}
            }
            config.plan(&rate(None), 1.0).unwrap().affine_precision
        };
        // In sixteenths: 4 = 1/4, 3 = 3/16, 2 = 1/8, 1 = 1/16.
        for (codec, gop, expected) in [
            (Codec::Tdct, 50, 3),
            (Codec::Jpeg, 50, 3),
            (Codec::Hevc, 1, 3),
            (Codec::Hevc, 50, 3),
            (Codec::Av1, 1, 4),
            (Codec::Av1, 50, 2),
            (Codec::Mpeg4, 50, 2),
            (Codec::Mpeg4, 1, 1),
        ] {
            assert_eq!(code(codec, gop), expected, "{codec:?} gop {gop}");
        }
        // MPEG-4's and AV1's P-frame groups take finer maps from quality 85, where their noise
        // costs more.
        for codec in [Codec::Mpeg4, Codec::Av1] {
            for (quality, expected) in [(84, 2), (85, 1), (97, 1)] {
                let plan = codec.default_config().plan(
                    &Rate {
                        quality,
                        ..rate(None)
                    },
                    1.0,
                );
                let precision = plan.unwrap().affine_precision;
                assert_eq!(precision, expected, "{codec:?} quality {quality}");
            }
        }
        let asked = Codec::Av1.default_config().plan(&rate(Some(0.5)), 1.0);
        assert_eq!(asked.unwrap().affine_precision, 8);
    }
}
