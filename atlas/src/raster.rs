//! Pixel geometry on the lattice: rounding a point to a pixel of a rectangle, scanning a
//! triangle's pixel centres with their barycentric weights, finding the nearest free pixel.

/// Marks a pixel without a vertex in the vertex grid.
pub(crate) const NO_VERTEX: u32 = u32::MAX;

/// Nearest pixel of `rect` (x0, y0, width, height) to a point.
pub(crate) fn clamp_pixel(p: [f64; 2], rect: [u32; 4]) -> [u32; 2] {
    let [x0, y0, w, h] = rect;
    let cx = p[0].round().clamp(f64::from(x0), f64::from(x0 + w - 1)) as u32;
    let cy = p[1].round().clamp(f64::from(y0), f64::from(y0 + h - 1)) as u32;
    [cx, cy]
}

/// Nearest pixel to `target` without a vertex, among the given blocks.
pub(crate) fn nearest_free(
    grid: &[u32],
    width: u32,
    block: u32,
    blocks: &[(u32, u32)],
    target: [u32; 2],
) -> Option<[u32; 2]> {
    let mut best: Option<(i64, [u32; 2])> = None;
    for &(bx, by) in blocks {
        for y in by * block..(by + 1) * block {
            for x in bx * block..(bx + 1) * block {
                if grid[(y * width + x) as usize] != NO_VERTEX {
                    continue;
                }
                let d = (i64::from(x) - i64::from(target[0])).pow(2)
                    + (i64::from(y) - i64::from(target[1])).pow(2);
                if best.is_none_or(|(bd, _)| d < bd) {
                    best = Some((d, [x, y]));
                }
            }
        }
    }
    best.map(|(_, p)| p)
}

/// Rasterises a triangle's pixel centres inside `rect`, calling `hit` with
/// the pixel and barycentric weights.
pub(crate) fn rasterise(c: [[f64; 2]; 3], rect: [u32; 4], mut hit: impl FnMut([u32; 2], [f64; 3])) {
    let det = (c[1][0] - c[0][0]) * (c[2][1] - c[0][1]) - (c[2][0] - c[0][0]) * (c[1][1] - c[0][1]);
    if !(det.abs() > 1e-12) {
        return;
    }
    let [x0, y0, w, h] = rect;
    let lo = |a: usize, r0: u32| {
        c.iter()
            .map(|p| p[a])
            .fold(f64::INFINITY, f64::min)
            .ceil()
            .max(f64::from(r0)) as u32
    };
    let hi = |a: usize, r0: u32, n: u32| {
        c.iter()
            .map(|p| p[a])
            .fold(f64::NEG_INFINITY, f64::max)
            .floor()
            .min(f64::from(r0 + n - 1))
    };
    let (xa, ya) = (lo(0, x0), lo(1, y0));
    let (xb, yb) = (hi(0, x0, w), hi(1, y0, h));
    if xb < f64::from(xa) || yb < f64::from(ya) {
        return;
    }
    for y in ya..=yb as u32 {
        for x in xa..=xb as u32 {
            let (px, py) = (f64::from(x), f64::from(y));
            let l1 =
                ((px - c[0][0]) * (c[2][1] - c[0][1]) - (c[2][0] - c[0][0]) * (py - c[0][1])) / det;
            let l2 =
                ((c[1][0] - c[0][0]) * (py - c[0][1]) - (px - c[0][0]) * (c[1][1] - c[0][1])) / det;
            let l0 = 1.0 - l1 - l2;
            let eps = -1e-9;
            if l0 >= eps && l1 >= eps && l2 >= eps {
                hit([x, y], [l0, l1, l2]);
            }
        }
    }
}
