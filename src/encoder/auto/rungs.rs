//! What tdct's cheap estimates rule out before a picture codec flattens any chart: they rank the
//! k-means ladder's rungs (`encoder/ladder.rs`) and only the first is tried with pictures (and the
//! rung above it when close: the pictures favour more clusters than tdct);
//! decimation, and the affine predictor on a segmentation, are tried only when the estimates do
//! not put them far behind; one candidate left is coded at once, with no sampled trial. Each
//! rung's atlas and sampled picture trials cost a picture codec's choice 1.3–2.0× its CPU; the
//! estimates cost a tenth of that (docs/design.md, "First-frame bits trials and k-means ladder",
//! "Candidates tdct's estimates rule out").

use super::{jobs_of, ladder, Candidate, ChoiceReport, Job, Shared};
use crate::codec::Codec;
use crate::encoder::{analysis, code, Analysed, Encoded, EncodeOptions, Keep};
use crate::encoder::{MotionModel, Segmentation, Settings, Stopwatch};
use crate::error::Result;
use crate::motion::PredictorKind;
use crate::geometry_image::lattice::AtlasCache;
use crate::progress::{Progress, Silent};
use std::sync::atomic::AtomicU64;
use std::time::Instant;

/// What tdct's cheap estimates said of a picture codec's candidates.
pub(super) struct Ranking {
    /// The K whose candidates rank first among the k-means rungs.
    pub(super) k: usize,
    /// The rung above it, when tdct's estimates put it within [`RUNG_ABOVE_WITHIN`] of it.
    pub(super) above: Option<usize>,
    /// tdct's estimated bytes of each candidate it coded, in the choice's order (none of a
    /// skipped rung's, nor of a failed trial's).
    pub(super) estimates: Vec<(MotionModel, u64)>,
}

/// A picture codec tries a segmentation other than k-means with pictures only when tdct's
/// smallest estimate on it is at most this many times the ranked rung's: its atlas and sampled
/// picture trials are a third of a picture codec's choice (pdance AV1: 4.4 of 12.8 CPU-s), and
/// on 84 choices (15 clips × 4 picture codecs at quality 50, 6 clips × JPEG and AV1 at 25 and
/// 75) the pictures' verdict on decimation against k-means favoured decimation at most 1.33×
/// more than tdct's did (horse-collapse, JPEG at quality 25: docs/design.md, "Candidates tdct's
/// estimates rule out").
pub(super) const OTHERS_WITHIN: f64 = 1.35;

/// A picture codec also tries the k-means rung above the ranked one when tdct's smallest estimate
/// on it is at most this many times the ranked rung's: the pictures favour more clusters than tdct
/// does. At quality 50, skinning on K = 40 against 30 at equal error: CesiumMan JPEG −15 %, AV1
/// −4.4 % (tdct: +3.1 %); the three.js Horse on 30 against 20, JPEG and AV1 −23 % (tdct: +4.3 %);
/// RiggedFigure −2 … −3 % (tdct: +4.7 %); pdance at quality 25 on 40 against 30 +1 … +3 % (tdct:
/// +3.0 %), which the trials then decline (docs/design.md, "Candidates tdct's estimates rule out").
pub(super) const RUNG_ABOVE_WITHIN: f64 = 1.05;

/// A picture codec drops the affine predictor on a segmentation where tdct's estimate for it is
/// at least this many times skinning's: on the same choices (168 pairs of affine and skinning
/// on one segmentation) the pictures judged affine against skinning as tdct did or worse in 150,
/// and never more than 1.17× better (chickenCrossing, AV1, K = 40: 1.315 by tdct, 1.125 by the
/// pictures). The other way round they disagree by up to 2.1× (RiggedFigure, JPEG: 0.769 by
/// tdct, 1.638 by the pictures), so skinning is never dropped.
pub(super) const AFFINE_BEHIND: f64 = 1.2;

impl Ranking {
    /// Whether `model` is tried with pictures: on the ranked rung, the rung above it when close
    /// ([`RUNG_ABOVE_WITHIN`]), or a segmentation tdct did not rank more than [`OTHERS_WITHIN`]
    /// times the rung's bytes (or could not rank); and not an affine predictor [`AFFINE_BEHIND`]
    /// skinning's on its segmentation.
    pub(super) fn keeps(&self, model: &MotionModel) -> bool {
        self.keeps_segmentation((model.segmentation, model.clusters)) && !self.affine_behind(model)
    }

