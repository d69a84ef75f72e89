//! Temporal segments: a clip longer than `segment_frames` is coded as runs of frames,
//! so that the temporal DCT and the groups of pictures, and the encoder's memory, stay the size
//! of a segment whatever the clip's length.
//!
//! The *analysis clip* — a segment's worth of frames spread evenly over the clip, the first frame
//! first ([`super::analysis_frames`]) — is encoded as a clip of its own, with every automatic choice
//! (motion model, K, first-frame precision). Its first frame, partition, lattice and skinning
//! weights become the whole stream's; each segment gets its own affine maps and residual parts,
//! predicted from the shared parts *as the decoder reads them* (decoded from the analysis clip's
//! stream), so encoder and decoder agree bit for bit. Frames spread over the clip let the
//! clusters and weights see all of its motion, not only its start (a captured performance often
//! opens in a rest pose; docs/design.md, "Temporal segments: 128 frames").
//!
//! A program can feed segments one by one ([`SegmentedEncoder::start`], [`SegmentedEncoder::push`],
//! [`SegmentedEncoder::finish`]), e.g. from a reader that never holds the whole clip.

use super::analysis::SegmentationReport;
use super::{EncodeOptions, EncodeReport, Encoded, MotionModel, PredictorChoice, Segmentation};
use crate::codec::{RatePlan, ResidualInput};
use crate::decoder::Decoder;
use crate::error::{Error, Result};
use crate::geometry_image::lattice::AtlasCache;
use crate::mesh::{AnimatedMesh, Point, Triangle};
use crate::motion::{AffineTrack, Partition, PredictorKind, SkinningWeights};
use crate::progress::{Budgeted, Progress};
use crate::stream::bytes::{ByteReader, ByteWriter};
use crate::stream::container::{ContainerReader, ContainerWriter, Part, Tag};
use crate::stream::header::Header;
use crate::stream::segments::SegmentStart;
use crate::stream::side_info;
use std::ops::Range;
use std::time::Instant;

/// An encoding in progress, one segment at a time.
pub struct SegmentedEncoder {
    opts: EncodeOptions,
    /// What [`SegmentedEncoder::start`] decided on the analysis clip, as
    /// [`SegmentedEncoder::analysis`] ships it.
    analysis: Analysis,
    /// What the decoder reads of the analysis clip's stream, which every segment is predicted from.
    reference: Vec<Point>,
    partition: Partition,
    weights: Option<SkinningWeights>,
    /// Every step and codec setting, resolved on the first frame (the whole clip's).
    plan: RatePlan,
    atlas: AtlasCache,
    header: Header,
    shared: Vec<Part>,
    segments: Vec<Vec<Part>>,
    /// Each segment's residual spread, where known ([`EncodeReport::residual_spread`]).
    spreads: Vec<Option<f64>>,
    frames: usize,
    report: EncodeReport,
    clock: Instant,
}

/// What [`SegmentedEncoder::start`] decides on the analysis clip and every segment is coded
/// from: the analysis clip's stream, and what a decoder of it cannot tell.
#[derive(Debug, Clone, PartialEq)]
struct Analysis {
    /// The analysis clip encoded as a clip of its own: its first frame, partition, weights and
    /// codec set-up are the whole stream's. Usually a stream of the first frame alone
    /// ([`super::Keep::SharedParts`]): its residuals would be dropped; every frame when the
    /// model is fixed and tdct's first-frame precisions are compared by whole streams.
    stream: Vec<u8>,
    /// Frames per segment; every segment but the last has this many.
    length: usize,
    /// The first frame's bounding-box diagonal, which every step is a fraction of.
    diagonal: f64,
    /// The connectivity in the input's vertex order, which segments' frames come in.
    triangles: Vec<Triangle>,
    /// First-frame coder's vertex order (stream index → input index), when it reordered.
    permutation: Option<Vec<u32>>,
    /// The motion model the analysis kept.
    model: MotionModel,
    /// A checksum of the options the analysis was made with: a segment coded with others would
    /// not join into a valid stream.
    options: u32,
}

/// The first bytes of [`SegmentedEncoder::analysis`]'s bytes, with the format's version.
const ANALYSIS_MAGIC: &[u8; 8] = b"MCGVANL1";

