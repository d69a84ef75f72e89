//! Coding a clip's residuals at its plan's depth (`RatePlan::depth_choices`), and for AV1's
//! 12-bit pictures at two splits of one quantiser step between pixel step and `crf`: the law's
//! own (fine samples, low `crf`) and the coarsest `crf` over samples as much finer as the
//! residuals leave room for. Which costs fewer bits at equal error depends on the clip, not on
//! anything measured before coding: at quality 90 the law's own split cost Fox 1.6 × and
//! RiggedSimple 1.3 × the bits of the other, and CesiumMan and walking_cat 10 % fewer (the
//! small meshes' key frames, whose finer quantisers stop at `qmin`, weigh more). So both are
//! coded whole and the fewer bits at equal error kept (docs/design.md, "Sample depth").

use super::{code_at, distortion, Analysed, Encoded, Keep, Settings, Stopwatch};
use crate::codec::RatePlan;
use crate::error::Result;
use crate::first_frame::EncodedFirstFrame;
use crate::mesh::AnimatedMesh;
use crate::progress::{Progress, Silent};
use crate::stream::container::Part;
use std::time::Instant;

/// Codes the residuals of `analysed` as [`code_at`] does, at the settings' plan at the depth
/// the clip's residuals want (all of them, even when the first frame alone is coded: a segmented
/// stream's analysis clip, whose set-up every segment takes); where AV1's 12-bit pictures have a
/// second split, at that one too, keeping the fewer bits at equal error (the law's own on a tie).
/// A first frame coded alone (a segmented stream's analysis clip, unless its trials were coded
/// whole) takes the law's own: it has no error to compare.
pub(super) fn code(
    mesh: &AnimatedMesh,
    ff: &EncodedFirstFrame,
    leading: Vec<Part>,
    settings: Settings,
    analysed: &Analysed,
    progress: &dyn Progress,
    clock: Stopwatch,
) -> Result<Encoded> {
    let residuals = &analysed.prediction.residuals;
    let (plan, other) = settings.plan.clone().depth_choices(residuals);
    let whole = settings.keep == Keep::Whole || mesh.frame_count() == 1;
    let coded = |plan: &RatePlan, leading, progress: &dyn Progress, clock| {
        code_at(
            plan,
            (mesh, ff),
            leading,
            settings,
            analysed,
            progress,
            clock,
        )
    };
    let Some(other) = other.filter(|_| whole) else {
        return coded(&plan, leading, progress, clock);
    };
    let own = coded(&plan, leading.clone(), progress, clock.clone())?;
    let start = Instant::now();
    // The bar has counted the clip's frames once: the second coding shows as a stage of its own.
    progress.stage("12-bit pictures at a coarser crf");
    let roomy = coded(&other, leading, &Silent, clock)?;
    let cost = |encoded: &Encoded| distortion::whole_cost(mesh, encoded).map(|(cost, _)| cost);
    let mut kept = match cost(&roomy)? < cost(&own)? {
        true => roomy,
        false => own,
    };
    // The kept stream's own stages are in its report; this is what the other split added.
    let stage = "12-bit crf split: the other coded, both measured".to_string();
    let seconds = start.elapsed().as_secs_f64();
    kept.report.stage_seconds.push((stage, seconds));
    Ok(kept)
}