    /// The candidates of `models` it [`keeps`](Self::keeps).
    pub(super) fn narrow(&self, models: &[MotionModel]) -> Vec<MotionModel> {
        models.iter().filter(|m| self.keeps(m)).copied().collect()
    }

    fn keeps_segmentation(&self, (s, k): (Segmentation, usize)) -> bool {
        match s {
            Segmentation::KMeans => k == self.k || Some(k) == self.above,
            _ => self.segmentation_ratio((s, k)).is_none_or(|r| r <= OTHERS_WITHIN),
        }
    }

    /// tdct's smallest estimate on `(s, k)` over the ranked rung's.
    fn segmentation_ratio(&self, on: (Segmentation, usize)) -> Option<f64> {
        let other = smallest_on(&self.estimates, on)?;
        let rung = smallest_on(&self.estimates, (Segmentation::KMeans, self.k))?;
        Some(other as f64 / rung.max(1) as f64)
    }

    /// tdct's smallest estimate on k-means rung `k` over the ranked rung's.
    fn rung_ratio(&self, k: usize) -> Option<f64> {
        self.segmentation_ratio((Segmentation::KMeans, k))
    }

    /// tdct's estimate of `model` over skinning's on its segmentation, for an affine predictor.
    fn affine_ratio(&self, model: &MotionModel) -> Option<f64> {
        if model.predictor != PredictorKind::Affine {
            return None;
        }
        let estimate = |predictor: PredictorKind| {
            let wanted = MotionModel { predictor, ..*model };
            let found = self.estimates.iter().find(|(m, _)| *m == wanted);
            found.map(|(_, bytes)| *bytes)
        };
        let affine = estimate(PredictorKind::Affine)?;
        let skinning = estimate(PredictorKind::Skinning)?;
        Some(affine as f64 / skinning.max(1) as f64)
    }

    fn affine_behind(&self, model: &MotionModel) -> bool {
        self.affine_ratio(model).is_some_and(|r| r >= AFFINE_BEHIND)
    }

    /// For the choice's reason: the rung kept and what tdct's estimates ruled out, among `models`.
    pub(super) fn describe(&self, models: &[MotionModel]) -> String {
        let mut text = format!(
            "k-means at K = {}, the rung tdct's estimates rank first",
            self.k
        );
        if let Some(above) = self.above {
            let ratio = self.rung_ratio(above).map_or(String::new(), |r| format!(" {}", relative(r)));
            text.push_str(&format!(
                "; K = {above} tried too: tdct's estimates put it{ratio}, within {:.0} %",
                100.0 * (RUNG_ABOVE_WITHIN - 1.0)
            ));
        }
        let mut told: Vec<(Segmentation, usize)> = Vec::new();
        for model in models {
            let on = (model.segmentation, model.clusters);
            if on.0 != Segmentation::KMeans && !told.contains(&on) {
                told.push(on);
                text.push_str(&self.describe_segmentation(on));
            }
            let affine = self.affine_ratio(model).filter(|_| self.keeps_segmentation(on));
            if let Some(r) = affine.filter(|&r| r >= AFFINE_BEHIND) {
                let (name, standing) = (model.name(), relative(r));
                text.push_str(&format!(
                    "; {name} not tried with pictures: tdct's estimate is {standing} skinning's"
                ));
            }
        }
        text
    }

    /// A segmentation other than k-means, for the reason: tried or not, and its estimate.
    fn describe_segmentation(&self, on: (Segmentation, usize)) -> String {
        let Some(ratio) = self.segmentation_ratio(on) else {
            return String::new();
        };
        let verdict = match self.keeps_segmentation(on) {
            true => "tried",
            false => "not tried with pictures",
        };
        let (name, standing) = (on.0.name(), relative(ratio));
        format!("; {name} {verdict}: tdct's estimates put it {standing} that rung")
    }
}

