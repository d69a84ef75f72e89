//! Budgets (issue 36): `encode_to_budget` lands within the tolerance under a size or an error
//! bound, never over it, and says the quality found and the encodes made; quality is monotone
//! in error for every codec, which the search relies on.
//!
//! pdance's figures (the issue's) need the shared media and take minutes on two cores: they are
//! `#[ignore]`d and run by `make test-budgets`.

use crate::common::{decode_all, read_media};
use mcgv_video::codec::{Codec, RatePlan};
use mcgv_video::encoder::{
    encode_to_budget, Budget, Budgeted, EncodeOptions, PredictorChoice, Segmentation,
    SegmentationChoice,
};
use mcgv_video::mesh::{read_animation, AnimatedMesh, ReadOptions};
use mcgv_video::metrics::vertex_errors;
use mcgv_video::motion::PredictorKind;
use std::path::PathBuf;

/// The vertex RMSE of a stream over the first frame's diagonal, measured apart from the search.
fn vertex_rmse(mesh: &AnimatedMesh, found: &Budgeted) -> f64 {
    let decoded = decode_all(found.encoded.to_bytes()).expect("decodes");
    vertex_errors(mesh, &decoded).expect("same sizes").rmse / mesh.bbox_diagonal()
}

/// Asserts that `found` is within `budget` and `tolerance` under it, by the stream itself.
fn assert_within(mesh: &AnimatedMesh, found: &Budgeted, budget: Budget, tolerance: f64) {
    let search = &found.search;
    let (measure, limit) = match budget {
        Budget::Bytes(bytes) => (found.encoded.to_bytes().len() as f64, bytes as f64),
        Budget::VertexRmse(e) => (vertex_rmse(mesh, found), e),
        other => panic!("not checked here: {other:?}"),
    };
    assert!(
        measure <= limit && measure >= limit * (1.0 - tolerance),
        "{budget:?}: {measure} not within {tolerance} under {limit}: {search:?}"
    );
    assert!(search.within_tolerance, "{search:?}");
    assert!(
        (search.achieved - measure).abs() <= 1e-9 * limit,
        "{search:?}"
    );
    assert_eq!(search.encodes, search.trials.len());
    let kept = search.trials.iter().find(|t| t.quality == search.quality);
    assert_eq!(kept.map(|t| t.bytes), Some(found.encoded.report.bytes));
    // The header records the quality found, rounded.
    let header = found.encoded.report.header.quality;
    assert_eq!(f64::from(header), search.quality.round(), "{search:?}");
}

/// A codec's options with one motion model (what the search keeps after its first encode), so
/// that the picture codecs' tests code no candidates.
fn fixed(codec: Codec) -> EncodeOptions {
    EncodeOptions {
        codec: codec.into(),
        predictor: PredictorKind::Affine.into(),
        segmentation: Segmentation::KMeans.into(),
        ..EncodeOptions::default()
    }
}

#[test]
fn tdct_lands_under_a_size_and_an_error_in_three_encodes() {
    let mesh = read_media("CesiumMan.glb");
    // The defaults: the automatic choice on the first encode, kept by the others.
    let opts = EncodeOptions::default();
    // 24 000 bytes: below the default stream (25 619 bytes in container version 11), so the
    // search moves.
    for budget in [Budget::Bytes(24_000), Budget::VertexRmse(2e-4)] {
        let found = encode_to_budget(&mesh, &opts, budget).expect("a stream within the budget");
        assert_within(&mesh, &found, budget, budget.tolerance());
        assert!(found.search.encodes <= 3, "{:?}", found.search);
        assert_ne!(found.search.quality, 50.0);
    }
}

#[test]
fn jpeg_lands_under_a_small_size_in_three_encodes() {
    let mesh = read_media("CesiumMan.glb");
    let opts = EncodeOptions {
        codec: Codec::Jpeg.into(),
        ..EncodeOptions::default()
    };
    // Under the default stream (70 818 bytes at quality 50 since the picture codecs climb the
    // k-means ladder: 30 clusters kept), where JPEG's bytes flatten: 50 000 bytes in 3 encodes.
    // 40 000 lands too, but in 4 (the prior curvature was fitted when 20 clusters were kept, whose
    // side information left more room: 3 encodes then), a limit the docs state.
    for (bytes, in_three) in [(50_000, true), (40_000, false)] {
        let budget = Budget::Bytes(bytes);
        let found = encode_to_budget(&mesh, &opts, budget).expect("a stream within the budget");
        assert_within(&mesh, &found, budget, budget.tolerance());
        assert!(!in_three || found.search.encodes <= 3, "{:?}", found.search);
    }
}

