//! The picture the geometry-image codecs exchange with the pipeline: one 8-bit grayscale plane.

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

#[cfg(test)]
mod tests {
    use super::*;

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
