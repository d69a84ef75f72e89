//! tdct's choice of first-frame precision, when the caller leaves `first_frame_bits` open: the
//! animation is coded at the precisions of [`FIRST_FRAME_BITS_TRIED`], finer to coarser while the
//! stream shrinks, and the smallest stream is kept.
//!
//! The temporal DCT codes frame 0's residual like any other frame's, so a coarser first frame is
//! corrected down to the quality's step: the bits move from the first-frame coder into the
//! residuals' lowest band, and which side codes them cheaper depends on the mesh (a detailed
//! shape costs the first-frame coder much; a flat grid it predicts almost exactly) and on the step.
//! The motion model is chosen once, at the default precision (the automatic choice's trials), and
//! the other precisions are coded with it fixed: the model follows the motion, the precision the
//! first frame's shape. Of a segmented encoding's analysis clip only the shared parts are used:
//! the default precision is coded on its first frame alone, and whole only when a coarser one's
//! estimate beats it and whole streams must be compared.

use super::{encode_once, estimate_once, EncodeOptions, Encoded, Keep, MotionModel, PredictorChoice};
use super::{SegmentationReport, Settings};
use crate::codec::RatePlan;
use crate::error::Result;
use crate::mesh::AnimatedMesh;
use crate::motion::Partition;
use crate::progress::Progress;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

pub use super::options::FIRST_FRAME_BITS_TRIED;

/// One first-frame precision tried and the size of its stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct FirstFrameTrial {
    /// Bits per coordinate of the first frame.
    pub bits: u8,
    /// The stream's bytes at that precision (estimated, see `estimated`).
    pub bytes: u64,
    /// Whether `bytes` is the codec's estimate (tdct: a precision whose estimate did not beat
    /// the kept one's is not coded in full; nor is the kept one of a segmented encoding's
    /// analysis clip, whose shared parts alone are used).
    pub estimated: bool,
    /// Whether the estimate stopped once sure not to beat the kept one's: `bytes` is then how far
    /// it got, at least the kept one's estimate.
    pub stopped: bool,
}

/// Codes `mesh` at the precisions of [`FIRST_FRAME_BITS_TRIED`], finer to coarser until one does
/// not shrink the stream, and keeps the smallest (the default on a tie); its report lists the
/// trials.
pub(super) fn choose(
    mesh: &AnimatedMesh,
    settings: Settings,
    progress: &dyn Progress,
) -> Result<Encoded> {
    let [default, others @ ..] = FIRST_FRAME_BITS_TRIED;
    let progress = Ahead {
        inner: progress,
        extra: others.len() as u64 * mesh.frame_count() as u64,
        first: AtomicU64::new(0),
        grown: AtomicU64::new(0),
        told: AtomicBool::new(false),
    };
    let mut search = Search::start(mesh, settings, default, &progress)?;
    for bits in others {
        progress.stage(&format!("first frame at {bits} bits"));
        if !search.try_bits(bits)? {
            break;
        }
    }
    search.best.report.first_frame_trials = search.trials;
    Ok(search.best)
}

/// `base` at first-frame precision `bits`.
fn at(bits: u8, base: &EncodeOptions) -> EncodeOptions {
    EncodeOptions {
        first_frame_bits: Some(bits),
        ..base.clone()
    }
}

/// `opts` with `best`'s motion model fixed: the model the other precisions are coded with.
fn kept_model(best: &Encoded, opts: &EncodeOptions) -> EncodeOptions {
    EncodeOptions {
        predictor: PredictorChoice::Fixed(best.model.predictor),
        segmentation: best.model.segmentation.into(),
        clusters: best.model.clusters,
        ..opts.clone()
    }
}

/// The precisions tried so far and the smallest stream among them.
struct Search<'a> {
    mesh: &'a AnimatedMesh,
    plan: &'a RatePlan,
    progress: &'a Ahead<'a>,
    /// The caller's options with the first encoding's motion model fixed.
    model: EncodeOptions,
    /// The default precision, coded first.
    default: u8,
    /// The first encoding's partition, reused unless the first-frame coder reorders vertices.
    known: Option<(Partition, SegmentationReport)>,
    best: Encoded,
    trials: Vec<FirstFrameTrial>,
    /// Whether `best` is a segmented encoding's analysis clip kept as its shared parts alone.
    partial: bool,
    /// The kept precision's estimate, when precisions are compared by estimates (tdct).
    best_estimate: Option<u64>,
}

