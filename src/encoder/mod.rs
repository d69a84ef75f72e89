//! The encoder: mesh → first frame → motion segmentation → predictor and residuals → residual
//! codec → stream.
//!
//! [`encode`] codes an animation with [`EncodeOptions`] and returns the stream with its
//! [`EncodeReport`]; options left open (`Auto` predictor or segmentation, first-frame precision)
//! are chosen by coding the candidates and keeping the fewest bits at equal error
//! ([`ChoiceReport`]). A clip longer than [`EncodeOptions::segment_frames`] is coded in temporal
//! segments: [`SegmentedEncoder`] does that one segment at a time, and [`CodedSegment`]s coded on
//! other threads or machines join into the same stream.

mod attributes;
mod budget;
mod budget_depth;
mod budget_line;
mod choice_reason;
mod crf_split;
mod options;
mod report;
internal! {
    analysis;
    auto;
    close_call;
    distortion;
    first_frame_bits;
    ladder;
    sampled_trial;
    segment_runs;
    segments;
    weights_rd;
}

pub use crate::motion::DEFAULT_E0;
use analysis::Prediction;
pub use analysis::SegmentationReport;
pub use auto::{Candidate, ChoiceReport};
pub use budget::{
    encode_to_budget, encode_to_budget_with_progress, Budget, BudgetReport, BudgetTrial, Budgeted,
    MAX_BUDGET_ENCODES,
};
use crf_split::code;
pub use first_frame_bits::FirstFrameTrial;
#[cfg(feature = "internals")]
pub use options::kmeans_ladder;
pub(crate) use options::MotionModel;
pub use options::{
    EncodeOptions, PredictorChoice, Segmentation, SegmentationChoice, DEFAULT_FIRST_FRAME_BITS,
    DEFAULT_PARALLEL_SEGMENTS, DEFAULT_QUALITY, DEFAULT_SEGMENT_FRAMES, FIRST_FRAME_BITS_TRIED,
};
pub use report::{EncodeReport, Encoded};
pub use segment_runs::{analysis_clip, analysis_frames, encode_source, segment_ranges};
pub use segments::{CodedSegment, SegmentedEncoder};

use crate::codec::{Estimate, Limit, RatePlan, ResidualInput};
use crate::error::{Error, Result};
use crate::first_frame::EncodedFirstFrame;
use crate::geometry_image::lattice::AtlasCache;
use crate::mesh::{AnimatedMesh, Point};
use crate::motion::Partition;
use crate::progress::{Progress, Silent};
use crate::stream::container::{ContainerWriter, Part, Tag};
use crate::stream::header::Header;
use crate::stream::side_info;
use std::sync::atomic::AtomicU64;
use std::time::Instant;

/// Encodes an animation.
pub fn encode(mesh: &AnimatedMesh, opts: &EncodeOptions) -> Result<Encoded> {
    encode_with_progress(mesh, opts, &Silent)
}

/// Encodes an animation, telling `progress` each stage and each frame coded. With an automatic
/// predictor or segmentation, every candidate is tried and the fewest bits at equal error kept
/// ([`ChoiceReport`]); so are the first-frame precisions when `first_frame_bits` is open and the
/// codec's trials are cheap ([`FirstFrameTrial`]).
pub fn encode_with_progress(
    mesh: &AnimatedMesh,
    opts: &EncodeOptions,
    progress: &dyn Progress,
) -> Result<Encoded> {
    encode_reusing(mesh, opts, progress, None)
}

/// Encodes `mesh` as one clip (its options checked), keeping of the stream what `keep` says, on
/// what `reuse` holds when its options fix the motion model and first-frame precision.
fn encode_clip(
    mesh: &AnimatedMesh,
    opts: &EncodeOptions,
    progress: &dyn Progress,
    keep: Keep,
    reuse: Option<&Reuse>,
) -> Result<Encoded> {
    let plan = opts.plan(mesh.bbox_diagonal())?;
    let trials = opts.codec.codec().cheap_exact_trials();
    let settings = Settings {
        opts,
        plan: &plan,
        keep,
    };
    let fixed = opts.motion_models().len() == 1 && opts.first_frame_bits.is_some();
    if let Some(reuse) = reuse.filter(|_| fixed) {
        let known = (reuse.partition.clone(), reuse.segmentation.clone());
        return encode_once(mesh, settings, progress, Some(known), Some(&reuse.atlas));
    }
    match opts.first_frame_bits {
        None if trials => first_frame_bits::choose(mesh, settings, progress),
        _ => encode_once(mesh, settings, progress, None, None),
    }
}