impl Analysis {
    fn to_bytes(&self) -> Vec<u8> {
        let mut w = ByteWriter::new();
        w.raw(ANALYSIS_MAGIC)
            .u32(self.options)
            .u32(self.length as u32)
            .u64(self.diagonal.to_bits())
            .u8(match self.model.predictor {
                PredictorKind::Affine => 0,
                PredictorKind::Skinning => 1,
            });
        match self.model.segmentation {
            Segmentation::KMeans => w.u8(0).u64(0),
            Segmentation::Decimation { e0 } => w.u8(1).u64(e0.to_bits()),
        };
        w.u32(self.model.clusters as u32);
        w.u8(u8::from(self.permutation.is_some()));
        if let Some(order) = &self.permutation {
            w.u32(order.len() as u32);
            for &v in order {
                w.u32(v);
            }
        }
        w.u32(self.triangles.len() as u32);
        for &v in self.triangles.iter().flatten() {
            w.u32(v);
        }
        w.u64(self.stream.len() as u64).raw(&self.stream);
        let mut bytes = w.into_bytes();
        let crc = crc32fast::hash(&bytes);
        bytes.extend_from_slice(&crc.to_le_bytes());
        bytes
    }

    /// Reads [`Analysis::to_bytes`]'s bytes, checking their checksum and every count against
    /// the bytes that must hold it before allocating.
    fn from_bytes(bytes: &[u8]) -> Result<Self> {
        let damaged = |what: &str| Error::Stream(format!("segment analysis: {what}"));
        let Some((body, crc)) = bytes.split_last_chunk::<4>() else {
            return Err(damaged("truncated"));
        };
        if !body.starts_with(ANALYSIS_MAGIC) {
            return Err(damaged("not the bytes of SegmentedEncoder::analysis"));
        }
        if crc32fast::hash(body) != u32::from_le_bytes(*crc) {
            return Err(damaged("checksum mismatch (damaged bytes)"));
        }
        let mut r = ByteReader::new(&body[ANALYSIS_MAGIC.len()..], "segment analysis");
        let options = r.u32()?;
        let length = r.u32()? as usize;
        let diagonal = f64::from_bits(r.u64()?);
        let predictor = match r.u8()? {
            0 => PredictorKind::Affine,
            1 => PredictorKind::Skinning,
            p => return Err(damaged(&format!("unknown predictor {p}"))),
        };
        let segmentation = match (r.u8()?, f64::from_bits(r.u64()?)) {
            (0, _) => Segmentation::KMeans,
            (1, e0) => Segmentation::Decimation { e0 },
            (s, _) => return Err(damaged(&format!("unknown segmentation {s}"))),
        };
        let clusters = r.u32()? as usize;
        let u32s = |r: &mut ByteReader, n: usize| -> Result<Vec<u32>> {
            let raw = r.take(n.checked_mul(4).ok_or_else(|| damaged("count overflows"))?)?;
            Ok(raw
                .chunks_exact(4)
                .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                .collect())
        };
        let permutation = match r.u8()? {
            0 => None,
            _ => {
                let n = r.u32()? as usize;
                Some(u32s(&mut r, n)?)
            }
        };
        let n = r.u32()? as usize;
        let corners = u32s(&mut r, n.checked_mul(3).ok_or_else(|| damaged("count overflows"))?)?;
        let triangles = corners.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
        let len = usize::try_from(r.u64()?).map_err(|_| damaged("stream length"))?;
        let stream = r.take(len)?.to_vec();
        r.finish()?;
        if length == 0 || !(diagonal.is_finite() && diagonal >= 0.0) {
            return Err(damaged("segment length or diagonal out of range"));
        }
        Ok(Self {
            stream,
            length,
            diagonal,
            triangles,
            permutation,
            model: MotionModel {
                predictor,
                segmentation,
                clusters,
            },
            options,
        })
    }
}

/// The report of a resumed encoder: the stream's figures are filled in by `finish`; the
/// analysis' choices and timings stayed with the encoder that made it.
fn resumed_report(header: &Header, analysis: &Analysis, opts: &EncodeOptions) -> EncodeReport {
    let model = analysis.model;
    EncodeReport {
        header: header.clone(),
        codec: opts.codec.codec(),
        parts: Vec::new(),
        bytes: 0,
        bpvf: 0.0,
        charts: 0,
        packing_efficiency: 0.0,
        moved_vertices: 0,
        l2_stretch: 0.0,
        stage_seconds: Vec::new(),
        segmentation: SegmentationReport {
            method: model.segmentation.name(),
            clusters: header.clusters as usize,
            seconds: 0.0,
            e0: match model.segmentation {
                Segmentation::Decimation { e0 } => Some(e0),
                Segmentation::KMeans => None,
            },
            error: None,
            components: None,
        },
        choice: None,
        first_frame_trials: Vec::new(),
        residual_spread: None,
        picture_depth: None,
        segments: 0,
        permutation: analysis.permutation.clone(),
    }
}

/// A checksum of the options that shape a segment: all but `parallel_segments` (how many are
/// coded at once) and `segment_frames` (the analysis holds the length).
fn options_checksum(opts: &EncodeOptions) -> u32 {
    let shaping = EncodeOptions {
        parallel_segments: 1,
        segment_frames: None,
        ..opts.clone()
    };
    crc32fast::hash(format!("{shaping:?}").as_bytes())
}

