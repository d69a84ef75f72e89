//! ψ minimised over the whole image instead of per block: every free pixel (empty blocks included)
//! solves `deg(p)·x_p − Σ_{free q ~ p} x_q = Σ_{held h ~ p} x_h` on the image's 8-connected grid.
//! Smooth across block borders, where the per-block solve leaves steps that cost AC coefficients.
//! One system of up to width×height unknowns: CG warm-started by push–pull, which already has the
//! low frequencies right, so the iteration cap mostly trims high-frequency error.

use crate::cg::{self, CgLimits, CgScratch};
use crate::{push_pull, PadStats};

/// Fills every pixel with `held[i] == false`; needs at least one held pixel.
pub(crate) fn fill(
    image: &mut [f32],
    width: usize,
    height: usize,
    held: &[bool],
    limits: CgLimits,
    stats: &mut PadStats,
) {
    push_pull::fill(image, width, height, held);
    let mut unknown_of = vec![usize::MAX; image.len()];
    let mut pixel_of = Vec::new();
    for (i, &h) in held.iter().enumerate() {
        if !h {
            unknown_of[i] = pixel_of.len();
            pixel_of.push(i);
        }
    }
    if pixel_of.is_empty() {
        return;
    }
    let mut degree = Vec::with_capacity(pixel_of.len());
    let mut link_start = Vec::with_capacity(pixel_of.len() + 1);
    let mut links = Vec::with_capacity(pixel_of.len() * 8);
    let mut rhs = Vec::with_capacity(pixel_of.len());
    for &i in &pixel_of {
        let (x, y) = (i % width, i / width);
        let mut d = 0.0;
        let mut b = 0.0;
        link_start.push(links.len());
        for ny in y.saturating_sub(1)..=(y + 1).min(height - 1) {
            for nx in x.saturating_sub(1)..=(x + 1).min(width - 1) {
                if (nx, ny) == (x, y) {
                    continue;
                }
                d += 1.0;
                let n = ny * width + nx;
                match unknown_of[n] {
                    usize::MAX => b += f64::from(image[n]),
                    u => links.push(u),
                }
            }
        }
        degree.push(d);
        rhs.push(b);
    }
    link_start.push(links.len());
    let mut x: Vec<f64> = pixel_of.iter().map(|&i| f64::from(image[i])).collect();
    let report = cg::solve(
        |v, out| cg::laplacian(&degree, &link_start, &links, v, out),
        &rhs,
        &mut x,
        limits,
        &mut CgScratch::default(),
    );
    stats.record(report);
    for (&i, &value) in pixel_of.iter().zip(&x) {
        image[i] = value as f32;
    }
}
