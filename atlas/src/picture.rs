//! The atlas as a picture (the paper's Fig. 5a): charts in colours, blocks outlined.

use crate::atlas::{Atlas, Occupancy};
use crate::AtlasError;
use std::path::Path;

/// Lattice pixels are drawn as squares of this many image pixels, so block
/// outlines can be drawn without hiding data pixels.
const ZOOM: u32 = 3;

/// A well-spread colour for chart `c` (golden-ratio hue steps).
fn chart_colour(c: u32) -> [u8; 3] {
    let hue = (f64::from(c) * 0.618_033_988_75).fract() * 6.0;
    let x = 1.0 - (hue % 2.0 - 1.0).abs();
    let (r, g, b) = match hue as u32 {
        0 => (1.0, x, 0.0),
        1 => (x, 1.0, 0.0),
        2 => (0.0, 1.0, x),
        3 => (0.0, x, 1.0),
        4 => (x, 0.0, 1.0),
        _ => (1.0, 0.0, x),
    };
    [r, g, b].map(|v: f64| (60.0 + 195.0 * v) as u8)
}

impl Atlas {
    /// Renders the atlas: fixed pixels in their chart's colour (vertex pixels
    /// brightest), free pixels of a chart's blocks dimmed, unowned blocks
    /// black, block borders grey.
    pub fn to_image(&self) -> image::RgbImage {
        let mut img = image::RgbImage::new(self.width * ZOOM, self.height * ZOOM);
        for y in 0..self.height {
            for x in 0..self.width {
                let occ = self.occupancy.get((y * self.width + x) as usize);
                let colour = match (self.chart_at(x, y), occ) {
                    (None, _) => [0, 0, 0],
                    (Some(c), Some(Occupancy::Vertex)) => chart_colour(c),
                    (Some(c), Some(Occupancy::Interior)) => {
                        chart_colour(c).map(|v| (u16::from(v) * 3 / 4) as u8)
                    }
                    (Some(c), _) => chart_colour(c).map(|v| v / 4),
                };
                for dy in 0..ZOOM {
                    for dx in 0..ZOOM {
                        let border =
                            (x % self.block == 0 && dx == 0) || (y % self.block == 0 && dy == 0);
                        let pixel = if border { [128, 128, 128] } else { colour };
                        img.put_pixel(x * ZOOM + dx, y * ZOOM + dy, image::Rgb(pixel));
                    }
                }
            }
        }
        img
    }

    /// Writes [`Atlas::to_image`] as a PNG.
    pub fn write_png(&self, path: impl AsRef<Path>) -> Result<(), AtlasError> {
        let path = path.as_ref();
        self.to_image()
            .save(path)
            .map_err(|source| AtlasError::Image {
                path: path.display().to_string(),
                source,
            })
    }
}