/// What a later encoding of the same animation, first-frame precision and motion model takes
/// from an earlier one instead of finding it again: its partition (and segmentation report) and
/// its atlas (picture codecs), which no quality changes. A budget search's encodes differ in
/// their quality alone.
pub(crate) struct Reuse {
    partition: Partition,
    segmentation: SegmentationReport,
    atlas: AtlasCache,
}

impl Reuse {
    /// Takes what `encoded` found (its atlas moves out of it).
    pub(crate) fn take(encoded: &mut Encoded) -> Self {
        Self {
            partition: encoded.partition.clone(),
            segmentation: encoded.report.segmentation.clone(),
            atlas: encoded
                .atlas
                .take()
                .map_or_else(AtlasCache::default, AtlasCache::holding),
        }
    }
}

/// [`encode_with_progress`] on what an earlier encoding `reuse` holds, if any, of the same
/// animation with the same motion model and first-frame precision (fixed by `opts`, or else
/// `reuse` is ignored): the same stream without segmenting and flattening the charts again (a
/// segmented encoding's analysis clip is the one that reuses them).
pub(crate) fn encode_reusing(
    mesh: &AnimatedMesh,
    opts: &EncodeOptions,
    progress: &dyn Progress,
    reuse: Option<&Reuse>,
) -> Result<Encoded> {
    opts.check(mesh)?;
    if let Some(length) = opts.segment_frames.filter(|&n| mesh.frame_count() > n) {
        return segment_runs::encode_reusing(mesh, opts, length, progress, reuse);
    }
    encode_clip(mesh, opts, progress, Keep::Whole, reuse)
}

/// What the caller reads of an encoding's stream.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Keep {
    /// All of it.
    Whole,
    /// Its whole-stream parts alone (a segmented encoding's analysis clip, whose affine maps and
    /// residuals are not the clip's): the kept motion model's residuals are coded on the first
    /// frame only, a valid stream of one frame, instead of every frame to be dropped.
    SharedParts,
}

/// What every stage of one encoding reads: the caller's options and the rate plan resolved from
/// them once.
#[derive(Clone, Copy)]
pub(crate) struct Settings<'a> {
    /// The caller's options.
    pub opts: &'a EncodeOptions,
    /// Every step and codec setting.
    pub plan: &'a RatePlan,
    /// What the caller reads of the kept stream (trials' streams are always whole).
    pub keep: Keep,
}

impl<'a> Settings<'a> {
    /// The settings of an encoding whose whole stream is read.
    pub fn whole(opts: &'a EncodeOptions, plan: &'a RatePlan) -> Self {
        Self {
            opts,
            plan,
            keep: Keep::Whole,
        }
    }

    /// How the skinning weights are quantised: the options' bits, the plan's affine precision.
    pub fn weight_plan(&self) -> weights_rd::WeightPlan {
        let (bits, plan) = (self.opts.weight_bits, self.plan);
        weights_rd::WeightPlan::new(bits, plan.affine_precision, plan.codec)
    }
}

/// Encodes an animation at one first-frame precision (the default if `opts` leaves it open); a
/// single motion model's segmentation is `known` when a trial before found it, and its `atlas`
/// when an encoding before built it.
fn encode_once(
    mesh: &AnimatedMesh,
    settings: Settings,
    progress: &dyn Progress,
    known: Option<(Partition, SegmentationReport)>,
    atlas: Option<&AtlasCache>,
) -> Result<Encoded> {
    let mut clock = Stopwatch::new();
    progress.stage("first frame");
    let (ff, permuted) = analysis::first_frame(mesh, settings.opts)?;
    let mesh = permuted.as_ref().unwrap_or(mesh);
    let leading = leading_parts(mesh, &ff.bytes, settings.opts)?;
    clock.lap("first frame");
    let models = settings.opts.motion_models();
    let [model] = models[..] else {
        return auto::choose(mesh, &ff, leading, settings, &models, progress, clock);
    };
    progress.total(mesh.frame_count() as u64);
    let once = Once::analyse(mesh, &ff, settings, model, known, &mut clock)?;
    let analysed = Analysed {
        atlas,
        ..once.analysed()
    };
    code(mesh, &ff, leading, settings, &analysed, progress, clock)
}

