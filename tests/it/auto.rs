//! `--predictor auto` and `--segmentation auto` (issue 18): the encoder tries every candidate at
//! the quality's step and keeps the smallest stream (tdct, by its estimates, then codes the
//! winner) or the fewest bits at equal error (picture codecs, whose errors at one step differ),
//! saying so in its report.

use crate::common::{animate, config, decode_all, decoder, tube, vertex_rmse, Counter};
use mcgv_video::codec::Codec;
use mcgv_video::encoder::distortion;
use mcgv_video::encoder::{
    encode, encode_with_progress, Candidate, ChoiceReport, EncodeOptions, PredictorChoice,
    Segmentation, SegmentationChoice,
};
use mcgv_video::mesh::{AnimatedMesh, Point};
use mcgv_video::motion::PredictorKind;
use mcgv_video::PaddingMethod;
use std::sync::atomic::Ordering;

/// A tube bent at its middle by linear-blend skinning over two bones, the blend spread over half
/// its length: what the skinning predictor models exactly and piecewise affine maps do not.
fn skinned_bend() -> AnimatedMesh {
    skinned_bend_of(30)
}

/// [`skinned_bend`] over `frames` frames.
fn skinned_bend_of(frames: usize) -> AnimatedMesh {
    let (mut points, mut tris) = (Vec::new(), Vec::new());
    tube(&mut points, &mut tris, -2.0, 2.0, 24, 12);
    animate(&points, tris, frames, |t, _, p: Point| {
        let w = ((p[0] + 1.0) / 2.0).clamp(0.0, 1.0);
        let w = w * w * (3.0 - 2.0 * w);
        let a = 1.4 * t;
        let (s, c) = a.sin_cos();
        let bent = [c * p[0] - s * p[1], s * p[0] + c * p[1], p[2]];
        std::array::from_fn(|k| (1.0 - w) * p[k] + w * bent[k])
    })
}

/// Two separate tubes, each turning rigidly: one affine map per tube is exact, so skinning
/// weights can only add bytes.
fn rigid_pair() -> AnimatedMesh {
    rigid_pair_of(30)
}

/// [`rigid_pair`] over `frames` frames.
fn rigid_pair_of(frames: usize) -> AnimatedMesh {
    let (mut points, mut tris) = (Vec::new(), Vec::new());
    tube(&mut points, &mut tris, -2.0, -0.2, 12, 12);
    tube(&mut points, &mut tris, 0.2, 2.0, 12, 12);
    animate(&points, tris, frames, |t, _, p: Point| {
        let a = if p[0] < 0.0 { 0.8 * t } else { -1.1 * t };
        let (s, c) = a.sin_cos();
        [c * p[0] - s * p[1], s * p[0] + c * p[1] + t, p[2]]
    })
}

/// Options with K = 2 and the first frame at the default 12 bits (tdct would otherwise try other
/// precisions too, see `first_frame_bits.rs`).
fn opts(
    codec: Codec,
    predictor: PredictorChoice,
    segmentation: SegmentationChoice,
) -> EncodeOptions {
    EncodeOptions {
        codec: config(codec, None, Some(PaddingMethod::Cg), None),
        clusters: 2,
        first_frame_bits: Some(12),
        predictor,
        segmentation,
        ..EncodeOptions::default()
    }
}

/// Bytes of the stream coded with this predictor and segmentation, fixed.
fn fixed_bytes(
    mesh: &AnimatedMesh,
    base: &EncodeOptions,
    model: (PredictorKind, Segmentation),
) -> Vec<u8> {
    let options = EncodeOptions {
        predictor: model.0.into(),
        segmentation: model.1.into(),
        ..base.clone()
    };
    let encoded = encode(mesh, &options).expect("encodes");
    assert!(
        encoded.report.choice.is_none(),
        "fixed options choose nothing"
    );
    encoded.to_bytes()
}

