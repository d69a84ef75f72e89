//! The automatic choice's reason in words ([`super::auto`]): the kept candidate's margin over the
//! runner-up, and what the trials left out.

use super::auto::Candidate;
use super::distortion;

/// Why candidate `chosen` was kept, in words: its margin over the runner-up (the next lowest
/// cost), in bytes or, when errors were weighed, in bits at equal error.
pub(super) fn reason(
    candidates: &[Candidate],
    costs: &[f64],
    chosen: usize,
    (trial_frames, frames): (usize, usize),
) -> String {
    let name = |c: &Candidate| {
        let model = format!("{}+{}", c.predictor.name(), c.segmentation);
        format!("{model} ({} clusters)", c.clusters)
    };
    let winner = &candidates[chosen];
    // The runner-up among the complete estimates: a stopped one's bytes are how far it got.
    let runner_up = (0..candidates.len())
        .filter(|&i| i != chosen && !candidates[i].stopped)
        .min_by(|&a, &b| costs[a].total_cmp(&costs[b]));
    let stopped = candidates.iter().filter(|c| c.stopped).count();
    let mut reason = match (runner_up, winner.vertex_rmse) {
        (Some(next), Some(rmse)) => format!(
            "fewest bits at equal error (RMSE ∝ rate^-{}): {} bytes at vertex RMSE {rmse:.3e}; \
             {} ({} bytes at {:.3e}) would need {:.1} % more bits at that error",
            distortion::RD_SLOPE,
            winner.bytes,
            name(&candidates[next]),
            candidates[next].bytes,
            candidates[next].vertex_rmse.unwrap_or(f64::NAN),
            100.0 * ((costs[next] - costs[chosen]).exp2() - 1.0),
        ),
        (Some(next), None) => {
            let next = &candidates[next];
            let what = match winner.estimated {
                true => {
                    "smallest estimate (one cheap pass over the residuals; the kept one then \
                         coded in full)"
                }
                false => "smallest stream",
            };
            format!(
                "{what} at the quality's step: {} bytes, {:.1} % below {} ({} bytes)",
                winner.bytes,
                100.0 * (1.0 - winner.bytes as f64 / next.bytes.max(1) as f64),
                name(next),
                next.bytes
            )
        }
        (None, _) if stopped > 0 => "the smallest estimate".to_string(),
        (None, _) => "the only candidate".to_string(),
    };
    if stopped > 0 {
        reason.push_str(&format!(
            "; {stopped} estimates stopped once they passed the smallest so far"
        ));
    }
    if trial_frames < frames {
        reason.push_str(&format!(
            "; sizes estimated from {trial_frames} of {frames} frames"
        ));
    }
    reason
}