/// With [`Keep::SharedParts`], the first frame of `mesh` alone and its prediction: the stream's
/// shared parts are those of the whole analysis (partition, weights and atlas come from every
/// frame; the first frame's residual is its own). `None` to code every frame.
fn first_frame_only(
    mesh: &AnimatedMesh,
    prediction: &Prediction,
    keep: Keep,
) -> Result<Option<(AnimatedMesh, Prediction)>> {
    if keep == Keep::Whole || mesh.frame_count() == 1 {
        return Ok(None);
    }
    let first = Prediction {
        track: prediction.track.select(&[0])?,
        weights: prediction.weights.clone(),
        residuals: prediction.residuals.iter().take(1).cloned().collect(),
    };
    Ok(Some((mesh.clip(0..1)?, first)))
}

/// One motion model's analysis of an animation whose first frame is coded: its segmentation and
/// prediction.
struct Once {
    model: MotionModel,
    partition: Partition,
    segmentation: SegmentationReport,
    prediction: Prediction,
}

impl Once {
    fn analyse(
        mesh: &AnimatedMesh,
        ff: &EncodedFirstFrame,
        settings: Settings,
        model: MotionModel,
        known: Option<(Partition, SegmentationReport)>,
        clock: &mut Stopwatch,
    ) -> Result<Self> {
        let (partition, segmentation) = match known {
            Some(known) => known,
            None => analysis::segment(mesh, model.segmentation, model.clusters)?,
        };
        clock.lap("segmentation");
        let reference = &ff.decoded_positions;
        let steps = (settings.plan.affine_step, settings.weight_plan());
        let prediction = analysis::predict(mesh, reference, &partition, steps, model.predictor)?;
        clock.lap("motion");
        Ok(Self {
            model,
            partition,
            segmentation,
            prediction,
        })
    }

    fn analysed(&self) -> Analysed<'_> {
        Analysed {
            model: self.model,
            partition: &self.partition,
            segmentation: self.segmentation.clone(),
            prediction: &self.prediction,
            atlas: None,
        }
    }
}

/// The bytes of one motion model's stream at one first-frame precision, its residual parts
/// estimated by the codec (`None` without an estimate) and stopped past `limit` (`u64::MAX`: none),
/// and what coding it needs; `model` and its `known` segmentation fixed.
fn estimate_once(
    mesh: &AnimatedMesh,
    settings: Settings,
    progress: &dyn Progress,
    (model, known): (MotionModel, Option<(Partition, SegmentationReport)>),
    limit: u64,
) -> Result<Option<(Estimate, Estimated)>> {
    if !settings.opts.codec.codec().estimated_trials() {
        return Ok(None);
    }
    let mut clock = Stopwatch::new();
    let (ff, permuted) = analysis::first_frame(mesh, settings.opts)?;
    let mesh = permuted.unwrap_or_else(|| mesh.clone());
    let leading = leading_parts(&mesh, &ff.bytes, settings.opts)?;
    let once = Once::analyse(&mesh, &ff, settings, model, known, &mut clock)?;
    let limit = AtomicU64::new(limit);
    let bytes = estimate(
        &mesh,
        (&ff, &leading),
        settings,
        &once.analysed(),
        progress,
        &limit,
    )?;
    let estimated = Estimated {
        mesh,
        ff,
        leading,
        once,
    };
    Ok(Some((bytes, estimated)))
}

/// What [`estimate_once`] analysed, for coding it in full.
struct Estimated {
    mesh: AnimatedMesh,
    ff: EncodedFirstFrame,
    leading: Vec<Part>,
    once: Once,
}

impl Estimated {
    /// The segmentation it used, for trials that keep it.
    fn segmentation(&self) -> (Partition, SegmentationReport) {
        (self.once.partition.clone(), self.once.segmentation.clone())
    }

    fn code(self, settings: Settings, progress: &dyn Progress) -> Result<Encoded> {
        let analysed = self.once.analysed();
        let (mesh, ff) = (&self.mesh, &self.ff);
        code(
            mesh,
            ff,
            self.leading,
            settings,
            &analysed,
            progress,
            Stopwatch::new(),
        )
    }
}

