//! The one user-facing rate knob, `quality` 1..100, and the law that maps it onto every codec: a
//! target step in units of the first frame's bounding-box diagonal (quality 50 ↔ 1/1000 of it,
//! scaled by the IJG law JPEG uses for its own quality), which the temporal DCT uses as its
//! quantiser step and the image codecs as their pixel step, times a factor chosen jointly with the
//! picture codec's own quantiser (JPEG quality, MPEG-4 qscale) so that one quality gives about the
//! same error whichever codec (issue 15; the sweep is `scripts/error_law_sweep.sh`).

/// The IJG quality law (libjpeg's `jpeg_quality_scaling`): the quantiser scale in percent for a
/// quality 1..100 (clamped), 5000/q below 50 and 200 − 2q from 50 up (0 at 100).
pub fn ijg_scale_percent(quality: u8) -> u32 {
    let q = u32::from(quality.clamp(1, 100));
    if q < 50 {
        5000 / q
    } else {
        200 - 2 * q
    }
}

/// The target step of `quality` in model units, for a first frame of bounding-box diagonal
/// `diagonal`: 1e-3 × diagonal × the IJG scale (1 % at quality 99 and 100, so never 0).
pub fn target_step(quality: u8, diagonal: f64) -> f64 {
    let s = ijg_scale_percent(quality).max(1);
    diagonal * 1e-3 * f64::from(s) / 100.0
}

/// The absolute step of an encoding in model units: `opts.step` (a fraction of the first frame's
/// bounding-box diagonal `diagonal`) or `factor` × the target step of `opts.quality`, rounded to
/// the `f32` the stream stores, so that the encoder quantises with exactly the step the decoder
/// reads. `what` names the step in the error a degenerate first frame gives.
pub fn stored_step(
    what: &str,
    diagonal: f64,
    opts: &crate::encoder::EncodeOptions,
    factor: f64,
) -> crate::error::Result<f32> {
    let step = match opts.step {
        Some(fraction) => diagonal * fraction,
        None => factor * target_step(opts.quality, diagonal),
    };
    let stored = step as f32;
    if !(stored.is_normal() && stored > 0.0) {
        return Err(crate::error::Error::Mesh(format!(
            "the {what} is {step} (first frame's bounding-box diagonal {diagonal}): \
             a degenerate first frame gives no scale to quantise against"
        )));
    }
    Ok(stored)
}

/// What one quality means for a picture codec.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PictureLaw {
    /// Pixel step (one grey level) as a multiple of the target step.
    pub step_factor: f64,
    /// The picture codec's quantiser: JPEG quality 1..100 or MPEG-4 qscale 1..31.
    pub quantiser: u8,
}

/// One anchor of a law: from `quality` up (until the next anchor), the codec's quantiser, and the
/// step factor at `quality` (interpolated log-linearly towards the next anchor's).
struct Anchor {
    quality: u8,
    step_factor: f64,
    quantiser: u8,
}

/// JPEG's law, read off the lower hull of (bpvf, vertex RMSE) over pixel step × JPEG quality
/// (`examples/error_law_sweep.rs` on CesiumMan, the walking cat and Cow): the error follows
/// about the square root of the pixel step, so the factor falls as the quality rises; JPEG quality
/// 75 is on the hull up to a vertex RMSE of about 4e-4 of the diagonal, 90 below. The shape was
/// read on the former automatic lattice (about 28 pixels a vertex); on the smallest lattice the
/// charts fit (`Lattice::Auto` since then) one pixel step gives more error for fewer bits, and
/// the anchors were re-measured there (`mcgv-video encode SEQ --step S --jpeg-quality J` and
/// `eval`, surface RMSE; docs/results.md, "Quality laws on the smallest lattice"):
/// - quality 50, 0.8 → 0.25: the hardest sequence, horse-collapse, reaches 3.8e-4 at pixel step
///   3e-4 and 5.3e-4 at 5e-4; the walking cat 3.9e-4 at 4e-4 (6.6 bpvf) and 2.3e-4 at 2e-4
///   (9.6 bpvf); quality 50 now lands at 1.8–3.3e-4 (Fox 0.67e-4) for 2.3–8.0 bpvf on the eight
///   media sequences of at least 1000 vertices.
/// - quality 75, 0.6 → 0.4 with JPEG quality 90 (pixel step 2e-4: 1.1e-4 on the cat, 9e-5 on
///   CesiumMan, about tdct's error at 75). Scaled as quality 50's (0.19) it reached the cat's
///   floor (5.4e-5, where the 8-bit range widens the step) already at 75, leaving quality 90 no
///   lower error (5.5e-5).
/// - quality 90, 0.3 → 0.2 (pixel step 4e-5, at or near that floor on the cat and Cow).
const JPEG_LAW: [Anchor; 4] = [
    anchor(1, 1.25, 75),
    anchor(50, 0.25, 75),
    anchor(75, 0.4, 90),
    anchor(90, 0.2, 90),
];

