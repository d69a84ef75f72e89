//! AV1 at 10 or 12 bits a sample: FFmpeg's `libaom-av1` encoder and its preferred AV1 decoder
//! (`libdav1d` in Debian's libavcodec 59), through `ffmpeg-next` (cargo feature `ffmpeg`); the encoder, decoder and set-up part are [`super::deep`]'s, shared with HEVC.
//!
//! The x | y | z picture is the three planes of a 4:4:4 picture, as for HEVC: profile 1 at 10 bits,
//! profile 2 at 12 (libaom picks the profile from the pixel format). The quantiser is libaom's
//! constant-quality level (`crf` 0..63, end usage `q`: no rate control), `tune=psnr`. A key frame
//! every `gop` frames (every frame with `gop` 1: all-intra), P-frames between, which look ahead
//! `LAG_IN_FRAMES` frames for hidden alternate-reference frames; one packet per frame (a hidden
//! frame rides in the packet of a shown one), in order, the sequence header in-band on every key
//! frame. One thread and no row multi-threading, so the output does not depend on scheduling.
//!
//! `cpu-used` `CPU_USED` trades compression for speed (docs/design.md, "AV1 settings").

use super::deep::DeepConfig;
use super::depth::DeepLaws;
use crate::codec::rate::{ijg_scale_percent, PictureLaw, Rate, RatePlan};
use crate::codec::Codec;
use crate::error::Result;
use crate::motion::DEFAULT_AFFINE_PRECISION;

#[cfg(feature = "ffmpeg")]
pub(crate) use coder::PICTURES;

/// The largest quantiser (`crf`) libaom takes.
pub const MAX_QP: u8 = 63;
/// Fails, naming the option, when one of `config` is out of range for AV1.
pub(crate) fn check(config: &DeepConfig) -> Result<()> {
    config.check(Codec::Av1, MAX_QP)
}

/// The plan of `rate` on a first frame of bounding-box diagonal `diagonal`: [`av1_law`]; affine
/// maps at a quarter of the residual step all-intra, finer in P-frame groups, whose prediction
/// coarser maps spoil ([`super::p_frame_affine_precision`], as MPEG-4's).
pub(crate) fn plan(config: &DeepConfig, rate: &Rate, diagonal: f64) -> Result<RatePlan> {
    let affine_precision = match config.gop {
        1 => DEFAULT_AFFINE_PRECISION,
        _ => super::p_frame_affine_precision(rate),
    };
    // The two splits were measured with P-frames only (all-intra streams: `qmin` changed none).
    let laws = DeepLaws {
        law: av1_law_at,
        coarser_12: (config.gop > 1).then_some(av1_coarser_laws_12),
        affine_precision,
    };
    config.plan(Codec::Av1, laws, rate, diagonal)
}

