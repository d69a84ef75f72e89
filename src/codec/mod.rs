//! Residual coders: how the motion the predictor leaves over is stored.
//!
//! Every codec implements one interface, [`ResidualEncoder`] and [`ResidualDecoder`], and the only
//! place that knows which codecs exist is [`Codec`] ([`Codec::encoder`], [`Codec::open_decoder`]):
//! a new codec is one new module and one variant.
//!
//! - [`jpeg`] and [`mpeg4`] are the paper's geometry video: the residuals are splatted onto a
//!   multi-chart atlas ([`geometry_video`]), padded, and coded as pictures — one JPEG per frame
//!   (any frame decodes alone) or MPEG-4 Part 2 I- and P-frames through FFmpeg (cargo feature
//!   `mpeg4`). [`hevc`] and [`av1`] code the same pictures at 10 or 12 bits a sample with libx265
//!   and libaom (same feature: they need FFmpeg too; their shared part is [`deep`]).
//! - [`tdct`] is the follow-up paper's temporal DCT: each vertex's residual trajectory transformed
//!   over all frames and coded band by band, no images.
//!
//! [`quality`] maps the one `quality` knob onto each codec's quantiser.

pub mod pictures;
pub mod quality;
pub mod tdct;

pub use pictures::{abbreviated, geometry_video, jpeg};
#[cfg(feature = "ffmpeg")]
pub use pictures::{av1, deep, hevc, mpeg4};

pub use crate::geometry_image::Plane;
pub use quality::{
    av1_law, hevc_law, ijg_scale_percent, jpeg_law, mpeg4_law, target_step, PictureLaw,
};

use crate::encoder::EncodeOptions;
use crate::error::{Error, Result};
use crate::mesh::{AnimatedMesh, Point, Triangle};
use crate::motion::Partition;
use crate::progress::Progress;
use crate::stream::container::{ContainerReader, Part};
use crate::stream::header::Header;
use std::io::{Read, Seek};

/// The stream id of the first temporal-DCT format (bands without spatial prediction), refused.
const RETIRED_TDCT_ID: u8 = 2;

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

    /// The codec's id in the stream header. The temporal DCT's is 3 since its bands are coded with
    /// spatial prediction (issue 18): id 2 was the format before, which this build refuses.
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
        if id == RETIRED_TDCT_ID {
            return Err(Error::Stream(format!(
                "codec id {id} is the temporal-DCT format from before spatial prediction of the \
                 bands, which this version of mcgv-video no longer decodes: re-encode the animation \
                 (`--codec tdct`) from its source"
            )));
        }
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

    /// Whether the codec codes geometry images on a lattice (and so has an atlas).
    pub fn has_images(self) -> bool {
        !matches!(self, Codec::Tdct)
    }

    /// Whether this build can code the codec (MPEG-4, HEVC and AV1 need the `mpeg4` feature, i.e.
    /// FFmpeg).
    pub fn available(self) -> bool {
        !matches!(self, Codec::Mpeg4 | Codec::Hevc | Codec::Av1) || cfg!(feature = "ffmpeg")
    }

    /// The codec's encoder.
    pub fn encoder(self) -> Result<Box<dyn ResidualEncoder>> {
        Ok(match self {
            Codec::Jpeg => Box::new(geometry_video::Encoder::new(jpeg::Pictures)),
            #[cfg(feature = "ffmpeg")]
            Codec::Mpeg4 => Box::new(geometry_video::Encoder::new(mpeg4::Pictures)),
            #[cfg(feature = "ffmpeg")]
            Codec::Hevc => Box::new(geometry_video::Encoder::new(hevc::PICTURES)),
            #[cfg(feature = "ffmpeg")]
            Codec::Av1 => Box::new(geometry_video::Encoder::new(av1::PICTURES)),
            #[cfg(not(feature = "ffmpeg"))]
            Codec::Mpeg4 | Codec::Hevc | Codec::Av1 => return Err(unavailable()),
            Codec::Tdct => Box::new(tdct::Encoder),
        })
    }

    /// The picture codec of a geometry-video codec (`None` for codecs without images).
    pub fn pictures(self) -> Result<Option<Box<dyn geometry_video::PictureCodec>>> {
        Ok(match self {
            Codec::Jpeg => Some(Box::new(jpeg::Pictures)),
            #[cfg(feature = "ffmpeg")]
            Codec::Mpeg4 => Some(Box::new(mpeg4::Pictures)),
            #[cfg(feature = "ffmpeg")]
            Codec::Hevc => Some(Box::new(hevc::PICTURES)),
            #[cfg(feature = "ffmpeg")]
            Codec::Av1 => Some(Box::new(av1::PICTURES)),
            #[cfg(not(feature = "ffmpeg"))]
            Codec::Mpeg4 | Codec::Hevc | Codec::Av1 => return Err(unavailable()),
            Codec::Tdct => None,
        })
    }

    /// Reads the codec's parts of a stream (everything but the coded residuals themselves, which
    /// a decoder reads on demand, or for tdct the bands, read here) and returns its decoder.
    pub fn open_decoder<R: Read + Seek>(
        self,
        stream: &StreamLayout,
        reader: &mut ContainerReader<R>,
        max_bands: Option<usize>,
    ) -> Result<Box<dyn ResidualDecoder<R>>> {
        Ok(match self {
            Codec::Jpeg => Box::new(geometry_video::Decoder::open(
                jpeg::Pictures,
                stream,
                reader,
            )?),
            #[cfg(feature = "ffmpeg")]
            Codec::Mpeg4 => Box::new(geometry_video::Decoder::open(
                mpeg4::Pictures,
                stream,
                reader,
            )?),
            #[cfg(feature = "ffmpeg")]
            Codec::Hevc => Box::new(geometry_video::Decoder::open(
                hevc::PICTURES,
                stream,
                reader,
            )?),
            #[cfg(feature = "ffmpeg")]
            Codec::Av1 => Box::new(geometry_video::Decoder::open(
                av1::PICTURES,
                stream,
                reader,
            )?),
            #[cfg(not(feature = "ffmpeg"))]
            Codec::Mpeg4 | Codec::Hevc | Codec::Av1 => return Err(unavailable()),
            Codec::Tdct => Box::new(tdct::Decoder::open(stream, reader, max_bands)?),
        })
    }
}