#[test]
fn auto_keeps_skinning_on_a_skinned_bend_and_its_stream_is_the_fixed_ones() {
    // Measured at quality 95 with K = 2: skinning 5 247 bytes, affine 6 196.
    let mesh = skinned_bend();
    let base = EncodeOptions {
        quality: 95,
        ..opts(
            Codec::Tdct,
            PredictorChoice::Auto,
            Segmentation::KMeans.into(),
        )
    };
    let encoded = encode(&mesh, &base).expect("encodes");
    let choice = encoded.report.choice.clone().expect("a choice");
    assert_eq!(choice.chosen, "skinning+kmeans", "{choice:?}");
    assert_eq!(choice.trial_frames, mesh.frame_count());
    let sizes: Vec<u64> = [PredictorKind::Affine, PredictorKind::Skinning]
        .into_iter()
        .map(|p| fixed_bytes(&mesh, &base, (p, Segmentation::KMeans)).len() as u64)
        .collect();
    // tdct ranks its candidates by estimates, codes only the one kept, and reports its bytes.
    let estimates: Vec<u64> = choice
        .candidates
        .iter()
        .filter_map(|c| c.estimate)
        .collect();
    assert_eq!(estimates.len(), 2, "{choice:?}");
    assert!(
        sizes[1] < sizes[0] && estimates[1] < estimates[0],
        "{choice:?}"
    );
    for (estimate, size) in estimates.iter().zip(&sizes) {
        let ratio = *estimate as f64 / *size as f64;
        assert!(
            (0.8..1.25).contains(&ratio),
            "estimate {estimate}, stream {size}"
        );
    }
    assert!(choice.candidates[0].estimated && !choice.candidates[1].estimated);
    assert_eq!(choice.candidates[1].bytes, sizes[1]);
    let skinning = fixed_bytes(
        &mesh,
        &base,
        (PredictorKind::Skinning, Segmentation::KMeans),
    );
    assert_eq!(
        encoded.to_bytes(),
        skinning,
        "the kept stream is the fixed encoding's"
    );
    let stream = decoder(encoded.to_bytes()).expect("decodes");
    assert_eq!(stream.header().predictor, PredictorKind::Skinning);
    assert!(choice.reason.contains("affine+kmeans"), "{}", choice.reason);
}

#[test]
fn auto_keeps_affine_on_rigid_parts_and_the_default_on_a_tie() {
    // Both segmentations find the two tubes, so they tie; skinning adds its weights (31 bytes).
    // tdct also tries k-means at 1.5 K (3): more clusters than parts only add side information,
    // so the ladder stops there and 2 K (4) is not tried.
    let mesh = rigid_pair();
    let options = opts(
        Codec::Tdct,
        PredictorChoice::Auto,
        SegmentationChoice::auto(),
    );
    let encoded = encode(&mesh, &options).expect("encodes");
    // The same rungs, hence the same stream, on one thread.
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build();
    let alone = pool.expect("a pool").install(|| encode(&mesh, &options));
    assert_eq!(alone.expect("encodes").to_bytes(), encoded.to_bytes());
    let choice = encoded.report.choice.expect("a choice");
    assert!(
        choice
            .reason
            .contains("K = 4 not tried: K = 3 did not beat K = 2"),
        "{}",
        choice.reason
    );
    let names: Vec<String> = choice
        .candidates
        .iter()
        .map(|c| format!("{}+{}", c.predictor.name(), c.segmentation))
        .collect();
    let pair = ["affine+kmeans", "skinning+kmeans"];
    let expected: Vec<&str> = [pair, pair, ["affine+decimation", "skinning+decimation"]].concat();
    assert_eq!(names, expected);
    let bytes: Vec<u64> = (choice.candidates.iter())
        .map(|c| c.estimate.expect("tdct estimates"))
        .collect();
    assert_eq!(bytes[0], bytes[4], "{bytes:?}");
    assert!(bytes[1] > bytes[0], "{bytes:?}");
    assert!(bytes[2..4].iter().all(|&b| b >= bytes[0]), "{bytes:?}");
    assert_eq!(choice.chosen, "affine+kmeans");
    assert_eq!(choice.candidates[0].clusters, 2);
    assert_eq!(encoded.report.segmentation.method, "kmeans");
    assert_eq!(encoded.report.header.predictor, PredictorKind::Affine);
    assert_eq!(encoded.report.header.requested_clusters, 2);
}

