//! From mesh and partition to a packed, injective lattice atlas.

use crate::atlas::{Atlas, AtlasStats, Chart, InteriorSample, Occupancy};
use crate::input::check_input;
use crate::layout::layouts;
use crate::ownership::{absorb_small_charts, assign_owners};
use crate::pack::Orientation;
use crate::raster::{clamp_pixel, nearest_free, rasterise, NO_VERTEX};
use crate::scale::best_scale;
use crate::seed::seeds;
use crate::stretch::StretchSum;
use crate::unwrap::{flatten, Flattening};
use crate::{AtlasError, AtlasOptions, Interior};
use std::time::Instant;

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
    let seeds = seeds(triangles, partition);
    let flat = if triangles.is_empty() {
        Flattening {
            face_chart: Vec::new(),
            corner_uv: Vec::new(),
            charts: 0,
            chart_stretch: Vec::new(),
            split_rounds: 0,
        }
    } else {
        flatten(
            positions,
            triangles,
            &seeds.face_piece,
            opts.max_stretch,
            opts.max_split_rounds,
        )?
    };
    let mut owner = assign_owners(
        triangles,
        partition,
        &seeds.face_cluster,
        &flat,
        positions.len(),
    );
    let absorbed = absorb_small_charts(triangles, &mut owner, flat.charts, opts.min_chart_vertices);
    let charts = layouts(&flat, &owner);
    let (scale, shapes, placements) = best_scale(&charts, opts)?;

    let (width, height, block) = (opts.width, opts.height, opts.block);
    let pixels = (width * height) as usize;
    let blocks_across = width / block;
    let mut grid = vec![NO_VERTEX; pixels];
    let mut vertex_pixels = vec![[0u16; 2]; positions.len()];
    let mut vertex_chart = vec![0u32; positions.len()];
    let mut block_chart = vec![None; ((width / block) * (height / block)) as usize];
    let mut occupancy = vec![Occupancy::Free; pixels];
    let mut interior = Vec::new();
    let mut covered = vec![false; pixels];
    let mut packed = Vec::with_capacity(charts.len());
    let mut moved = 0usize;
    let mut total_stretch = StretchSum::default();
    let mut max_chart_stretch: f64 = 0.0;

    for (ci, ((layout, shape), place)) in charts.iter().zip(&shapes).zip(&placements).enumerate() {
        let fp = &shape.footprint;
        let blocks: Vec<(u32, u32)> = place.cells(fp).collect();
        for &(bx, by) in &blocks {
            block_chart[(by * blocks_across + bx) as usize] = Some(ci as u32);
        }
        let local_rect = [0, 0, fp.width * block, fp.height * block];
        let frame = Frame {
            origin: [f64::from(place.bx * block), f64::from(place.by * block)],
            size: [f64::from(local_rect[2]), f64::from(local_rect[3])],
            orientation: place.orientation,
        };
        let lattice_pixel = |local: [f64; 2]| {
            let p = frame.to_lattice(local);
            [p[0].round() as u32, p[1].round() as u32]
        };
        for (k, &(v, uv)) in layout.owned.iter().enumerate() {
            let target = if layout.faceless {
                let k = k as u32;
                lattice_pixel([f64::from(k % local_rect[2]), f64::from(k / local_rect[2])])
            } else {
                lattice_pixel(
                    clamp_pixel(layout.local(uv, scale, shape.offset), local_rect).map(f64::from),
                )
            };
            let mut at = target;
            if grid[(at[1] * width + at[0]) as usize] != NO_VERTEX {
                // The chart's blocks hold a pixel per owned vertex, so this finds one.
                at = nearest_free(&grid, width, block, &blocks, target).unwrap_or(target);
                moved += 1;
            }
            grid[(at[1] * width + at[0]) as usize] = v;
            occupancy[(at[1] * width + at[0]) as usize] = Occupancy::Vertex;
            covered[(at[1] * width + at[0]) as usize] = true;
            vertex_pixels[v as usize] = [at[0] as u16, at[1] as u16];
            vertex_chart[v as usize] = ci as u32;
        }
        for (f, corners) in &layout.faces {
            let local = corners.map(|uv| layout.local(uv, scale, shape.offset));
            let tri = triangles[*f];
            rasterise(local, local_rect, |p, w| {
                let [x, y] = lattice_pixel(p.map(f64::from));
                let i = (y * width + x) as usize;
                if covered[i]
                    || block_chart[((y / block) * blocks_across + x / block) as usize]
                        != Some(ci as u32)
                {
                    return;
                }
                covered[i] = true;
                if opts.interior == Interior::Rasterised {
                    occupancy[i] = Occupancy::Interior;
                    interior.push(InteriorSample {
                        pixel: i as u32,
                        vertices: tri,
                        weights: w.map(|x| x as f32),
                    });
                }
            });
        }
        let stretch = layout.stretch.value().filter(|_| !layout.faceless);
        if let Some(s) = stretch {
            total_stretch.merge(&layout.stretch);
            max_chart_stretch = max_chart_stretch.max(s);
        }
        let (ow, oh) = if place.orientation.transposed {
            (local_rect[3], local_rect[2])
        } else {
            (local_rect[2], local_rect[3])
        };
        packed.push(Chart {
            origin: [place.bx * block, place.by * block],
            size: [ow, oh],
            blocks: blocks.len(),
            transposed: place.orientation.transposed,
            vertices: layout.owned.len(),
            stretch,
        });
    }

    let chart_pixels = covered.iter().filter(|&&c| c).count();
    let owned_blocks = block_chart.iter().filter(|b| b.is_some()).count();
    let stats = AtlasStats {
        charts: packed.len(),
        seed_pieces: seeds.pieces as usize,
        split_rounds: flat.split_rounds,
        scale,
        chart_pixels,
        packing_efficiency: chart_pixels as f64 / pixels as f64,
        block_efficiency: owned_blocks as f64 / block_chart.len().max(1) as f64,
        moved_vertices: moved,
        absorbed_vertices: absorbed,
        faceless_vertices: charts
            .iter()
            .filter(|c| c.faceless)
            .map(|c| c.owned.len())
            .sum(),
        l2_stretch: total_stretch.value().unwrap_or(1.0),
        max_chart_stretch,
        build_time: start.elapsed(),
    };
    Ok(Atlas {
        width,
        height,
        block,
        vertex_pixels,
        vertex_chart,
        occupancy,
        block_chart,
        charts: packed,
        interior,
        stats,
    })
}
