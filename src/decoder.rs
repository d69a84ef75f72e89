//! The decoder: stream → first frame, partition, the residual codec's side parts, predictor →
//! prediction + decoded residuals → frames. Everything but the coded residuals is read and checked
//! when a stream is opened; residuals are read on demand (a frame needs only its own, or those
//! from its group's key frame).

use crate::codec::geometry_video::ImageLayout;
use crate::codec::tdct::Bands;
use crate::codec::{Codec, Plane, ResidualDecoder, StreamLayout};
use crate::error::{Error, Result};
use crate::first_frame;
use crate::geometry_image::FrameRanges;
use crate::limits::{self, DEFAULT_MAX_POSITIONS};
use crate::mesh::{AnimatedMesh, Attributes, Point, Triangle};
use crate::motion::{predict_frame, AffineTrack, Partition, PredictorKind, SkinningWeights};
use crate::progress::{Progress, Silent};
use crate::stream::attributes::decode_attributes;
use crate::stream::container::{ContainerReader, Tag};
use crate::stream::frame_index::ChunkEntry;
use crate::stream::header::Header;
use crate::stream::side_info;
use std::fs::File;
use std::io::{BufReader, Cursor, Read, Seek};
use std::path::Path;

/// Choices a reader can make about decoding.
#[derive(Debug, Clone, Copy)]
pub struct DecodeOptions {
    /// Temporal DCT only: decode no more than this many frequency bands (a progressive preview).
    pub max_bands: Option<usize>,
    /// Refuse a stream whose header promises more positions (vertices × frames) than this, before
    /// reading anything else (default [`DEFAULT_MAX_POSITIONS`]).
    pub max_positions: u64,
}

impl Default for DecodeOptions {
    fn default() -> Self {
        Self {
            max_bands: None,
            max_positions: DEFAULT_MAX_POSITIONS,
        }
    }
}

/// An opened stream: everything but the coded residuals is read and checked at open.
pub struct Decoder<R> {
    reader: ContainerReader<R>,
    header: Header,
    triangles: Vec<Triangle>,
    reference: Vec<Point>,
    partition: Partition,
    track: AffineTrack,
    weights: Option<SkinningWeights>,
    residuals: Box<dyn ResidualDecoder<R>>,
    attributes: Attributes,
}

impl Decoder<BufReader<File>> {
    /// Opens a `.mcgv` file.
    pub fn open(path: &Path) -> Result<Self> {
        Self::from_container(ContainerReader::open(path)?, &DecodeOptions::default())
    }

    /// Opens a `.mcgv` file with decoding options.
    pub fn open_with(path: &Path, options: &DecodeOptions) -> Result<Self> {
        Self::from_container(ContainerReader::open(path)?, options)
    }
}

impl<'a> Decoder<Cursor<&'a [u8]>> {
    /// Opens a stream held in memory.
    pub fn new(bytes: &'a [u8]) -> Result<Self> {
        Self::from_container(
            ContainerReader::new(Cursor::new(bytes))?,
            &DecodeOptions::default(),
        )
    }
}

