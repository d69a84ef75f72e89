//! Temporal segments (issue 20): a clip longer than `segment_frames` is coded as runs of frames,
//! so that the temporal DCT and the groups of pictures, and the encoder's memory, stay the size
//! of a segment whatever the clip's length.
//!
//! The first segment is encoded as a clip of its own, with every automatic choice (motion model,
//! K, first-frame precision). Its first frame, partition, lattice and skinning weights become the
//! whole stream's; each later segment gets its own affine maps and residual parts, predicted from
//! the shared parts *as the decoder reads them* (decoded from the first segment's stream), so
//! encoder and decoder agree bit for bit. Shared analysis from the first segment alone keeps the
//! encoder one pass over the clip with memory of one segment; its price — a partition and weights
//! that saw only the first segment's motion — is measured in docs/results.md.
//!
//! A program can feed segments one by one ([`SegmentedEncoder::start`], [`SegmentedEncoder::push`],
//! [`SegmentedEncoder::finish`]), e.g. from a reader that never holds the whole clip.

use super::{EncodeOptions, EncodeReport, Encoded, MotionModel, PredictorChoice};
use crate::codec::{CodecParams, ResidualInput};
use crate::decoder::Decoder;
use crate::error::{Error, Result};
use crate::geometry_image::lattice::AtlasCache;
use crate::mesh::{AnimatedMesh, FrameSource, Point, Triangle};
use crate::motion::{self, AffineTrack, Partition, SkinningWeights};
use crate::progress::Progress;
use crate::stream::container::{ContainerWriter, Part, Tag};
use crate::stream::header::Header;
use crate::stream::segments::SegmentStart;
use crate::stream::side_info;
use std::ops::Range;
use std::time::Instant;

/// An encoding in progress, one segment at a time.
pub struct SegmentedEncoder {
    opts: EncodeOptions,
    /// Frames per segment; every segment but the last has this many.
    length: usize,
    /// What the decoder reads of the first segment's stream, which every segment is predicted from.
    reference: Vec<Point>,
    /// The connectivity in the input's vertex order, which pushed frames come in.
    input_triangles: Vec<Triangle>,
    partition: Partition,
    weights: Option<SkinningWeights>,
    /// First-frame coder's vertex order (stream index → input index), when it reordered.
    permutation: Option<Vec<u32>>,
    /// The first frame's bounding-box diagonal, which the quality's steps are fractions of.
    diagonal: f64,
    atlas: AtlasCache,
    header: Header,
    params: CodecParams,
    shared: Vec<Part>,
    segments: Vec<Vec<Part>>,
    frames: usize,
    report: EncodeReport,
    model: MotionModel,
    clock: Instant,
}

impl SegmentedEncoder {
    /// Encodes the first segment, `first` (the clip's first `length` frames, or all of a shorter
    /// clip), with every automatic choice `opts` leaves open.
    pub fn start(
        first: &AnimatedMesh,
        opts: &EncodeOptions,
        length: usize,
        progress: &dyn Progress,
    ) -> Result<Self> {
        if length == 0 || first.frame_count() > length {
            return Err(Error::option(
                "segment_frames",
                format!(
                    "{length}: the first segment has {} frames",
                    first.frame_count()
                ),
            ));
        }
        let clock = Instant::now();
        let whole = EncodeOptions {
            segment_frames: None,
            ..opts.clone()
        };
        let encoded = super::encode_with_progress(first, &whole, &NoTotal(progress))?;
        let bytes = encoded.to_bytes();
        let decoder = Decoder::new(&bytes)?;
        let header = decoder.header().clone();
        let params = CodecParams {
            lattice: (header.lattice_width, header.lattice_height),
            qscale: header.qscale,
            gop: header.gop,
            padding: header.padding.clone(),
        };
        // Later segments repeat the first one's choices instead of making their own.
        let opts = EncodeOptions {
            predictor: PredictorChoice::Fixed(header.predictor),
            first_frame_bits: Some(header.first_frame_bits),
            segment_frames: Some(length),
            ..opts.clone()
        };
        let (mut shared, mut own) = (Vec::new(), Vec::new());
        for part in encoded.container.into_parts() {
            match part.tag.per_segment() {
                true => own.push(part),
                false if part.tag == Tag::HEADER => {}
                false => shared.push(part),
            }
        }
        own.insert(0, SegmentStart::part(&(0..first.frame_count()))?);
        Ok(Self {
            opts,
            length,
            reference: decoder.reference().to_vec(),
            input_triangles: first.triangles().to_vec(),
            partition: decoder.partition().clone(),
            weights: decoder.weights().cloned(),
            permutation: encoded.report.permutation.clone(),
            diagonal: first.bbox_diagonal(),
            atlas: AtlasCache::default(),
            header,
            params,
            shared,
            segments: vec![own],
            frames: first.frame_count(),
            report: encoded.report,
            model: encoded.model,
            clock,
        })
    }

    /// Frames coded so far.
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Codes the next segment: `frames`, the clip's frames from [`SegmentedEncoder::frames`] on,
    /// in the input's vertex order, at most a segment's length.
    pub fn push(&mut self, frames: Vec<Vec<Point>>, progress: &dyn Progress) -> Result<()> {
        if frames.is_empty() || frames.len() > self.length {
            return Err(Error::Usage(format!(
                "a segment holds 1 to {} frames, not {}",
                self.length,
                frames.len()
            )));
        }
        let range = self.frames..self.frames + frames.len();
        let mut clip = AnimatedMesh::new(self.input_triangles.clone(), frames)?;
        if let Some(order) = &self.permutation {
            clip = clip.permuted(order)?;
        }
        let parts = self.code(&clip, &range, progress)?;
        self.segments.push(parts);
        self.frames = range.end;
        Ok(())
    }

