//! The encoder's automatic choice of motion model (`PredictorChoice::Auto`,
//! `SegmentationChoice::Auto`): every candidate predictor × segmentation is coded at the encoding's
//! quality, hence at one step, and the one with the fewest bits at equal error is kept: the
//! smallest stream for tdct, whose step is the same for every candidate; the picture codecs'
//! candidates are decoded and their bits charged for their error ([`super::distortion`]), since a
//! step widened where residuals outgrow the samples buys fewer bits with more error. Which one
//! wins depends on the animation (skinning on rigid bones, the affine maps on soft bodies), so it
//! is measured, not guessed.
//!
//! Shared between the candidates: the first frame, each segmentation (used by every predictor)
//! and its affine track (skinning blends its maps). tdct ranks every candidate by its codec's
//! cheap estimate and codes the winner. The picture codecs, whose pictures cost most of an
//! encoding, code a sample of frames per candidate ([`super::sampled_trial`]: a spread dozen of
//! intra pictures, or runs of consecutive P-frames), scale the sample's per-frame parts to the
//! whole, weigh the error of the sample's own stream (decoded), and then code the winner once in
//! full: the sample's bytes alone can keep a candidate whose whole stream is both larger and
//! worse (docs/design.md, "Automatic choice: bits at equal error"). When the sample cannot tell
//! its two best apart, both are coded whole ([`super::close_call`]). Clips too short to sample
//! code every candidate whole and keep the winner's stream.

use super::choice_reason::reason;
use super::close_call::{self, Podium};
use super::ladder;
use super::sampled_trial::Sample;
use super::{analysis, code, distortion, estimate, Analysed, Encoded, Keep, Settings, Stopwatch};
use crate::encoder::{MotionModel, Segmentation};
use crate::error::{Error, Result};
use crate::first_frame::EncodedFirstFrame;
use crate::geometry_image::lattice::{self, AtlasCache};
use crate::mesh::AnimatedMesh;
use crate::motion::{AffineTrack, Partition, PredictorKind};
use crate::progress::Progress;
use crate::stream::container::Part;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

mod rungs;
use rungs::{only, rank_rungs};

/// What the automatic choice measured and kept.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ChoiceReport {
    /// The motion model kept, `predictor+segmentation`.
    pub chosen: String,
    /// Frames each candidate's residuals were coded on: every frame, or a sample (picture codecs
    /// on animations long enough) whose per-frame parts were scaled to the whole.
    pub trial_frames: usize,
    /// Every candidate, in the order tried (the default first: it wins ties).
    pub candidates: Vec<Candidate>,
    /// Why the chosen one was kept.
    pub reason: String,
}

/// One candidate of an automatic choice and its measured size.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Candidate {
    /// Its predictor.
    pub predictor: PredictorKind,
    /// Its segmentation, `kmeans` or `decimation`.
    pub segmentation: &'static str,
    /// Clusters its segmentation found.
    pub clusters: usize,
    /// Its stream's bytes: measured for the one kept; for the others, estimated when the trials
    /// estimate (tdct's from one cheap pass over the bands, the picture codecs' from a sample of
    /// frames), and for the one kept too when only a segmented encoding's shared parts were
    /// coded from it (its analysis clip's residuals are the segments'), or when the picture
    /// codecs' sample kept it (measured for the two best when the sample could not tell them
    /// apart and both were coded whole).
    pub bytes: u64,
    /// Whether `bytes` is an estimate.
    pub estimated: bool,
    /// Whether its estimate stopped once it passed the smallest one so far (tdct): it could not
    /// win, and `bytes` is how far it got. Which candidates stop depends on the order the
    /// parallel trials end in; the one kept does not.
    pub stopped: bool,
    /// The estimate the choice ranked it by, when tdct's trials estimated it (the kept one's too,
    /// whose `bytes` are then measured).
    pub estimate: Option<u64>,
    /// Its decoded stream's RMS vertex error over the first frame's bounding-box diagonal, when
    /// the choice weighed errors (picture codecs; a sampled trial's over its sample's frames).
    pub vertex_rmse: Option<f64>,
    /// Seconds of its trial: prediction and residual coding (the segmentations and the picture
    /// codecs' atlases are in the report's stages).
    pub seconds: f64,
}