/// AV1's law at 10 bits a sample, made as HEVC's: a pixel step of [`AV1_STEP_FACTOR`] × the target
/// step and the quantiser (libaom's `crf` 0..63, AV1's quantiser index over 4) whose quantiser step
/// follows the target step ([`AV1_QP_AT_50`] at quality 50), between [`AV1_MIN_QP`] and
/// [`AV1_MAX_QP`]; beyond them the pixel step takes the rest. Unlike HEVC's QP, AV1's quantiser
/// index does not double its step at a fixed pace (about linear up to index 96, then about 9.5
/// `crf` per doubling), so the law reads the step off [`AV1_AC_STEPS`]. At equal error the rate
/// hardly depends on how pixel step and `crf` share it up to `crf` 32, above which libaom's
/// constant-quality mode keeps its key frames' quantiser and the error stops growing. The factor
/// puts quality 50 near MPEG-4's error at quality 50, with the alternate references of P-frame
/// groups (docs/design.md, "Quality laws (JPEG, MPEG-4, HEVC, AV1)").
pub const AV1_STEP_FACTOR: f64 = 0.028;
/// libaom's `crf` at quality 50 at 10 bits a sample.
pub const AV1_QP_AT_50: u8 = 32;
/// The highest `crf` the law uses (the error stops following `crf` above it).
pub const AV1_MAX_QP: u8 = 32;
/// The lowest `crf` the law uses. Not 0: with no quantiser deltas `crf` 0 is lossless coding. Not
/// higher either: where the pixel step cannot go finer than a group's residual range allows, a
/// higher floor would stop the error falling from quality 90 up (docs/design.md, "AV1 settings").
pub const AV1_MIN_QP: u8 = 1;
/// AV1's AC quantiser step at 10 and 12 bits a sample (the specification's `ac_qlookup_10` and
/// `ac_qlookup_12` tables, libaom's `ac_qlookup_10_QTX` and `ac_qlookup_12_QTX`) at quantiser
/// index 4 × `crf` for `crf` 0, 1, 2, 3, 4, 8, …, 60, and at index 255 (`crf` 63): the law
/// interpolates log-linearly between these. From `crf` 8 up the 12-bit step is about 4 × the
/// 10-bit one (the step is relative to the sample range, as HEVC's QP); below it the 12-bit step
/// is finer (0.55 × at `crf` 1), hence both columns.
pub const AV1_AC_STEPS: [(u8, u16, u16); 20] = [
    (0, 4, 4),
    (1, 16, 35),
    (2, 27, 75),
    (3, 40, 126),
    (4, 55, 183),
    (8, 122, 456),
    (12, 195, 753),
    (16, 267, 1049),
    (20, 337, 1335),
    (24, 409, 1627),
    (28, 539, 2150),
    (32, 700, 2798),
    (36, 922, 3684),
    (40, 1218, 4871),
    (44, 1631, 6522),
    (48, 2199, 8795),
    (52, 2971, 11885),
    (56, 4028, 16110),
    (60, 5476, 21902),
    (63, 7312, 29247),
];

/// log2 of AV1's AC step at a (fractional) `crf` 0..=63 at `depth` bits, from [`AV1_AC_STEPS`], in
/// 10-bit units (the 12-bit step over 4).
pub(crate) fn av1_log2_step(crf: f64, depth: u8) -> f64 {
    let log2_at = |&(_, s10, s12): &(u8, u16, u16)| {
        if depth >= 12 {
            f64::from(s12).log2() - 2.0
        } else {
            f64::from(s10).log2()
        }
    };
    let i = AV1_AC_STEPS
        .iter()
        .rposition(|&(c, _, _)| f64::from(c) <= crf)
        .unwrap_or(0)
        .min(AV1_AC_STEPS.len() - 2);
    let (a, b) = (&AV1_AC_STEPS[i], &AV1_AC_STEPS[i + 1]);
    let t = (crf - f64::from(a.0)) / f64::from(b.0 - a.0);
    let (l0, l1) = (log2_at(a), log2_at(b));
    l0 + t * (l1 - l0)
}

/// The (fractional) `crf` whose AC step at `depth` bits has log2 `log2_step` (in 10-bit units, as
/// [`av1_log2_step`]), clamped to 0..=63.
fn av1_crf_of(log2_step: f64, depth: u8) -> f64 {
    let logs = AV1_AC_STEPS.map(|(c, _, _)| (f64::from(c), av1_log2_step(f64::from(c), depth)));
    if log2_step <= logs[0].1 {
        return 0.0;
    }
    match logs.windows(2).find(|w| log2_step <= w[1].1) {
        Some(w) => w[0].0 + (log2_step - w[0].1) / (w[1].1 - w[0].1) * (w[1].0 - w[0].0),
        None => 63.0,
    }
}

/// AV1's pixel step factor and `crf` for a user quality 1..100 at `depth` bits a sample: the `crf`
/// whose quantiser step is the one of [`AV1_QP_AT_50`] scaled as the target step; a deeper sample
/// wants a step a quarter as large per 2 bits (the same step in model units, finer rounding), down
/// to [`AV1_MIN_QP`], below which the pixel step takes the rest.
#[cfg_attr(not(any(test, feature = "internals")), allow(dead_code))]
pub fn av1_law(quality: u8, depth: u8) -> PictureLaw {
    av1_law_at(f64::from(ijg_scale_percent(quality).max(1)), depth)
}