impl<R: Read + Seek> Decoder<R> {
    /// Reads and checks every part but the coded residuals (temporal-DCT bands are decoded here).
    pub fn from_container(mut reader: ContainerReader<R>, options: &DecodeOptions) -> Result<Self> {
        let header = Header::from_bytes(&reader.part(Tag::HEADER)?)?;
        limits::check_stream(header.vertices, header.frames, options.max_positions)?;
        let (v, f) = (header.vertices as usize, header.frames as usize);
        let (triangles, reference) = first_frame::decode(&reader.part(Tag::FIRST_FRAME)?)?;
        if reference.len() != v || triangles.len() != header.triangles as usize {
            return Err(Error::Stream(format!(
                "first frame has {} vertices and {} triangles, header says {v} and {}",
                reference.len(),
                triangles.len(),
                header.triangles
            )));
        }
        let attributes = match reader.has(Tag::ATTRIBUTES) {
            true => decode_attributes(&reader.part(Tag::ATTRIBUTES)?, &triangles, &reference)?,
            false => Attributes::default(),
        };
        let labels = side_info::decode_partition(
            &reader.part(Tag::PARTITION)?,
            v,
            header.clusters as usize,
            &triangles,
        )?;
        let partition = Partition::from_labels(labels, header.clusters as usize)?;
        if options.max_bands.is_some() && header.codec != Codec::Tdct {
            return Err(Error::option(
                "max_bands",
                format!(
                    "applies to tdct streams; this one is {}",
                    header.codec.name()
                ),
            ));
        }
        // The affine part is read first keeping none of its levels (constant memory): it must hold
        // every frame up to its end word, which proves the header's frame count before the codec's
        // parts allocate per frame (a temporal-DCT index of empty bands takes a fraction of a bit
        // a frame and proves none) and before the track gets room for 12 levels a frame and cluster.
        side_info::check_affine(&reader.part(Tag::AFFINE)?, f, &partition, &reference)?;
        let layout = StreamLayout {
            header: &header,
            triangles: &triangles,
        };
        let residuals = header
            .codec
            .open_decoder(&layout, &mut reader, options.max_bands)?;
        let track = side_info::decode_checked_affine(
            &reader.part(Tag::AFFINE)?,
            f,
            &partition,
            &reference,
        )?;
        let weights = read_weights(&mut reader, &header, &partition, &triangles)?;
        Ok(Self {
            reader,
            header,
            triangles,
            reference,
            partition,
            track,
            weights,
            residuals,
            attributes,
        })
    }

    /// The stream header.
    pub fn header(&self) -> &Header {
        &self.header
    }

    /// Texture coordinates and materials, in the decoder's order (empty when the stream has none).
    pub fn attributes(&self) -> &Attributes {
        &self.attributes
    }

    /// The triangles of every frame, in the decoder's order.
    pub fn triangles(&self) -> &[Triangle] {
        &self.triangles
    }

    /// The decoded first frame (12-bit geometry), which every prediction starts from.
    pub fn reference(&self) -> &[Point] {
        &self.reference
    }

    /// The motion partition.
    pub fn partition(&self) -> &Partition {
        &self.partition
    }

    /// The skinning weights, when the stream uses the skinning predictor.
    pub fn weights(&self) -> Option<&SkinningWeights> {
        self.weights.as_ref()
    }

    /// The part table, for bit budgets.
    pub fn container(&self) -> &ContainerReader<R> {
        &self.reader
    }

    /// The geometry-image side of the stream (`None` for codecs without images).
    pub fn images(&self) -> Option<&ImageLayout> {
        self.residuals.images()
    }

    /// The temporal-DCT bands (`None` for codecs without bands).
    pub fn bands(&self) -> Option<&Bands> {
        self.residuals.bands()
    }

    /// Temporal-DCT bands decoded (all of them for a complete stream, fewer for a truncated one
    /// or a preview); 0 for image codecs.
    pub fn bands_decoded(&self) -> usize {
        self.bands().map_or(0, |b| b.decoded.len())
    }

    /// Temporal-DCT bands in the stream (one per frame); 0 for image codecs.
    pub fn bands_total(&self) -> usize {
        self.bands().map_or(0, |b| b.lengths.len())
    }

    /// Byte length of every temporal-DCT band, low to high frequency (empty for image codecs).
    pub fn band_lengths(&self) -> &[u64] {
        self.bands().map_or(&[], |b| &b.lengths)
    }

    /// The temporal-DCT quantiser step in the mesh's units (`None` for image codecs).
    pub fn band_step(&self) -> Option<f32> {
        self.bands().map(|b| b.step)
    }

