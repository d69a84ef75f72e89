//! One frame's three residual images (x, y, z) on the atlas: the quantised residuals at each
//! vertex's pixel, then padded. The encoder and `inspect` both make them here, so the pictures
//! `inspect` shows are the ones the encoder coded.

use super::corrections::Corrections;
use super::quantise::{self, FrameRanges, RangeMode};
use crate::error::Result;

/// What it takes to make an encoding's residual images.
pub struct GeometryImages {
    /// The lattice size.
    pub lattice: (u16, u16),
    /// The atlas: each vertex's pixel, the chart pixels.
    pub atlas: atlas::Atlas,
    /// One grey level in model units, before any frame's shift.
    pub pixel_step: f32,
    /// Residual range (shift and offset) per frame and coordinate.
    pub ranges: Vec<FrameRanges>,
    /// The residuals the ranges clip, sent apart.
    pub corrections: Corrections,
    /// How free pixels are filled: the options, made ready for the atlas's mask.
    pub padding: padding::Padder,
    /// Frames per group: the first frame of a group is padded on its own, the others continue the
    /// previous frame's padding (P-frames); 1 for intra codecs.
    pub gop: usize,
    /// Bits a sample of the pictures (8 for JPEG and MPEG-4).
    pub depth: u8,
    /// The residuals' spread ([`quantise::Chosen::spread`]).
    pub spread: f64,
}

impl GeometryImages {
    /// The images of an encoding on `atlas` at `pixel_step` and `depth` bits a sample, with
    /// offsets centred on the `residuals` of each frame or group as `mode` groups them. Errors when
    /// the padding options do not fit the lattice.
    pub fn new(
        lattice: (u16, u16),
        atlas: atlas::Atlas,
        residuals: &[Vec<[f32; 3]>],
        (mode, depth): (RangeMode, u8),
        pixel_step: f32,
        padding: padding::PaddingOptions,
    ) -> Result<Self> {
        let chosen = quantise::choose(residuals, mode, pixel_step, depth);
        let (w, h) = (usize::from(lattice.0), usize::from(lattice.1));
        let padding = padding::Padder::new(w, h, &atlas.fixed_mask(), &padding)?;
        Ok(Self {
            lattice,
            atlas,
            pixel_step,
            ranges: chosen.ranges,
            corrections: chosen.corrections,
            padding,
            gop: mode.group(),
            depth,
            spread: chosen.spread,
        })
    }

    /// Frame `f`'s residuals of coordinate `axis` as levels in `0..=max level` on the lattice, before
    /// padding (free pixels are 0).
    pub fn level_image(&self, frame: &[[f32; 3]], f: usize, axis: usize) -> Result<Vec<f32>> {
        let range = self.ranges[f][axis];
        let levels: Vec<f32> = frame.iter().map(|r| range.quantise(r[axis])).collect();
        Ok(self.atlas.try_splat(&levels)?)
    }

    /// The three level images of frame `f` with every pixel that carries no vertex at 0.
    pub fn raw(&self, frame: &[[f32; 3]], f: usize) -> Result<[Vec<f32>; 3]> {
        let mut out: [Vec<f32>; 3] = Default::default();
        for (a, img) in out.iter_mut().enumerate() {
            *img = self.level_image(frame, f, a)?;
            for (p, &keep) in img.iter_mut().zip(self.padding.fixed()) {
                if !keep {
                    *p = 0.0;
                }
            }
        }
        Ok(out)
    }

    /// The three padded images of frame `f` (levels in `0..=max level`, before rounding). `previous`
    /// holds the previous frame's padded images when `f` continues a group (see [`Self::continues`]).
    pub fn padded(
        &self,
        frame: &[[f32; 3]],
        f: usize,
        previous: Option<&[Vec<f32>; 3]>,
    ) -> Result<[Vec<f32>; 3]> {
        let mut out: [Vec<f32>; 3] = Default::default();
        for (a, img) in out.iter_mut().enumerate() {
            let mut image = self.level_image(frame, f, a)?;
            self.padding
                .pad(&mut image, previous.map(|p| p[a].as_slice()))?;
            *img = image;
        }
        Ok(out)
    }

    /// Whether frame `f` is padded against the previous frame's images (not the first of its group).
    pub fn continues(&self, f: usize) -> bool {
        f % self.gop != 0
    }

    /// Frame `f`'s padded images as the encoder made them, re-padding from the start of its group
    /// when it continues one (`residuals[g]` is frame g's residuals).
    pub fn padded_alone(&self, residuals: &[Vec<[f32; 3]>], f: usize) -> Result<[Vec<f32>; 3]> {
        let start = f - f % self.gop;
        let mut images = self.padded(&residuals[start], start, None)?;
        for (g, frame) in residuals.iter().enumerate().take(f + 1).skip(start + 1) {
            images = self.padded(frame, g, Some(&images))?;
        }
        Ok(images)
    }
}