/// [`av1_law`] at the IJG scale `scale_percent` of a quality (between the integers too).
pub(crate) fn av1_law_at(scale_percent: f64, depth: u8) -> PictureLaw {
    let scale = scale_percent / 100.0;
    let deeper = f64::from(depth) - 10.0;
    let want = av1_log2_step(f64::from(AV1_QP_AT_50), 10) + scale.log2() - deeper;
    // The floor is a `crf`, not a step, at either depth: a floor following the depth sends the
    // top qualities at 12 bits to tiny `crf`s and huge rates (docs/design.md, "AV1 settings").
    let floor = av1_log2_step(f64::from(AV1_MIN_QP), depth);
    let ceiling = av1_log2_step(f64::from(AV1_MAX_QP), depth);
    let crf = av1_crf_of(want.clamp(floor, ceiling), depth).round();
    // The pixel step takes what the integer `crf` cannot: the rest beyond the floor or the
    // ceiling, and within them the rounding, so that the step (hence the error) follows a fine
    // quality between two `crf`s instead of jumping at each (docs/design.md, "Budgets").
    let rest = want - av1_log2_step(crf, depth);
    PictureLaw {
        step_factor: AV1_STEP_FACTOR * 2f64.powf(rest),
        quantiser: crf as u8,
    }
}

/// AV1's other 12-bit laws beside `own`, [`av1_law_at`]'s at 12 bits: each coarser `crf` up to
/// the one whose step is 4 × its step (two bits of headroom; at most [`AV1_MAX_QP`]) at a pixel
/// step as much finer, the same quantiser step in model units. Where
/// the residuals leave room in 12-bit samples, the encoder codes the coarsest beside the law's own
/// and keeps the fewer bits at equal error ([`RatePlan::depth_choices`]): at the law's low `crf`
/// libaom's finer quantisers for key frames and alternate references stop at `qmin`, which cost
/// the small glTF characters up to 67 % more bits than 10-bit pictures at quality 90 (Fox), while
/// the larger meshes gain up to 38 % there; over finer samples the coarser `crf` codes them as
/// 10-bit pictures with two more bits of range (docs/design.md, "Sample depth").
pub(crate) fn av1_coarser_laws_12(own: PictureLaw) -> Vec<PictureLaw> {
    let own_step = av1_log2_step(f64::from(own.quantiser), 12);
    let coarsest = av1_crf_of(own_step + 2.0, 12)
        .floor()
        .min(f64::from(AV1_MAX_QP)) as u8;
    let coarser = (own.quantiser + 1..=coarsest).map(|crf| PictureLaw {
        step_factor: own.step_factor * 2f64.powf(own_step - av1_log2_step(f64::from(crf), 12)),
        quantiser: crf,
    });
    coarser.collect()
}

/// libaom as a [`deep::Flavour`].
#[cfg(feature = "ffmpeg")]
mod coder {
    use super::super::deep::{self, Flavour};
    use super::MAX_QP;

    /// libaom's speed preset: 0 (slowest, smallest) ..= 6 in its "good" usage; slower presets
    /// gain little error for much more encode time (docs/design.md, "AV1 settings").
    pub const CPU_USED: u8 = 6;
    /// Frames libaom looks ahead in a P-frame group (`--gop` above 1), which lets it code hidden
    /// alternate-reference frames (`auto-alt-ref`): a future frame coded first, shown later, that the
    /// frames between predict from. The hidden frame travels in the packet of a shown frame (AV1's
    /// temporal unit), so the stream keeps one packet per frame, in order. Fewer bits at equal error
    /// than no look-ahead, and less encode time (docs/design.md, "AV1 settings").
    pub const LAG_IN_FRAMES: u8 = 19;
    /// The finest quantiser (libaom's `qmin`; quantiser index 4 × it) of any frame in a 12-bit
    /// P-frame group: 1, not libaom's 0, which the finer quantisers libaom gives key frames and
    /// alternate references reach from the low `crf`s of 12-bit pictures — index 0, lossless
    /// coding. At quality 90, 5–31 % fewer bytes for a vertex RMSE 0.5–11 % higher, fewer at equal
    /// error on all ten sequences measured; at 10 bits it changed only the small glTF characters'
    /// streams (Fox 23 % fewer bytes at quality 85, 1 % more at equal error at 75) and is not taken
    /// there yet (docs/design.md, "AV1 settings").
    pub const DEEP_P_FRAME_QMIN: u8 = 1;
    /// Strength of the temporal filter libaom runs over the frames an alternate reference stands for:
    /// 0, no filtering (docs/design.md, "AV1 settings").
    pub const ARNR_STRENGTH: u8 = 0;
    use ffmpeg_next::{codec, Dictionary};

