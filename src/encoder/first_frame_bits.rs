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

use super::{encode_once, estimate_once, EncodeOptions, Encoded, Keep, PredictorChoice};
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
    let opts = settings.opts;
    let [default, others @ ..] = FIRST_FRAME_BITS_TRIED;
    let frames = mesh.frame_count() as u64;
    let progress = Ahead {
        inner: progress,
        extra: others.len() as u64 * frames,
        first: AtomicU64::new(0),
        grown: AtomicU64::new(0),
        told: AtomicBool::new(false),
    };
    let at = |bits: u8, base: &EncodeOptions| EncodeOptions {
        first_frame_bits: Some(bits),
        ..base.clone()
    };
    let first = at(default, opts);
    let plan = settings.plan;
    // A segmented encoding's analysis clip keeps its shared parts alone, unless precisions are
    // compared by whole streams: a fixed model has no estimate to compare them by.
    let estimated = opts.motion_models().len() > 1 && opts.codec.codec().estimated_trials();
    let mut partial = settings.keep == Keep::SharedParts && estimated;
    let keep = if partial { Keep::SharedParts } else { Keep::Whole };
    let settings_first = Settings {
        opts: &first,
        plan,
        keep,
    };
    let mut best = encode_once(mesh, settings_first, &progress, None, None)?;
    let model = EncodeOptions {
        predictor: PredictorChoice::Fixed(best.model.predictor),
        segmentation: best.model.segmentation.into(),
        clusters: best.model.clusters,
        ..opts.clone()
    };
    // The segmentation runs on the animation alone, so the trials keep the first one's, unless
    // the first-frame coder reorders the vertices (its order may change with the precision).
    let known = (!opts.reorder).then(|| (best.partition.clone(), best.report.segmentation.clone()));
    // With a codec that estimates (tdct), precisions are compared by their estimates, and only
    // one that beats the kept one's is coded in full. The kept one's is the least (a stopped one
    // passed the least so far).
    let chosen = best.report.choice.as_ref().and_then(|c| {
        c.candidates.iter().filter_map(|k| k.estimate).min()
    });
    let mut trials = vec![FirstFrameTrial {
        bits: default,
        bytes: chosen.filter(|_| partial).unwrap_or(best.report.bytes),
        estimated: partial,
        stopped: false,
    }];
    if partial && chosen.is_none() {
        // No estimate to compare by after all: compared by whole streams.
        let whole = at(default, &model);
        recode_whole(mesh, (&mut best, &mut trials[0]), &whole, plan, &progress, &known)?;
        partial = false;
    }
    // A fixed model has no estimate to compare with: its precisions are coded in full.
    let mut best_estimate = chosen;
    for bits in others {
        progress.stage(&format!("first frame at {bits} bits"));
        let opts = at(bits, &model);
        let settings = Settings::whole(&opts, plan);
        let encoded = match best_estimate {
            Some(estimate_before) => {
                let fixed = (best.model, known.clone());
                // Its estimate stops once it is sure not to be below the kept one's.
                let limit = estimate_before.saturating_sub(1);
                let Some((estimate, analysis)) =
                    estimate_once(mesh, settings, &progress, fixed, limit)?
                else {
                    break;
                };
                // A stopped estimate is at least `estimate_before`.
                let (estimate, stopped) = (estimate.bytes, estimate.stopped);
                if estimate >= estimate_before {
                    trials.push(FirstFrameTrial {
                        bits,
                        bytes: estimate,
                        estimated: true,
                        stopped,
                    });
                    progress.retell(trials.len() as u64 - 1, frames);
                    break;
                }
                best_estimate = Some(estimate);
                if partial {
                    // The finer stream is compared whole: coded whole now, as it would have been.
                    let whole = at(default, &model);
                    recode_whole(mesh, (&mut best, &mut trials[0]), &whole, plan, &progress, &known)?;
                    partial = false;
                }
                // Coded in full after its estimate: its frames count twice.
                progress.grow(frames);
                analysis.code(settings, &progress)?
            }
            None => encode_once(mesh, settings, &progress, known.clone(), None)?,
        };
        trials.push(FirstFrameTrial {
            bits,
            bytes: encoded.report.bytes,
            estimated: false,
            stopped: false,
        });
        if encoded.report.bytes >= best.report.bytes {
            // Coarser has not helped where this did not
            // (docs/design.md, "First-frame bits trials and k-means ladder").
            progress.retell(trials.len() as u64 - 1, frames);
            break;
        }
        let choice = best.report.choice.take();
        best = encoded;
        best.report.choice = choice;
    }
    best.report.first_frame_trials = trials;
    Ok(best)
}

/// Codes `best`, kept as its shared parts alone, whole with `opts` (its model fixed, its partition
/// `known` unless reordered), as the automatic choice had kept it; `trial` is its precision's.
fn recode_whole(
    mesh: &AnimatedMesh,
    (best, trial): (&mut Encoded, &mut FirstFrameTrial),
    opts: &EncodeOptions,
    plan: &RatePlan,
    progress: &Ahead,
    known: &Option<(Partition, SegmentationReport)>,
) -> Result<()> {
    progress.grow(mesh.frame_count() as u64);
    let mut choice = best.report.choice.take();
    *best = encode_once(mesh, Settings::whole(opts, plan), progress, known.clone(), None)?;
    // The kept candidate (the least estimate, the first on a tie) is measured now.
    let candidates = choice.iter_mut().flat_map(|c| c.candidates.iter_mut());
    if let Some(kept) = candidates.min_by_key(|c| c.bytes) {
        kept.bytes = best.report.bytes;
        kept.estimated = false;
    }
    best.report.choice = choice;
    trial.bytes = best.report.bytes;
    trial.estimated = false;
    Ok(())
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
