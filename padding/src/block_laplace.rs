//! The paper's padding (MCGV eq. 5–6): per block, free pixels minimise ψ(B) = Σ (B_p − B_q)² over the
//! 8-connected pixel pairs inside the block, fixed pixels held.
//!
//! Setting ∂ψ/∂B_p = 0 gives, for each free p, `deg(p)·B_p − Σ_{free q ~ p} B_q = Σ_{fixed h ~ p} B_h`,
//! where deg(p) is p's neighbour count inside the block (8 inside, 5 on an edge, 3 in a corner; the
//! paper writes 8 for all). The matrix is a graph Laplacian with the fixed pixels' rows removed; the
//! block's 8-connected grid is connected, so with one fixed pixel it is SPD and CG applies.

use crate::cg::{self, CgLimits, CgScratch};
use crate::grid::{BlockGrid, BlockRect};
use crate::PadStats;

/// Per-block system layout, reused across blocks.
#[derive(Debug, Default)]
pub(crate) struct BlockLaplace {
    /// Image index of each unknown.
    pixel_of: Vec<usize>,
    /// Unknown number of each block pixel (usize::MAX when fixed), block-row-major.
    unknown_of: Vec<usize>,
    /// For each unknown, its neighbour count and the range of its free neighbours in `links`.
    degree: Vec<f64>,
    link_start: Vec<usize>,
    links: Vec<usize>,
    rhs: Vec<f64>,
    x: Vec<f64>,
    scratch: CgScratch,
}

impl BlockLaplace {
    /// Pads the free pixels of one block that holds at least one fixed pixel.
    pub fn pad_block(
        &mut self,
        grid: &BlockGrid,
        rect: BlockRect,
        image: &mut [f32],
        fixed: &[bool],
        limits: CgLimits,
        stats: &mut PadStats,
    ) {
        let width = grid.width;
        self.pixel_of.clear();
        self.unknown_of.clear();
        let mut fixed_sum = 0.0f64;
        let mut fixed_count = 0usize;
        for i in grid.pixels(rect) {
            if fixed[i] {
                self.unknown_of.push(usize::MAX);
                fixed_sum += f64::from(image[i]);
                fixed_count += 1;
            } else {
                self.unknown_of.push(self.pixel_of.len());
                self.pixel_of.push(i);
            }
        }
        if self.pixel_of.is_empty() || fixed_count == 0 {
            return;
        }
        self.degree.clear();
        self.link_start.clear();
        self.links.clear();
        self.rhs.clear();
        for &i in &self.pixel_of {
            let (x, y) = (i % width - rect.x0, i / width - rect.y0);
            let mut degree = 0.0;
            let mut rhs = 0.0;
            self.link_start.push(self.links.len());
            for ny in y.saturating_sub(1)..=(y + 1).min(rect.h - 1) {
                for nx in x.saturating_sub(1)..=(x + 1).min(rect.w - 1) {
                    if (nx, ny) == (x, y) {
                        continue;
                    }
                    degree += 1.0;
                    match self.unknown_of[ny * rect.w + nx] {
                        usize::MAX => {
                            rhs += f64::from(image[(rect.y0 + ny) * width + rect.x0 + nx]);
                        }
                        u => self.links.push(u),
                    }
                }
            }
            self.degree.push(degree);
            self.rhs.push(rhs);
        }
        self.link_start.push(self.links.len());
        // The fixed pixels' mean is the zeroth-order answer; CG corrects it.
        let start = fixed_sum / fixed_count as f64;
        self.x.clear();
        self.x.resize(self.pixel_of.len(), start);
        let (degree, link_start, links) = (&self.degree, &self.link_start, &self.links);
        let report = cg::solve(
            |v, out| cg::laplacian(degree, link_start, links, v, out),
            &self.rhs,
            &mut self.x,
            limits,
            &mut self.scratch,
        );
        stats.record(report);
        for (&i, &value) in self.pixel_of.iter().zip(&self.x) {
            image[i] = value as f32;
        }
    }
}
