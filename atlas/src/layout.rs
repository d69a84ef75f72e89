//! Charts before packing: each chart's 2D extent, owned vertices and faces ([`ChartLayout`]), and
//! at a given scale the blocks it needs ([`Shape`]).

use crate::pack::Footprint;
use crate::raster::{clamp_pixel, rasterise};
use crate::stretch::StretchSum;
use crate::unwrap::Flattening;

/// A chart before placement: its 2D extent and the vertices it owns.
pub(crate) struct ChartLayout {
    /// Smallest 2D corner coordinate, surface units.
    pub min: [f64; 2],
    /// Extent, surface units (zero for the face-less chart).
    pub extent: [f64; 2],
    /// Owned vertices and their 2D position.
    pub owned: Vec<(u32, [f64; 2])>,
    /// Faces to rasterise and their 2D corners.
    pub faces: Vec<(usize, [[f64; 2]; 3])>,
    /// Stretch sums (empty for the face-less chart).
    pub stretch: StretchSum,
    /// Whether this chart holds the face-less vertices in a plain grid.
    pub faceless: bool,
}

/// A chart at one scale: its local frame and the blocks it needs.
pub(crate) struct Shape {
    pub footprint: Footprint,
    /// Local pixel offset of the 2D minimum (centres the chart in its frame).
    pub offset: [f64; 2],
}

impl ChartLayout {
    /// Local pixel position of a 2D point at scale `s`.
    pub(crate) fn local(&self, uv: [f64; 2], s: f64, offset: [f64; 2]) -> [f64; 2] {
        [0, 1].map(|a| (uv[a] - self.min[a]) * s + offset[a])
    }

    /// The blocks the chart's triangles and vertices touch at scale `s`,
    /// or its whole frame when those hold fewer pixels than it has vertices.
    /// `None` when the frame cannot fit a `grid` of blocks in any orientation.
    pub(crate) fn shape(&self, s: f64, block: u32, grid: [u32; 2]) -> Option<Shape> {
        let n = self.owned.len() as u64;
        let per_block = u64::from(block) * u64::from(block);
        let full = |bw: u32, bh: u32| Footprint {
            width: bw,
            height: bh,
            cells: (0..bh).flat_map(|y| (0..bw).map(move |x| (x, y))).collect(),
        };
        if self.faceless {
            let nb = n.div_ceil(per_block).max(1);
            let bw = (nb as f64).sqrt().ceil().max(1.0) as u32;
            let bh = nb.div_ceil(u64::from(bw)) as u32;
            return Some(Shape {
                footprint: full(bw, bh),
                offset: [0.0; 2],
            });
        }
        let px = self.extent.map(|e| (e * s).round().min(1e6) as u32 + 1);
        let (bw, bh) = (px[0].div_ceil(block), px[1].div_ceil(block));
        if bw.max(bh) > grid[0].max(grid[1]) || bw.min(bh) > grid[0].min(grid[1]) {
            return None;
        }
        let offset = [0, 1].map(|a| f64::from(([bw, bh][a] * block - px[a]) / 2));
        let rect = [0, 0, bw * block, bh * block];
        let mut touched = vec![false; (bw * bh) as usize];
        let mut mark = |p: [u32; 2]| touched[((p[1] / block) * bw + p[0] / block) as usize] = true;
        for (_, uv) in &self.owned {
            mark(clamp_pixel(self.local(*uv, s, offset), rect));
        }
        for (_, corners) in &self.faces {
            let c = corners.map(|uv| self.local(uv, s, offset));
            rasterise(c, rect, |p, _| mark(p));
        }
        let cells: Vec<(u32, u32)> = (0..bh)
            .flat_map(|y| (0..bw).map(move |x| (x, y)))
            .filter(|&(x, y)| touched[(y * bw + x) as usize])
            .collect();
        if cells.len() as u64 * per_block >= n {
            return Some(Shape {
                footprint: Footprint {
                    width: bw,
                    height: bh,
                    cells,
                },
                offset,
            });
        }
        let (mut gw, mut gh) = (u64::from(bw), u64::from(bh));
        while gw * gh * per_block < n {
            if gw <= gh {
                gw += 1;
            } else {
                gh += 1;
            }
        }
        Some(Shape {
            footprint: full(gw as u32, gh as u32),
            offset,
        })
    }
}

/// One layout per chart that owns a vertex, plus one for the face-less vertices if any.
pub(crate) fn layouts(flat: &Flattening, owner: &[Option<(u32, [f64; 2])>]) -> Vec<ChartLayout> {
    let mut charts: Vec<ChartLayout> = (0..flat.charts as usize)
        .map(|c| ChartLayout {
            min: [f64::INFINITY; 2],
            extent: [f64::NEG_INFINITY; 2],
            owned: Vec::new(),
            faces: Vec::new(),
            stretch: flat.chart_stretch.get(c).copied().unwrap_or_default(),
            faceless: false,
        })
        .collect();
    let mut max = vec![[f64::NEG_INFINITY; 2]; charts.len()];
    for (f, chart) in flat.face_chart.iter().enumerate() {
        let Some(c) = chart else { continue };
        let layout = &mut charts[*c as usize];
        layout.faces.push((f, flat.corner_uv[f]));
        for uv in flat.corner_uv[f] {
            for a in 0..2 {
                layout.min[a] = layout.min[a].min(uv[a]);
                max[*c as usize][a] = max[*c as usize][a].max(uv[a]);
            }
        }
    }
    let mut faceless = Vec::new();
    for (v, o) in owner.iter().enumerate() {
        match o {
            Some((c, uv)) => charts[*c as usize].owned.push((v as u32, *uv)),
            None => faceless.push((v as u32, [0.0, 0.0])),
        }
    }
    for (layout, hi) in charts.iter_mut().zip(&max) {
        layout.extent = [0, 1].map(|a| (hi[a] - layout.min[a]).max(0.0));
    }
    // A chart whose every vertex is owned elsewhere carries no data: drop it,
    // its area is left to padding.
    charts.retain(|c| !c.owned.is_empty());
    if !faceless.is_empty() {
        charts.push(ChartLayout {
            min: [0.0; 2],
            extent: [0.0; 2],
            owned: faceless,
            faces: Vec::new(),
            stretch: StretchSum::default(),
            faceless: true,
        });
    }
    charts
}