/// The best candidate so far: its whole stream, or (sampled trials) what coding it in full needs.
pub(super) struct Best<'a> {
    pub(super) index: usize,
    pub(super) cost: f64,
    pub(super) kept: Kept<'a>,
}

pub(super) enum Kept<'a> {
    Stream(Box<Encoded>),
    Analysis(Box<Trial<'a>>),
}

/// What coding a sampled trial's candidate in full needs: its partition, segmentation report,
/// prediction (its residuals left out, made again by [`keep`]) and atlas.
type Trial<'a> = (
    Partition,
    analysis::SegmentationReport,
    analysis::Prediction,
    &'a AtlasCache,
);

/// Tries every motion model of `models` on `mesh` (already in the stream's vertex order, its
/// first frame coded as `ff`) and returns the smallest stream, its report saying why.
///
/// Each segmentation and the candidates on it are one job, the jobs run on rayon's threads, and
/// the winner is the lowest cost, the earliest candidate on a tie, whatever order the jobs end
/// in: the same stream on any number of threads.
pub(super) fn choose(
    mesh: &AnimatedMesh,
    ff: &EncodedFirstFrame,
    leading: Vec<Part>,
    settings: Settings,
    models: &[MotionModel],
    progress: &dyn Progress,
    mut clock: Stopwatch,
) -> Result<Encoded> {
    let sample = Sample::of(mesh, settings)?;
    let shared = Shared {
        mesh,
        ff,
        leading: &leading,
        settings,
        sample: sample.as_ref(),
        smallest_estimate: AtomicU64::new(u64::MAX),
    };
    let segmenter = analysis::Segmenter::new(mesh);
    let segmentations = segmentations(models);
    prepare_kmeans(&segmenter, &segmentations, &mut clock);
    // A picture codec tries the k-means rung tdct's estimates rank first (and the one above when
    // close), and decimation and the affine predictor unless they rank them far behind.
    let ranked = rank_rungs(&shared, &segmenter, (&segmentations, models), progress, &mut clock)?;
    let narrowed = ranked.as_ref().map(|ranking| ranking.narrow(models));
    let tried = narrowed.as_deref().unwrap_or(models);
    if let ([model], Some(ranking)) = (tried, &ranked) {
        return only(&shared, &segmenter, (*model, models), ranking, progress, clock);
    }
    let segmentations = self::segmentations(tried);
    let (frames, trial_frames) = (mesh.frame_count(), shared.trial_frames());
    let estimated = sample.is_some() || settings.opts.codec.codec().estimated_trials();
    let total = (tried.len() * trial_frames + if estimated { frames } else { 0 }) as u64;
    progress.total(total);
    let atlases: Vec<AtlasCache> = segmentations.iter().map(|_| AtlasCache::default()).collect();
    // The ladder's stop reads tdct's estimates of each rung (`ladder`; a picture codec has the one
    // or two rungs `rank_rungs` kept, too few for a gate).
    let gates = ladder::gates(&segmentations);
    let jobs = jobs_of(tried, &segmentations, &atlases, &gates);
    let outcomes = ladder::run_jobs(
        &gates,
        |i| jobs[i].run(&shared, &segmenter, progress),
        |i| jobs[i].skip(&shared, progress),
        |outcome| outcome.podium.best.as_ref().map(|(b, _)| b.cost),
    )?;
    let Tally {
        mut candidates,
        costs,
        podium,
        skipped,
    } = tally(outcomes, &mut clock);
    let (best, at) = (podium.best)
        .ok_or_else(|| Error::option("predictor", "no candidate to choose from"))?;
    let mut reason = reason(&candidates, &costs, at, (trial_frames, frames));
    reason.extend(skipped.iter().map(|s| format!("; {s}")));
    if let Some(ranking) = &ranked {
        reason.push_str(&format!("; {}", ranking.describe(models)));
    }
    // A sample too close to call: both coded whole (a segmented encoding's analysis clip is
    // coded on its first frame alone, so its sample decides).
    let whole_streams = sample.is_some() && settings.keep == Keep::Whole;
    let close = (podium.runner_up)
        .filter(|(r, _)| whole_streams && close_call::is_close(best.cost, r.cost));
    let (mut encoded, model) = match close {
        Some(runner_up) => {
            progress.total(total + frames as u64);
            let pair = [(best, at), runner_up];
            let (encoded, model, why) =
                close_call::settle(&shared, pair, tried, &mut candidates, progress, clock)?;
            reason = format!("{why}. On the sample: {reason}");
            (encoded, model)
        }
        None => {
            let model = tried[best.index];
            (keep(&shared, model, best.kept, progress, clock)?, model)
        }
    };
    // The kept one's size is its stream's now, not an estimate (unless the stream is the analysis
    // clip's first frame alone).
    let measured = sample.is_none() && settings.keep == Keep::Whole;
    if let Some(kept) = candidates.get_mut(at).filter(|c| measured && c.estimated) {
        kept.bytes = encoded.report.bytes;
        kept.estimated = false;
    }
    encoded.report.choice = Some(ChoiceReport {
        chosen: model.name(),
        trial_frames,
        reason,
        candidates,
    });
    Ok(encoded)
}

