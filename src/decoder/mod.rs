//! The decoder: stream → first frame, partition, the residual codec's side parts, predictor →
//! prediction + decoded residuals → frames. Everything but the coded residuals is read and checked
//! when a stream is opened; residuals are read on demand (a frame needs only its own, or those
//! from its group's key frame).

use crate::codec::{Codec, Description, ResidualDecoder, StreamLayout};
use crate::error::{Error, Result};
use crate::first_frame;
use crate::limits::{self, DEFAULT_MAX_POSITIONS};
use crate::mesh::{AnimatedMesh, Attributes, Point, Triangle};
use crate::motion::{predict_frame, AffineTrack, Partition, PredictorKind, SkinningWeights};
use crate::progress::{Progress, Silent};
use crate::stream::attributes::decode_attributes;
use crate::stream::container::{ContainerReader, Tag, FILE_HEADER_LEN, PART_HEADER_LEN};
use crate::stream::header::Header;
use crate::stream::segments;
use crate::stream::side_info;
mod pictures;

use std::fs::File;
use std::io::{BufReader, Cursor, Read, Seek};
use std::ops::Range;
use std::path::Path;

/// Choices a reader can make about decoding.
#[derive(Debug, Clone, Copy)]
pub struct DecodeOptions {
    /// Temporal DCT only: decode no more than this many frequency bands (a progressive preview).
    pub max_bands: Option<usize>,
    /// Refuse a stream whose header promises more positions (vertices × frames) than this, before
    /// reading anything else (default [`DEFAULT_MAX_POSITIONS`]).
    pub max_positions: u64,
    /// The bytes are the start of a stream still arriving (a download): its last part may be cut
    /// short whatever its kind, so a JPEG stream's frames decode as their chunks arrive (a frame
    /// whose chunk has not is an error until it has), as a temporal-DCT stream's bands always do.
    /// Only with [`Decoder::from_reader`]; a stream cut in any other part is an error either way.
    pub partial: bool,
}

impl Default for DecodeOptions {
    fn default() -> Self {
        Self {
            max_bands: None,
            max_positions: DEFAULT_MAX_POSITIONS,
            partial: false,
        }
    }
}

/// An opened stream: everything but the coded residuals is read and checked at open.
pub struct Decoder<R> {
    reader: ContainerReader<R>,
    header: Header,
    codec: Codec,
    triangles: Vec<Triangle>,
    reference: Vec<Point>,
    partition: Partition,
    weights: Option<SkinningWeights>,
    attributes: Attributes,
    options: DecodeOptions,
    /// The frames of each temporal segment (one segment for a stream not cut into them).
    segments: Vec<Range<usize>>,
    /// The segment whose parts are read: its affine maps and residual decoder. A stream of one
    /// segment reads it at open; a segmented one when a frame of it is first asked for.
    open: Option<OpenSegment<R>>,
}

/// One temporal segment's predictor and residual decoder, read when a frame of it is asked for.
struct OpenSegment<R> {
    index: usize,
    track: AffineTrack,
    residuals: Box<dyn ResidualDecoder<R>>,
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
    /// Opens a stream from any seekable source — a file, or a [`Cursor`] over bytes the decoder
    /// then owns (`Cursor<Vec<u8>>`, for a decoder that outlives the caller's buffer) — with
    /// decoding options; with [`DecodeOptions::partial`], the start of a stream still arriving. A
    /// decoder over a reader that is `Send` is `Send`.
    pub fn from_reader(source: R, options: &DecodeOptions) -> Result<Self> {
        let reader = match options.partial {
            true => ContainerReader::partial(source)?,
            false => ContainerReader::new(source)?,
        };
        Self::from_container(reader, options)
    }

