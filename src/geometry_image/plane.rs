//! The picture the geometry-image codecs exchange with the pipeline: one grayscale plane, of 8-bit
//! samples (`Plane`, what JPEG and MPEG-4 code) or of up to 16 (`Plane<u16>`, what the geometry-video
//! coder makes, at the picture codec's sample depth).

use crate::{Error, Result};

/// One grayscale picture, rows top to bottom, `width` samples per row, no padding.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Plane<S = u8> {
    /// Pixels per row.
    pub width: u32,
    /// Number of rows.
    pub height: u32,
    /// `width × height` samples, row-major.
    pub data: Vec<S>,
}

impl<S: Copy> Plane<S> {
    /// A plane from its samples; fails when `data` does not hold exactly `width × height` samples.
    pub fn new(width: u32, height: u32, data: Vec<S>) -> Result<Self> {
        let plane = Plane {
            width,
            height,
            data,
        };
        plane.check()?;
        Ok(plane)
    }

    /// A plane with every sample set to `value`.
    pub fn filled(width: u32, height: u32, value: S) -> Self {
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
    pub fn row(&self, y: u32) -> Option<&[S]> {
        let w = self.width as usize;
        let start = y as usize * w;
        self.data.get(start..start + w)
    }

    fn same_size<T>(&self, other: &Plane<T>) -> Result<()> {
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

impl Plane<u16> {
    /// The 8-bit plane of the same samples, for the 8-bit picture codecs; fails when a sample
    /// exceeds 255 (a picture made at a deeper sample depth).
    pub fn to_8bit(&self) -> Result<Plane> {
        let data = self
            .data
            .iter()
            .map(|&v| u8::try_from(v))
            .collect::<std::result::Result<Vec<u8>, _>>()
            .map_err(|_| Error::Codec("an 8-bit codec was given samples above 255".into()))?;
        Plane::new(self.width, self.height, data)
    }
}

impl Plane {
    /// The same samples as 16-bit values (what the geometry-video coder reads).
    pub fn widen(&self) -> Plane<u16> {
        Plane {
            width: self.width,
            height: self.height,
            data: self.data.iter().map(|&v| u16::from(v)).collect(),
        }
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
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plane_rejects_wrong_length() {
        assert!(Plane::new(4, 4, vec![0; 15]).is_err());
        assert!(Plane::<u8>::new(0, 4, vec![]).is_err());
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
        assert_eq!(a.widen().to_8bit()?, a);
        assert!(Plane::<u16>::filled(2, 2, 256).to_8bit().is_err());
        Ok(())
    }
}