/// Prepares the k-means descriptors and seeds for the largest K of `segmentations` (shared by
/// the smaller ones), timed in `clock`.
fn prepare_kmeans(
    segmenter: &analysis::Segmenter,
    segmentations: &[(Segmentation, usize)],
    clock: &mut Stopwatch,
) {
    let largest = segmentations.iter().filter(|(s, _)| *s == Segmentation::KMeans);
    if let Some(&(_, k)) = largest.max_by_key(|(_, k)| *k) {
        let start = Instant::now();
        segmenter.prepare_kmeans(k);
        let seconds = start.elapsed().as_secs_f64();
        clock.stages.push(("motion descriptors and seeds".into(), seconds));
    }
}

/// One job per segmentation of `models` (each with its atlas cache and gate), its candidates
/// numbered on from the previous job's.
fn jobs_of<'a>(
    models: &[MotionModel],
    segmentations: &[(Segmentation, usize)],
    atlases: &'a [AtlasCache],
    gates: &[Option<(usize, usize)>],
) -> Vec<Job<'a>> {
    let mut jobs = Vec::with_capacity(segmentations.len());
    for (index, (&(segmentation, k), atlas)) in segmentations.iter().zip(atlases).enumerate() {
        let same = |m: &&MotionModel| (m.segmentation, m.clusters) == (segmentation, k);
        let first = jobs.iter().map(|j: &Job| j.models.len()).sum();
        let models = models.iter().filter(same).copied().collect();
        let gate = gates.get(index).copied().flatten();
        let k_of = |job: usize| segmentations.get(job).map_or(0, |s| s.1);
        jobs.push(Job {
            segmentation: (segmentation, k),
            models,
            first,
            atlas,
            below: gate.map(|(a, b)| (k_of(a), k_of(b))),
            may_stop: ladder::may_stop(gates, index),
        });
    }
    jobs
}

/// Every job's candidates in the jobs' order, their costs, the lowest (and its place among the
/// candidates), and why rungs were skipped.
struct Tally<'a> {
    candidates: Vec<Candidate>,
    costs: Vec<f64>,
    /// The two lowest costs, with their places among `candidates`.
    podium: Podium<'a>,
    skipped: Vec<String>,
}

/// Gathers the jobs' outcomes, their stages into `clock`; the lowest cost wins, the earliest
/// candidate on a tie.
fn tally<'a>(outcomes: Vec<Outcome<'a>>, clock: &mut Stopwatch) -> Tally<'a> {
    let mut tally = Tally {
        candidates: Vec::new(),
        costs: Vec::new(),
        podium: Podium::new(),
        skipped: Vec::new(),
    };
    for outcome in outcomes {
        clock.stages.extend(outcome.stages);
        tally.skipped.extend(outcome.skipped);
        // Where the job's candidates start in the report (a skipped rung has none).
        let base = tally.candidates.len();
        tally.candidates.extend(outcome.candidates);
        tally.costs.extend(outcome.costs);
        let Podium { best, runner_up } = outcome.podium;
        for (b, at) in [best, runner_up].into_iter().flatten() {
            tally.podium.offer(b, base + at);
        }
    }
    tally
}

