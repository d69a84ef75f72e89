//! Temporal segments: a clip longer than `segment_frames` is coded as runs of frames,
//! so that the temporal DCT and the groups of pictures, and the encoder's memory, stay the size
//! of a segment whatever the clip's length.
//!
//! The *analysis clip* — a segment's worth of frames spread evenly over the clip, the first frame
//! first ([`analysis_frames`]) — is encoded as a clip of its own, with every automatic choice
//! (motion model, K, first-frame precision). Its first frame, partition, lattice and skinning
//! weights become the whole stream's; each segment gets its own affine maps and residual parts,
//! predicted from the shared parts *as the decoder reads them* (decoded from the analysis clip's
//! stream), so encoder and decoder agree bit for bit. Frames spread over the clip let the
//! clusters and weights see all of its motion, not only its start (a captured performance often
//! opens in a rest pose; docs/design.md, "Temporal segments: 128 frames").
//!
//! A program can feed segments one by one ([`SegmentedEncoder::start`], [`SegmentedEncoder::push`],
//! [`SegmentedEncoder::finish`]), e.g. from a reader that never holds the whole clip.

use super::{EncodeOptions, EncodeReport, Encoded, MotionModel, PredictorChoice};
use crate::codec::{RatePlan, ResidualInput};
use crate::decoder::Decoder;
use crate::error::{Error, Result};
use crate::geometry_image::lattice::AtlasCache;
use crate::mesh::{AnimatedMesh, FrameSource, Point, Triangle};
use crate::motion::{AffineTrack, Partition, SkinningWeights};
use crate::progress::Progress;
use crate::stream::container::{ContainerReader, ContainerWriter, Part, Tag};
use crate::stream::header::Header;
use crate::stream::segments::SegmentStart;
use crate::stream::side_info;
use rayon::prelude::*;
use std::ops::Range;
use std::time::Instant;

/// An encoding in progress, one segment at a time.
pub struct SegmentedEncoder {
    opts: EncodeOptions,
    /// Frames per segment; every segment but the last has this many.
    length: usize,
    /// What the decoder reads of the analysis clip's stream, which every segment is predicted from.
    reference: Vec<Point>,
    /// The connectivity in the input's vertex order, which pushed frames come in.
    input_triangles: Vec<Triangle>,
    partition: Partition,
    weights: Option<SkinningWeights>,
    /// First-frame coder's vertex order (stream index → input index), when it reordered.
    permutation: Option<Vec<u32>>,
    /// Every step and codec setting, resolved on the first frame (the whole clip's).
    plan: RatePlan,
    atlas: AtlasCache,
    header: Header,
    shared: Vec<Part>,
    segments: Vec<Vec<Part>>,
    frames: usize,
    report: EncodeReport,
    model: MotionModel,
    clock: Instant,
}

impl SegmentedEncoder {
    /// Makes the choices of an encoding in segments of `length` frames on `analysis`, the clip's
    /// [`analysis_frames`] (frame 0 first), with every automatic choice `opts` leaves open.
    pub fn start(
        analysis: &AnimatedMesh,
        opts: &EncodeOptions,
        length: usize,
        progress: &dyn Progress,
    ) -> Result<Self> {
        if length == 0 || analysis.frame_count() > length {
            return Err(Error::option(
                "segment_frames",
                format!(
                    "{length}: the analysis clip has {} frames",
                    analysis.frame_count()
                ),
            ));
        }
        let clock = Instant::now();
        let whole = EncodeOptions {
            segment_frames: None,
            ..opts.clone()
        };
        let encoded = super::encode_with_progress(analysis, &whole, &NoTotal(progress))?;
        let bytes = encoded.to_bytes();
        let decoder = Decoder::new(&bytes)?;
        let header = decoder.header().clone();
        let plan = opts.plan(analysis.bbox_diagonal())?;
        // Every segment repeats the analysis clip's choices instead of making its own.
        let opts = EncodeOptions {
            predictor: PredictorChoice::Fixed(header.predictor),
            first_frame_bits: Some(header.first_frame_bits),
            segment_frames: Some(length),
            ..opts.clone()
        };
        // The analysis clip's own affine maps and residuals are not the clip's: dropped.
        let shared = encoded
            .container
            .into_parts()
            .into_iter()
            .filter(|p| !p.tag.per_segment() && p.tag != Tag::HEADER)
            .collect();
        Ok(Self {
            opts,
            length,
            reference: decoder.reference().to_vec(),
            input_triangles: analysis.triangles().to_vec(),
            partition: decoder.partition().clone(),
            weights: decoder.weights().cloned(),
            permutation: encoded.report.permutation.clone(),
            plan,
            atlas: AtlasCache::default(),
            header,
            shared,
            segments: Vec::new(),
            frames: 0,
            report: encoded.report,
            model: encoded.model,
            clock,
        })
    }