/// MPEG-4's law, made as [`JPEG_LAW`] over pixel step × qscale: qscales 1, 2 and 4 lie on one
/// curve (error about pixel step^0.6) where the 8-bit range allows; 2 is kept, and 1 from quality
/// 90, where finer steps meet the 8-bit floor on sequences with large residuals. Re-measured on
/// the smallest lattice as JPEG's:
/// - quality 50, 0.8 → 0.21 (quality 1, 3.0 → 0.8, scaled alike): at qscale 2, surface RMSE 4e-4
///   needs pixel step 2.3e-4 on horse-collapse (3.4 bpvf), the hardest for error per step; the
///   walking cat and Cow need about 5.8 and 5.3 bpvf for it (any qscale) and have about 9.7e-4
///   and 5.3e-4 at 4 bpvf, so quality 50 spends more than 4 bpvf there to keep the error
///   under 4e-4 (6.5 and 6.2 bpvf at 2.9 and 3.2e-4; 1.7–3.6 bpvf at 1.8–3.6e-4 elsewhere, Fox
///   0.36e-4).
/// - quality 75, 0.45 → 0.27, and 90, 0.6 → 0.16: qualities 90 and 97 end at about the same
///   error where the 8-bit range widens the step (walking cat 8.1e-5, Cow 9.9e-5: there the
///   automatic choice keeps the smaller stream at the step, affine maps on the cat, though
///   skinning reaches 4.2e-5 at 97 for 30 % more bytes), so quality 75 stays at least twice above
///   that: 0.24 gave the cat 1.8e-4 but Cow 1.92e-4 (1.94×); 0.16 and 0.12 gave the cat 1.3e-4
///   and, with affine maps, 1.6e-4.
const MPEG4_LAW: [Anchor; 4] = [
    anchor(1, 0.8, 2),
    anchor(50, 0.21, 2),
    anchor(75, 0.27, 2),
    anchor(90, 0.16, 1),
];

const fn anchor(quality: u8, step_factor: f64, quantiser: u8) -> Anchor {
    Anchor {
        quality,
        step_factor,
        quantiser,
    }
}

/// JPEG's pixel step factor and JPEG quality for a user quality 1..100.
pub fn jpeg_law(quality: u8) -> PictureLaw {
    read_law(&JPEG_LAW, quality)
}

/// HEVC's law at 10 bits a sample: a pixel step of [`HEVC_STEP_FACTOR`] × the target step and the
/// QP that follows the target step, 6 per halving ([`HEVC_QP_AT_50`] at quality 50), between
/// [`HEVC_MIN_QP`] and 51; beyond them the pixel step takes the rest. Read off the sweep of pixel
/// step × QP on CesiumMan (docs/results.md): the error follows step × 2^(QP/6) and, at equal error,
/// the rate hardly depends on how the two share it (within 3 % from QP 10 to 40), except that QPs
/// under 10 cost more than a finer pixel step at equal error, hence the floor. Quality 50 lands on
/// MPEG-4's error at quality 50: the factor was 0.05 on the former automatic lattice; on the
/// smallest lattice that fits, where MPEG-4's quality 50 was re-anchored 2.4× lower in error
/// ([`MPEG4_LAW`]), it is 0.02 (docs/results.md, "Quality laws on the smallest lattice").
pub const HEVC_STEP_FACTOR: f64 = 0.02;
/// The QP of quality 50 at 10 bits a sample.
pub const HEVC_QP_AT_50: f64 = 28.0;
/// The lowest QP the law uses at 10 bits a sample.
pub const HEVC_MIN_QP: f64 = 10.0;