    /// The first frame of a stream of which only the start may have arrived: its header, first
    /// frame (the stream's first parts, about a third of a 2-second clip at the default
    /// quality, less of a longer or finer one) and, once arrived, its texture coordinates and
    /// materials. A player draws it while the rest arrives.
    pub fn first_frame(source: R, options: &DecodeOptions) -> Result<FirstFrame> {
        let mut reader = ContainerReader::partial(source)?;
        let header = Header::from_bytes(&reader.part(Tag::HEADER)?)?;
        Codec::from_id(header.codec)?;
        limits::check_stream(header.vertices, header.frames, options.max_positions)?;
        let (triangles, positions) = first_frame::decode(&reader.part(Tag::FIRST_FRAME)?)?;
        check_first_frame(&header, &triangles, &positions)?;
        // The attributes come right after the first frame: a later part tells there are none.
        let later = |t: Tag| t != Tag::HEADER && t != Tag::FIRST_FRAME && t != Tag::ATTRIBUTES;
        let attributes = match reader.has(Tag::ATTRIBUTES) {
            true => Some(decode_attributes(
                &reader.part(Tag::ATTRIBUTES)?,
                &triangles,
                &positions,
            )?),
            false if reader.parts().iter().any(|p| later(p.tag)) => Some(Attributes::default()),
            false => None,
        };
        Ok(FirstFrame {
            header,
            triangles,
            positions,
            attributes,
        })
    }

    /// Reads and checks every part but the coded residuals (temporal-DCT bands are decoded here),
    /// and of a segmented stream, the first segment's.
    pub fn from_container(mut reader: ContainerReader<R>, options: &DecodeOptions) -> Result<Self> {
        let header = Header::from_bytes(&reader.part(Tag::HEADER)?)?;
        let codec = Codec::from_id(header.codec)?;
        limits::check_stream(header.vertices, header.frames, options.max_positions)?;
        let (v, f) = (header.vertices as usize, header.frames as usize);
        let (triangles, reference) = first_frame::decode(&reader.part(Tag::FIRST_FRAME)?)?;
        check_first_frame(&header, &triangles, &reference)?;
        let attributes = match reader.has(Tag::ATTRIBUTES) {
            true => decode_attributes(&reader.part(Tag::ATTRIBUTES)?, &triangles, &reference)?,
            false => Attributes::default(),
        };
        let labels = side_info::decode_partition(
            &reader.part(Tag::PARTITION)?,
            v,
            header.clusters as usize,
            (&triangles, &reference),
        )?;
        let partition = Partition::from_labels(labels, header.clusters as usize)?;
        if options.max_bands.is_some() && !codec.has_bands() {
            let banded: Vec<&str> = Codec::ALL
                .iter()
                .filter(|c| c.has_bands())
                .map(|c| c.name())
                .collect();
            return Err(Error::option(
                "max_bands",
                format!(
                    "applies to {} streams; this one is {}",
                    banded.join(" and "),
                    codec.name()
                ),
            ));
        }
        let weights = read_weights(&mut reader, &header, &partition, (&triangles, &reference))?;
        let segments = segments::read_ranges(&mut reader, f)?;
        let shared = Shared {
            header: &header,
            codec,
            triangles: &triangles,
            reference: &reference,
            partition: &partition,
            options,
        };
        let open = match reader.segments() {
            0 => Some(shared.open_segment(&mut reader, &segments, 0)?),
            _ => None,
        };
        Ok(Self {
            reader,
            header,
            codec,
            triangles,
            reference,
            partition,
            weights,
            attributes,
            options: *options,
            segments,
            open,
        })
    }

    /// The stream header.
    pub fn header(&self) -> &Header {
        &self.header
    }

