//! The one interface of the residual coders: what the encoder hands a coder and gets back, what a
//! decoder of a stream does, and how a codec describes what it stored.

use super::pictures::geometry_video::ImageLayout;
use super::Codec;
use crate::error::{Error, Result};
#[cfg(feature = "encode")]
use crate::geometry_image::lattice::AtlasCache;
use crate::geometry_image::Plane;
#[cfg(feature = "encode")]
use crate::mesh::AnimatedMesh;
use crate::mesh::{Point, Triangle};
#[cfg(feature = "encode")]
use crate::motion::Partition;
use crate::progress::Progress;
use crate::stream::container::ContainerReader;
#[cfg(feature = "encode")]
use crate::stream::container::{Part, Tag};
use crate::stream::header::Header;
#[cfg(feature = "encode")]
use std::sync::atomic::{AtomicU64, Ordering};

/// What the encoder hands a residual coder: the animation, the decoder's reference frame and
/// partition, and every frame's residual against the quantised predictor. The coder's settings
/// were given when it was made (from the encoding's rate plan).
#[cfg(feature = "encode")]
pub(crate) struct ResidualInput<'a> {
    /// The animation (vertices in the stream's order): the clip, or one temporal segment of it.
    pub mesh: &'a AnimatedMesh,
    /// The decoded first frame, which the decoder will have.
    pub reference: &'a [Point],
    /// The motion clusters.
    pub partition: &'a Partition,
    /// `residuals[f][v]`: frame f's residual of vertex v against the quantised predictor.
    pub residuals: &'a [Vec<[f32; 3]>],
    /// Where to report frames done.
    pub progress: &'a dyn Progress,
    /// Codecs with an atlas: the atlas of `reference` and `partition` if already built, else
    /// where to keep it (encodings sharing one partition share it); `None` builds it afresh.
    pub atlas: Option<&'a AtlasCache>,
}

/// What a residual coder produced: its set-up and its parts, in file order.
#[cfg(feature = "encode")]
pub(crate) struct CodedResiduals {
    /// The payload of the codec's set-up part (whole stream, first of the codec's parts): its
    /// own version and settings.
    pub setup: Vec<u8>,
    /// The atlas and its lattice (codecs with an atlas): its figures for the report, and the
    /// atlas itself for later encodings on the same first frame and partition.
    pub atlas: Option<((u16, u16), atlas::Atlas)>,
    /// Whole-stream parts written after the set-up, before the predictor's (geometry video: the
    /// lattice coordinates).
    pub before_predictor: Vec<Part>,
    /// Parts written after the predictor's (a temporal segment's own).
    pub after_predictor: Vec<Part>,
    /// Seconds per stage of the coder.
    pub stage_seconds: Vec<(String, f64)>,
    /// Picture codecs: the residuals' spread (`geometry_image::quantise::Chosen::spread`).
    pub residual_spread: Option<f64>,
    /// Picture codecs: the bits a sample of the pictures coded.
    pub picture_depth: Option<u8>,
}

#[cfg(feature = "encode")]
impl CodedResiduals {
    /// The codec's parts around the predictor's, in file order: the set-up part and the other
    /// whole-stream parts before, a segment's own after.
    pub fn into_parts(self) -> (Vec<Part>, Vec<Part>) {
        let mut before = vec![Part::whole(Tag::CODEC_SETUP, self.setup)];
        before.extend(self.before_predictor);
        (before, self.after_predictor)
    }
}

/// The encoding half of a residual codec.
#[cfg(feature = "encode")]
pub(crate) trait ResidualEncoder {
    /// Codes every frame's residuals.
    fn encode(&self, input: &ResidualInput) -> Result<CodedResiduals>;

    /// The bytes of the parts [`Self::encode`] would give, estimated at a fraction of its cost,
    /// close enough to rank the automatic choice's candidates; `None` when the codec has no such
    /// estimate (its trials code in full). The coder may stop once the estimate is sure to pass
    /// `limit` (a candidate that cannot win), returning how far it got.
    fn estimate_bytes(&self, _input: &ResidualInput, _limit: &Limit) -> Result<Option<Estimate>> {
        Ok(None)
    }
}

/// Where an estimate may stop: once the stream's bytes pass the smallest estimate so far, read as
/// the estimate goes (parallel trials lower it), `counted` bytes of the stream (its other parts)
/// already known.
#[cfg(feature = "encode")]
pub(crate) struct Limit<'a> {
    /// The smallest estimate so far; `u64::MAX` for none.
    pub smallest: &'a AtomicU64,
    /// The stream's bytes outside the estimated parts.
    pub counted: u64,
}