#[test]
fn tdct_tries_a_ladder_of_cluster_counts_and_keeps_the_smallest() {
    let mesh = skinned_bend();
    let options = opts(
        Codec::Tdct,
        PredictorKind::Affine.into(),
        SegmentationChoice::auto(),
    );
    let encoded = encode(&mesh, &options).expect("encodes");
    let choice = encoded.report.choice.expect("a choice");
    let kmeans: Vec<&Candidate> = (choice.candidates.iter())
        .filter(|c| c.segmentation == "kmeans")
        .collect();
    assert_eq!(kmeans.len(), 3, "{choice:?}");
    let smallest = choice.candidates.iter().filter_map(|c| c.estimate).min();
    let kept = choice
        .candidates
        .iter()
        .find(|c| !c.estimated)
        .expect("kept");
    assert_eq!(kept.estimate, smallest, "{choice:?}");
    assert_eq!(encoded.report.bytes, kept.bytes, "{choice:?}");
    // Each rung's estimate is near the fixed encoding at that K, the kept one is that encoding,
    // and the header records the K asked for.
    for (c, k) in kmeans.iter().zip([2, 3, 4]) {
        let fixed = EncodeOptions {
            clusters: k,
            ..opts(
                Codec::Tdct,
                PredictorKind::Affine.into(),
                Segmentation::KMeans.into(),
            )
        };
        let bytes = encode(&mesh, &fixed).expect("encodes").to_bytes();
        if c.stopped {
            // Its estimate stopped past the smallest one so far, so past the kept one's.
            assert!(c.estimate > kept.estimate, "K = {k}: {choice:?}");
            continue;
        }
        let ratio = c.estimate.expect("estimated") as f64 / bytes.len() as f64;
        assert!(
            (0.8..1.25).contains(&ratio),
            "K = {k}: {c:?}, {}",
            bytes.len()
        );
        if !c.estimated {
            assert_eq!(bytes.len() as u64, c.bytes, "K = {k}");
        }
    }
    // The picture codecs' options name the same ladder (since 2026-12-04; K alone before, too
    // few clusters for a dancer): three k-means rungs and decimation, of which they try the rung
    // tdct's estimates rank first.
    let jpeg = opts(
        Codec::Jpeg,
        PredictorKind::Affine.into(),
        SegmentationChoice::auto(),
    );
    assert_eq!(jpeg.motion_models().len(), 4);
}

#[test]
fn a_segmented_choice_reports_sizes_of_the_whole_analysis_clip() {
    // The analysis clip of a segmented encoding is kept as its shared parts (tdct at fixed
    // first-frame bits codes it on one frame): its winner's size stays the estimate, not that
    // one-frame stream's.
    let mesh = skinned_bend_of(40);
    let options = EncodeOptions {
        segment_frames: Some(16),
        ..opts(
            Codec::Tdct,
            PredictorChoice::Auto,
            SegmentationChoice::auto(),
        )
    };
    let encoded = encode(&mesh, &options).expect("encodes");
    assert_eq!(encoded.report.segments, 3);
    let choice = encoded.report.choice.clone().expect("a choice");
    for c in &choice.candidates {
        assert!(c.estimated && c.estimate == Some(c.bytes), "{c:?}");
    }
    // With the first-frame precisions open, the finest one's trial is the kept candidate's size:
    // its estimate, or its whole stream's when a coarser one's estimate called for comparing
    // whole streams.
    let open = EncodeOptions {
        first_frame_bits: None,
        ..options
    };
    let encoded = encode(&mesh, &open).expect("encodes");
    let choice = encoded.report.choice.clone().expect("a choice");
    let finest = encoded.report.first_frame_trials[0];
    let measured = choice.candidates.iter().filter(|c| !c.estimated).count();
    let least = choice.candidates.iter().map(|c| c.bytes).min();
    assert_eq!(Some(finest.bytes), least, "{choice:?}");
    assert_eq!(measured, usize::from(!finest.estimated), "{choice:?}");
}

#[test]
fn picture_codecs_try_a_sample_of_frames_then_code_the_winner_whole() {
    // JPEG: a spread dozen of 30 frames; MPEG-4 (P-frames): two runs of 16 of 64.
    for (codec, frames, sample) in [(Codec::Jpeg, 30, 12), (Codec::Mpeg4, 64, 32)] {
        sample_then_whole(codec, skinned_bend_of(frames), sample);
    }
}