    /// The residual codec.
    pub fn codec(&self) -> Codec {
        self.codec
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

    /// Where each of `original`'s vertices is in the decoded frames, when the stream holds them
    /// in another order (`inverse[v]` is input vertex `v`'s decoded index), so that they can be
    /// put back ([`AnimatedMesh::permuted`]); `None` when the order is the input's, or `original`
    /// is not the stream's source. A stream encoded with `reorder` keeps no permutation (that is
    /// what saves its bits), but the first-frame coder is deterministic: coding the original's
    /// first frame again gives it.
    pub fn input_order(&self, original: &AnimatedMesh) -> Result<Option<Vec<u32>>> {
        let h = &self.header;
        if !h.reorder || original.vertex_count() != h.vertices as usize {
            return Ok(None);
        }
        let options = first_frame::FirstFrameOptions {
            bits: h.first_frame_bits,
            reorder: true,
        };
        let coded = first_frame::encode(original.frame(0), original.triangles(), &options)?;
        let Some(permutation) = coded.permutation else {
            return Ok(None);
        };
        if permutation.len() != original.vertex_count() {
            return Ok(None);
        }
        // permutation[new] = old: input vertex `old` is decoded vertex `new`.
        let mut inverse = vec![0u32; permutation.len()];
        for (new, &old) in permutation.iter().enumerate() {
            inverse[old as usize] = new as u32;
        }
        Ok(Some(inverse))
    }

    /// The stream's length in bytes.
    pub fn file_len(&self) -> u64 {
        self.reader.file_len()
    }

    /// Bytes each part takes in the file (its part header included), by part name in file order,
    /// after the file header; the parts of one kind in a segmented stream are summed.
    pub fn part_bytes(&self) -> Vec<(String, u64)> {
        let mut parts = vec![("file header".to_string(), FILE_HEADER_LEN as u64)];
        for p in self.reader.parts() {
            let bytes = p.len + PART_HEADER_LEN as u64;
            match parts.iter_mut().find(|(name, _)| name == p.tag.name()) {
                Some((_, total)) => *total += bytes,
                None => parts.push((p.tag.name().to_string(), bytes)),
            }
        }
        parts
    }

    /// The frames of each temporal segment, in order (one segment for a stream not cut into them).
    pub fn segments(&self) -> &[Range<usize>] {
        &self.segments
    }

    /// The segment whose parts are read, if any: the one [`Decoder::describe`] and the figures
    /// built on it describe. A stream of one segment opens it with the stream;
    /// a segmented one opens none until a frame is asked for or [`Decoder::seek_segment`].
    pub fn open_segment(&self) -> Option<usize> {
        self.open.as_ref().map(|o| o.index)
    }

    /// The open segment's affine base step (a fraction of the bounding-box diagonal).
    pub(crate) fn affine_step(&self) -> Option<f64> {
        let open = self.open.as_ref()?;
        Some(f64::from(open.track.quantised().step))
    }

    /// Reads segment `s`'s affine maps and residual parts (the segment's alone), unless open.
    pub fn seek_segment(&mut self, s: usize) -> Result<()> {
        if self.open_segment() == Some(s) {
            return Ok(());
        }
        if s >= self.segments.len() {
            return Err(Error::Usage(format!(
                "segment {s}: the stream has {} segments",
                self.segments.len()
            )));
        }
        let shared = Shared {
            header: &self.header,
            codec: self.codec,
            triangles: &self.triangles,
            reference: &self.reference,
            partition: &self.partition,
            options: &self.options,
        };
        // The old segment goes first: two segments' decoded bands are never held at once.
        self.open = None;
        self.open = Some(shared.open_segment(&mut self.reader, &self.segments, s)?);
        Ok(())
    }

    /// What the residual codec stored (of the open segment): its settings, and its bands or
    /// pictures. `None` until a segment is open (a segmented stream opens none until a frame is
    /// asked for or [`Decoder::seek_segment`]).
    pub fn describe(&self) -> Option<Description> {
        self.open.as_ref().map(|o| o.residuals.describe())
    }

    /// Whether the file ends inside the temporal-DCT coefficients (of the last segment: the bands
    /// after the cut are decoded as zero, a coarser animation).
    pub fn truncated(&self) -> bool {
        self.reader.cut_short()
    }

    /// Opens the segment of frame `f`; returns `f`'s index in it.
    fn seek_frame(&mut self, f: usize) -> Result<usize> {
        let s = segments::segment_of(&self.segments, f).ok_or_else(|| {
            Error::Usage(format!(
                "frame {f}: the stream has frames 0 to {}",
                self.header.frames - 1
            ))
        })?;
        self.seek_segment(s)?;
        Ok(f - self.segments[s].start)
    }

    /// Decodes frame `f` alone: reads only its segment's parts, and of them only its own chunk for
    /// intra streams, the chunks from the last key frame for P-frame streams, and sums the decoded
    /// bands' basis functions at `f` for temporal-DCT streams.
    pub fn decode_frame(&mut self, f: usize) -> Result<Vec<Point>> {
        let local = self.seek_frame(f)?;
        let mut out = self.predict(local)?;
        let open = self.open.as_mut().ok_or_else(closed)?;
        open.residuals
            .add_frame(&mut self.reader, local, &mut out)?;
        finite(f, &out)?;
        Ok(out)
    }

    /// Decodes frames `frames.start` to `frames.end - 1`, in order. Each temporal segment they
    /// fall in is decoded whole, as [`Decoder::decode_all`] decodes it, so the frames are
    /// `decode_all`'s, value for value; a range past the last frame is an error.
    pub fn decode_frames(
        &mut self,
        frames: Range<usize>,
        progress: &dyn Progress,
    ) -> Result<Vec<Vec<Point>>> {
        let count = self.header.frames as usize;
        if frames.start > frames.end || frames.end > count {
            return Err(Error::Usage(format!(
                "frames {}..{}: the stream has frames 0..{count}",
                frames.start, frames.end
            )));
        }
        let mut out = Vec::with_capacity(frames.len());
        for (s, segment) in self.segments.clone().into_iter().enumerate() {
            if segment.end <= frames.start || segment.start >= frames.end {
                continue;
            }
            let skip = frames.start.saturating_sub(segment.start);
            let take = frames.end.min(segment.end) - segment.start - skip;
            let decoded = self.decode_segment(s, progress)?;
            out.extend(decoded.into_iter().skip(skip).take(take));
        }
        Ok(out)
    }

    /// Decodes every frame in order.
    pub fn decode_all(&mut self) -> Result<AnimatedMesh> {
        self.decode_all_with_progress(&Silent)
    }

    /// Decodes every frame in order, telling `progress` each frame done.
    pub fn decode_all_with_progress(&mut self, progress: &dyn Progress) -> Result<AnimatedMesh> {
        let mut frames = Vec::with_capacity(self.segments.last().map_or(0, |r| r.end));
        self.for_each_frame(progress, |_, frame| {
            frames.push(frame);
            Ok(())
        })?;
        let rate = f64::from(self.header.frame_rate);
        Ok(AnimatedMesh::new(self.triangles.clone(), frames)?
            .with_attributes(self.attributes.clone())?
            .with_frame_rate(Some(rate)))
    }

    /// Decodes every frame in order and hands each to `each` (frame number, positions) as soon as
    /// its segment is decoded: no more than one segment's frames are held at once.
    pub fn for_each_frame(
        &mut self,
        progress: &dyn Progress,
        mut each: impl FnMut(usize, Vec<Point>) -> Result<()>,
    ) -> Result<()> {
        for s in 0..self.segments.len() {
            let start = self.segments[s].start;
            for (i, frame) in self.decode_segment(s, progress)?.into_iter().enumerate() {
                each(start + i, frame)?;
            }
        }
        Ok(())
    }

    /// Decodes the frames of segment `s` ([`Decoder::segments`]) in order.
    pub fn decode_segment(&mut self, s: usize, progress: &dyn Progress) -> Result<Vec<Vec<Point>>> {
        self.seek_segment(s)?;
        let frames = self.segments[s].clone();
        let mut out = (0..frames.len())
            .map(|f| self.predict(f))
            .collect::<Result<Vec<_>>>()?;
        let open = self.open.as_mut().ok_or_else(closed)?;
        open.residuals
            .add_all(&mut self.reader, &mut out, progress)?;
        for (f, frame) in frames.zip(&out) {
            finite(f, frame)?;
        }
        Ok(out)
    }

    /// The prediction of the open segment's frame `local`.
    fn predict(&self, local: usize) -> Result<Vec<Point>> {
        let open = self.open.as_ref().ok_or_else(closed)?;
        predict_frame(
            &open.track,
            self.weights.as_ref(),
            local,
            &self.reference,
            &self.partition,
        )
    }
}

/// The first frame's counts must be the header's.
fn check_first_frame(header: &Header, triangles: &[Triangle], reference: &[Point]) -> Result<()> {
    if reference.len() != header.vertices as usize || triangles.len() != header.triangles as usize {
        return Err(Error::Stream(format!(
            "first frame has {} vertices and {} triangles, header says {} and {}",
            reference.len(),
            triangles.len(),
            header.vertices,
            header.triangles
        )));
    }
    Ok(())
}

/// What the first parts of a stream hold: enough to draw its first frame before the rest has
/// arrived ([`Decoder::first_frame`]).
#[derive(Debug, Clone, PartialEq)]
pub struct FirstFrame {
    /// The stream header.
    pub header: Header,
    /// The triangles of every frame, in the decoder's order.
    pub triangles: Vec<Triangle>,
    /// Frame 0 as the first-frame coder stored it (the reference every frame is predicted from,
    /// [`Decoder::reference`]), in the decoder's vertex order: the decoded frame 0 differs from
    /// it by what the predictor and residuals of frame 0 add (of the order of the step).
    pub positions: Vec<Point>,
    /// Texture coordinates and materials; `None` while their part may still be to come.
    pub attributes: Option<Attributes>,
}

/// A mesh holds finite coordinates only: a decoded frame with an infinity or NaN is refused.
fn finite(f: usize, frame: &[Point]) -> Result<()> {
    match frame.iter().position(|p| p.iter().any(|x| !x.is_finite())) {
        Some(v) => Err(Error::Stream(format!(
            "frame {f}, vertex {v}: coordinate is not a finite number"
        ))),
        None => Ok(()),
    }
}

/// What every segment is decoded against: the parts the whole stream shares.
struct Shared<'a> {
    header: &'a Header,
    codec: Codec,
    triangles: &'a [Triangle],
    reference: &'a [Point],
    partition: &'a Partition,
    options: &'a DecodeOptions,
}