    /// Frames coded so far.
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Codes the next segment: `frames`, the clip's frames from [`SegmentedEncoder::frames`] on
    /// (the first segment starts at the clip's first frame), in the input's vertex order, at most
    /// a segment's length.
    pub fn push(&mut self, frames: Vec<Vec<Point>>, progress: &dyn Progress) -> Result<()> {
        let segment = self.code_segment(self.frames, frames, progress)?;
        self.add(segment)
    }

    /// Codes the segment of `frames` starting at clip frame `first_frame`, without adding it: any
    /// segment, in any order, on any thread — or on another machine whose encoder started from
    /// the same analysis clip and options (the encoder is deterministic), to be
    /// [added](SegmentedEncoder::add) in order here.
    pub fn code_segment(
        &self,
        first_frame: usize,
        frames: Vec<Vec<Point>>,
        progress: &dyn Progress,
    ) -> Result<CodedSegment> {
        if frames.is_empty() || frames.len() > self.length {
            return Err(Error::Usage(format!(
                "a segment holds 1 to {} frames, not {}",
                self.length,
                frames.len()
            )));
        }
        let range = first_frame..first_frame + frames.len();
        let mut clip = AnimatedMesh::new(self.input_triangles.clone(), frames)?;
        if let Some(order) = &self.permutation {
            clip = clip.permuted(order)?;
        }
        let parts = self.code(&clip, &range, progress)?;
        Ok(CodedSegment {
            frames: range,
            parts,
        })
    }

    /// Appends a coded segment; it must start where the segments added so far end.
    pub fn add(&mut self, segment: CodedSegment) -> Result<()> {
        if segment.frames.start != self.frames {
            return Err(Error::Usage(format!(
                "the segment of frames {:?} does not follow frame {}: add segments in order",
                segment.frames, self.frames
            )));
        }
        self.frames = segment.frames.end;
        self.segments.push(segment.parts);
        Ok(())
    }

    /// The stream: the shared parts, then every segment's.
    pub fn finish(self) -> Result<Encoded> {
        if self.segments.is_empty() {
            return Err(Error::Usage(
                "no segment was pushed: the stream has no frames".into(),
            ));
        }
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

    /// One segment's parts: its marker, affine maps and residual coder's parts.
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
            self.plan.affine_step,
        )?;
        let residuals = super::analysis::residuals_of(
            clip,
            &self.reference,
            &self.partition,
            &track,
            self.weights.as_ref(),
        )?;
        let coded = self.plan.encoder()?.encode(&ResidualInput {
            mesh: clip,
            reference: &self.reference,
            partition: &self.partition,
            residuals: &residuals,
            progress,
            atlas: Some(&self.atlas),
        })?;
        let (before, after) = coded.into_parts();
        self.check_shared(&before)?;
        let mut parts = vec![
            SegmentStart::part(range)?,
            Part::whole(Tag::AFFINE, side_info::encode_affine(&track)?),
        ];
        parts.extend(after);
        Ok(parts)
    }

    /// A segment's codec must have made the analysis clip's set-up and whole-stream parts (its
    /// lattice and settings): those are the whole stream's.
    fn check_shared(&self, before: &[Part]) -> Result<()> {
        let same = before.iter().all(|p| {
            self.shared
                .iter()
                .any(|s| s.tag == p.tag && s.bytes == p.bytes)
        });
        if !same {
            return Err(Error::Codec(format!(
                "segment from frame {}: the {} coder did not reproduce the analysis clip's set-up \
                 and lattice",
                self.frames,
                self.opts.codec.codec().name(),
            )));
        }
        Ok(())
    }
}

/// The frames of the analysis clip of a clip of `frames` frames cut into segments of `length`:
/// `length` frames spread evenly from the first to the last (all of a clip no longer than that).
pub fn analysis_frames(frames: usize, length: usize) -> Vec<usize> {
    let n = length.clamp(1, frames.max(1));
    if n == 1 {
        return vec![0];
    }
    (0..n).map(|i| i * (frames - 1) / (n - 1)).collect()
}