fn sample_then_whole(codec: Codec, mesh: AnimatedMesh, sample: usize) {
    let options = opts(codec, PredictorChoice::Auto, SegmentationChoice::auto());
    let encoded = encode(&mesh, &options).expect("encodes");
    let choice = encoded.report.choice.clone().expect("a choice");
    assert_eq!(choice.trial_frames, sample, "{codec:?}: {choice:?}");
    assert!(choice.reason.contains("estimated"), "{}", choice.reason);
    // The k-means rung tdct's estimates rank first, beside decimation, and the rung above it
    // only when the estimates put it within 5 % (on this bend: K = 3 at 1.4 % above K = 2).
    assert!(
        choice.reason.contains("tdct's estimates rank first"),
        "{}",
        choice.reason
    );
    let mut ks: Vec<usize> = (choice.candidates.iter())
        .filter(|c| c.segmentation == "kmeans")
        .map(|c| c.clusters)
        .collect();
    ks.dedup();
    let above = choice.reason.contains("tried too");
    assert_eq!(ks.len(), 1 + usize::from(above), "{choice:?}");
    // Each candidate's sample stream, with those frames' affine maps, is decoded and its error
    // weighed as the whole stream's.
    let best = kept_at_least_cost(&choice, mesh.bbox_diagonal());
    let segmentation = match best.segmentation {
        "kmeans" => Segmentation::KMeans,
        _ => Segmentation::Decimation {
            e0: mcgv_video::motion::DEFAULT_E0,
        },
    };
    // The kept rung's K, for k-means (decimation finds its own count).
    let clusters = match segmentation {
        Segmentation::KMeans => best.clusters,
        _ => options.clusters,
    };
    let base = EncodeOptions {
        clusters,
        ..options.clone()
    };
    let fixed = fixed_bytes(&mesh, &base, (best.predictor, segmentation));
    assert_eq!(
        encoded.to_bytes(),
        fixed,
        "the winner is coded whole, as if fixed"
    );
    // The sample's error stands for the whole stream's.
    let measured = vertex_rmse(&mesh, &decode_all(fixed.clone()).expect("decodes"));
    let sampled = best.vertex_rmse.expect("an error");
    assert!(
        (0.5..2.0).contains(&(measured / sampled)),
        "whole {measured} vs sample {sampled}"
    );
    // The estimate from the sample is close to the whole (measured: JPEG 0.2 %, MPEG-4 4.3 %).
    let error = (best.bytes as f64 / fixed.len() as f64 - 1.0).abs();
    assert!(
        error < 0.1,
        "{codec:?}: estimate {} vs {} bytes",
        best.bytes,
        fixed.len()
    );
}

/// The candidate of least bits at equal error, after checking that the choice kept it; every
/// candidate must report its error.
fn kept_at_least_cost(choice: &ChoiceReport, diagonal: f64) -> Candidate {
    let cost = |c: &Candidate| {
        let rmse = c.vertex_rmse.expect("each candidate's error was weighed");
        distortion::cost(8.0 * c.bytes as f64, Some(rmse * diagonal))
    };
    let best = choice
        .candidates
        .iter()
        .min_by(|a, b| cost(a).total_cmp(&cost(b)))
        .expect("candidates");
    assert_eq!(
        choice.chosen,
        format!("{}+{}", best.predictor.name(), best.segmentation)
    );
    best.clone()
}

#[test]
fn a_sample_too_close_to_call_codes_its_two_best_whole_and_keeps_the_better() {
    // Both segmentations find the two tubes, so the sample cannot tell them apart.
    let mesh = rigid_pair_of(64);
    let options = opts(
        Codec::Mpeg4,
        PredictorChoice::Auto,
        SegmentationChoice::auto(),
    );
    let encoded = encode(&mesh, &options).expect("encodes");
    let choice = encoded.report.choice.clone().expect("a choice");
    assert_eq!(choice.trial_frames, 32, "{choice:?}");
    assert!(
        choice.reason.contains("too close to tell"),
        "{}",
        choice.reason
    );
    let diagonal = mesh.bbox_diagonal();
    let whole: Vec<&Candidate> = choice.candidates.iter().filter(|c| !c.estimated).collect();
    assert_eq!(whole.len(), 2, "{choice:?}");
    let mut costs = Vec::new();
    for c in &whole {
        let segmentation = match c.segmentation {
            "kmeans" => Segmentation::KMeans,
            _ => Segmentation::Decimation {
                e0: mcgv_video::motion::DEFAULT_E0,
            },
        };
        // Each was coded whole, as if fixed, and its error measured on every frame.
        let fixed = fixed_bytes(&mesh, &options, (c.predictor, segmentation));
        assert_eq!(c.bytes, fixed.len() as u64, "{c:?}");
        let measured = vertex_rmse(&mesh, &decode_all(fixed.clone()).expect("decodes"));
        let reported = c.vertex_rmse.expect("an error");
        assert!(
            (reported / measured - 1.0).abs() < 1e-6,
            "{c:?}: {measured}"
        );
        let model = format!("{}+{}", c.predictor.name(), c.segmentation);
        let cost = distortion::cost(8.0 * c.bytes as f64, Some(reported * diagonal));
        costs.push((cost, model, fixed));
    }
    // The better of the two whole streams is the one kept, on any number of threads.
    let (_, model, fixed) = costs
        .into_iter()
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .expect("two");
    assert_eq!(choice.chosen, model);
    assert_eq!(encoded.to_bytes(), fixed);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build();
    let alone = pool.expect("a pool").install(|| encode(&mesh, &options));
    assert_eq!(alone.expect("encodes").to_bytes(), encoded.to_bytes());
}

