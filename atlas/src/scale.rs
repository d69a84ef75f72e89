//! Step 4 of the build, packing: the largest common scale at which every chart's blocks fit the
//! lattice, with the chart shapes at that scale and their placements.

use crate::layout::{ChartLayout, Shape};
use crate::pack::{pack, Footprint, Placement};
use crate::{AtlasError, AtlasOptions};

/// The chart shapes at scale `s` and their placements, or `None` when they do not all fit.
fn try_pack(
    charts: &[ChartLayout],
    s: f64,
    opts: &AtlasOptions,
) -> Option<(Vec<Shape>, Vec<Placement>)> {
    let grid = [opts.width / opts.block, opts.height / opts.block];
    let shapes: Vec<Shape> = charts
        .iter()
        .map(|c| c.shape(s, opts.block, grid))
        .collect::<Option<_>>()?;
    let footprints: Vec<Footprint> = shapes.iter().map(|s| s.footprint.clone()).collect();
    let placed = pack(
        &footprints,
        opts.width / opts.block,
        opts.height / opts.block,
    )?;
    Some((shapes, placed))
}

/// A scale, the chart shapes at that scale and where they go.
pub(crate) type Packing = (f64, Vec<Shape>, Vec<Placement>);

/// Largest common scale at which every chart's blocks fit (bisection; the
/// greedy packer is not exactly monotonic in the scale, so this is the
/// largest scale found, not a proven optimum).
pub(crate) fn best_scale(
    charts: &[ChartLayout],
    opts: &AtlasOptions,
) -> Result<Packing, AtlasError> {
    let Some(at_zero) = try_pack(charts, 0.0, opts) else {
        return Err(charts_do_not_fit(charts, opts));
    };
    let area: f64 = charts.iter().map(|c| c.stretch.area_2d()).sum();
    let pixels = f64::from(opts.width) * f64::from(opts.height);
    // No chart set fits at a scale where its triangles alone outgrow the lattice.
    let mut hi = if area > 0.0 {
        (pixels / area).sqrt() * 1.01
    } else {
        0.0
    };
    let mut lo = 0.0;
    let mut best = at_zero;
    if hi > 0.0 {
        if let Some((shapes, placed)) = try_pack(charts, hi, opts) {
            return Ok((hi, shapes, placed));
        }
    }
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        match try_pack(charts, mid, opts) {
            Some(p) => {
                lo = mid;
                best = p;
            }
            None => hi = mid,
        }
        if hi - lo <= 1e-3 * hi {
            break;
        }
    }
    // The greedy packer can fail at one scale and succeed at a larger one:
    // look a little above the bisection's answer too.
    let mut found = lo;
    for k in 1..=24 {
        let s = lo * (1.0 + 0.025 * f64::from(k));
        if let Some(p) = try_pack(charts, s, opts) {
            found = s;
            best = p;
        }
    }
    Ok((found, best.0, best.1))
}

/// The error for charts that do not fit even at scale 0: the blocks they need and a square
/// lattice with room for twice as many.
fn charts_do_not_fit(charts: &[ChartLayout], opts: &AtlasOptions) -> AtlasError {
    let unbounded = [u32::MAX; 2];
    let blocks: usize = charts
        .iter()
        .filter_map(|c| c.shape(0.0, opts.block, unbounded))
        .map(|s| s.footprint.cells.len())
        .sum();
    let mut suggest = opts.width.max(opts.height).next_power_of_two();
    while ((suggest / opts.block) as usize).pow(2) < 2 * blocks && suggest < 16384 {
        suggest *= 2;
    }
    AtlasError::ChartsDoNotFit {
        charts: charts.len(),
        blocks,
        available: ((opts.width / opts.block) * (opts.height / opts.block)) as usize,
        block: opts.block,
        width: opts.width,
        height: opts.height,
        suggest,
    }
}