    /// Whether the file ends inside the temporal-DCT coefficients (the bands after the cut are
    /// decoded as zero: a coarser animation).
    pub fn truncated(&self) -> bool {
        self.bands().is_some_and(|b| b.truncated)
    }

    /// Lattice pixel of every vertex (empty for codecs without a lattice).
    pub fn vertex_pixels(&self) -> &[[u16; 2]] {
        self.images().map_or(&[], |i| &i.pixels)
    }

    /// The residual range of every frame and coordinate (empty for codecs without images).
    pub fn ranges(&self) -> &[FrameRanges] {
        self.images().map_or(&[], |i| &i.ranges)
    }

    /// Where frame `f`'s coded picture lies in the images part.
    pub fn frame_entry(&self, f: usize) -> Result<ChunkEntry> {
        match self.images() {
            Some(i) => i.index.entry(f),
            None => Err(Error::Usage(format!(
                "a {} stream has no images: its residuals are temporal-DCT bands",
                self.header.codec.name()
            ))),
        }
    }

    /// The decoded picture (x | y | z residual images side by side) of frame `f`.
    pub fn decoded_plane(&mut self, f: usize) -> Result<Plane<u16>> {
        self.residuals.picture(&mut self.reader, f)
    }

    /// Decodes frame `f` alone: reads only its own chunk for intra streams, the chunks from the
    /// last key frame for P-frame streams, and sums the decoded bands' basis functions at `f` for
    /// temporal-DCT streams.
    pub fn decode_frame(&mut self, f: usize) -> Result<Vec<Point>> {
        let frames = self.header.frames as usize;
        if f >= frames {
            return Err(Error::Usage(format!(
                "frame {f}: the stream has frames 0 to {}",
                frames - 1
            )));
        }
        let mut out = self.predict(f)?;
        self.residuals.add_frame(&mut self.reader, f, &mut out)?;
        // decode_all refuses such a frame (a mesh holds finite coordinates only): a frame read
        // alone must not come back as infinities instead.
        if let Some(v) = out.iter().position(|p| p.iter().any(|x| !x.is_finite())) {
            return Err(Error::Stream(format!(
                "frame {f}, vertex {v}: coordinate is not a finite number"
            )));
        }
        Ok(out)
    }

    /// Decodes every frame in order.
    pub fn decode_all(&mut self) -> Result<AnimatedMesh> {
        self.decode_all_with_progress(&Silent)
    }

    /// Decodes every frame in order, telling `progress` each frame done.
    pub fn decode_all_with_progress(&mut self, progress: &dyn Progress) -> Result<AnimatedMesh> {
        let frames = self.header.frames as usize;
        let mut out = (0..frames)
            .map(|f| self.predict(f))
            .collect::<Result<Vec<_>>>()?;
        self.residuals
            .add_all(&mut self.reader, &mut out, progress)?;
        let rate = f64::from(self.header.frame_rate);
        Ok(AnimatedMesh::new(self.triangles.clone(), out)?
            .with_attributes(self.attributes.clone())?
            .with_frame_rate(Some(rate)))
    }

    fn predict(&self, f: usize) -> Result<Vec<Point>> {
        predict_frame(
            &self.track,
            self.weights.as_ref(),
            f,
            &self.reference,
            &self.partition,
        )
    }
}

/// The skinning weights part, which a skinning stream must have and an affine one must not.
fn read_weights<R: Read + Seek>(
    reader: &mut ContainerReader<R>,
    header: &Header,
    partition: &Partition,
    triangles: &[Triangle],
) -> Result<Option<SkinningWeights>> {
    match header.predictor {
        PredictorKind::Affine if reader.has(Tag::WEIGHTS) => Err(Error::Stream(
            "the header says affine predictor but the stream has skinning weights".into(),
        )),
        PredictorKind::Affine => Ok(None),
        PredictorKind::Skinning => Ok(Some(side_info::decode_weights(
            &reader.part(Tag::WEIGHTS)?,
            partition,
            triangles,
        )?)),
    }
}
