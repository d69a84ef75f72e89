//! Step 5 of the build: writes the packed charts into the lattice. Each chart claims its blocks;
//! each vertex takes its rounded pixel, or the nearest free pixel of its chart's blocks when that
//! one is taken, so the map is injective; the pixels of the chart triangles become interior
//! samples (barycentric recipes) in [`Interior::Rasterised`] mode.

use crate::atlas::{Chart, InteriorSample, Occupancy};
use crate::layout::{ChartLayout, Shape};
use crate::pack::{Orientation, Placement};
use crate::raster::{clamp_pixel, nearest_free, rasterise, NO_VERTEX};
use crate::{AtlasOptions, Interior};

/// Where one chart sits: maps its local pixels to lattice pixels.
struct Frame {
    origin: [f64; 2],
    /// Local frame size in pixels.
    size: [f64; 2],
    orientation: Orientation,
}

impl Frame {
    fn to_lattice(&self, local: [f64; 2]) -> [f64; 2] {
        let p = self.orientation.apply(local, self.size[0], self.size[1]);
        [self.origin[0] + p[0], self.origin[1] + p[1]]
    }
}

/// One chart at its place and scale: what writing it into the lattice needs.
struct Placed<'a> {
    index: u32,
    layout: &'a ChartLayout,
    scale: f64,
    /// Local pixel offset of the chart's 2D minimum.
    offset: [f64; 2],
    /// The lattice blocks it owns.
    blocks: Vec<(u32, u32)>,
    /// Its local frame (x0, y0, width, height) in pixels.
    rect: [u32; 4],
    frame: Frame,
}

impl<'a> Placed<'a> {
    fn new(
        index: u32,
        layout: &'a ChartLayout,
        shape: &Shape,
        place: &Placement,
        scale: f64,
        block: u32,
    ) -> Self {
        let fp = &shape.footprint;
        let rect = [0, 0, fp.width * block, fp.height * block];
        Placed {
            index,
            layout,
            scale,
            offset: shape.offset,
            blocks: place.cells(fp).collect(),
            rect,
            frame: Frame {
                origin: [f64::from(place.bx * block), f64::from(place.by * block)],
                size: [f64::from(rect[2]), f64::from(rect[3])],
                orientation: place.orientation,
            },
        }
    }

    /// Local pixel position of a 2D chart point.
    fn local(&self, uv: [f64; 2]) -> [f64; 2] {
        self.layout.local(uv, self.scale, self.offset)
    }

    /// Lattice pixel of a local pixel position.
    fn lattice_pixel(&self, local: [f64; 2]) -> [u32; 2] {
        let p = self.frame.to_lattice(local);
        [p[0].round() as u32, p[1].round() as u32]
    }

    /// Where the chart's `k`-th owned vertex, at 2D position `uv`, would go.
    fn target(&self, k: usize, uv: [f64; 2]) -> [u32; 2] {
        if self.layout.faceless {
            let k = k as u32;
            self.lattice_pixel([f64::from(k % self.rect[2]), f64::from(k / self.rect[2])])
        } else {
            self.lattice_pixel(clamp_pixel(self.local(uv), self.rect).map(f64::from))
        }
    }

    /// The chart as packed.
    fn chart(&self, place: &Placement, block: u32) -> Chart {
        let (ow, oh) = if place.orientation.transposed {
            (self.rect[3], self.rect[2])
        } else {
            (self.rect[2], self.rect[3])
        };
        Chart {
            origin: [place.bx * block, place.by * block],
            size: [ow, oh],
            blocks: self.blocks.len(),
            transposed: place.orientation.transposed,
            vertices: self.layout.owned.len(),
            stretch: self
                .layout
                .stretch
                .value()
                .filter(|_| !self.layout.faceless),
        }
    }
}