/// One segmentation and the candidates that use it, numbered from `first` among all.
struct Job<'a> {
    segmentation: (Segmentation, usize),
    models: Vec<MotionModel>,
    first: usize,
    atlas: &'a AtlasCache,
    /// The K of the k-means rungs whose costs decide whether this one runs ([`ladder`]).
    below: Option<(usize, usize)>,
    /// Whether its estimates may stop early (not when a gate reads them).
    may_stop: bool,
}

/// A job's partition, its segmentation's report, its affine track and the stages' seconds.
type Prepared = (
    Partition,
    analysis::SegmentationReport,
    AffineTrack,
    Vec<(String, f64)>,
);

/// One candidate tried: its report, cost, and what keeping it needs.
struct Tried<'a> {
    candidate: Candidate,
    cost: f64,
    kept: Kept<'a>,
}

/// What a job measured: its candidates and their costs, its stages' seconds, its two best (each
/// with its place among the job's candidates); or why it was not tried.
struct Outcome<'a> {
    candidates: Vec<Candidate>,
    costs: Vec<f64>,
    stages: Vec<(String, f64)>,
    podium: Podium<'a>,
    skipped: Option<String>,
}

impl<'a> Job<'a> {
    /// A job of one candidate on its own segmentation, no gate.
    fn alone(model: MotionModel, atlas: &'a AtlasCache) -> Self {
        Job {
            segmentation: (model.segmentation, model.clusters),
            models: vec![model],
            first: 0,
            atlas,
            below: None,
            may_stop: false,
        }
    }