#[test]
fn picture_codecs_weigh_each_candidates_measured_error_against_its_bits() {
    let mesh = skinned_bend();
    let options = EncodeOptions {
        quality: 70,
        ..opts(
            Codec::Mpeg4,
            PredictorChoice::Auto,
            SegmentationChoice::auto(),
        )
    };
    let encoded = encode(&mesh, &options).expect("encodes");
    let choice = encoded.report.choice.clone().expect("a choice");
    let best = kept_at_least_cost(&choice, mesh.bbox_diagonal());
    assert!(choice.reason.contains("equal error"), "{}", choice.reason);
    // The error the choice weighed is the decoded stream's.
    let measured = vertex_rmse(&mesh, &decode_all(encoded.to_bytes()).expect("decodes"));
    let reported = best.vertex_rmse.expect("an error");
    assert!(
        (measured / reported - 1.0).abs() < 1e-6,
        "{measured} vs {reported}"
    );
    // tdct's candidates share one step and are ranked by bytes alone.
    let tdct = EncodeOptions {
        codec: Codec::Tdct.into(),
        ..options
    };
    let choice = encode(&mesh, &tdct).expect("encodes").report.choice;
    let choice = choice.expect("a choice");
    assert!(choice.candidates.iter().all(|c| c.vertex_rmse.is_none()));
}

#[test]
fn progress_announces_the_trials_frames_and_reports_them_all() {
    let mesh = skinned_bend();
    let frames = mesh.frame_count() as u64;
    // tdct estimates every candidate (its k-means at three K and decimation, two predictors
    // each), then codes the winner; the picture codecs try the rung tdct's estimates rank first,
    // the one above it (within 5 % on this bend) and decimation (their ranking is not on the
    // bar): MPEG-4 codes every candidate whole, JPEG 12 frames each, then the winner whole.
    let codecs = [
        (Codec::Tdct, 8 * frames + frames),
        (Codec::Mpeg4, 6 * frames),
        (Codec::Jpeg, 6 * 12 + frames),
    ];
    for (codec, expected) in codecs {
        let counter = Counter::default();
        let options = opts(codec, PredictorChoice::Auto, SegmentationChoice::auto());
        encode_with_progress(&mesh, &options, &counter).expect("encodes");
        assert_eq!(counter.total.load(Ordering::Relaxed), expected, "{codec:?}");
        assert_eq!(counter.done.load(Ordering::Relaxed), expected, "{codec:?}");
    }
    let counter = Counter::default();
    encode_with_progress(
        &mesh,
        &opts(
            Codec::Tdct,
            PredictorKind::Affine.into(),
            Segmentation::KMeans.into(),
        ),
        &counter,
    )
    .expect("encodes");
    assert_eq!(counter.total.load(Ordering::Relaxed), frames);
    assert_eq!(counter.done.load(Ordering::Relaxed), frames);
}

#[test]
fn auto_segmentation_checks_its_threshold() {
    let mesh = rigid_pair();
    let options = opts(
        Codec::Tdct,
        PredictorChoice::Auto,
        SegmentationChoice::Auto { e0: -1.0 },
    );
    let err = encode(&mesh, &options).err().expect("refused").to_string();
    assert!(err.contains("e0"), "{err}");
}

#[test]
fn a_picture_codec_codes_the_one_candidate_tdct_leaves_without_a_trial() {
    // A smooth bend: skinning blends the clusters' maps, affine on 4 clusters is 24 % larger by
    // tdct's estimates; a coarse decimation (E0 = 0.1) leaves 2 clusters, twice k-means' bytes.
    let mesh = skinned_bend_of(30);
    let options = EncodeOptions {
        clusters: 4,
        ..opts(
            Codec::Jpeg,
            PredictorChoice::Auto,
            SegmentationChoice::Auto { e0: 0.1 },
        )
    };
    let encoded = encode(&mesh, &options).expect("encodes");
    let choice = encoded.report.choice.clone().expect("a choice");
    assert_eq!(choice.chosen, "skinning+kmeans", "{choice:?}");
    assert_eq!(choice.trial_frames, 0, "{choice:?}");
    assert_eq!(choice.candidates.len(), 1, "{choice:?}");
    for words in [
        "the one candidate tdct's estimates left",
        "affine+kmeans not tried with pictures",
        "decimation not tried with pictures",
    ] {
        assert!(choice.reason.contains(words), "{}", choice.reason);
    }
    // The stream is the one that candidate gives when fixed.
    let fixed = fixed_bytes(
        &mesh,
        &options,
        (PredictorKind::Skinning, Segmentation::KMeans),
    );
    assert_eq!(encoded.to_bytes(), fixed);
}
