//! Image and video codecs for the 8-bit residual geometry images.
//!
//! The pipeline hands over grayscale [`Plane`]s and gets them back after a lossy round trip:
//! [`jpeg`] codes every plane on its own (any frame decodes alone), [`mpeg4`] codes a sequence as
//! MPEG-4 Part 2 I- and P-frames through FFmpeg. [`quality_to_qscale`] maps the one user-facing rate
//! knob (`--quality 1..100`) onto the MPEG-4 quantiser so both codecs follow the same scale.
//!
//! Three coordinate images per frame, measured on smooth synthetic 256×256 planes (see
//! `measure_rate_distortion_and_speed` in `tests/codec.rs`): tiling them into one 768×256 picture
//! saves JPEG ≈ 460 bytes a frame with full headers (2–4 %) but only ≈ 100–130 bytes (< 1 %) in the
//! abbreviated form the stream stores ([`abbreviated`]), while MPEG-4 codes three separate streams 2–4 % smaller
//! than the tiled picture. Chroma is flat and costs nothing measurable
//! (the GRAY flag changes no byte).

pub mod abbreviated;
pub mod jpeg;
pub mod mpeg4;

use crate::{Error, Result};

/// One 8-bit grayscale picture, rows top to bottom, `width` bytes per row, no padding.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Plane {
    /// Pixels per row.
    pub width: u32,
    /// Number of rows.
    pub height: u32,
    /// `width × height` samples, row-major.
    pub data: Vec<u8>,
}

impl Plane {
    /// A plane from its samples; fails when `data` does not hold exactly `width × height` bytes.
    pub fn new(width: u32, height: u32, data: Vec<u8>) -> Result<Self> {
        let plane = Plane {
            width,
            height,
            data,
        };
        plane.check()?;
        Ok(plane)
    }

    /// A plane with every sample set to `value`.
    pub fn filled(width: u32, height: u32, value: u8) -> Self {
        Plane {
            width,
            height,
            data: vec![value; width as usize * height as usize],
        }
    }

    /// Fails when the fields are inconsistent (the fields are public, so anyone can break them).
    pub fn check(&self) -> Result<()> {
        let expected = self.width as usize * self.height as usize;
        if self.width == 0 || self.height == 0 {
            return Err(Error::Codec(format!(
                "empty plane {}×{}",
                self.width, self.height
            )));
        }
        if self.data.len() != expected {
            return Err(Error::Codec(format!(
                "plane {}×{} holds {} bytes, expected {expected}",
                self.width,
                self.height,
                self.data.len()
            )));
        }
        Ok(())
    }

    /// One row of samples; `None` past the last row.
    pub fn row(&self, y: u32) -> Option<&[u8]> {
        let w = self.width as usize;
        let start = y as usize * w;
        self.data.get(start..start + w)
    }

    /// Largest absolute sample difference to `other`; fails when the sizes differ.
    pub fn max_abs_diff(&self, other: &Plane) -> Result<u8> {
        self.same_size(other)?;
        Ok(self
            .data
            .iter()
            .zip(&other.data)
            .map(|(a, b)| a.abs_diff(*b))
            .max()
            .unwrap_or(0))
    }

    /// Mean squared sample difference to `other`; fails when the sizes differ.
    pub fn mse(&self, other: &Plane) -> Result<f64> {
        self.same_size(other)?;
        let sum: u64 = self
            .data
            .iter()
            .zip(&other.data)
            .map(|(a, b)| u64::from(a.abs_diff(*b)).pow(2))
            .sum();
        Ok(sum as f64 / self.data.len().max(1) as f64)
    }

    /// Peak signal-to-noise ratio to `other` in dB (peak 255); infinite for identical planes.
    pub fn psnr(&self, other: &Plane) -> Result<f64> {
        let mse = self.mse(other)?;
        Ok(10.0 * (255.0_f64 * 255.0 / mse).log10())
    }

    fn same_size(&self, other: &Plane) -> Result<()> {
        if (self.width, self.height) != (other.width, other.height)
            || self.data.len() != other.data.len()
        {
            return Err(Error::Codec(format!(
                "planes differ in size: {}×{} vs {}×{}",
                self.width, self.height, other.width, other.height
            )));
        }
        Ok(())
    }
}

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

    #[test]
    fn plane_rejects_wrong_length() {
        assert!(Plane::new(4, 4, vec![0; 15]).is_err());
        assert!(Plane::new(0, 4, vec![]).is_err());
        let p = Plane::new(4, 2, (0..8).collect());
        assert!(p.is_ok());
    }

    #[test]
    fn plane_measures() -> Result<()> {
        let a = Plane::new(2, 2, vec![10, 20, 30, 40])?;
        let b = Plane::new(2, 2, vec![11, 20, 27, 40])?;
        assert_eq!(a.max_abs_diff(&b)?, 3);
        assert!((a.mse(&b)? - 2.5).abs() < 1e-12);
        assert!(a.psnr(&a)?.is_infinite());
        assert!(a.mse(&Plane::filled(1, 4, 0)).is_err());
        Ok(())
    }
}