/// Encodes `mesh` in segments of `length` frames.
pub fn encode(
    mesh: &AnimatedMesh,
    opts: &EncodeOptions,
    length: usize,
    progress: &dyn Progress,
) -> Result<Encoded> {
    let frames = mesh.frame_count();
    let read = |list: &[usize]| Ok(list.iter().map(|&f| mesh.frame(f).to_vec()).collect());
    encode_runs(mesh, frames, length, opts, progress, read)
}

/// Encodes the animation `source` reads, in segments when it is longer than the options' segment
/// length: memory holds `parallel_segments` segments' frames and working data (one by default),
/// whatever the clip's length.
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
    let first = source.first().clone();
    encode_runs(&first, frames, length, opts, progress, |list| {
        source.read_list(list)
    })
}

/// Encodes a clip of `frames` frames in segments of `length`, reading its frames by ranges with
/// `read`: the analysis clip's frames, then `parallel_segments` segments at a time,
/// coded on rayon's threads. `first` gives the connectivity, attributes and frame rate.
fn encode_runs(
    first: &AnimatedMesh,
    frames: usize,
    length: usize,
    opts: &EncodeOptions,
    progress: &dyn Progress,
    mut read: impl FnMut(&[usize]) -> Result<Vec<Vec<Point>>>,
) -> Result<Encoded> {
    let spread = read(&analysis_frames(frames, length))?;
    let analysis = AnimatedMesh::new(first.triangles().to_vec(), spread)?
        .with_attributes(first.attributes().clone())?
        .with_frame_rate(first.frame_rate());
    progress.total(frames as u64);
    let mut encoder = SegmentedEncoder::start(&analysis, opts, length, progress)?;
    drop(analysis);
    progress.stage("segments");
    let ranges = crate::stream::segments::split(frames, length);
    for batch in ranges.chunks(opts.parallel_segments.max(1)) {
        let runs = batch
            .iter()
            .map(|r| Ok((r.start, read(&r.clone().collect::<Vec<_>>())?)))
            .collect::<Result<Vec<_>>>()?;
        let coded: Vec<Result<CodedSegment>> = runs
            .into_par_iter()
            .map(|(start, frames)| encoder.code_segment(start, frames, progress))
            .collect();
        for segment in coded {
            encoder.add(segment?)?;
        }
    }
    encoder.finish()
}

/// One coded segment, a separable unit of the stream: its start marker, affine maps and residual
/// parts. [`CodedSegment::to_bytes`] makes it a file of its own (a container of those parts) to
/// ship between machines; [`CodedSegment::from_bytes`] reads it back.
#[derive(Debug, Clone, PartialEq)]
pub struct CodedSegment {
    frames: Range<usize>,
    parts: Vec<Part>,
}

impl CodedSegment {
    /// The clip frames the segment codes.
    pub fn frames(&self) -> Range<usize> {
        self.frames.clone()
    }

    /// The segment as bytes: a container of its parts.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut container = ContainerWriter::new();
        self.parts.iter().for_each(|p| container.push(p.clone()));
        container.to_bytes()
    }

    /// Reads a segment [`CodedSegment::to_bytes`] wrote, checking its parts' checksums.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self> {
        let mut reader = ContainerReader::new(std::io::Cursor::new(bytes))?;
        let entries = reader.parts().to_vec();
        let one_segment =
            reader.segments() == 1 && entries.first().map(|e| e.tag) == Some(Tag::SEGMENT);
        if !one_segment {
            return Err(Error::Stream(
                "not a coded segment: it must hold one segment's parts and nothing else".into(),
            ));
        }
        let parts = entries
            .iter()
            .map(|e| {
                Ok(Part {
                    tag: e.tag,
                    bytes: reader.payload(e)?,
                    checksum: e.checksum,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        // The first part is the start marker (checked above).
        let start = SegmentStart::from_bytes(&parts[0].bytes)?;
        let first = start.first_frame as usize;
        Ok(Self {
            frames: first..first + start.frames as usize,
            parts,
        })
    }
}

/// Passes progress on, except the analysis clip's total: the whole clip's is told up front.
struct NoTotal<'a>(&'a dyn Progress);

impl Progress for NoTotal<'_> {
    fn stage(&self, name: &str) {
        self.0.stage(name);
    }

    fn frames(&self, count: u64) {
        self.0.frames(count);
    }
}