impl Shared<'_> {
    /// Reads segment `s`'s residual parts and affine maps.
    fn open_segment<R: Read + Seek>(
        &self,
        reader: &mut ContainerReader<R>,
        segments: &[Range<usize>],
        s: usize,
    ) -> Result<OpenSegment<R>> {
        let frames = segments
            .get(s)
            .cloned()
            .ok_or_else(|| Error::Stream(format!("no segment {s}")))?;
        reader.select(s as u32)?;
        // The segment's residual coder sees a clip of the segment's frames.
        let header = Header {
            frames: frames.len() as u32,
            ..self.header.clone()
        };
        let layout = StreamLayout {
            header: &header,
            triangles: self.triangles,
            reference: self.reference,
        };
        // The affine part is read first keeping none of its levels (constant memory): it must hold
        // every frame up to its end word, which proves the segment's frame count before the
        // codec's parts allocate per frame (a temporal-DCT index of empty bands takes a fraction
        // of a bit a frame and proves none) and before the track gets room for 12 levels a frame
        // and cluster.
        let affine = reader.part(Tag::AFFINE)?;
        let (partition, reference) = (self.partition, self.reference);
        side_info::check_affine(&affine, frames.len(), partition, reference)?;
        let residuals = self
            .codec
            .open_decoder(&layout, reader, self.options.max_bands)?;
        let track = side_info::decode_checked_affine(&affine, frames.len(), partition, reference)?;
        Ok(OpenSegment {
            index: s,
            track,
            residuals,
        })
    }
}

/// The error of a frame asked of no open segment (a segment that failed to open).
fn closed() -> Error {
    Error::Stream("no segment is open".into())
}

/// The skinning weights part, which a skinning stream must have and an affine one must not.
fn read_weights<R: Read + Seek>(
    reader: &mut ContainerReader<R>,
    header: &Header,
    partition: &Partition,
    first_frame: (&[Triangle], &[Point]),
) -> Result<Option<SkinningWeights>> {
    match header.predictor {
        PredictorKind::Affine if reader.has(Tag::WEIGHTS) => Err(Error::Stream(
            "the header says affine predictor but the stream has skinning weights".into(),
        )),
        PredictorKind::Affine => Ok(None),
        PredictorKind::Skinning => Ok(Some(side_info::decode_weights(
            &reader.part(Tag::WEIGHTS)?,
            partition,
            first_frame,
        )?)),
    }
}
