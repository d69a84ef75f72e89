//! The picture codecs' k-means rung, chosen before any chart is flattened: tdct's cheap estimates
//! rank the ladder's rungs (`encoder/ladder.rs`), and only the first is tried with pictures
//! beside decimation. Each rung's atlas and sampled picture trials cost a picture codec's choice
//! 1.3–2.0× its CPU; the estimates cost a tenth of that, and on 8 clips the K they rank first was
//! the one with the least AV1 cost at equal error, or within a few per cent of it
//! (docs/design.md, "First-frame bits trials and k-means ladder").

use super::{jobs_of, ladder, Shared};
use crate::codec::Codec;
use crate::encoder::{analysis, EncodeOptions, MotionModel, Segmentation, Settings, Stopwatch};
use crate::error::Result;
use crate::geometry_image::lattice::AtlasCache;
use crate::progress::{Progress, Silent};
use std::sync::atomic::AtomicU64;
use std::time::Instant;

/// For a picture codec whose choice climbs the k-means ladder: the K whose candidates tdct's cheap
/// estimates rank first (the earliest on a tie, the same gate on the rungs), so that only that
/// rung's charts are flattened and its pictures tried beside decimation's. On 8 clips the K with
/// the least AV1 cost at equal error was tdct's first (docs/design.md, "First-frame bits trials
/// and k-means ladder"). `None` for tdct, or with one rung.
pub(super) fn rank_rungs(
    shared: &Shared,
    segmenter: &analysis::Segmenter,
    (segmentations, models): (&[(Segmentation, usize)], &[MotionModel]),
    progress: &dyn Progress,
    clock: &mut Stopwatch,
) -> Result<Option<usize>> {
    let rungs: Vec<(Segmentation, usize)> = (segmentations.iter())
        .filter(|(s, _)| *s == Segmentation::KMeans)
        .copied()
        .collect();
    if shared.settings.plan.pictures.is_none() || rungs.len() < 2 {
        return Ok(None);
    }
    let start = Instant::now();
    progress.stage("k-means rungs by tdct's estimates");
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
    let on_rungs: Vec<MotionModel> = (models.iter())
        .filter(|m| m.segmentation == Segmentation::KMeans)
        .copied()
        .collect();
    let atlases: Vec<AtlasCache> = rungs.iter().map(|_| AtlasCache::default()).collect();
    let gates = ladder::gates(&rungs);
    let jobs = jobs_of(&on_rungs, &rungs, &atlases, &gates);
    let outcomes = ladder::run_jobs(
        &gates,
        |i| jobs[i].run(&tdct, segmenter, &Silent),
        |i| jobs[i].skip(&tdct, &Silent),
        |outcome| outcome.podium.best.as_ref().map(|(b, _)| b.cost),
    )?;
    let costs = outcomes.iter().zip(&rungs).filter_map(|(outcome, &(_, k))| {
        let best = outcome.podium.best.as_ref();
        best.map(|(b, _)| (b.cost, k))
    });
    let first = costs.fold(None, |best: Option<(f64, usize)>, (cost, k)| match best {
        Some((least, _)) if least <= cost => best,
        _ => Some((cost, k)),
    });
    let seconds = start.elapsed().as_secs_f64();
    clock.stages.push(("k-means rungs by tdct's estimates".into(), seconds));
    Ok(first.map(|(_, k)| k))
}