#[test]
fn av1_lands_under_a_size_and_an_error() {
    if !Codec::Av1.available() {
        return;
    }
    let mesh = cesium_man_at(12.0);
    // AV1's bytes jump between neighbouring qualities, as its quantiser index is an integer
    // (CesiumMan at 12 frames/s, container version 6: 37 492 bytes at quality 54.49, 39 608 at
    // 54.50), so a byte budget that falls in a jump cannot land within 2 % (39 000 there; 40 000
    // and 41 000 before): the search then keeps the largest stream under the budget it met and says
    // it missed. The error budget lands.
    let budget = Budget::Bytes(39_000);
    let found = encode_to_budget(&mesh, &fixed(Codec::Av1), budget).expect("within budget");
    let search = &found.search;
    let bytes = found.encoded.to_bytes().len() as u64;
    assert!(bytes <= 39_000, "{search:?}");
    assert_eq!(search.achieved, bytes as f64, "{search:?}");
    let best_under = (search.trials.iter().map(|t| t.bytes))
        .filter(|&b| b <= 39_000)
        .max();
    assert_eq!(best_under, Some(bytes), "{search:?}");
    let landed = bytes as f64 >= 39_000.0 * (1.0 - budget.tolerance());
    assert_eq!(search.within_tolerance, landed, "{search:?}");
    assert!(search.encodes <= mcgv_video::encoder::MAX_BUDGET_ENCODES);
    let budget = Budget::VertexRmse(2.5e-4);
    let found = encode_to_budget(&mesh, &fixed(Codec::Av1), budget).expect("within budget");
    assert_within(&mesh, &found, budget, budget.tolerance());
    assert!(found.search.encodes <= mcgv_video::encoder::MAX_BUDGET_ENCODES);
}

#[test]
fn picture_codecs_report_the_spread_their_samples_must_hold() {
    // What a search reads the depth of HEVC's and AV1's pictures off (`deeper_from`).
    let mesh = read_media("CesiumMan.glb");
    let encode = |opts: &EncodeOptions| mcgv_video::encode(&mesh, opts).expect("encodes");
    assert_eq!(encode(&fixed(Codec::Tdct)).report.residual_spread, None);
    let whole = encode(&fixed(Codec::Jpeg)).report.residual_spread;
    let whole = whole.expect("a picture codec's spread");
    // Residuals spread over a small share of the first frame's diagonal.
    assert!(whole > 1e-4 * mesh.bbox_diagonal() && whole < 0.1 * mesh.bbox_diagonal());
    // A segmented encoding's is the widest of its segments'; the first frames' pictures alone
    // spread less.
    let segmented = EncodeOptions {
        segment_frames: Some(16),
        ..fixed(Codec::Jpeg)
    };
    let segmented = encode(&segmented).report.residual_spread;
    assert!(segmented.is_some_and(|s| s > 0.5 * whole && s < 2.0 * whole));
    let first_frames = mesh.clip(0..4).expect("four frames");
    let short = mcgv_video::encode(&first_frames, &fixed(Codec::Jpeg)).expect("encodes");
    assert!(short.report.residual_spread.is_some_and(|s| s <= whole));
}

#[test]
fn the_later_encodes_keep_the_first_ones_partition_and_atlas_and_make_its_streams() {
    // The first encode chooses the model; the later ones reuse its partition and atlas (of the
    // analysis clip when segmented) instead of finding them again. The stream kept is the one a
    // plain encode of the model found, at the quality found, makes.
    let mesh = cesium_man_at(12.0);
    for segment_frames in [None, Some(8)] {
        let opts = EncodeOptions {
            codec: Codec::Mpeg4.into(),
            segment_frames,
            ..EncodeOptions::default()
        };
        let plain = mcgv_video::encode(&mesh, &opts).expect("encodes");
        let budget = Budget::Bytes(plain.report.bytes * 4 / 5);
        let found = encode_to_budget(&mesh, &opts, budget).expect("within budget");
        assert!(found.search.encodes >= 2, "{:?}", found.search);
        let report = &found.encoded.report;
        let segmentation = match report.segmentation.method {
            "kmeans" => Segmentation::KMeans,
            _ => Segmentation::Decimation {
                e0: mcgv_video::motion::DEFAULT_E0,
            },
        };
        let quality = found.search.quality;
        let pinned = EncodeOptions {
            predictor: PredictorChoice::Fixed(report.header.predictor),
            segmentation: SegmentationChoice::Fixed(segmentation),
            clusters: report.header.requested_clusters as usize,
            first_frame_bits: Some(report.header.first_frame_bits),
            quality: quality.round() as u8,
            fine_quality: (quality.fract() != 0.0).then_some(quality),
            ..opts.clone()
        };
        let again = mcgv_video::encode(&mesh, &pinned).expect("encodes");
        assert_eq!(
            again.to_bytes(),
            found.encoded.to_bytes(),
            "{segment_frames:?}: {:?}",
            found.search
        );
    }
}