#[cfg(not(feature = "ffmpeg"))]
fn unavailable() -> Error {
    Error::Codec(
        "this build has no MPEG-4, HEVC or AV1 codec (built without the `mpeg4` feature, FFmpeg)"
            .into(),
    )
}

/// What the encoder hands a residual coder: the animation, the decoder's reference frame and
/// partition, and every frame's residual against the quantised predictor.
pub struct ResidualInput<'a> {
    /// The animation (vertices in the stream's order): the clip, or one temporal segment of it.
    pub mesh: &'a AnimatedMesh,
    /// The clip's first-frame bounding-box diagonal, which steps are fractions of (a segment's
    /// own first frame is not the clip's).
    pub diagonal: f64,
    /// The decoded first frame, which the decoder will have.
    pub reference: &'a [Point],
    /// The motion clusters.
    pub partition: &'a Partition,
    /// `residuals[f][v]`: frame f's residual of vertex v against the quantised predictor.
    pub residuals: &'a [Vec<[f32; 3]>],
    /// The encoding's options.
    pub options: &'a EncodeOptions,
    /// Where to report frames done.
    pub progress: &'a dyn Progress,
    /// Codecs with an atlas: the atlas of `reference` and `partition` if already built, else
    /// where to keep it (encodings sharing one partition share it); `None` builds it afresh.
    pub atlas: Option<&'a crate::geometry_image::lattice::AtlasCache>,
}

/// The codec's fields of the stream header.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CodecParams {
    /// Geometry-image lattice, (0, 0) without images.
    pub lattice: (u16, u16),
    /// The picture codec's own quantiser: MPEG-4 qscale, JPEG quality, HEVC QP, AV1 `crf`
    /// (0 without pictures).
    pub qscale: u8,
    /// Frames per group of pictures (1 for intra codecs).
    pub gop: u32,
    /// The padding method's name (`none` without images).
    pub padding: String,
}

/// What a residual coder produced: its header fields and its parts, in file order.
pub struct CodedResiduals {
    /// The codec's fields of the header.
    pub params: CodecParams,
    /// The atlas's figures, for codecs with an atlas.
    pub atlas: Option<atlas::AtlasStats>,
    /// Parts written before the predictor's (geometry video: the lattice coordinates).
    pub before_predictor: Vec<Part>,
    /// Parts written after the predictor's.
    pub after_predictor: Vec<Part>,
    /// Seconds per stage of the coder.
    pub stage_seconds: Vec<(String, f64)>,
}

/// The encoding half of a residual codec.
pub trait ResidualEncoder {
    /// Codes every frame's residuals.
    fn encode(&self, input: &ResidualInput) -> Result<CodedResiduals>;
}

/// What every residual decoder may need of the stream, read before it.
pub struct StreamLayout<'a> {
    /// The stream header.
    pub header: &'a Header,
    /// The shared connectivity.
    pub triangles: &'a [Triangle],
}

/// The decoding half of a residual codec: adds the coded residuals to the decoder's prediction.
pub trait ResidualDecoder<R> {
    /// Adds frame `f`'s residuals to its prediction, reading no more of the stream than `f` needs.
    fn add_frame(
        &mut self,
        reader: &mut ContainerReader<R>,
        f: usize,
        frame: &mut [Point],
    ) -> Result<()>;

    /// Adds every frame's residuals to the predictions, in order.
    fn add_all(
        &mut self,
        reader: &mut ContainerReader<R>,
        frames: &mut [Vec<Point>],
        progress: &dyn Progress,
    ) -> Result<()>;

    /// The geometry-image side of the stream, for codecs that code images.
    fn images(&self) -> Option<&geometry_video::ImageLayout> {
        None
    }

    /// Frame `f`'s decoded picture (x | y | z residual images side by side, samples of the stream's
    /// depth), for codecs that code images.
    fn picture(&mut self, _reader: &mut ContainerReader<R>, _f: usize) -> Result<Plane<u16>> {
        Err(Error::Usage(
            "a tdct stream has no images: its residuals are temporal-DCT bands".into(),
        ))
    }

    /// The temporal-DCT bands, for codecs that code them.
    fn bands(&self) -> Option<&tdct::Bands> {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stream_ids_round_trip_and_the_old_tdct_format_is_refused() {
        for codec in Codec::ALL {
            assert_eq!(Codec::from_id(codec.id()).unwrap(), codec);
        }
        let old = Codec::from_id(RETIRED_TDCT_ID).unwrap_err().to_string();
        assert!(old.contains("re-encode"), "{old}");
        assert!(Codec::from_id(6).is_err());
    }
}
