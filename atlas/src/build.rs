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
use std::time::{Duration, Instant};

/// Builds the atlas of a mesh whose vertices are partitioned into clusters
/// (one cluster id per vertex).
pub fn build(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    partition: &[u32],
    opts: &AtlasOptions,
) -> Result<Atlas, AtlasError> {
    Flattened::new(positions, triangles, partition, opts)?.lay_out(opts.width, opts.height)
}

/// A mesh's charts flattened and every vertex given one (steps 1–3), before any lattice: most of
/// a build's time (uvunwrap's solves) and the same whatever the lattice's size, so a caller that
/// tries sizes until the charts fit flattens once and lays the charts out on each size.
pub struct Flattened<'a> {
    positions: &'a [[f32; 3]],
    triangles: &'a [[u32; 3]],
    partition: &'a [u32],
    opts: AtlasOptions,
    seeds: Seeds,
    flat: Flattening,
    charts: Vec<ChartLayout>,
    absorbed: usize,
    time: Duration,
}

impl<'a> Flattened<'a> {
    /// Checks the inputs (for `opts`'s lattice size too) and flattens the charts with `opts`.
    pub fn new(
        positions: &'a [[f32; 3]],
        triangles: &'a [[u32; 3]],
        partition: &'a [u32],
        opts: &AtlasOptions,
    ) -> Result<Self, AtlasError> {
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
        Ok(Self {
            positions,
            triangles,
            partition,
            opts: opts.clone(),
            seeds,
            flat,
            charts,
            absorbed,
            time: start.elapsed(),
        })
    }

    /// The atlas on a `width × height` lattice (the flattening's other options): errors as
    /// [`build`] does, e.g. when the charts do not fit.
    pub fn lay_out(&self, width: u32, height: u32) -> Result<Atlas, AtlasError> {
        let start = Instant::now();
        let opts = AtlasOptions {
            width,
            height,
            ..self.opts.clone()
        };
        let (positions, triangles) = (self.positions, self.triangles);
        check_input(positions, triangles, self.partition, &opts)?;
        let (scale, shapes, placements) = best_scale(&self.charts, &opts)?;
        let lattice = Lattice::write(
            &self.charts,
            &shapes,
            &placements,
            scale,
            triangles,
            positions.len(),
            &opts,
        );
        let (seeds, flat, charts) = (&self.seeds, &self.flat, &self.charts);
        let mut stats = stats(seeds, flat, charts, &lattice, scale, self.absorbed, &opts);
        stats.build_time = self.time + start.elapsed();
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