/// The rung after `k` among `rungs` (the ladder's K, ascending) when tdct's smallest estimate on it
/// is within [`RUNG_ABOVE_WITHIN`] of `least`, `k`'s; `None` when `k` is the top rung or the one
/// above was not estimated (its gate skipped it).
fn rung_above(
    mut rungs: impl Iterator<Item = usize>,
    (k, least): (usize, u64),
    estimates: &[(MotionModel, u64)],
) -> Option<usize> {
    let next = rungs.by_ref().skip_while(|&r| r != k).nth(1)?;
    let bytes = smallest_on(estimates, (Segmentation::KMeans, next))?;
    (bytes as f64 <= RUNG_ABOVE_WITHIN * least as f64).then_some(next)
}

/// tdct's smallest estimate among the candidates on `on`.
fn smallest_on(estimates: &[(MotionModel, u64)], on: (Segmentation, usize)) -> Option<u64> {
    let same = estimates.iter().filter(|(m, _)| (m.segmentation, m.clusters) == on);
    same.map(|(_, bytes)| *bytes).min()
}

/// A ratio of bytes in words: "43.9 % above", "1.0 % below".
fn relative(ratio: f64) -> String {
    let change = 100.0 * (ratio - 1.0);
    match change >= 0.0 {
        true => format!("{change:.1} % above"),
        false => format!("{:.1} % below", -change),
    }
}

/// For a picture codec whose choice climbs the k-means ladder: the K whose candidates tdct's cheap
/// estimates rank first (the earliest on a tie, the same gate on the rungs), the rung above it
/// when close, and every candidate's estimate, from which [`Ranking::keeps`] tells which
/// candidates' charts are flattened and pictures tried. On 8 clips the K with the least AV1 cost
/// at equal error was tdct's first or (CesiumMan) the one above (docs/design.md, "First-frame
/// bits trials and k-means ladder"). `None` for tdct, or with one rung.
pub(super) fn rank_rungs(
    shared: &Shared,
    segmenter: &analysis::Segmenter,
    (segmentations, models): (&[(Segmentation, usize)], &[MotionModel]),
    progress: &dyn Progress,
    clock: &mut Stopwatch,
) -> Result<Option<Ranking>> {
    let rungs = segmentations.iter().filter(|(s, _)| *s == Segmentation::KMeans);
    if shared.settings.plan.pictures.is_none() || rungs.count() < 2 {
        return Ok(None);
    }
    let start = Instant::now();
    progress.stage("candidates by tdct's estimates");
    let opts = EncodeOptions {
        codec: Codec::Tdct.into(),
        ..shared.settings.opts.clone()
    };
    let plan = opts.plan(shared.mesh.bbox_diagonal())?;
    let tdct = Shared {
        settings: Settings {
            opts: &opts,
            plan: &plan,
            keep: shared.settings.keep,
        },
        sample: None,
        smallest_estimate: AtomicU64::new(u64::MAX),
        ..*shared
    };
    let atlases: Vec<AtlasCache> = segmentations.iter().map(|_| AtlasCache::default()).collect();
    let gates = ladder::gates(segmentations);
    let mut jobs = jobs_of(models, segmentations, &atlases, &gates);
    // Every estimate is compared with another's: each runs to the end (a stopped one's bytes
    // would depend on which trials ended first, hence on the threads).
    jobs.iter_mut().for_each(|j| j.may_stop = false);
    let outcomes = ladder::run_jobs(
        &gates,
        |i| jobs[i].run(&tdct, segmenter, &Silent),
        |i| jobs[i].skip(&tdct, &Silent),
        |outcome| outcome.podium.best.as_ref().map(|(b, _)| b.cost),
    )?;
    let mut estimates = Vec::new();
    let mut first: Option<(u64, usize)> = None;
    for (job, outcome) in jobs.iter().zip(&outcomes) {
        for (model, candidate) in job.models.iter().zip(&outcome.candidates) {
            estimates.push((*model, candidate.bytes));
            let better = first.is_none_or(|(least, _)| candidate.bytes < least);
            if model.segmentation == Segmentation::KMeans && better {
                first = Some((candidate.bytes, model.clusters));
            }
        }
    }
    let seconds = start.elapsed().as_secs_f64();
    clock.stages.push(("candidates by tdct's estimates".into(), seconds));
    let Some((least, k)) = first else {
        return Ok(None);
    };
    let rungs = segmentations.iter().filter(|(s, _)| *s == Segmentation::KMeans);
    let above = rung_above(rungs.map(|&(_, r)| r), (k, least), &estimates);
    Ok(Some(Ranking {
        k,
        above,
        estimates,
    }))
}

