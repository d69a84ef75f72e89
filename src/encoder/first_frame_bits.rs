//! tdct's choice of first-frame precision, when the caller leaves `first_frame_bits` open: the
//! animation is coded at each of [`FIRST_FRAME_BITS_TRIED`] and the smallest stream is kept.
//!
//! The temporal DCT codes frame 0's residual like any other frame's, so a coarser first frame is
//! corrected down to the quality's step: the bits move from the first-frame coder into the
//! residuals' lowest band, and which side codes them cheaper depends on the mesh (a detailed
//! shape costs the first-frame coder much; a flat grid it predicts almost exactly) and on the step.
//! The motion model is chosen once, at the default precision (the automatic choice's trials), and
//! the other precisions are coded with it fixed: the model follows the motion, the precision the
//! first frame's shape.

use super::{encode_once, EncodeOptions, Encoded, PredictorChoice, Segmentation};
use crate::error::Result;
use crate::mesh::AnimatedMesh;
use crate::progress::Progress;
use std::sync::atomic::{AtomicBool, Ordering};

pub use super::options::FIRST_FRAME_BITS_TRIED;

/// One first-frame precision tried and the size of its stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct FirstFrameTrial {
    /// Bits per coordinate of the first frame.
    pub bits: u8,
    /// The stream's bytes at that precision.
    pub bytes: u64,
}

/// Codes `mesh` at every precision of [`FIRST_FRAME_BITS_TRIED`] and keeps the smallest stream
/// (the default on a tie); its report lists the trials.
pub(super) fn choose(
    mesh: &AnimatedMesh,
    opts: &EncodeOptions,
    progress: &dyn Progress,
) -> Result<Encoded> {
    let [default, others @ ..] = FIRST_FRAME_BITS_TRIED;
    let progress = Ahead {
        inner: progress,
        extra: (others.len() * mesh.frame_count()) as u64,
        told: AtomicBool::new(false),
    };
    let at = |bits: u8, base: &EncodeOptions| EncodeOptions {
        first_frame_bits: Some(bits),
        ..base.clone()
    };
    let mut best = encode_once(mesh, &at(default, opts), &progress)?;
    let model = chosen_model(&best, opts);
    let mut trials = vec![FirstFrameTrial {
        bits: default,
        bytes: best.report.bytes,
    }];
    for bits in others {
        progress.stage(&format!("first frame at {bits} bits"));
        let encoded = encode_once(mesh, &at(bits, &model), &progress)?;
        trials.push(FirstFrameTrial {
            bits,
            bytes: encoded.report.bytes,
        });
        if encoded.report.bytes < best.report.bytes {
            let choice = best.report.choice.take();
            best = encoded;
            best.report.choice = choice;
        }
    }
    best.report.first_frame_trials = trials;
    Ok(best)
}

/// `opts` with the motion model `encoded` was coded with fixed: its predictor, its segmentation
/// and (k-means) the K it asked for.
fn chosen_model(encoded: &Encoded, opts: &EncodeOptions) -> EncodeOptions {
    let report = &encoded.report;
    let segmentation = match report.segmentation.e0 {
        Some(e0) => Segmentation::Decimation { e0 },
        None => Segmentation::KMeans,
    };
    EncodeOptions {
        predictor: PredictorChoice::Fixed(report.header.predictor),
        segmentation: segmentation.into(),
        clusters: report.header.requested_clusters as usize,
        ..opts.clone()
    }
}

/// Passes progress on, telling the whole work ahead once: the first encoding's total plus the
/// frames of the trials after it (whose own totals are dropped).
struct Ahead<'a> {
    inner: &'a dyn Progress,
    extra: u64,
    told: AtomicBool,
}

impl Progress for Ahead<'_> {
    fn stage(&self, name: &str) {
        self.inner.stage(name);
    }

    fn total(&self, frames: u64) {
        if !self.told.swap(true, Ordering::Relaxed) {
            self.inner.total(frames + self.extra);
        }
    }

    fn frames(&self, count: u64) {
        self.inner.frames(count);
    }
}