    /// libaom's encoder and FFmpeg's AV1 decoder.
    #[derive(Debug, Clone, Copy)]
    pub struct Libaom;

    /// AV1 as the geometry-video picture codec.
    pub(crate) const PICTURES: deep::Pictures<Libaom> = deep::Pictures(Libaom);

    impl Flavour for Libaom {
        fn name(&self) -> &'static str {
            "av1"
        }

        fn encoder_name(&self) -> &'static str {
            "libaom-av1"
        }

        fn decoder_id(&self) -> codec::Id {
            codec::Id::AV1
        }

        fn max_qp(&self) -> u8 {
            MAX_QP
        }

        /// Constant quality at `crf` = the quantiser, key frames exactly every `gop` frames
        /// (`keyint_min` = `g`), one tile, no row threads; P-frame groups look ahead and code hidden
        /// alternate-reference frames, all-intra streams do not.
        fn settings(&self, options: &deep::Options, gop: u32, _: (u32, u32)) -> Dictionary<'static> {
            let mut dict = Dictionary::new();
            dict.set("usage", "good");
            dict.set("cpu-used", &CPU_USED.to_string());
            dict.set("crf", &options.qp.to_string());
            // libaom's constant-quality mode gives key frames a finer quantiser than `crf`, as x265's
            // fixed QP does (its I/P ratio); pinning every frame to `crf` (`qmin` = `qmax`) costs more
            // bits at equal error (docs/design.md, "Quality laws (JPEG, MPEG-4, HEVC, AV1)"). These
            // are libaom's own bounds but the lowest of 12-bit P-frame groups ([`DEEP_P_FRAME_QMIN`]):
            // FFmpeg's generic defaults (2..31, MPEG-4's qscale range) would clamp every `crf`
            // above 31 to 31 (docs/design.md, "AV1 settings").
            let qmin = match (gop, options.depth) {
                (2.., 12) => DEEP_P_FRAME_QMIN,
                _ => 0,
            };
            dict.set("qmin", &qmin.to_string());
            dict.set("qmax", &MAX_QP.to_string());
            dict.set("keyint_min", &gop.to_string());
            let (lag, alt_ref) = if gop > 1 {
                (LAG_IN_FRAMES, "1")
            } else {
                (0, "0")
            };
            dict.set("lag-in-frames", &lag.to_string());
            dict.set("auto-alt-ref", alt_ref);
            dict.set("arnr-strength", &ARNR_STRENGTH.to_string());
            dict.set("row-mt", "0");
            dict.set("tune", "psnr");
            dict.set("aq-mode", "none");
            dict
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rate(quality: u8) -> Rate {
        Rate {
            quality,
            fine_quality: None,
            step: None,
            affine_precision: None,
        }
    }

    fn plans(quality: u8, config: DeepConfig) -> (RatePlan, RatePlan) {
        let rate = rate(quality);
        let av1 = plan(&config, &rate, 1.0).unwrap();
        let hevc = super::super::hevc::plan(&config, &rate, 1.0).unwrap();
        (av1, hevc)
    }

    fn at(bit_depth: Option<u8>) -> DeepConfig {
        DeepConfig {
            bit_depth,
            ..DeepConfig::default()
        }
    }

    #[test]
    fn the_automatic_depth_is_12_bits_from_each_codecs_quality() {
        let depth = |quality, bit_depth| {
            let (av1, hevc) = plans(quality, at(bit_depth));
            let depth = |plan: RatePlan| plan.pictures.map_or(0, |p| p.depth);
            (depth(av1), depth(hevc))
        };
        assert_eq!(depth(64, None), (10, 10));
        assert_eq!(depth(65, None), (10, 12));
        assert_eq!(depth(89, None), (10, 12));
        assert_eq!(depth(90, None), (12, 12));
        assert_eq!(depth(97, Some(10)), (10, 10));
        assert_eq!(depth(50, Some(12)), (12, 12));
        // All-intra alike.
        let intra = |quality| {
            let (av1, hevc) = plans(quality, DeepConfig { gop: 1, ..at(None) });
            let depth = |plan: RatePlan| plan.pictures.map_or(0, |p| p.depth);
            (depth(av1), depth(hevc))
        };
        assert_eq!(intra(64), (10, 10));
        assert_eq!(intra(65), (10, 12));
        assert_eq!(intra(90), (12, 12));
    }

    #[test]
    fn residuals_that_widen_10_bit_samples_take_the_12_bit_plan() {
        let widening = vec![vec![[0.0f32; 3], [0.5, -0.5, 0.5]]; 2];
        let narrow = vec![vec![[0.0f32; 3], [1e-6, -1e-6, 0.0]]; 2];
        for quality in [30, 50, 59] {
            let (av1, hevc) = plans(quality, at(None));
            let (ten_av1, ten_hevc) = plans(quality, at(Some(10)));
            let (deep_av1, deep_hevc) = plans(quality, at(Some(12)));
            // Exactly the plan a 12-bit encoding makes (the affine step does not depend on the
            // depth): a stream turned deep is the one `--bit-depth 12` codes.
            let deep_av1 = deep_av1.at_depth_for(&widening);
            assert_eq!(av1.clone().at_depth_for(&widening), deep_av1, "{quality}");
            assert_eq!(hevc.clone().at_depth_for(&widening), deep_hevc, "{quality}");
            assert_eq!(av1.at_depth_for(&narrow), ten_av1, "{quality}");
            assert_eq!(hevc.at_depth_for(&narrow), ten_hevc, "{quality}");
        }
        // A depth or a quantiser the caller gave does not turn.
        let (ten, _) = plans(50, at(Some(10)));
        assert_eq!(ten.clone().at_depth_for(&widening), ten);
        let fixed_qp = DeepConfig {
            qp: Some(30),
            ..DeepConfig::default()
        };
        let (fixed, _) = plans(50, fixed_qp);
        assert_eq!(fixed.clone().at_depth_for(&widening), fixed);
    }

    #[test]
    fn twelve_bit_av1_trades_its_crf_for_the_room_the_residuals_leave() {
        let quantiser_step = |plan: &RatePlan| {
            let pictures = plan.pictures.as_ref().expect("pictures");
            let crf = f64::from(pictures.quantiser);
            f64::from(plan.step) * 2f64.powf(av1_log2_step(crf, pictures.depth))
        };
        for quality in [30, 60, 75, 90] {
            let (deep, _) = plans(quality, at(Some(12)));
            let (ten, _) = plans(quality, at(Some(10)));
            let step = f64::from(deep.step);
            // Residuals that fill 12-bit samples at the law's own pixel step keep it; ones that
            // fill a quarter of them take a coarser `crf` over finer samples, at about 10-bit
            // pictures' `crf` and the same quantiser step in model units.
            let span = |levels: f64| vec![vec![[0.0f32; 3], [(levels * step) as f32, 0.0, 0.0]]];
            let (own, none) = deep.clone().depth_choices(&span(4000.0));
            let quantiser = |plan: &RatePlan| plan.pictures.as_ref().map(|p| p.quantiser);
            assert_eq!((own.step, quantiser(&own)), (deep.step, quantiser(&deep)));
            assert_eq!(none, None, "{quality}");
            let (same, roomy) = deep.clone().depth_choices(&span(1000.0));
            assert_eq!(same, own, "{quality}");
            let roomy = roomy.expect("room for a coarser crf");
            let (roomy_crf, ten_crf) = (roomy.pictures.as_ref(), ten.pictures.as_ref());
            let (roomy_crf, ten_crf) = (roomy_crf.unwrap().quantiser, ten_crf.unwrap().quantiser);
            assert!(roomy_crf.abs_diff(ten_crf) <= 1, "{quality}: {roomy_crf} {ten_crf}");
            assert!(roomy.step < own.step && 4.0 * roomy.step >= own.step, "{quality}");
            let ratio = quantiser_step(&roomy) / quantiser_step(&own);
            assert!((ratio - 1.0).abs() < 1e-6, "{quality}: {ratio}");
        }
        // A `crf` the caller gave stays; so do all-intra pictures (measured with P-frames only)
        // and a pixel step the caller gave (the coarser laws would keep it, coarsening the
        // quantiser step).
        let fixed = DeepConfig {
            qp: Some(7),
            ..at(Some(12))
        };
        let (fixed, _) = plans(75, fixed);
        assert_eq!(fixed.clone().at_depth_for(&[]), fixed);
        let (intra, _) = plans(75, DeepConfig { gop: 1, ..at(Some(12)) });
        assert!(intra.pictures.as_ref().is_some_and(|p| p.deeper.is_none()));
        let given_step = Rate {
            step: Some(1e-3),
            ..rate(75)
        };
        let given = plan(&at(Some(12)), &given_step, 1.0).unwrap();
        assert!(given.pictures.as_ref().is_some_and(|p| p.deeper.is_none()));
    }

    #[test]
    fn the_crf_of_a_step_inverts_the_step_of_a_crf() {
        for depth in [10, 12] {
            for crf in 0..=63 {
                let c = f64::from(crf);
                let back = av1_crf_of(av1_log2_step(c, depth), depth);
                assert!((back - c).abs() < 1e-9, "{crf} at {depth} bits");
            }
        }
    }

    #[test]
    fn av1_quantiser_keeps_falling_up_to_quality_97_at_12_bits() {
        // A floor of `crf` 8 would hold every quality from 90 up at one `crf`.
        let crfs: Vec<u8> = (90..=97).map(|q| av1_law(q, 12).quantiser).collect();
        assert!(crfs[0] < 8, "{crfs:?}");
        assert!(crfs[7] < crfs[0], "{crfs:?}");
        assert!(crfs.iter().all(|&c| c >= AV1_MIN_QP), "{crfs:?}");
    }

    #[test]
    fn affine_maps_are_finer_in_p_frame_groups_only() {
        let code = |gop, quality| {
            let rate = Rate {
                quality,
                fine_quality: None,
                step: None,
                affine_precision: None,
            };
            let config = DeepConfig {
                gop,
                ..DeepConfig::default()
            };
            plan(&config, &rate, 1.0).unwrap().affine_precision
        };
        // In sixteenths: a quarter all-intra; 1/8 in P-frame groups, 1/16 from quality 85.
        assert_eq!((code(1, 50), code(50, 50)), (4, 2));
        assert_eq!((code(1, 90), code(50, 90)), (4, 1));
    }
}

#[cfg(all(test, feature = "ffmpeg"))]
mod ffmpeg_tests {
    use super::coder::*;
    use crate::codec::pictures::deep;

    #[test]
    fn deep_planes_round_trip_with_key_frames_every_gop() {
        // crf 4 (qindex 16) is a step of about one level of an 8-bit picture.
        deep::testing::round_trip(&Libaom, 4, 4);
    }

    #[test]
    fn bad_settings_are_errors() {
        deep::testing::bad_settings_are_errors(Libaom, 32);
    }

    #[test]
    fn the_same_pictures_give_the_same_bytes_every_run() {
        deep::testing::same_bytes_every_run(&Libaom, 24, 50, 3);
    }
}
