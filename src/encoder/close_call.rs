//! Close calls of the picture codecs' sampled trials. A sample of frames ranks the candidates by
//! bits at equal error, but its relative costs stray from the whole stream's by about a tenth
//! (docs/design.md, "Automatic choice: bits at equal error"): when it puts its two best within
//! [`CLOSE`] of each other it cannot tell them apart, so both are coded whole and the one of fewer
//! bits at equal error is kept. On 66 measured clips the sample's winner was the whole trials'
//! but once, a cut of chickenCrossing at MPEG-4 quality 30, whose two best were 0.07 % apart on
//! the sample and 4.4 % apart whole; five of the 66 were that close.

use super::auto::{keep, Best, Candidate, Shared};
use super::{distortion, Encoded, MotionModel, Stopwatch};
use crate::error::Result;
use crate::progress::Progress;
use std::time::Instant;

/// More bits at equal error, as a fraction, within which the sample's runner-up is coded whole
/// beside its best.
pub const CLOSE: f64 = 0.02;

/// Whether a runner-up of cost `runner_up` is a close call against the best's `best` (costs of
/// [`distortion::cost`]: a difference of one is twice the bits).
pub(super) fn is_close(best: f64, runner_up: f64) -> bool {
    runner_up - best <= (1.0 + CLOSE).log2()
}

/// The two lowest-cost candidates offered, each with its place among the reported candidates;
/// the earlier offered wins a tie, so the order the trials end in never matters.
pub(super) struct Podium<'a> {
    pub(super) best: Option<(Best<'a>, usize)>,
    pub(super) runner_up: Option<(Best<'a>, usize)>,
}

impl<'a> Podium<'a> {
    pub(super) fn new() -> Self {
        Self {
            best: None,
            runner_up: None,
        }
    }

    /// Offers candidate `b`, reported at `at`.
    pub(super) fn offer(&mut self, b: Best<'a>, at: usize) {
        let beats =
            |other: &Option<(Best, usize)>| other.as_ref().is_none_or(|(o, _)| b.cost < o.cost);
        if beats(&self.best) {
            self.runner_up = self.best.replace((b, at));
        } else if beats(&self.runner_up) {
            self.runner_up = Some((b, at));
        }
    }
}

/// One of a close call's pair coded whole.
struct Whole {
    encoded: Encoded,
    model: MotionModel,
    at: usize,
    cost: f64,
    rmse: f64,
}

/// Codes the sample's `best` and `runner_up` whole, side by side, and returns the stream of fewer
/// bits at equal error (the sample's best on a tie), its model, and a sentence saying why. Both
/// candidates' reports get their whole streams' bytes and errors.
pub(super) fn settle(
    shared: &Shared,
    [best, runner_up]: [(Best, usize); 2],
    models: &[MotionModel],
    candidates: &mut [Candidate],
    progress: &dyn Progress,
    clock: Stopwatch,
) -> Result<(Encoded, MotionModel, String)> {
    let start = Instant::now();
    let whole = |(b, at): (Best, usize), clock: Stopwatch| -> Result<Whole> {
        let model = models[b.index];
        let encoded = keep(shared, model, b.kept, progress, clock)?;
        let (cost, rmse) = distortion::whole_cost(shared.mesh, &encoded)?;
        Ok(Whole {
            encoded,
            model,
            at,
            cost,
            rmse,
        })
    };
    let second_clock = clock.clone();
    let (first, second) = rayon::join(|| whole(best, clock), || whole(runner_up, second_clock));
    let (first, second) = (first?, second?);
    let diagonal = shared.diagonal();
    for w in [&first, &second] {
        if let Some(c) = candidates.get_mut(w.at) {
            c.bytes = w.encoded.report.bytes;
            c.estimated = false;
            c.vertex_rmse = Some(w.rmse / diagonal);
        }
    }
    let name = |w: &Whole| w.model.name();
    let said = |w: &Whole| {
        let rmse = w.rmse / diagonal;
        format!(
            "{} {} bytes at vertex RMSE {rmse:.3e}",
            name(w),
            w.encoded.report.bytes
        )
    };
    let sentence = format!(
        "the sample put {} and {} within {:.0} % in bits at equal error, too close to tell, so \
         both were coded whole: {}, {}",
        name(&first),
        name(&second),
        100.0 * CLOSE,
        said(&first),
        said(&second),
    );
    let (kept, other) = match second.cost < first.cost {
        true => (second, first),
        false => (first, second),
    };
    let more = 100.0 * ((other.cost - kept.cost).exp2() - 1.0);
    let sentence = format!("{sentence}; {} needs {more:.1} % more bits", name(&other));
    let mut encoded = kept.encoded;
    let seconds = start.elapsed().as_secs_f64();
    let stage = "close call (both coded whole)".to_string();
    encoded.report.stage_seconds.push((stage, seconds));
    Ok((encoded, kept.model, sentence))
}
