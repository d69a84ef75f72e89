//! The built atlas: where every vertex lives in the lattice, which pixels
//! carry data, which chart owns each block.

use crate::AtlasError;
use std::time::Duration;

/// What one lattice pixel holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Occupancy {
    /// No data: padding may set it freely.
    Free,
    /// The pixel of one vertex (exact value).
    Vertex,
    /// Inside a chart triangle (value interpolated from the corners); only in
    /// [`crate::Interior::Rasterised`] mode.
    Interior,
}

/// One chart as packed.
#[derive(Clone, Debug, PartialEq)]
pub struct Chart {
    /// Top-left pixel of its frame (a rectangle of whole blocks).
    pub origin: [u32; 2],
    /// Frame size in pixels, as placed; the chart owns only the blocks of
    /// the frame that its triangles or vertices touch.
    pub size: [u32; 2],
    /// Blocks it owns.
    pub blocks: usize,
    /// Whether the chart's u axis runs down the image (it may also be turned by half a turn).
    pub transposed: bool,
    /// Vertices it owns.
    pub vertices: usize,
    /// Normalised L2 stretch of its parameterization (`None` for the chart of
    /// vertices without faces).
    pub stretch: Option<f64>,
}

/// Figures about one build.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AtlasStats {
    /// Charts packed (including the chart of face-less vertices, if any).
    pub charts: usize,
    /// Seed pieces: clusters split into edge-connected pieces.
    pub seed_pieces: usize,
    /// Rounds of stretch-driven splitting.
    pub split_rounds: u32,
    /// Common scale: lattice pixels per unit of surface length.
    pub scale: f64,
    /// Pixels covered by chart triangles or holding a vertex.
    pub chart_pixels: usize,
    /// `chart_pixels` over lattice pixels.
    pub packing_efficiency: f64,
    /// Blocks owned by a chart over all blocks.
    pub block_efficiency: f64,
    /// Vertices moved off their rounded position to keep the map injective.
    pub moved_vertices: usize,
    /// Vertices handed from a chart with too few vertices to a neighbouring one.
    pub absorbed_vertices: usize,
    /// Vertices no face charts (isolated or only in dropped degenerate faces).
    pub faceless_vertices: usize,
    /// Area-weighted normalised L2 stretch over all charts (1 = no stretch).
    pub l2_stretch: f64,
    /// Largest chart stretch.
    pub max_chart_stretch: f64,
    /// Wall time of [`crate::build`].
    pub build_time: Duration,
}

/// Per-pixel barycentric recipe of a rasterised interior pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct InteriorSample {
    pub pixel: u32,
    pub vertices: [u32; 3],
    pub weights: [f32; 3],
}

/// A multi-chart atlas of one mesh in a `width × height` lattice.
#[derive(Clone, Debug, PartialEq)]
pub struct Atlas {
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) block: u32,
    pub(crate) vertex_pixels: Vec<[u16; 2]>,
    pub(crate) vertex_chart: Vec<u32>,
    pub(crate) occupancy: Vec<Occupancy>,
    pub(crate) block_chart: Vec<Option<u32>>,
    pub(crate) charts: Vec<Chart>,
    pub(crate) interior: Vec<InteriorSample>,
    pub(crate) stats: AtlasStats,
}

impl Atlas {
    /// Lattice width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Lattice height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Block side.
    pub fn block(&self) -> u32 {
        self.block
    }

    /// Pixel `[x, y]` of every vertex; no two vertices share one.
    pub fn vertex_pixels(&self) -> &[[u16; 2]] {
        &self.vertex_pixels
    }

    /// Chart of every vertex (index into [`Atlas::charts`]).
    pub fn vertex_charts(&self) -> &[u32] {
        &self.vertex_chart
    }

    /// The packed charts.
    pub fn charts(&self) -> &[Chart] {
        &self.charts
    }

    /// Occupancy of every pixel, row-major.
    pub fn occupancy(&self) -> &[Occupancy] {
        &self.occupancy
    }

    /// Pixels that carry data (vertex or rasterised interior), row-major.
    pub fn fixed_mask(&self) -> Vec<bool> {
        self.occupancy
            .iter()
            .map(|o| *o != Occupancy::Free)
            .collect()
    }

    /// Chart owning the block that holds pixel `(x, y)`, if any.
    pub fn chart_at(&self, x: u32, y: u32) -> Option<u32> {
        if x >= self.width || y >= self.height {
            return None;
        }
        let blocks_across = self.width / self.block;
        let i = (y / self.block) * blocks_across + x / self.block;
        self.block_chart.get(i as usize).copied().flatten()
    }

    /// Figures about the build.
    pub fn stats(&self) -> &AtlasStats {
        &self.stats
    }

    /// [`Atlas::splat`] that first checks there is one value per vertex.
    pub fn try_splat(&self, values: &[f32]) -> Result<Vec<f32>, AtlasError> {
        if values.len() != self.vertex_pixels.len() {
            return Err(AtlasError::Length {
                what: "per-vertex values",
                expected: self.vertex_pixels.len(),
                got: values.len(),
            });
        }
        Ok(self.splat(values))
    }

    /// Writes one value per vertex into a row-major image: vertex pixels get
    /// their value exactly, rasterised interior pixels the barycentric blend
    /// of their triangle's corners, free pixels 0. Vertices without a value
    /// (a short slice) read as 0 and extra values are ignored; use
    /// [`Atlas::try_splat`] to have a length mismatch reported instead.
    pub fn splat(&self, values: &[f32]) -> Vec<f32> {
        let mut image = vec![0.0f32; (self.width * self.height) as usize];
        for s in &self.interior {
            let v = s
                .vertices
                .map(|v| values.get(v as usize).copied().unwrap_or(0.0));
            if let Some(p) = image.get_mut(s.pixel as usize) {
                *p = s.weights[0] * v[0] + s.weights[1] * v[1] + s.weights[2] * v[2];
            }
        }
        for (v, px) in self.vertex_pixels.iter().enumerate() {
            let i = px[1] as usize * self.width as usize + px[0] as usize;
            if let Some(p) = image.get_mut(i) {
                *p = values.get(v).copied().unwrap_or(0.0);
            }
        }
        image
    }
}

/// Reads the value of every vertex back from a row-major image of the given
/// width (the decoder's side: it only needs the vertex pixels).
pub fn sample(
    vertex_pixels: &[[u16; 2]],
    width: u32,
    image: &[f32],
) -> Result<Vec<f32>, AtlasError> {
    vertex_pixels
        .iter()
        .enumerate()
        .map(|(vertex, &[x, y])| {
            let i = y as usize * width as usize + x as usize;
            if u32::from(x) >= width {
                None
            } else {
                image.get(i).copied()
            }
            .ok_or(AtlasError::PixelOutside {
                vertex,
                x,
                y,
                width,
                pixels: image.len(),
            })
        })
        .collect()
}
