//! Blocks with no fixed pixel: copied from the previous frame (P-frames: the codec skips them) or, in
//! intra frames, set flat (a DC value and an end-of-block code for JPEG) at a level chosen by
//! [`crate::EmptyBlocks`].

use crate::grid::BlockGrid;

/// Copies `previous` into every block not `filled`, marking them filled and their pixels `held`.
pub(crate) fn copy_from_previous(
    grid: &BlockGrid,
    image: &mut [f32],
    previous: &[f32],
    filled: &mut [bool],
    held: &mut [bool],
) {
    for (b, done) in filled.iter_mut().enumerate() {
        if *done {
            continue;
        }
        for i in grid.pixels(grid.rect(b)) {
            image[i] = previous[i];
            held[i] = true;
        }
        *done = true;
    }
}

/// Sets every block not `filled` to the mean of the block before it in raster order (which is
/// filled by then), or to `first` while no block before it is.
pub(crate) fn fill_from_raster_previous(
    grid: &BlockGrid,
    image: &mut [f32],
    filled: &mut [bool],
    first: f32,
) {
    let mut previous_mean = first;
    for (b, done) in filled.iter_mut().enumerate() {
        let rect = grid.rect(b);
        if !*done {
            grid.pixels(rect).for_each(|i| image[i] = previous_mean);
            *done = true;
        } else {
            let sum: f64 = grid.pixels(rect).map(|i| f64::from(image[i])).sum();
            previous_mean = (sum / (rect.w * rect.h) as f64) as f32;
        }
    }
}

/// Sets every block not `filled` to `value`.
pub(crate) fn fill_flat(grid: &BlockGrid, image: &mut [f32], filled: &mut [bool], value: f32) {
    for (b, done) in filled.iter_mut().enumerate() {
        if !*done {
            grid.pixels(grid.rect(b)).for_each(|i| image[i] = value);
            *done = true;
        }
    }
}

/// Fills every block not `filled` flat, growing outwards from the filled ones: each pass sets the
/// blocks that touch a filled block (4-neighbours) to the mean of the touching border pixels.
/// With no filled block at all, everything becomes `fallback`.
pub(crate) fn fill_flat_from_neighbours(
    grid: &BlockGrid,
    image: &mut [f32],
    filled: &mut [bool],
    fallback: f32,
) {
    if !filled.iter().any(|&f| f) {
        image.fill(fallback);
        filled.fill(true);
        return;
    }
    let width = grid.width;
    let mut assignments: Vec<(usize, f32)> = Vec::new();
    while filled.iter().any(|&f| !f) {
        assignments.clear();
        for b in (0..grid.len()).filter(|&b| !filled[b]) {
            let rect = grid.rect(b);
            let (bx, by) = (b % grid.cols, b / grid.cols);
            let mut sum = 0.0f64;
            let mut count = 0usize;
            let mut take = |i: usize| {
                sum += f64::from(image[i]);
                count += 1;
            };
            if bx > 0 && filled[b - 1] {
                (rect.y0..rect.y0 + rect.h).for_each(|y| take(y * width + rect.x0 - 1));
            }
            if bx + 1 < grid.cols && filled[b + 1] {
                (rect.y0..rect.y0 + rect.h).for_each(|y| take(y * width + rect.x0 + rect.w));
            }
            if by > 0 && filled[b - grid.cols] {
                (rect.x0..rect.x0 + rect.w).for_each(|x| take((rect.y0 - 1) * width + x));
            }
            if by + 1 < grid.rows && filled[b + grid.cols] {
                (rect.x0..rect.x0 + rect.w).for_each(|x| take((rect.y0 + rect.h) * width + x));
            }
            if count > 0 {
                assignments.push((b, (sum / count as f64) as f32));
            }
        }
        if assignments.is_empty() {
            // Unreachable on a connected block grid; kept so a logic slip cannot loop forever.
            fill_flat(grid, image, filled, fallback);
            break;
        }
        for &(b, value) in &assignments {
            for i in grid.pixels(grid.rect(b)) {
                image[i] = value;
            }
            filled[b] = true;
        }
    }
}