/// The one candidate tdct's estimates leave a picture codec (of `models`, the choice's):
/// coded at once, with no sampled trial; the report names it and what was ruled out.
pub(super) fn only(
    shared: &Shared,
    segmenter: &analysis::Segmenter,
    (model, models): (MotionModel, &[MotionModel]),
    ranking: &Ranking,
    progress: &dyn Progress,
    mut clock: Stopwatch,
) -> Result<Encoded> {
    let start = Instant::now();
    let atlas = AtlasCache::default();
    let job = Job::alone(model, &atlas);
    let (mesh, settings) = (shared.mesh, shared.settings);
    progress.total(mesh.frame_count() as u64);
    let (partition, segmentation, track, stages) = job.prepare(shared, segmenter, progress)?;
    clock.stages.extend(stages);
    let (reference, bits) = (&shared.ff.decoded_positions, settings.weight_plan());
    let kind = model.predictor;
    let prediction = analysis::predict_on(mesh, reference, &partition, bits, kind, track)?;
    let seconds = start.elapsed().as_secs_f64();
    let analysed = Analysed {
        model,
        partition: &partition,
        segmentation,
        prediction: &prediction,
        atlas: Some(&atlas),
    };
    let leading = shared.leading.to_vec();
    let mut encoded = code(mesh, shared.ff, leading, settings, &analysed, progress, clock)?;
    let estimate = ranking.estimates.iter().find(|(m, _)| *m == model).map(|(_, b)| *b);
    // A segmented encoding's analysis clip codes its first frame alone: its bytes are not the
    // stream's, tdct's estimate stands for them.
    let measured = settings.keep == Keep::Whole;
    encoded.report.choice = Some(ChoiceReport {
        chosen: model.name(),
        trial_frames: 0,
        candidates: vec![Candidate {
            predictor: model.predictor,
            segmentation: model.segmentation.name(),
            clusters: partition.clusters(),
            bytes: match measured {
                true => encoded.report.bytes,
                false => estimate.unwrap_or_default(),
            },
            estimated: !measured,
            stopped: false,
            estimate,
            vertex_rmse: None,
            seconds,
        }],
        reason: format!(
            "the one candidate tdct's estimates left to try with pictures: {}",
            ranking.describe(models)
        ),
    });
    Ok(encoded)
}

#[cfg(test)]
mod tests {
    use super::*;

    const DECIMATION: Segmentation = Segmentation::Decimation { e0: 0.003 };

    fn model(predictor: PredictorKind, segmentation: Segmentation, clusters: usize) -> MotionModel {
        MotionModel {
            predictor,
            segmentation,
            clusters,
        }
    }

    /// Rungs K = 20 and 30 (30 ranked first) and decimation, each with both predictors: affine
    /// at `affine` times skinning's bytes, decimation's skinning at `decimation` times K = 30's.
    fn ranking(affine: f64, decimation: f64) -> (Ranking, Vec<MotionModel>) {
        let mut estimates = Vec::new();
        for (segmentation, k, skinning) in [
            (Segmentation::KMeans, 20, 1100.0),
            (Segmentation::KMeans, 30, 1000.0),
            (DECIMATION, 20, 1000.0 * decimation),
        ] {
            let bytes = |r: f64| (skinning * r).round() as u64;
            estimates.push((model(PredictorKind::Affine, segmentation, k), bytes(affine)));
            estimates.push((model(PredictorKind::Skinning, segmentation, k), bytes(1.0)));
        }
        let models = estimates.iter().map(|(m, _)| *m).collect();
        let ranking = Ranking {
            k: 30,
            above: None,
            estimates,
        };
        (ranking, models)
    }

    fn kept(r: &Ranking, models: &[MotionModel]) -> Vec<String> {
        let kept = models.iter().filter(|m| r.keeps(m));
        kept.map(|m| format!("{}{}", m.name(), m.clusters)).collect()
    }

