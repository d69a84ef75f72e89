//! The one user-facing rate knob, `quality` 1..100, and the laws that map it onto each codec's
//! quantiser (the IJG law JPEG itself uses, anchored for MPEG-4 and the temporal DCT).

/// The MPEG-4 quantiser (`qscale`, 1..31, lower = better) for a user quality 1..100 (higher = better).
///
/// Follows the IJG law that JPEG uses for its quality (table scale 5000/q % below 50, 200 − 2q %
/// from 50 up), anchored so that quality 50 ↔ qscale 4: on a smooth 256×256 test sequence that pair,
/// and every other along the law (10↔20, 20↔10, 30↔7, 75↔2, 90↔1), gives the two codecs the same PSNR
/// within about 1 dB (measured by `measure_rate_distortion_and_speed` in `tests/codec.rs`). So one
/// `--quality` means roughly the same distortion whichever codec is chosen.
pub fn quality_to_qscale(quality: u8) -> u8 {
    let scale_percent = ijg_scale_percent(quality);
    // qscale = 4 · scale / 100, rounded to nearest.
    let qscale = (4 * scale_percent + 50) / 100;
    qscale.clamp(1, 31) as u8
}

/// The IJG quality law (libjpeg's `jpeg_quality_scaling`): the quantiser scale in percent for a
/// quality 1..100 (clamped), 5000/q below 50 and 200 − 2q from 50 up (0 at 100).
///
/// Shared by every codec that follows the one `--quality` scale: MPEG-4's qscale
/// ([`quality_to_qscale`]) and the temporal-DCT step.
pub fn ijg_scale_percent(quality: u8) -> u32 {
    let q = u32::from(quality.clamp(1, 100));
    if q < 50 {
        5000 / q
    } else {
        200 - 2 * q
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quality_mapping_is_monotone_and_anchored() {
        assert_eq!(quality_to_qscale(50), 4);
        assert_eq!(quality_to_qscale(75), 2);
        assert_eq!(quality_to_qscale(10), 20);
        assert_eq!(quality_to_qscale(100), 1);
        assert_eq!(quality_to_qscale(1), 31);
        assert_eq!(quality_to_qscale(0), 31);
        let mut last = u8::MAX;
        for q in 1..=100 {
            let s = quality_to_qscale(q);
            assert!((1..=31).contains(&s));
            assert!(s <= last, "qscale must not grow with quality ({q})");
            last = s;
        }
    }
}
