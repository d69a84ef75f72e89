//! The build pipeline, from mesh and partition to a packed, injective lattice atlas: check the
//! inputs, seed and flatten the charts, give every vertex one chart, find the scale at which the
//! charts pack, write them into the lattice, sum up the figures. Each stage lives in its own file.

use crate::atlas::{Atlas, AtlasStats};
use crate::charts::flatten;
use crate::input::check_input;
use crate::lattice::Lattice;
use crate::layout::{layouts, ChartLayout};
use crate::ownership::{absorb_small_charts, assign_owners};
use crate::scale::best_scale;
use crate::seed::{seeds, Seeds};
use crate::stretch::StretchSum;
use crate::unwrap::Flattening;
use crate::weld::welded;
use crate::{AtlasError, AtlasOptions};
use std::time::Instant;

/// Builds the atlas of a mesh whose vertices are partitioned into clusters
/// (one cluster id per vertex).
pub fn build(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    partition: &[u32],
    opts: &AtlasOptions,
) -> Result<Atlas, AtlasError> {
    let start = Instant::now();
    check_input(positions, triangles, partition, opts)?;
    let welded = if opts.weld {
        welded(positions, triangles)
    } else {
        triangles.to_vec()
    };
    let seeds = seeds(triangles, &welded, partition);
    let flat = flatten_seeds(positions, &welded, &seeds, opts)?;
    let (charts, absorbed) =
        owned_layouts(triangles, partition, &seeds, &flat, positions.len(), opts);
    let (scale, shapes, placements) = best_scale(&charts, opts)?;
    let lattice = Lattice::write(
        &charts,
        &shapes,
        &placements,
        scale,
        triangles,
        positions.len(),
        opts,
    );
    let mut stats = stats(&seeds, &flat, &charts, &lattice, scale, absorbed, opts);
    stats.build_time = start.elapsed();
    Ok(Atlas {
        width: opts.width,
        height: opts.height,
        block: opts.block,
        vertex_pixels: lattice.vertex_pixels,
        vertex_chart: lattice.vertex_chart,
        occupancy: lattice.occupancy,
        block_chart: lattice.block_chart,
        charts: lattice.charts,
        interior: lattice.interior,
        stats,
    })
}

/// Steps 1–2: the seed pieces flattened into charts (none for a mesh without faces), on the
/// welded triangles.
fn flatten_seeds(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    seeds: &Seeds,
    opts: &AtlasOptions,
) -> Result<Flattening, AtlasError> {
    if triangles.is_empty() {
        return Ok(Flattening {
            face_chart: Vec::new(),
            corner_uv: Vec::new(),
            charts: 0,
            chart_stretch: Vec::new(),
            split_rounds: 0,
        });
    }
    flatten(
        positions,
        triangles,
        &seeds.face_piece,
        seeds.pieces,
        opts.max_stretch,
        opts.max_split_rounds,
    )
}

/// Step 3: every vertex owned by one chart, small charts absorbed; returns the layouts of the
/// charts that own vertices and how many vertices were absorbed.
fn owned_layouts(
    triangles: &[[u32; 3]],
    partition: &[u32],
    seeds: &Seeds,
    flat: &Flattening,
    vertices: usize,
    opts: &AtlasOptions,
) -> (Vec<ChartLayout>, usize) {
    let mut owner = assign_owners(triangles, partition, &seeds.face_cluster, flat, vertices);
    let absorbed = absorb_small_charts(triangles, &mut owner, flat.charts, opts.min_chart_vertices);
    (layouts(flat, &owner), absorbed)
}

/// The build's figures; `build_time` is left at zero for the caller to set.
fn stats(
    seeds: &Seeds,
    flat: &Flattening,
    charts: &[ChartLayout],
    lattice: &Lattice,
    scale: f64,
    absorbed: usize,
    opts: &AtlasOptions,
) -> AtlasStats {
    let pixels = (opts.width * opts.height) as usize;
    let chart_pixels = lattice.chart_pixels();
    let owned_blocks = lattice.block_chart.iter().filter(|b| b.is_some()).count();
    let (total_stretch, max_chart_stretch) = stretch(charts, lattice);
    AtlasStats {
        charts: lattice.charts.len(),
        seed_pieces: seeds.pieces as usize,
        split_rounds: flat.split_rounds,
        scale,
        chart_pixels,
        packing_efficiency: chart_pixels as f64 / pixels as f64,
        block_efficiency: owned_blocks as f64 / lattice.block_chart.len().max(1) as f64,
        moved_vertices: lattice.moved,
        absorbed_vertices: absorbed,
        faceless_vertices: charts
            .iter()
            .filter(|c| c.faceless)
            .map(|c| c.owned.len())
            .sum(),
        l2_stretch: total_stretch.value().unwrap_or(1.0),
        max_chart_stretch,
        build_time: Default::default(),
    }
}

/// The stretch summed over the charts that have one, and the largest chart stretch.
fn stretch(charts: &[ChartLayout], lattice: &Lattice) -> (StretchSum, f64) {
    let mut total = StretchSum::default();
    let mut max: f64 = 0.0;
    for (layout, chart) in charts.iter().zip(&lattice.charts) {
        if let Some(s) = chart.stretch {
            total.merge(&layout.stretch);
            max = max.max(s);
        }
    }
    (total, max)
}