    #[test]
    fn only_the_ranked_rung_of_kmeans_is_kept() {
        let (r, models) = ranking(1.0, 1.0);
        let kept = kept(&r, &models);
        assert_eq!(
            kept,
            [
                "affine+kmeans30",
                "skinning+kmeans30",
                "affine+decimation20",
                "skinning+decimation20"
            ]
        );
    }

    #[test]
    fn decimation_is_kept_unless_tdct_ranks_it_far_behind() {
        let (near, models) = ranking(1.0, OTHERS_WITHIN - 0.01);
        assert_eq!(kept(&near, &models).len(), 4);
        let (far, models) = ranking(1.0, OTHERS_WITHIN + 0.01);
        assert_eq!(kept(&far, &models), ["affine+kmeans30", "skinning+kmeans30"]);
        // Nothing estimated on decimation (its trials failed): it is tried with pictures.
        let (mut unknown, models) = ranking(1.0, 2.0);
        unknown.estimates.retain(|(m, _)| m.segmentation == Segmentation::KMeans);
        assert_eq!(kept(&unknown, &models).len(), 4);
    }

    #[test]
    fn affine_is_dropped_far_behind_skinning_and_skinning_never() {
        let (behind, models) = ranking(AFFINE_BEHIND + 0.01, 1.0);
        assert_eq!(
            kept(&behind, &models),
            ["skinning+kmeans30", "skinning+decimation20"]
        );
        let (close, models) = ranking(AFFINE_BEHIND - 0.01, 1.0);
        assert_eq!(kept(&close, &models).len(), 4);
        let (ahead, models) = ranking(0.5, 1.0);
        assert_eq!(kept(&ahead, &models).len(), 4);
    }

    #[test]
    fn the_reason_says_what_was_not_tried_and_why() {
        let (r, models) = ranking(1.493, 1.439);
        let text = r.describe(&models);
        assert!(text.contains("K = 30"), "{text}");
        assert!(
            text.contains("decimation not tried with pictures: tdct's estimates put it 43.9 %"),
            "{text}"
        );
        assert!(
            text.contains("affine+kmeans not tried with pictures: tdct's estimate is 49.3 % above"),
            "{text}"
        );
        let (r, models) = ranking(1.0, 0.95);
        let text = r.describe(&models);
        assert!(text.contains("decimation tried: tdct's estimates put it 5.0 % below"), "{text}");
        assert!(!text.contains("affine"), "{text}");
    }

    #[test]
    fn the_rung_above_is_kept_when_it_is_close() {
        let (mut r, models) = ranking(1.0, 2.0);
        r.k = 20;
        r.above = Some(30);
        let kept = kept(&r, &models);
        assert_eq!(
            kept,
            [
                "affine+kmeans20",
                "skinning+kmeans20",
                "affine+kmeans30",
                "skinning+kmeans30"
            ]
        );
        let text = r.describe(&models);
        assert!(text.contains("K = 30 tried too: tdct's estimates put it 9.1 % below"), "{text}");
    }

    #[test]
    fn the_rung_above_is_the_next_one_up_within_five_per_cent() {
        // K = 20, 30, 40 at 1000, 1030 and 1100 bytes (skinning; affine more).
        let at = |k: usize, bytes: u64| {
            let m = model(PredictorKind::Skinning, Segmentation::KMeans, k);
            [(m, bytes), (MotionModel { predictor: PredictorKind::Affine, ..m }, 2 * bytes)]
        };
        let estimates: Vec<(MotionModel, u64)> =
            [at(20, 1000), at(30, 1030), at(40, 1100)].concat();
        let ladder = || [20, 30, 40].into_iter();
        assert_eq!(rung_above(ladder(), (20, 1000), &estimates), Some(30));
        // 40 is 6.8 % above 30: too far.
        assert_eq!(rung_above(ladder(), (30, 1030), &estimates), None);
        // No rung above the top one; none estimated above (a skipped rung).
        assert_eq!(rung_above(ladder(), (40, 1100), &estimates), None);
        assert_eq!(rung_above(ladder(), (20, 1000), &estimates[..2]), None);
    }
}