/// The lattice as the charts are written into it.
pub(crate) struct Lattice {
    width: u32,
    block: u32,
    interior_mode: Interior,
    /// Vertex of each pixel, [`NO_VERTEX`] where none.
    grid: Vec<u32>,
    /// Pixels covered by a chart triangle or holding a vertex.
    covered: Vec<bool>,
    pub vertex_pixels: Vec<[u16; 2]>,
    pub vertex_chart: Vec<u32>,
    pub block_chart: Vec<Option<u32>>,
    pub occupancy: Vec<Occupancy>,
    pub interior: Vec<InteriorSample>,
    pub charts: Vec<Chart>,
    /// Vertices moved off their rounded pixel.
    pub moved: usize,
}

impl Lattice {
    /// Writes the charts, with their shapes at `scale` and their placements, into an empty
    /// lattice for a mesh of `vertices` vertices.
    pub(crate) fn write(
        charts: &[ChartLayout],
        shapes: &[Shape],
        placements: &[Placement],
        scale: f64,
        triangles: &[[u32; 3]],
        vertices: usize,
        opts: &AtlasOptions,
    ) -> Self {
        let (width, height, block) = (opts.width, opts.height, opts.block);
        let pixels = (width * height) as usize;
        let mut lattice = Lattice {
            width,
            block,
            interior_mode: opts.interior,
            grid: vec![NO_VERTEX; pixels],
            covered: vec![false; pixels],
            vertex_pixels: vec![[0u16; 2]; vertices],
            vertex_chart: vec![0u32; vertices],
            block_chart: vec![None; ((width / block) * (height / block)) as usize],
            occupancy: vec![Occupancy::Free; pixels],
            interior: Vec::new(),
            charts: Vec::with_capacity(charts.len()),
            moved: 0,
        };
        for (ci, ((layout, shape), place)) in charts.iter().zip(shapes).zip(placements).enumerate()
        {
            let placed = Placed::new(ci as u32, layout, shape, place, scale, block);
            lattice.claim_blocks(&placed);
            lattice.place_vertices(&placed);
            lattice.rasterise_faces(&placed, triangles);
            lattice.charts.push(placed.chart(place, block));
        }
        lattice
    }

    /// Pixels covered by a chart triangle or holding a vertex.
    pub(crate) fn chart_pixels(&self) -> usize {
        self.covered.iter().filter(|&&c| c).count()
    }

    fn claim_blocks(&mut self, placed: &Placed) {
        let blocks_across = self.width / self.block;
        for &(bx, by) in &placed.blocks {
            self.block_chart[(by * blocks_across + bx) as usize] = Some(placed.index);
        }
    }

    fn place_vertices(&mut self, placed: &Placed) {
        let width = self.width;
        for (k, &(v, uv)) in placed.layout.owned.iter().enumerate() {
            let target = placed.target(k, uv);
            let mut at = target;
            if self.grid[(at[1] * width + at[0]) as usize] != NO_VERTEX {
                // The chart's blocks hold a pixel per owned vertex, so this finds one.
                at = nearest_free(&self.grid, width, self.block, &placed.blocks, target)
                    .unwrap_or(target);
                self.moved += 1;
            }
            let i = (at[1] * width + at[0]) as usize;
            self.grid[i] = v;
            self.occupancy[i] = Occupancy::Vertex;
            self.covered[i] = true;
            self.vertex_pixels[v as usize] = [at[0] as u16, at[1] as u16];
            self.vertex_chart[v as usize] = placed.index;
        }
    }

    fn rasterise_faces(&mut self, placed: &Placed, triangles: &[[u32; 3]]) {
        let (width, block) = (self.width, self.block);
        let blocks_across = width / block;
        for (f, corners) in &placed.layout.faces {
            let local = corners.map(|uv| placed.local(uv));
            let tri = triangles[*f];
            rasterise(local, placed.rect, |p, w| {
                let [x, y] = placed.lattice_pixel(p.map(f64::from));
                let i = (y * width + x) as usize;
                if self.covered[i]
                    || self.block_chart[((y / block) * blocks_across + x / block) as usize]
                        != Some(placed.index)
                {
                    return;
                }
                self.covered[i] = true;
                if self.interior_mode == Interior::Rasterised {
                    self.occupancy[i] = Occupancy::Interior;
                    self.interior.push(InteriorSample {
                        pixel: i as u32,
                        vertices: tri,
                        weights: w.map(|x| x as f32),
                    });
                }
            });
        }
    }
}