    /// The stream: the shared parts, then every segment's.
    pub fn finish(self) -> Result<Encoded> {
        let header = Header {
            frames: u32::try_from(self.frames)
                .map_err(|_| Error::Usage(format!("{} frames is past 2^32", self.frames)))?,
            ..self.header
        };
        let segments = self.segments.len();
        let mut container = ContainerWriter::new();
        container.push(Part::whole(Tag::HEADER, header.to_bytes()));
        self.shared.into_iter().for_each(|p| container.push(p));
        for parts in self.segments {
            parts.into_iter().for_each(|p| container.push(p));
        }
        let mut report = self.report;
        report
            .stage_seconds
            .push(("segments".into(), self.clock.elapsed().as_secs_f64()));
        report.parts = container.part_sizes();
        report.bytes = container.len();
        report.bpvf = report.bytes as f64 * 8.0 / (header.vertices as f64 * self.frames as f64);
        report.segments = segments;
        report.header = header;
        Ok(Encoded {
            container,
            report,
            model: self.model,
            partition: self.partition,
        })
    }

    /// One later segment's parts: its marker, affine maps and residual coder's parts.
    fn code(
        &self,
        clip: &AnimatedMesh,
        range: &Range<usize>,
        progress: &dyn Progress,
    ) -> Result<Vec<Part>> {
        let track = AffineTrack::fit(
            clip.frames(),
            &self.reference,
            &self.partition,
            self.opts.affine_step(),
        )?;
        let residuals = (0..clip.frame_count())
            .map(|f| {
                let predicted = motion::predict_frame(
                    &track,
                    self.weights.as_ref(),
                    f,
                    &self.reference,
                    &self.partition,
                )?;
                Ok(motion::residuals(clip.frame(f), &predicted))
            })
            .collect::<Result<Vec<_>>>()?;
        let coded = self.opts.codec.encoder()?.encode(&ResidualInput {
            mesh: clip,
            diagonal: self.diagonal,
            reference: &self.reference,
            partition: &self.partition,
            residuals: &residuals,
            options: &self.opts,
            progress,
            atlas: Some(&self.atlas),
        })?;
        self.check_shared(&coded.params, &coded.before_predictor)?;
        let mut parts = vec![
            SegmentStart::part(range)?,
            Part::whole(Tag::AFFINE, side_info::encode_affine(&track)?),
        ];
        parts.extend(coded.after_predictor);
        Ok(parts)
    }

    /// A later segment's codec must have made the first one's lattice and settings: the header
    /// and the lattice part are the whole stream's.
    fn check_shared(&self, params: &CodecParams, before: &[Part]) -> Result<()> {
        let same_parts = before.iter().all(|p| {
            self.shared
                .iter()
                .any(|s| s.tag == p.tag && s.bytes == p.bytes)
        });
        if *params != self.params || !same_parts {
            return Err(Error::Codec(format!(
                "segment from frame {}: the {} coder did not reproduce the first segment's \
                 lattice and settings ({params:?} against {:?})",
                self.frames,
                self.opts.codec.name(),
                self.params
            )));
        }
        Ok(())
    }
}

/// Encodes `mesh` in segments of `length` frames.
pub fn encode(
    mesh: &AnimatedMesh,
    opts: &EncodeOptions,
    length: usize,
    progress: &dyn Progress,
) -> Result<Encoded> {
    let ranges = crate::stream::segments::split(mesh.frame_count(), length);
    progress.total(mesh.frame_count() as u64);
    let mut encoder =
        SegmentedEncoder::start(&mesh.clip(ranges[0].clone())?, opts, length, progress)?;
    for range in &ranges[1..] {
        progress.stage(&format!("segment from frame {}", range.start));
        encoder.push(mesh.frames()[range.clone()].to_vec(), progress)?;
    }
    encoder.finish()
}

/// Encodes the animation `source` reads, a segment at a time when it is longer than the
/// options' segment length: memory holds one segment's frames, whatever the clip's length.
pub fn encode_source(
    source: &mut FrameSource,
    opts: &EncodeOptions,
    progress: &dyn Progress,
) -> Result<Encoded> {
    let frames = source.frame_count();
    let length = match opts.segment_frames {
        Some(n) if frames > n => n,
        _ => return super::encode_with_progress(&source.clip(0..frames)?, opts, progress),
    };
    let ranges = crate::stream::segments::split(frames, length);
    let first = source.clip(ranges[0].clone())?;
    progress.total(frames as u64);
    let mut encoder = SegmentedEncoder::start(&first, opts, length, progress)?;
    drop(first);
    for range in &ranges[1..] {
        progress.stage(&format!("segment from frame {}", range.start));
        encoder.push(source.read(range.clone())?, progress)?;
    }
    encoder.finish()
}

/// Passes progress on, except the first segment's total: the whole clip's is told up front.
struct NoTotal<'a>(&'a dyn Progress);

impl Progress for NoTotal<'_> {
    fn stage(&self, name: &str) {
        self.0.stage(name);
    }

    fn frames(&self, count: u64) {
        self.0.frames(count);
    }
}