impl SegmentedEncoder {
    /// Makes the choices of an encoding in segments of `length` frames on `analysis`, the clip's
    /// [`super::analysis_frames`] (frame 0 first), with every automatic choice `opts` leaves open.
    /// Its work counts as `analysis`'s frames on `progress` (whose total it does not tell): a
    /// caller's total for the whole encoding is the clip's frames plus these.
    pub fn start(
        analysis: &AnimatedMesh,
        opts: &EncodeOptions,
        length: usize,
        progress: &dyn Progress,
    ) -> Result<Self> {
        Self::start_reusing(analysis, opts, length, progress, None)
    }

    /// [`Self::start`], the analysis clip coded on what `reuse` holds (see
    /// [`super::encode_reusing`]).
    pub(crate) fn start_reusing(
        analysis: &AnimatedMesh,
        opts: &EncodeOptions,
        length: usize,
        progress: &dyn Progress,
        reuse: Option<&super::Reuse>,
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
        whole.check(analysis)?;
        let keep = super::Keep::SharedParts;
        let budgeted = Budgeted::new(progress, analysis.frame_count() as u64);
        let mut encoded = super::encode_clip(analysis, &whole, &budgeted, keep, reuse)?;
        budgeted.finish();
        // The segments' atlas is the analysis clip's (same first frame, partition and lattice
        // option; `check_shared` holds them to its lattice part): built once, not twice.
        let atlas = encoded.atlas.take().map_or_else(AtlasCache::default, AtlasCache::holding);
        let shared = Analysis {
            stream: encoded.to_bytes(),
            length,
            diagonal: analysis.bbox_diagonal(),
            triangles: analysis.triangles().to_vec(),
            permutation: encoded.report.permutation.clone(),
            model: encoded.model,
            options: options_checksum(opts),
        };
        Self::from_analysis(shared, opts, (Some(encoded.report), atlas), clock)
    }

    /// The analysis [`SegmentedEncoder::start`] made, as bytes (the analysis clip's stream and
    /// what its decoder cannot tell; about the size of that stream plus 12 bytes a triangle):
    /// [`SegmentedEncoder::resume`] makes an encoder from them on another thread, process or
    /// machine without redoing the analysis, which costs more than coding a segment.
    pub fn analysis(&self) -> Vec<u8> {
        self.analysis.to_bytes()
    }

    /// An encoder from [`SegmentedEncoder::analysis`]'s bytes and the options the analysis was
    /// made with (another `parallel_segments` is fine; other options are an error): it codes
    /// segments, and adds and finishes them, as the encoder that ran [`SegmentedEncoder::start`]
    /// does, byte for byte. Its [`Encoded::report`] holds the stream's figures but not the
    /// analysis' choices and timings, which stay with that encoder.
    pub fn resume(analysis: &[u8], opts: &EncodeOptions) -> Result<Self> {
        let analysis = Analysis::from_bytes(analysis)?;
        if analysis.options != options_checksum(opts) {
            return Err(Error::Usage(
                "the analysis was made with other encoding options: resume with the same".into(),
            ));
        }
        let fresh = (None, AtlasCache::default());
        Self::from_analysis(analysis, opts, fresh, Instant::now())
    }