/// HEVC's pixel step factor and QP for a user quality 1..100 at `depth` bits a sample. A deeper
/// sample takes the same pixel step and a QP 6 lower per bit over 10: HEVC's QP is relative to the
/// sample range, so this is the same quantiser step in model units (measured: CesiumMan at pixel
/// step 5e-5, 10 bits QP 28 and 12 bits QP 16 give the same error). What 12 bits add is a finer
/// rounding of the samples; the QP stops at 0.
pub fn hevc_law(quality: u8, depth: u8) -> PictureLaw {
    let scale = f64::from(ijg_scale_percent(quality).max(1)) / 100.0;
    let deeper = 6.0 * (f64::from(depth) - 10.0);
    let exact = HEVC_QP_AT_50 + 6.0 * scale.log2() - deeper;
    let qp = exact.round().clamp((HEVC_MIN_QP - deeper).max(0.0), 51.0);
    let beyond = if exact.round() == qp { 0.0 } else { exact - qp };
    PictureLaw {
        step_factor: HEVC_STEP_FACTOR * 2f64.powf(beyond / 6.0),
        quantiser: qp as u8,
    }
}

/// AV1's law at 10 bits a sample, made as HEVC's: a pixel step of [`AV1_STEP_FACTOR`] × the target
/// step and the quantiser (libaom's `crf` 0..63, AV1's quantiser index over 4) whose quantiser step
/// follows the target step ([`AV1_QP_AT_50`] at quality 50), between [`AV1_MIN_QP`] and
/// [`AV1_MAX_QP`]; beyond them the pixel step takes the rest. Unlike HEVC's QP, AV1's quantiser
/// index does not double its step at a fixed pace (about linear up to index 96, then about 9.5
/// `crf` per doubling), so the law reads the step off [`AV1_AC_STEPS`]. Measured on CesiumMan
/// (docs/results.md, "AV1"): quality 50 lands on HEVC's error at quality 50 (RMSE 3.80e-4 at
/// 2.72 bpvf, HEVC 3.81e-4 at 2.79); at equal error the rate hardly depends on how pixel step
/// and `crf` share it (pixel step 5e-5 `crf` 32, 1e-4 `crf` 20, 2e-4 `crf` 8: 3.82, 3.71, 4.36
/// bpvf at RMSE 2.45, 2.54, 2.20e-4) up to `crf` 32, above which libaom's constant-quality mode
/// keeps its key frames' quantiser and the error stops growing (5e-5: `crf` 32–56 all 2.45e-4).
/// Those figures are on the former automatic lattice, where the factor was 0.1; on the smallest
/// lattice that fits it was 0.04, scaled as [`HEVC_STEP_FACTOR`] (docs/results.md, "Quality laws
/// on the smallest lattice"); the alternate references of P-frame groups (docs/results.md, "AV1
/// tuning") then raised the error at quality 50 by 1.3× (CesiumMan 2.75e-4 against MPEG-4's
/// 2.12e-4) and 1.6× (horse-gallop 3.27e-4 against 2.03e-4), hence 0.028.
pub const AV1_STEP_FACTOR: f64 = 0.028;
/// libaom's `crf` at quality 50 at 10 bits a sample.
pub const AV1_QP_AT_50: u8 = 32;
/// The highest `crf` the law uses (the error stops following `crf` above it).
pub const AV1_MAX_QP: u8 = 32;
/// The lowest `crf` the law uses. Not 0: with no quantiser deltas `crf` 0 is lossless coding.
/// It was 8, which capped P-frame groups at the top (horse-collapse: quality 90 and 97 both at
/// RMSE 1.27e-4, 5.6 bpvf, as there the pixel step cannot go finer than the group's residual range
/// allows at 12 bits); `crf` 1 lets the error keep falling up to quality 97 (horse-collapse: 3.8e-5
/// at 11.8 bpvf, 1.06e-5 at 21.7; docs/results.md, "AV1 and HEVC padding").
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
fn av1_log2_step(crf: f64, depth: u8) -> f64 {
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
pub fn av1_law(quality: u8, depth: u8) -> PictureLaw {
    let scale = f64::from(ijg_scale_percent(quality).max(1)) / 100.0;
    let deeper = f64::from(depth) - 10.0;
    let want = av1_log2_step(f64::from(AV1_QP_AT_50), 10) + scale.log2() - deeper;
    // The floor is a `crf`, not a step, at either depth (measured: quality 90 at 12 bits with a
    // floor two bits lower than 10 bits' went to `crf` 3 and 159 bpvf on CesiumMan).
    let floor = av1_log2_step(f64::from(AV1_MIN_QP), depth);
    let ceiling = av1_log2_step(f64::from(AV1_MAX_QP), depth);
    let crf = av1_crf_of(want.clamp(floor, ceiling), depth).round();
    // Beyond the floor or the ceiling the pixel step takes what the quantiser cannot.
    let beyond = if (floor..=ceiling).contains(&want) {
        0.0
    } else {
        want - av1_log2_step(crf, depth)
    };
    PictureLaw {
        step_factor: AV1_STEP_FACTOR * 2f64.powf(beyond),
        quantiser: crf as u8,
    }
}

/// MPEG-4's pixel step factor and qscale for a user quality 1..100.
pub fn mpeg4_law(quality: u8) -> PictureLaw {
    read_law(&MPEG4_LAW, quality)
}

fn read_law(law: &[Anchor], quality: u8) -> PictureLaw {
    let q = quality.clamp(1, 100);
    let i = law.iter().rposition(|a| a.quality <= q).unwrap_or(0);
    let here = &law[i];
    let step_factor = match law.get(i + 1) {
        Some(next) => {
            let t = f64::from(q - here.quality) / f64::from(next.quality - here.quality);
            here.step_factor * (next.step_factor / here.step_factor).powf(t)
        }
        None => here.step_factor,
    };
    PictureLaw {
        step_factor,
        quantiser: here.quantiser,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_target_step_is_anchored_and_falls_with_quality() {
        assert!((target_step(50, 2.0) - 2e-3).abs() < 1e-12);
        assert!((target_step(75, 1.0) - 0.5e-3).abs() < 1e-12);
        assert!(target_step(100, 1.0) > 0.0);
        for q in 1..100u8 {
            assert!(target_step(q + 1, 1.0) <= target_step(q, 1.0), "{q}");
        }
    }

    #[test]
    fn pixel_steps_fall_and_quantisers_do_not_coarsen_with_quality() {
        let hevc10 = |q| hevc_law(q, 10);
        let hevc12 = |q| hevc_law(q, 12);
        let av1_10 = |q| av1_law(q, 10);
        let av1_12 = |q| av1_law(q, 12);
        for law in [jpeg_law, mpeg4_law, hevc10, hevc12, av1_10, av1_12] {
            for q in 1..100u8 {
                let (a, b) = (law(q), law(q + 1));
                let step = |l: PictureLaw, q| l.step_factor * target_step(q, 1.0);
                assert!(step(b, q + 1) <= step(a, q), "pixel step grows at {q}");
            }
        }
        for q in 1..100u8 {
            assert!(jpeg_law(q + 1).quantiser >= jpeg_law(q).quantiser);
            assert!(mpeg4_law(q + 1).quantiser <= mpeg4_law(q).quantiser);
            assert!((1..=31).contains(&mpeg4_law(q).quantiser));
            assert!(hevc_law(q + 1, 10).quantiser <= hevc_law(q, 10).quantiser);
            assert!(hevc_law(q, 12).quantiser <= 51);
            assert!(av1_law(q + 1, 10).quantiser <= av1_law(q, 10).quantiser);
            assert!(av1_law(q, 10).quantiser <= 63);
        }
        assert_eq!(hevc_law(50, 10).quantiser, HEVC_QP_AT_50 as u8);
        assert_eq!(hevc_law(50, 12).quantiser, HEVC_QP_AT_50 as u8 - 12);
        assert_eq!(av1_law(50, 10).quantiser, AV1_QP_AT_50);
        // The 12-bit crf of quality 50 has a quarter of the 10-bit step (700 / 4 = 175: crf 11).
        assert_eq!(av1_law(50, 12).quantiser, 11);
        assert_eq!(av1_law(10, 10).quantiser, AV1_MAX_QP);
        assert!(av1_law(10, 10).step_factor > AV1_STEP_FACTOR);
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
        // The former floor (`crf` 8) held every quality from 90 up at one `crf`.
        let crfs: Vec<u8> = (90..=97).map(|q| av1_law(q, 12).quantiser).collect();
        assert!(crfs[0] < 8, "{crfs:?}");
        assert!(crfs[7] < crfs[0], "{crfs:?}");
        assert!(crfs.iter().all(|&c| c >= AV1_MIN_QP), "{crfs:?}");
    }
}