#[test]
fn a_largest_error_budget_lands_though_that_error_jumps_between_qualities() {
    // On RiggedFigure the largest vertex error jumps between neighbouring qualities (container
    // version 6, with the temporal DCT's copies alone: 8.89e-4 at quality 30.53, 9.51e-4 at 30.48,
    // 1.05e-3 at 30.41): the search brackets by neighbouring steps, not by the measure, never exceeds the
    // bound, and keeps the largest error under it that it met; within 3 % of it when one exists
    // among its encodes, which a measure set by one vertex of 370 does not promise.
    let mesh = read_media("RiggedFigure.glb");
    let budget = Budget::MaxVertexError(1e-3);
    let found = encode_to_budget(&mesh, &EncodeOptions::default(), budget).expect("within");
    let decoded = decode_all(found.encoded.to_bytes()).expect("decodes");
    let largest = mesh
        .frames()
        .iter()
        .zip(decoded.frames())
        .flat_map(|(a, b)| a.iter().zip(b))
        .map(|(p, q)| (0..3).map(|i| f64::from(p[i] - q[i]).powi(2)).sum::<f64>())
        .fold(0.0f64, f64::max)
        .sqrt()
        / mesh.bbox_diagonal();
    let search = &found.search;
    assert!(largest <= 1e-3, "{largest}: {search:?}");
    assert!((search.achieved - largest).abs() < 1e-12, "{search:?}");
    let best_under = (search.trials.iter())
        .filter_map(|t| t.max_vertex_error.filter(|&e| e <= 1e-3))
        .fold(0.0f64, f64::max);
    assert_eq!(search.achieved, best_under, "{search:?}");
    assert_eq!(search.within_tolerance, largest >= 0.97e-3, "{search:?}");
    assert!(search.encodes <= 10, "{search:?}");
}

#[test]
fn an_unreachable_budget_is_an_error_naming_its_option() {
    let mesh = read_media("RiggedSimple.glb");
    let err = encode_to_budget(&mesh, &EncodeOptions::default(), Budget::Bytes(10))
        .err()
        .expect("10 bytes hold no stream");
    assert!(err.to_string().contains("target_size"), "{err}");
    // Said after the first encode: the parts no quality changes fill the budget alone.
    assert!(err.to_string().contains("no quality changes"), "{err}");
    let opts = EncodeOptions {
        step: Some(1e-3),
        ..EncodeOptions::default()
    };
    let err = encode_to_budget(&mesh, &opts, Budget::VertexRmse(1e-3)).err();
    assert!(err.is_some_and(|e| e.to_string().contains("step")));
    let err = encode_to_budget(&mesh, &EncodeOptions::default(), Budget::Bpvf(-1.0)).err();
    assert!(err.is_some_and(|e| e.to_string().contains("target_bpvf")));
}

#[test]
fn a_fine_quality_codes_between_its_integers() {
    let mesh = read_media("RiggedSimple.glb");
    let diagonal = mesh.bbox_diagonal();
    for codec in Codec::ALL.into_iter().filter(|c| c.available()) {
        let at = |quality: u8, fine_quality: Option<f64>| {
            let opts = EncodeOptions {
                quality,
                fine_quality,
                ..fixed(codec)
            };
            opts.plan(diagonal).expect("a plan")
        };
        let (lower, between, upper) = (at(60, None), at(61, Some(60.5)), at(61, None));
        // Finer: a smaller pixel step, or (HEVC, AV1, whose pixel step takes their integer
        // quantiser's rounding) a lower quantiser; the target step, hence the affine step, falls.
        let finer = |a: &RatePlan, b: &RatePlan| {
            let q = |p: &RatePlan| p.quantiser().unwrap_or(0);
            let by_quantiser = matches!(codec, Codec::Hevc | Codec::Av1) && q(a) < q(b);
            a.affine_step < b.affine_step && (by_quantiser || (q(a) == q(b) && a.step < b.step))
        };
        assert!(
            finer(&between, &lower) && finer(&upper, &between),
            "{codec:?}: {lower:?} {between:?} {upper:?}"
        );
        assert_eq!(between.quality, 61);
        // A fine quality at an integer is that integer.
        assert_eq!(at(60, Some(60.0)), lower);
    }
    let opts = EncodeOptions {
        fine_quality: Some(60.5),
        ..fixed(Codec::Tdct)
    };
    let encoded = mcgv_video::encode(&mesh, &opts).expect("encodes");
    assert_eq!(encoded.report.header.quality, 61);
}