/// What the residual coder of `analysed` is given, to code or to estimate.
fn residual_input<'a>(
    mesh: &'a AnimatedMesh,
    ff: &'a EncodedFirstFrame,
    analysed: &'a Analysed,
    progress: &'a dyn Progress,
) -> ResidualInput<'a> {
    ResidualInput {
        mesh,
        reference: &ff.decoded_positions,
        partition: analysed.partition,
        residuals: &analysed.prediction.residuals,
        progress,
        atlas: analysed.atlas,
    }
}

/// The stream bytes of `analysed` with its residuals' parts estimated by the codec (tdct), the
/// rest as the stream will hold it. The estimate may stop once it is sure to pass `smallest` (read
/// as it goes; `u64::MAX` for no limit): then its bytes are how far it got.
fn estimate(
    mesh: &AnimatedMesh,
    (ff, leading): (&EncodedFirstFrame, &[Part]),
    settings: Settings,
    analysed: &Analysed,
    progress: &dyn Progress,
    smallest: &AtomicU64,
) -> Result<Estimate> {
    let (partition, prediction) = (analysed.partition, analysed.prediction);
    let header = header(mesh, settings, analysed.model, partition);
    let side = assemble(
        &header,
        leading.to_vec(),
        (mesh, &ff.decoded_positions),
        partition,
        prediction,
        (vec![], vec![]),
    )?;
    let input = residual_input(mesh, ff, analysed, progress);
    let limit = Limit {
        smallest,
        counted: side.len(),
    };
    let residuals = settings.plan.encoder()?.estimate_bytes(&input, &limit)?;
    let residuals = residuals.ok_or_else(|| {
        Error::Codec("the automatic choice asked for an estimate the codec does not make".into())
    })?;
    Ok(Estimate {
        bytes: side.len() + residuals.bytes,
        stopped: residuals.stopped,
    })
}

/// The first frame's part and, for inputs with texture coordinates, the attributes'.
fn leading_parts(
    mesh: &AnimatedMesh,
    first_frame: &[u8],
    opts: &EncodeOptions,
) -> Result<Vec<Part>> {
    let mut leading = vec![Part::whole(Tag::FIRST_FRAME, first_frame.to_vec())];
    if !mesh.attributes().is_empty() {
        let bytes = attributes::encode(mesh, first_frame, opts.uv_bits)?;
        leading.push(Part::whole(Tag::ATTRIBUTES, bytes));
    }
    Ok(leading)
}

/// One motion model's analysis of the animation: what the residual codec is given.
struct Analysed<'a> {
    model: MotionModel,
    partition: &'a Partition,
    segmentation: SegmentationReport,
    prediction: &'a Prediction,
    /// The partition's atlas, shared by the encodings on it (codecs with an atlas).
    atlas: Option<&'a AtlasCache>,
}