    /// The encoder of an analysis: everything but the analysis' own figures (`report`, when it
    /// was just made) and its atlas (`atlas`, when one was built) is read from the analysis
    /// clip's stream as the decoder reads it, so a started and a resumed encoder agree.
    fn from_analysis(
        analysis: Analysis,
        opts: &EncodeOptions,
        (report, atlas): (Option<EncodeReport>, AtlasCache),
        clock: Instant,
    ) -> Result<Self> {
        let decoder = Decoder::new(&analysis.stream)?;
        let header = decoder.header().clone();
        let report = report.unwrap_or_else(|| resumed_report(&header, &analysis, opts));
        let vertices = header.vertices as usize;
        let consistent = analysis.triangles.len() == header.triangles as usize
            && analysis.triangles.iter().flatten().all(|&v| (v as usize) < vertices)
            && analysis.permutation.as_ref().is_none_or(|p| p.len() == vertices)
            && header.predictor == analysis.model.predictor;
        if !consistent {
            return Err(Error::Stream(
                "segment analysis: its connectivity or vertex order does not fit its stream".into(),
            ));
        }
        // Every segment repeats the analysis clip's choices instead of making its own.
        let opts = EncodeOptions {
            predictor: PredictorChoice::Fixed(header.predictor),
            first_frame_bits: Some(header.first_frame_bits),
            segment_frames: Some(analysis.length),
            ..opts.clone()
        };
        // The analysis clip's own affine maps and residuals are not the clip's: dropped.
        let mut reader = ContainerReader::new(std::io::Cursor::new(&analysis.stream[..]))?;
        let shared = reader
            .parts()
            .to_vec()
            .into_iter()
            .filter(|e| !e.tag.per_segment() && e.tag != Tag::HEADER)
            .map(|e| {
                Ok(Part {
                    tag: e.tag,
                    bytes: reader.payload(&e)?,
                    checksum: e.checksum,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        // Every segment codes its pictures at the depth the analysis clip's set-up took.
        let setup = shared.iter().find(|p| p.tag == Tag::CODEC_SETUP);
        let plan = opts.plan(analysis.diagonal)?;
        let plan = match setup {
            Some(setup) => plan.pinned_to(&setup.bytes, header.vertices)?,
            None => plan,
        };
        let (reference, partition, weights) = (
            decoder.reference().to_vec(),
            decoder.partition().clone(),
            decoder.weights().cloned(),
        );
        drop(decoder);
        Ok(Self {
            opts,
            reference,
            partition,
            weights,
            plan,
            atlas,
            header,
            shared,
            segments: Vec::new(),
            spreads: Vec::new(),
            frames: 0,
            report,
            clock,
            analysis,
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
        if frames.is_empty() || frames.len() > self.analysis.length {
            return Err(Error::Usage(format!(
                "a segment holds 1 to {} frames, not {}",
                self.analysis.length,
                frames.len()
            )));
        }
        let range = first_frame..first_frame + frames.len();
        let mut clip = AnimatedMesh::new(self.analysis.triangles.clone(), frames)?;
        if let Some(order) = &self.analysis.permutation {
            clip = clip.permuted(order)?;
        }
        let (parts, residual_spread) = self.code(&clip, &range, progress)?;
        Ok(CodedSegment {
            frames: range,
            parts,
            residual_spread,
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
        self.spreads.push(segment.residual_spread);
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
        container.push(Part::whole(Tag::HEADER, header.to_bytes()))?;
        for part in self.shared.into_iter().chain(self.segments.into_iter().flatten()) {
            container.push(part)?;
        }
        let mut report = self.report;
        report
            .stage_seconds
            .push(("segments".into(), self.clock.elapsed().as_secs_f64()));
        report.parts = container.part_sizes();
        report.bytes = container.len();
        report.bpvf = report.bytes as f64 * 8.0 / (header.vertices as f64 * self.frames as f64);
        report.segments = segments;
        // Known when every segment's is (one shipped as bytes does not carry it).
        let spreads: Option<Vec<f64>> = self.spreads.iter().copied().collect();
        report.residual_spread = spreads.and_then(|s| s.into_iter().reduce(f64::max));
        report.picture_depth = self.plan.pictures.as_ref().map(|p| p.depth);
        report.header = header;
        Ok(Encoded {
            container,
            report,
            model: self.analysis.model,
            partition: self.partition,
            atlas: self.atlas.into_inner(),
        })
    }

    /// One segment's parts: its marker, affine maps and residual coder's parts.
    fn code(
        &self,
        clip: &AnimatedMesh,
        range: &Range<usize>,
        progress: &dyn Progress,
    ) -> Result<(Vec<Part>, Option<f64>)> {
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
        let spread = coded.residual_spread;
        let (before, after) = coded.into_parts();
        self.check_shared(&before)?;
        let mut parts = vec![
            SegmentStart::part(range)?,
            Part::whole(Tag::AFFINE, side_info::encode_affine(&track)?),
        ];
        parts.extend(after);
        Ok((parts, spread))
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

/// One coded segment, a separable unit of the stream: its start marker, affine maps and residual
/// parts. [`CodedSegment::to_bytes`] makes it a file of its own (a container of those parts) to
/// ship between machines; [`CodedSegment::from_bytes`] reads it back.
#[derive(Debug, Clone, PartialEq)]
pub struct CodedSegment {
    frames: Range<usize>,
    parts: Vec<Part>,
    /// Its residuals' spread ([`EncodeReport::residual_spread`]); not among its bytes.
    residual_spread: Option<f64>,
}

impl CodedSegment {
    /// The clip frames the segment codes.
    pub fn frames(&self) -> Range<usize> {
        self.frames.clone()
    }

    /// The segment as bytes: a container of its parts.
    pub fn to_bytes(&self) -> Result<Vec<u8>> {
        let mut container = ContainerWriter::new();
        for part in &self.parts {
            container.push(part.clone())?;
        }
        Ok(container.to_bytes())
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
            residual_spread: None,
        })
    }
}