impl<'a> Search<'a> {
    /// Codes the default precision `default` with the caller's choices.
    fn start(
        mesh: &'a AnimatedMesh,
        settings: Settings<'a>,
        default: u8,
        progress: &'a Ahead<'a>,
    ) -> Result<Self> {
        let (opts, plan) = (settings.opts, settings.plan);
        let first = at(default, opts);
        let models = opts.motion_models();
        let shared = settings.keep == Keep::SharedParts;
        if let ([model], true, true) = (&models[..], opts.codec.codec().estimated_trials(), shared)
        {
            return Self::start_fixed(mesh, settings, &first, *model, progress);
        }
        // A segmented encoding's analysis clip keeps its shared parts alone, unless precisions
        // are compared by whole streams (a picture codec has no estimate to compare them by).
        let estimated = models.len() > 1 && opts.codec.codec().estimated_trials();
        let partial = shared && estimated;
        let keep = if partial { Keep::SharedParts } else { Keep::Whole };
        let settings_first = Settings {
            opts: &first,
            plan,
            keep,
        };
        let best = encode_once(mesh, settings_first, progress, None, None)?;
        let model = kept_model(&best, opts);
        // The segmentation runs on the animation alone, so the trials keep the first one's,
        // unless the first-frame coder reorders the vertices (its order may change with the
        // precision).
        let known =
            (!opts.reorder).then(|| (best.partition.clone(), best.report.segmentation.clone()));
        // With a codec that estimates (tdct), precisions are compared by their estimates, and
        // only one that beats the kept one's is coded in full. The kept one's is the least (a
        // stopped one passed the least so far).
        let chosen = best.report.choice.as_ref().and_then(|c| {
            c.candidates.iter().filter_map(|k| k.estimate).min()
        });
        let trials = vec![FirstFrameTrial {
            bits: default,
            bytes: chosen.filter(|_| partial).unwrap_or(best.report.bytes),
            estimated: partial,
            stopped: false,
        }];
        let mut search = Self {
            mesh,
            plan,
            progress,
            model,
            default,
            known,
            best,
            trials,
            partial,
            // A fixed model has no estimate here (a clip of one segment, coded whole anyway; see
            // `start_fixed`): its precisions are coded in full.
            best_estimate: chosen,
        };
        if partial && chosen.is_none() {
            // No estimate to compare by after all: compared by whole streams.
            search.recode_whole()?;
        }
        Ok(search)
    }

    /// [`Self::start`] for a segmented encoding's analysis clip with a fixed motion model and a
    /// codec that estimates (tdct): the default precision (`first`) is estimated, then coded as
    /// the shared parts alone, so that a coarser precision is compared by its estimate, as after
    /// the automatic choice, instead of the analysis clip being coded whole at both (pdance
    /// `--predictor affine --segmentation kmeans`: 1.9 → 1.2 CPU s). A clip of one segment keeps
    /// comparing whole streams: its default precision is coded whole anyway, and an estimate
    /// more would cost as much as it spares.
    fn start_fixed(
        mesh: &'a AnimatedMesh,
        settings: Settings<'a>,
        first: &EncodeOptions,
        model: MotionModel,
        progress: &'a Ahead<'a>,
    ) -> Result<Self> {
        let default = first.first_frame_bits.unwrap_or_default();
        let whole = Settings::whole(first, settings.plan);
        let Some((estimate, analysis)) =
            estimate_once(mesh, whole, progress, (model, None), u64::MAX)?
        else {
            return Err(crate::error::Error::Usage(
                "the codec gave no estimate although it estimates its trials".into(),
            ));
        };
        let known = (!first.reorder).then(|| analysis.segmentation());
        let kept = Settings {
            opts: first,
            ..settings
        };
        let best = analysis.code(kept, progress)?;
        let trials = vec![FirstFrameTrial {
            bits: default,
            bytes: estimate.bytes,
            estimated: true,
            stopped: false,
        }];
        Ok(Self {
            mesh,
            plan: settings.plan,
            progress,
            model: kept_model(&best, settings.opts),
            default,
            known,
            best,
            trials,
            partial: true,
            best_estimate: Some(estimate.bytes),
        })
    }