#[cfg(feature = "encode")]
impl Limit<'_> {
    /// Whether an estimate of `bytes` (of the estimated parts, so far) has passed the limit.
    pub fn passed(&self, bytes: u64) -> bool {
        self.counted.saturating_add(bytes) > self.smallest.load(Ordering::Relaxed)
    }
}

/// An estimate of a stream's (or its residual parts') bytes.
#[cfg(feature = "encode")]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Estimate {
    /// The bytes estimated; when `stopped`, a lower bound above the limit the estimate was given.
    pub bytes: u64,
    /// Whether the estimate stopped once it passed its limit.
    pub stopped: bool,
}

/// What every residual decoder may need of the stream, read before it.
pub(crate) struct StreamLayout<'a> {
    /// The stream header (of a temporal segment: its frames).
    pub header: &'a Header,
    /// The shared connectivity.
    pub triangles: &'a [Triangle],
    /// The decoded first frame every frame is predicted from.
    pub reference: &'a [Point],
}

/// The decoding half of a residual codec: adds the coded residuals to the decoder's prediction.
/// `Send`, so that a [`Decoder`](crate::Decoder) can move to another thread (a binding that
/// releases its interpreter's lock while decoding does).
pub(crate) trait ResidualDecoder<R>: Send {
    /// Adds frame `f`'s residuals to its prediction, reading no more of the stream than `f` needs.
    fn add_frame(
        &mut self,
        reader: &mut ContainerReader<R>,
        f: usize,
        frame: &mut [Point],
    ) -> Result<()>;

    /// Adds every frame's residuals to the predictions, in order: by default frame by frame; a
    /// codec whose frames share work (a group of pictures, an inverse transform) does it once.
    fn add_all(
        &mut self,
        reader: &mut ContainerReader<R>,
        frames: &mut [Vec<Point>],
        progress: &dyn Progress,
    ) -> Result<()> {
        for (f, frame) in frames.iter_mut().enumerate() {
            self.add_frame(reader, f, frame)?;
            progress.frames(1);
        }
        Ok(())
    }

    /// What the codec stored: its settings, and its bands or pictures.
    fn describe(&self) -> Description;

    /// The geometry-image side of the stream, for codecs that code images.
    fn images(&self) -> Option<&ImageLayout> {
        None
    }

    /// Adds frame `f`'s residuals read from its picture `plane`, decoded outside (x | y | z
    /// residual images side by side, samples of the stream's depth), for codecs that code images.
    fn add_picture(&self, _f: usize, _plane: &Plane<u16>, _frame: &mut [Point]) -> Result<()> {
        Err(Error::Usage(format!(
            "a {} stream has no pictures",
            self.describe().codec.name()
        )))
    }

    /// Frame `f`'s decoded picture (x | y | z residual images side by side, samples of the stream's
    /// depth), for codecs that code images.
    fn picture(&mut self, _reader: &mut ContainerReader<R>, _f: usize) -> Result<Plane<u16>> {
        Err(Error::Usage(format!(
            "a {} stream has no pictures",
            self.describe().codec.name()
        )))
    }
}

/// What a residual codec stored, as reports show it.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Description {
    /// The codec.
    pub codec: Codec,
    /// The codec's own settings, named as its options are (`jpeg_quality`, `qscale`, `qp`,
    /// `gop`, `bit_depth`), in the order reports list them.
    pub settings: Vec<(&'static str, u32)>,
    /// Codecs that code pictures: their lattice and atlas.
    pub pictures: Option<PicturesDescription>,
    /// Codecs that code frequency bands: the bands.
    pub bands: Option<BandsDescription>,
}

/// The pictures of a geometry-video stream.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PicturesDescription {
    /// Lattice width and height in pixels.
    pub lattice: (u16, u16),
    /// Bits a sample.
    pub bit_depth: u8,
    /// Charts in the atlas.
    pub charts: u32,
    /// Chart pixels over lattice pixels.
    pub packing_efficiency: f64,
    /// The padding the encoder used.
    pub padding: &'static str,
    /// Per frame, the residuals sent exactly beside the pictures (those outside the frame's
    /// range).
    pub corrections: Vec<u32>,
}

/// The frequency bands of a temporal-DCT stream (of its open segment).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct BandsDescription {
    /// The quantiser step in the mesh's units.
    pub step: f32,
    /// Byte length of every band, low to high frequency.
    pub lengths: Vec<u64>,
    /// Bands decoded: all of them, or fewer for a truncated stream or a preview.
    pub decoded: usize,
}