/// CesiumMan at `fps` frames a second (12: 24 frames), to keep the sweeps short.
fn cesium_man_at(fps: f64) -> AnimatedMesh {
    let read = ReadOptions {
        fps: Some(fps),
        ..ReadOptions::default()
    };
    let path = crate::common::media_path("CesiumMan.glb");
    read_animation(&path, &read).expect("reads")
}

/// Vertex RMSE over the diagonal of `codec` with one motion model at each of `qualities`.
fn errors_over_qualities(mesh: &AnimatedMesh, codec: Codec, qualities: &[u8]) -> Vec<f64> {
    qualities
        .iter()
        .map(|&quality| {
            let opts = EncodeOptions {
                quality,
                ..fixed(codec)
            };
            let bytes = mcgv_video::encode(mesh, &opts).expect("encodes").to_bytes();
            let decoded = decode_all(bytes).expect("decodes");
            vertex_errors(mesh, &decoded).expect("same sizes").rmse / mesh.bbox_diagonal()
        })
        .collect()
}

/// What a search needs of every codec's law: with the motion model fixed (as the search keeps
/// it), a higher quality gives no larger error, beyond 1 % — the noise where the 8-bit range, not
/// the quality, sets MPEG-4's step (qualities 90–100 within 0.1–0.3 % on CesiumMan, pcow and the
/// horses). The qualities straddle the laws' seams: anchors at 75 and 90, the 12-bit samples of
/// HEVC from 65 and of AV1 from 90, the quantisers' floors.
#[test]
fn a_higher_quality_never_gives_a_larger_error_for_any_codec() {
    let mesh = cesium_man_at(6.0);
    let qualities = [10u8, 50, 64, 65, 75, 89, 90, 97, 100];
    for codec in Codec::ALL.into_iter().filter(|c| c.available()) {
        let errors = errors_over_qualities(&mesh, codec, &qualities);
        for (i, pair) in errors.windows(2).enumerate() {
            assert!(
                pair[1] <= pair[0] * 1.01,
                "{codec:?}: quality {} gives {:.4e}, quality {} {:.4e}: {errors:?}",
                qualities[i + 1],
                pair[1],
                qualities[i],
                pair[0]
            );
        }
        eprintln!("{codec:?} {errors:?}");
    }
}

/// pdance unpacked from the shared media (`MCGV_PDANCE`, else `bench-out/media/pdance`, where
/// `make test-budgets` and `make bench` unpack it from `${MCGV_SHARED_MEDIA:-../shared/media}`).
fn pdance() -> Option<AnimatedMesh> {
    let folder = std::env::var_os("MCGV_PDANCE")
        .map(PathBuf::from)
        .unwrap_or_else(|| crate::common::repo_root().join("bench-out/media/pdance"));
    read_animation(&folder.display().to_string(), &ReadOptions::default()).ok()
}

/// The figures on pdance: `--target-size 100000` lands in 98 000–100 000 bytes and
/// `--target-error 2e-4` in a vertex RMSE of 1.94e-4–2e-4, for tdct and AV1, in at most 3 encodes.
#[test]
#[ignore = "pdance, minutes on two cores: make test-budgets"]
fn pdance_lands_under_100_kb_and_under_2e_4() {
    let Some(mesh) = pdance() else {
        eprintln!("no pdance unpacked (make test-budgets unpacks the shared media's): skipped");
        return;
    };
    for codec in [Codec::Tdct, Codec::Av1]
        .into_iter()
        .filter(|c| c.available())
    {
        let opts = EncodeOptions {
            codec: codec.into(),
            ..EncodeOptions::default()
        };
        for budget in [Budget::Bytes(100_000), Budget::VertexRmse(2e-4)] {
            let found = encode_to_budget(&mesh, &opts, budget).expect("within budget");
            let search = &found.search;
            eprintln!(
                "pdance {codec:?} {budget:?}: quality {} in {} encodes, {} bytes, {:?}",
                search.quality, search.encodes, found.encoded.report.bytes, search.achieved
            );
            // The size window is 98 000–100 000 bytes: 2 %, narrower than the 3 % a
            // search accepts from its third encode on.
            let tolerance = match budget {
                Budget::Bytes(_) => 0.02,
                _ => budget.tolerance(),
            };
            assert_within(&mesh, &found, budget, tolerance);
            assert!(search.encodes <= 3, "{search:?}");
        }
    }
}