    /// Segments, fits the affine track every predictor builds on, and tries each candidate.
    fn run(
        &self,
        shared: &Shared,
        segmenter: &analysis::Segmenter,
        progress: &dyn Progress,
    ) -> Result<Outcome<'a>> {
        let (partition, segmented, track, stages) = self.prepare(shared, segmenter, progress)?;
        let mut outcome = Outcome {
            candidates: Vec::new(),
            costs: Vec::new(),
            stages,
            podium: Podium::new(),
            skipped: None,
        };
        let pictures = shared.settings.plan.pictures.as_ref();
        let analysis = (&partition, &segmented, &track);
        let one = |&model: &MotionModel| self.try_model(shared, analysis, model, progress);
        let tried: Vec<Result<Tried>> = match pictures {
            Some(_) => self.models.par_iter().map(one).collect(),
            None => self.models.iter().map(one).collect(),
        };
        for (i, (model, tried)) in self.models.iter().zip(tried).enumerate() {
            let Tried {
                candidate,
                cost,
                kept,
            } = tried?;
            let seconds = candidate.seconds;
            outcome.stages.push((format!("trial {}", model.name()), seconds));
            outcome.candidates.push(candidate);
            outcome.costs.push(cost);
            let best = Best {
                index: self.first + i,
                cost,
                kept,
            };
            outcome.podium.offer(best, i);
        }
        Ok(outcome)
    }

    /// The job's partition, its affine track and (picture codecs) its atlas, built first: most of
    /// a picture codec's trial, shared by its candidates, whose trials then run side by side
    /// (tdct's, cheap and stopping once they cannot win, run in turn); and the stages' seconds.
    fn prepare(
        &self,
        shared: &Shared,
        segmenter: &analysis::Segmenter,
        progress: &dyn Progress,
    ) -> Result<Prepared> {
        let (segmentation, k) = self.segmentation;
        let (mesh, settings) = (shared.mesh, shared.settings);
        let stage = match segmentation {
            Segmentation::KMeans => format!("segmentation (kmeans, K = {k})"),
            Segmentation::Decimation { .. } => "segmentation (decimation)".to_string(),
        };
        progress.stage(&stage);
        let start = Instant::now();
        let (partition, segmented) = segmenter.segment(segmentation, k)?;
        let reference = &shared.ff.decoded_positions;
        let track = analysis::fit_track(mesh, reference, &partition, settings.plan.affine_step)?;
        let mut stages = vec![(stage, start.elapsed().as_secs_f64())];
        if let Some(option) = settings.plan.pictures.as_ref().map(|p| p.lattice) {
            let start = Instant::now();
            let triangles = mesh.triangles();
            let build = || lattice::build_atlas(reference, triangles, &partition, option);
            self.atlas.get_or_build(build)?;
            stages.push(("atlas".into(), start.elapsed().as_secs_f64()));
        }
        Ok((partition, segmented, track, stages))
    }

    /// Predicts `model` on the job's partition and track and tries it ([`trial`]).
    fn try_model(
        &self,
        shared: &Shared,
        (partition, segmented, track): (&Partition, &analysis::SegmentationReport, &AffineTrack),
        model: MotionModel,
        progress: &dyn Progress,
    ) -> Result<Tried<'a>> {
        let start = Instant::now();
        let (mesh, settings) = (shared.mesh, shared.settings);
        let progress = Labelled {
            inner: progress,
            label: model.name(),
        };
        progress.stage("motion");
        let (reference, bits) = (&shared.ff.decoded_positions, settings.weight_plan());
        let (kind, track) = (model.predictor, track.clone());
        let prediction = analysis::predict_on(mesh, reference, partition, bits, kind, track)?;
        let analysed = Analysed {
            model,
            partition,
            segmentation: segmented.clone(),
            prediction: &prediction,
            atlas: Some(self.atlas),
        };
        let (bytes, encoded, error, stopped) = trial(shared, &analysed, self.may_stop, &progress)?;
        let diagonal = shared.diagonal();
        let candidate = Candidate {
            predictor: model.predictor,
            segmentation: self.segmentation.0.name(),
            clusters: partition.clusters(),
            bytes,
            estimated: encoded.is_none(),
            stopped,
            estimate: (encoded.is_none() && shared.sample.is_none()).then_some(bytes),
            vertex_rmse: error.map(|e| e / diagonal),
            seconds: start.elapsed().as_secs_f64(),
        };
        let kept = match encoded {
            Some(encoded) => Kept::Stream(Box::new(encoded)),
            None => {
                // Its residuals are made again if it wins ([`keep`]): held by each trial until
                // the job picks its best, they were the largest memory of long segments' choices.
                let mut prediction = prediction;
                prediction.residuals = Vec::new();
                let analysis = (partition.clone(), segmented.clone(), prediction);
                Kept::Analysis(Box::new((analysis.0, analysis.1, analysis.2, self.atlas)))
            }
        };
        Ok(Tried {
            candidate,
            cost: distortion::cost(8.0 * bytes as f64, error),
            kept,
        })
    }

    /// The outcome of a rung the ladder does not climb to: no candidate, the reason, and its
    /// trials' share of the progress bar.
    fn skip(&self, shared: &Shared, progress: &dyn Progress) -> Outcome<'a> {
        let below = self.below.unwrap_or_default();
        progress.frames((self.models.len() * shared.trial_frames()) as u64);
        let k = self.segmentation.1;
        let why = format!(
            "k-means K = {k} not tried: K = {} did not beat K = {}",
            below.1, below.0
        );
        Outcome {
            candidates: Vec::new(),
            costs: Vec::new(),
            stages: vec![(format!("segmentation (kmeans, K = {k}) skipped"), 0.0)],
            podium: Podium::new(),
            skipped: Some(why),
        }
    }
}

/// What every trial shares: the animation (in the stream's vertex order), its coded first frame
/// and the parts before the partition, the options and, for sampled trials, the sample.
pub(super) struct Shared<'a> {
    pub(super) mesh: &'a AnimatedMesh,
    ff: &'a EncodedFirstFrame,
    leading: &'a [Part],
    settings: Settings<'a>,
    sample: Option<&'a Sample>,
    /// The smallest complete estimate so far (tdct), past which an estimate stops: a candidate
    /// above it cannot be the smallest, whichever trials end first, so the stream kept is the
    /// same on any number of threads ("early exit when a candidate cannot win").
    smallest_estimate: AtomicU64,
}

