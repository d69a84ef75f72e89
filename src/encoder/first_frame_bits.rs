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
//! first frame's shape.

use super::{encode_once, EncodeOptions, Encoded, PredictorChoice, Settings};
use crate::error::Result;
use crate::mesh::AnimatedMesh;
use crate::progress::Progress;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

pub use super::options::FIRST_FRAME_BITS_TRIED;

/// One first-frame precision tried and the size of its stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct FirstFrameTrial {
    /// Bits per coordinate of the first frame.
    pub bits: u8,
    /// The stream's bytes at that precision.
    pub bytes: u64,
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
        told: AtomicBool::new(false),
    };
    let at = |bits: u8, base: &EncodeOptions| EncodeOptions {
        first_frame_bits: Some(bits),
        ..base.clone()
    };
    let first = at(default, opts);
    let plan = settings.plan;
    let mut best = encode_once(mesh, Settings { opts: &first, plan }, &progress, None)?;
    let model = EncodeOptions {
        predictor: PredictorChoice::Fixed(best.model.predictor),
        segmentation: best.model.segmentation.into(),
        clusters: best.model.clusters,
        ..opts.clone()
    };
    // The segmentation runs on the animation alone, so the trials keep the first one's, unless
    // the first-frame coder reorders the vertices (its order may change with the precision).
    let known = (!opts.reorder).then(|| (best.partition.clone(), best.report.segmentation.clone()));
    let mut trials = vec![FirstFrameTrial {
        bits: default,
        bytes: best.report.bytes,
    }];
    for bits in others {
        progress.stage(&format!("first frame at {bits} bits"));
        let opts = at(bits, &model);
        let settings = Settings { opts: &opts, plan };
        let encoded = encode_once(mesh, settings, &progress, known.clone())?;
        trials.push(FirstFrameTrial {
            bits,
            bytes: encoded.report.bytes,
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

/// Passes progress on, telling the whole work ahead once: the first encoding's total plus the
/// frames of the trials after it (whose own totals are dropped).
struct Ahead<'a> {
    inner: &'a dyn Progress,
    extra: u64,
    /// The first encoding's own total.
    first: AtomicU64,
    told: AtomicBool,
}

impl Ahead<'_> {
    /// Tells the total again when the trials stop after `run` of them, `frames` frames each.
    fn retell(&self, run: u64, frames: u64) {
        self.inner
            .total(self.first.load(Ordering::Relaxed) + run * frames);
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
