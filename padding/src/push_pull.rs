//! Multigrid push–pull hole filling over the whole image (as MPEG V-PCC pads its geometry images).
//!
//! Push: halve the image repeatedly, each coarse pixel the weighted mean of its 2×2 children, its
//! weight min(1, Σ child weights) (fixed pixels weigh 1, free 0). Pull: from the 1×1 level down,
//! each pixel becomes w·own + (1 − w)·(bilinear upsample of the filled coarser level).

/// Fills every pixel with `held[i] == false` in place; held pixels are not written.
pub(crate) fn fill(image: &mut [f32], width: usize, height: usize, held: &[bool]) {
    let mut levels = vec![Level {
        width,
        height,
        value: image.iter().map(|&v| f64::from(v)).collect(),
        weight: held.iter().map(|&h| if h { 1.0 } else { 0.0 }).collect(),
    }];
    while let Some(fine) = levels.last().filter(|l| l.width > 1 || l.height > 1) {
        let coarse = fine.push();
        levels.push(coarse);
    }
    let mut filled = levels.pop().map(|l| l.value).unwrap_or_default();
    while let Some(level) = levels.pop() {
        filled = level.pull(coarse_dims(&level), &filled);
    }
    for ((pixel, &value), &h) in image.iter_mut().zip(&filled).zip(held) {
        if !h {
            *pixel = value as f32;
        }
    }
}

/// Size of the level one push above `level`.
fn coarse_dims(level: &Level) -> (usize, usize) {
    (level.width.div_ceil(2), level.height.div_ceil(2))
}

struct Level {
    width: usize,
    height: usize,
    value: Vec<f64>,
    weight: Vec<f64>,
}

impl Level {
    fn push(&self) -> Level {
        let (cw, ch) = coarse_dims(self);
        let mut value = vec![0.0; cw * ch];
        let mut weight = vec![0.0; cw * ch];
        for cy in 0..ch {
            for cx in 0..cw {
                let mut sum = 0.0;
                let mut total = 0.0;
                for y in 2 * cy..(2 * cy + 2).min(self.height) {
                    for x in 2 * cx..(2 * cx + 2).min(self.width) {
                        let w = self.weight[y * self.width + x];
                        sum += w * self.value[y * self.width + x];
                        total += w;
                    }
                }
                let c = cy * cw + cx;
                if total > 0.0 {
                    value[c] = sum / total;
                }
                weight[c] = total.min(1.0);
            }
        }
        Level {
            width: cw,
            height: ch,
            value,
            weight,
        }
    }

    /// This level with its holes filled from `coarse` (fully filled, `dims` in size).
    fn pull(&self, (cw, ch): (usize, usize), coarse: &[f64]) -> Vec<f64> {
        let sample = |x: usize, y: usize| coarse[y.min(ch - 1) * cw + x.min(cw - 1)];
        let mut out = Vec::with_capacity(self.value.len());
        for y in 0..self.height {
            // Fine pixel centre y + 0.5 sits at coarse coordinate (y + 0.5) / 2 − 0.5.
            let fy = ((y as f64 + 0.5) / 2.0 - 0.5).max(0.0);
            let (y0, ty) = (fy.floor() as usize, fy.fract());
            for x in 0..self.width {
                let fx = ((x as f64 + 0.5) / 2.0 - 0.5).max(0.0);
                let (x0, tx) = (fx.floor() as usize, fx.fract());
                let up = (1.0 - ty) * ((1.0 - tx) * sample(x0, y0) + tx * sample(x0 + 1, y0))
                    + ty * ((1.0 - tx) * sample(x0, y0 + 1) + tx * sample(x0 + 1, y0 + 1));
                let i = y * self.width + x;
                let w = self.weight[i];
                out.push(w * self.value[i] + (1.0 - w) * up);
            }
        }
        out
    }
}