impl Shared<'_> {
    /// Frames each candidate's residuals are coded on: the sample's, or every frame.
    fn trial_frames(&self) -> usize {
        self.sample
            .map_or(self.mesh.frame_count(), |s| s.frames.len())
    }

    /// The unit of the candidates' reported errors: the bounding-box diagonal (never zero).
    pub(super) fn diagonal(&self) -> f64 {
        self.mesh.bbox_diagonal().max(f64::MIN_POSITIVE)
    }
}

/// Codes one candidate: its bytes, whole stream and (picture codecs) decoded error, or (sampled
/// trials) its estimated bytes and the sample's error; and whether its estimate stopped.
fn trial(
    shared: &Shared,
    analysed: &Analysed,
    may_stop: bool,
    progress: &dyn Progress,
) -> Result<(u64, Option<Encoded>, Option<f64>, bool)> {
    let Shared {
        mesh, ff, settings, ..
    } = *shared;
    match shared.sample {
        None if settings.opts.codec.codec().estimated_trials() => {
            let ff_and_leading = (shared.ff, shared.leading);
            let smallest = &shared.smallest_estimate;
            // A gated rung reads this estimate: it runs to the end, whatever ended before it.
            let never = AtomicU64::new(u64::MAX);
            let limit = if may_stop { smallest } else { &never };
            let estimate = estimate(mesh, ff_and_leading, settings, analysed, progress, limit)?;
            if !estimate.stopped {
                smallest.fetch_min(estimate.bytes, Ordering::Relaxed);
            }
            Ok((estimate.bytes, None, None, estimate.stopped))
        }
        None => {
            let leading = shared.leading.to_vec();
            let encoded = code(
                mesh,
                ff,
                leading,
                Settings::whole(settings.opts, settings.plan),
                analysed,
                progress,
                Stopwatch::new(),
            )?;
            // A picture codec's step may widen where residuals outgrow the samples: errors differ.
            let error = match settings.opts.codec.codec().has_images() {
                true => Some(distortion::vertex_rmse(mesh, &encoded)?),
                false => None,
            };
            Ok((encoded.report.bytes, Some(encoded), error, false))
        }
        Some(sample) => {
            let trial = (ff.decoded_positions.as_slice(), shared.leading);
            let (bytes, error) = sample.estimate(mesh, trial, settings, analysed, progress)?;
            Ok((bytes, None, Some(error), false))
        }
    }
}

/// The winner's stream: kept from its trial (its report's stages replaced by the whole
/// choice's), or coded in full now.
pub(super) fn keep(
    shared: &Shared,
    model: MotionModel,
    kept: Kept,
    progress: &dyn Progress,
    clock: Stopwatch,
) -> Result<Encoded> {
    match kept {
        Kept::Stream(encoded) => {
            let mut encoded = *encoded;
            encoded.report.stage_seconds = clock.stages;
            Ok(encoded)
        }
        Kept::Analysis(analysis) => {
            let (partition, segmentation, mut prediction, atlas) = *analysis;
            let (mesh, reference) = (shared.mesh, &shared.ff.decoded_positions);
            let weights = prediction.weights.as_ref();
            prediction.residuals =
                analysis::residuals_of(mesh, reference, &partition, &prediction.track, weights)?;
            let analysed = Analysed {
                model,
                partition: &partition,
                segmentation,
                prediction: &prediction,
                atlas: Some(atlas),
            };
            let Shared {
                mesh, ff, settings, ..
            } = *shared;
            let leading = shared.leading.to_vec();
            code(mesh, ff, leading, settings, &analysed, progress, clock)
        }
    }
}

/// The distinct segmentations of `models` (with k-means's K), in order.
fn segmentations(models: &[MotionModel]) -> Vec<(Segmentation, usize)> {
    let mut distinct: Vec<(Segmentation, usize)> = Vec::new();
    for model in models {
        let partition = (model.segmentation, model.clusters);
        if !distinct.contains(&partition) {
            distinct.push(partition);
        }
    }
    distinct
}

/// Progress of one candidate's trial: its stages named after it.
struct Labelled<'a> {
    inner: &'a dyn Progress,
    label: String,
}

impl Progress for Labelled<'_> {
    fn stage(&self, name: &str) {
        self.inner.stage(&format!("{}: {name}", self.label));
    }

    fn frames(&self, count: u64) {
        self.inner.frames(count);
    }
}