    /// Tries precision `bits`; returns whether a coarser one is worth trying.
    fn try_bits(&mut self, bits: u8) -> Result<bool> {
        let opts = at(bits, &self.model);
        let settings = Settings::whole(&opts, self.plan);
        let encoded = match self.best_estimate {
            Some(before) => match self.estimate_then_code(bits, settings, before)? {
                Some(encoded) => encoded,
                None => return Ok(false),
            },
            None => encode_once(self.mesh, settings, self.progress, self.known.clone(), None)?,
        };
        self.trials.push(FirstFrameTrial {
            bits,
            bytes: encoded.report.bytes,
            estimated: false,
            stopped: false,
        });
        if encoded.report.bytes >= self.best.report.bytes {
            // Coarser has not helped where this did not
            // (docs/design.md, "First-frame bits trials and k-means ladder").
            self.retell();
            return Ok(false);
        }
        let choice = self.best.report.choice.take();
        self.best = encoded;
        self.best.report.choice = choice;
        Ok(true)
    }

    /// Estimates precision `bits`, stopping once sure not to be below the kept one's estimate
    /// `before`, and codes it in full if it is below (`None` when it is not).
    fn estimate_then_code(
        &mut self,
        bits: u8,
        settings: Settings,
        before: u64,
    ) -> Result<Option<Encoded>> {
        let fixed = (self.best.model, self.known.clone());
        let limit = before.saturating_sub(1);
        let Some((estimate, analysis)) =
            estimate_once(self.mesh, settings, self.progress, fixed, limit)?
        else {
            return Ok(None);
        };
        // A stopped estimate is at least `before`.
        if estimate.bytes >= before {
            self.trials.push(FirstFrameTrial {
                bits,
                bytes: estimate.bytes,
                estimated: true,
                stopped: estimate.stopped,
            });
            self.retell();
            return Ok(None);
        }
        self.best_estimate = Some(estimate.bytes);
        if self.partial {
            // The finer stream is compared whole: coded whole now, as it would have been.
            self.recode_whole()?;
        }
        // Coded in full after its estimate: its frames count twice.
        self.progress.grow(self.mesh.frame_count() as u64);
        analysis.code(settings, self.progress).map(Some)
    }

    /// Tells the progress the work's total now that the trials stop.
    fn retell(&self) {
        let frames = self.mesh.frame_count() as u64;
        self.progress.retell(self.trials.len() as u64 - 1, frames);
    }

    /// Codes the default precision, kept as its shared parts alone, whole (its model fixed, its
    /// partition `known` unless reordered), as the automatic choice had kept it.
    fn recode_whole(&mut self) -> Result<()> {
        let (mesh, progress) = (self.mesh, self.progress);
        let whole = at(self.default, &self.model);
        progress.grow(mesh.frame_count() as u64);
        let best = &mut self.best;
        let mut choice = best.report.choice.take();
        let settings = Settings::whole(&whole, self.plan);
        *best = encode_once(mesh, settings, progress, self.known.clone(), None)?;
        // The kept candidate (the least estimate, the first on a tie) is measured now.
        let candidates = choice.iter_mut().flat_map(|c| c.candidates.iter_mut());
        if let Some(kept) = candidates.min_by_key(|c| c.bytes) {
            kept.bytes = best.report.bytes;
            kept.estimated = false;
        }
        best.report.choice = choice;
        if let Some(trial) = self.trials.first_mut() {
            trial.bytes = best.report.bytes;
            trial.estimated = false;
        }
        self.partial = false;
        Ok(())
    }
}

/// Passes progress on, telling the whole work ahead once: the first encoding's total plus the
/// frames of the trials after it (whose own totals are dropped).
struct Ahead<'a> {
    inner: &'a dyn Progress,
    extra: u64,
    /// Frames added to the work since it was told ([`Ahead::grow`]).
    grown: AtomicU64,
    /// The first encoding's own total.
    first: AtomicU64,
    told: AtomicBool,
}

impl Ahead<'_> {
    /// Tells the total again when the trials stop after `run` of them, `frames` frames each.
    fn retell(&self, run: u64, frames: u64) {
        let grown = self.grown.load(Ordering::Relaxed);
        self.inner
            .total(self.first.load(Ordering::Relaxed) + run * frames + grown);
    }

    /// Adds `frames` to the work ahead and tells the new total.
    fn grow(&self, frames: u64) {
        let grown = self.grown.fetch_add(frames, Ordering::Relaxed) + frames;
        self.inner
            .total(self.first.load(Ordering::Relaxed) + self.extra + grown);
    }
}

impl Progress for Ahead<'_> {
    fn stage(&self, name: &str) {
        self.inner.stage(name);
    }

    fn total(&self, frames: u64) {
        if !self.told.swap(true, Ordering::Relaxed) {
            self.first.store(frames, Ordering::Relaxed);
            self.inner.total(frames + self.extra);
        }
    }

    fn frames(&self, count: u64) {
        self.inner.frames(count);
    }
}
