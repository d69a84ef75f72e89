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
/// 75 is on the hull up to a vertex RMSE of about 4e-4 of the diagonal, 90 below. Quality 50 lands
/// at about 9e-4 (vertex RMSE; the papers' surface RMSE about 4e-4) on CesiumMan.
const JPEG_LAW: [Anchor; 4] = [
    anchor(1, 4.0, 75),
    anchor(50, 0.8, 75),
    anchor(75, 0.6, 90),
    anchor(90, 0.3, 90),
];

/// MPEG-4's law, made as [`JPEG_LAW`] over pixel step × qscale: qscales 1, 2 and 4 lie on one
/// curve (error about pixel step^0.6) where the 8-bit range allows; 2 is kept, and 1 from quality
/// 90, where finer steps meet the 8-bit floor on sequences with large residuals.
const MPEG4_LAW: [Anchor; 4] = [
    anchor(1, 3.0, 2),
    anchor(50, 0.8, 2),
    anchor(75, 0.45, 2),
    anchor(90, 0.6, 1),
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
/// MPEG-4's error at quality 50.
pub const HEVC_STEP_FACTOR: f64 = 0.05;
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
        for law in [jpeg_law, mpeg4_law, hevc10, hevc12] {
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
        }
        assert_eq!(hevc_law(50, 10).quantiser, HEVC_QP_AT_50 as u8);
        assert_eq!(hevc_law(50, 12).quantiser, HEVC_QP_AT_50 as u8 - 12);
    }
}