/// Codes the residuals of `analysed` at `plan` (the settings' plan at its depth,
/// [`code`]) and assembles the stream behind the `leading` parts; the report's stages
/// are the `clock`'s and the coder's. Every frame, or the first alone when the caller keeps the
/// shared parts ([`Keep::SharedParts`]).
fn code_at(
    plan: &RatePlan,
    (mesh, ff): (&AnimatedMesh, &EncodedFirstFrame),
    leading: Vec<Part>,
    settings: Settings,
    analysed: &Analysed,
    progress: &dyn Progress,
    mut clock: Stopwatch,
) -> Result<Encoded> {
    let first_only = first_frame_only(mesh, analysed.prediction, settings.keep)?;
    let restricted;
    let (mesh, analysed) = match &first_only {
        Some((first, prediction)) => {
            // The frames not coded count as done.
            progress.frames(mesh.frame_count() as u64 - 1);
            restricted = Analysed {
                prediction,
                segmentation: analysed.segmentation.clone(),
                ..*analysed
            };
            (first, &restricted)
        }
        None => (mesh, analysed),
    };
    let (partition, prediction) = (analysed.partition, analysed.prediction);
    let mut coded = plan
        .encoder()?
        .encode(&residual_input(mesh, ff, analysed, progress))?;
    clock.stages.extend(coded.stage_seconds.iter().cloned());
    clock.restart();
    let atlas = coded.atlas.take();
    let (residual_spread, picture_depth) = (coded.residual_spread, coded.picture_depth);
    let stats = atlas.as_ref().map(|(_, a)| a.stats());
    let model = analysed.model;
    let header = header(mesh, settings, model, partition);
    let parts = coded.into_parts();
    let first_frame = (mesh, &ff.decoded_positions[..]);
    let container = assemble(&header, leading, first_frame, partition, prediction, parts)?;
    clock.lap("side information");
    let report = EncodeReport {
        parts: container.part_sizes(),
        bytes: container.len(),
        bpvf: container.len() as f64 * 8.0 / (mesh.vertex_count() * mesh.frame_count()) as f64,
        header,
        codec: settings.opts.codec.codec(),
        charts: stats.map_or(0, |s| s.charts),
        packing_efficiency: stats.map_or(0.0, |s| s.packing_efficiency),
        moved_vertices: stats.map_or(0, |s| s.moved_vertices),
        l2_stretch: stats.map_or(0.0, |s| s.l2_stretch),
        stage_seconds: clock.stages,
        segmentation: analysed.segmentation.clone(),
        choice: None,
        first_frame_trials: Vec::new(),
        residual_spread,
        picture_depth,
        segments: 1,
        permutation: ff.permutation.clone(),
    };
    Ok(Encoded {
        container,
        report,
        model,
        partition: partition.clone(),
        atlas,
    })
}

/// Seconds per stage.
#[derive(Clone)]
struct Stopwatch {
    stages: Vec<(String, f64)>,
    start: Instant,
}

impl Stopwatch {
    fn new() -> Self {
        Self {
            stages: Vec::new(),
            start: Instant::now(),
        }
    }

    fn lap(&mut self, name: &str) {
        self.stages
            .push((name.to_string(), self.start.elapsed().as_secs_f64()));
        self.restart();
    }

    fn restart(&mut self) {
        self.start = Instant::now();
    }
}

/// The stream header of an encoding.
fn header(
    mesh: &AnimatedMesh,
    Settings { opts, plan, .. }: Settings,
    model: MotionModel,
    partition: &Partition,
) -> Header {
    Header {
        vertices: mesh.vertex_count() as u32,
        frames: mesh.frame_count() as u32,
        triangles: mesh.triangles().len() as u32,
        clusters: partition.clusters() as u32,
        codec: opts.codec.codec().id(),
        quality: plan.quality,
        affine_precision: plan.affine_precision,
        first_frame_bits: opts.first_frame_bits_or_default(),
        // Decimation asks for no K: the header then records the K it found.
        requested_clusters: match model.segmentation {
            Segmentation::KMeans => model.clusters as u32,
            Segmentation::Decimation { .. } => partition.clusters() as u32,
        },
        reorder: opts.reorder,
        frame_rate: mesh.frame_rate().map_or(0.0, |r| r as f32),
        predictor: model.predictor,
    }
}

/// The container in file order: header, first frame (and attributes), partition, the codec's
/// set-up and whole-stream parts, the predictor (affine track, skinning weights), the codec's
/// segment parts.
fn assemble(
    header: &Header,
    leading: Vec<Part>,
    (mesh, reference): (&AnimatedMesh, &[Point]),
    partition: &Partition,
    prediction: &Prediction,
    (before, after): (Vec<Part>, Vec<Part>),
) -> Result<ContainerWriter> {
    let first_frame = (mesh.triangles(), reference);
    let mut parts = vec![Part::whole(Tag::HEADER, header.to_bytes())];
    parts.extend(leading);
    parts.push(Part::whole(
        Tag::PARTITION,
        side_info::encode_partition(partition.labels(), partition.clusters(), first_frame)?,
    ));
    parts.extend(before);
    parts.push(Part::whole(
        Tag::AFFINE,
        side_info::encode_affine(&prediction.track)?,
    ));
    if let Some(weights) = &prediction.weights {
        let bytes = side_info::encode_weights(weights, partition, first_frame)?;
        parts.push(Part::whole(Tag::WEIGHTS, bytes));
    }
    parts.extend(after);
    let mut container = ContainerWriter::new();
    for part in parts {
        container.push(part)?;
    }
    Ok(container)
}
