//! From mesh and partition to a packed, injective lattice atlas.

use crate::atlas::{Atlas, AtlasStats, Chart, InteriorSample, Occupancy};
use crate::pack::{pack, Placement};
use crate::seed::seeds;
use crate::stretch::StretchSum;
use crate::unwrap::{flatten, Flattening};
use crate::{AtlasError, AtlasOptions, Interior};
use std::time::Instant;

/// Marks a pixel without a vertex in the vertex grid.
const NO_VERTEX: u32 = u32::MAX;

/// A chart before placement: its 2D extent and the vertices it owns.
struct ChartLayout {
    /// Smallest 2D corner coordinate, surface units.
    min: [f64; 2],
    /// Extent, surface units (zero for the face-less chart).
    extent: [f64; 2],
    /// Owned vertices and their 2D position.
    owned: Vec<(u32, [f64; 2])>,
    /// Faces to rasterise.
    faces: Vec<usize>,
    /// Stretch sums (empty for the face-less chart).
    stretch: StretchSum,
    /// Whether this chart holds the face-less vertices in a plain grid.
    faceless: bool,
}

impl ChartLayout {
    /// Rectangle in blocks at scale `s`, before any transposition; large
    /// enough to give every owned vertex its own pixel.
    fn blocks(&self, s: f64, block: u32) -> (u32, u32, [u32; 2]) {
        let n = self.owned.len() as u64;
        let per_block = u64::from(block) * u64::from(block);
        if self.faceless {
            let nb = n.div_ceil(per_block).max(1);
            let bw = (nb as f64).sqrt().ceil().max(1.0) as u64;
            let bh = nb.div_ceil(bw);
            let px = [
                (bw * u64::from(block)) as u32,
                (bh * u64::from(block)) as u32,
            ];
            return (bw as u32, bh as u32, px);
        }
        let px = self.extent.map(|e| (e * s).round().min(1e9) as u32 + 1);
        let mut bw = u64::from(px[0].div_ceil(block));
        let mut bh = u64::from(px[1].div_ceil(block));
        while bw * bh * per_block < n {
            if bw <= bh {
                bw += 1;
            } else {
                bh += 1;
            }
        }
        (
            bw.min(u64::from(u32::MAX)) as u32,
            bh.min(u64::from(u32::MAX)) as u32,
            px,
        )
    }
}

fn check_input(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    partition: &[u32],
    opts: &AtlasOptions,
) -> Result<(), AtlasError> {
    opts.validate()?;
    if partition.len() != positions.len() {
        return Err(AtlasError::PartitionLength {
            partition: partition.len(),
            vertices: positions.len(),
        });
    }
    if let Some(i) = positions
        .iter()
        .position(|p| p.iter().any(|c| !c.is_finite()))
    {
        return Err(AtlasError::NonFinitePosition(i));
    }
    for (t, tri) in triangles.iter().enumerate() {
        if let Some(&v) = tri.iter().find(|&&v| v as usize >= positions.len()) {
            return Err(AtlasError::VertexOutOfRange {
                triangle: t,
                vertex: v,
                vertices: positions.len(),
            });
        }
    }
    let pixels = u64::from(opts.width) * u64::from(opts.height);
    if positions.len() as u64 > pixels {
        return Err(AtlasError::TooManyVertices {
            vertices: positions.len(),
            width: opts.width,
            height: opts.height,
            suggest: suggest_side(positions.len(), opts),
        });
    }
    Ok(())
}

/// A power-of-two square lattice with room for twice the vertices.
fn suggest_side(vertices: usize, opts: &AtlasOptions) -> u32 {
    let mut side = opts
        .width
        .max(opts.height)
        .max(opts.block)
        .next_power_of_two();
    while (side as usize) * (side as usize) < 2 * vertices && side < 65536 {
        side *= 2;
    }
    side
}

/// Each vertex goes to one chart: among the charts with a face on it, the
/// one with most faces among those whose faces are in the vertex's own
/// cluster, else the one with most faces; ties go to the lower chart id.
/// Preferring big charts empties the slivers uvunwrap leaves along seams,
/// which are then dropped instead of each costing a block.
fn assign_owners(
    triangles: &[[u32; 3]],
    partition: &[u32],
    face_cluster: &[u32],
    flat: &Flattening,
    vertices: usize,
) -> Vec<Option<(u32, [f64; 2])>> {
    let mut chart_faces = vec![0usize; flat.charts as usize];
    for c in flat.face_chart.iter().flatten() {
        chart_faces[*c as usize] += 1;
    }
    // Rank: (own cluster, faces in chart, lower id first).
    type Rank = (bool, usize, std::cmp::Reverse<u32>);
    let mut owner: Vec<Option<(Rank, u32, [f64; 2])>> = vec![None; vertices];
    for (f, tri) in triangles.iter().enumerate() {
        let Some(chart) = flat.face_chart[f] else {
            continue;
        };
        for (k, &v) in tri.iter().enumerate() {
            let own_cluster = partition.get(v as usize) == face_cluster.get(f);
            let rank = (
                own_cluster,
                chart_faces[chart as usize],
                std::cmp::Reverse(chart),
            );
            let slot = &mut owner[v as usize];
            if slot.as_ref().is_none_or(|(r, _, _)| rank > *r) {
                *slot = Some((rank, chart, flat.corner_uv[f][k]));
            }
        }
    }
    owner
        .into_iter()
        .map(|o| o.map(|(_, c, uv)| (c, uv)))
        .collect()
}

/// Hands the vertices of charts owning fewer than `min` vertices to the
/// neighbouring chart that owns most of their mesh neighbours, placed at the
/// mean of those neighbours' 2D positions: a chart of a few vertices would
/// otherwise hold a whole block alone. Returns how many vertices moved chart.
fn absorb_small_charts(
    triangles: &[[u32; 3]],
    owner: &mut [Option<(u32, [f64; 2])>],
    charts: u32,
    min: usize,
) -> usize {
    let mut count = vec![0usize; charts as usize];
    for (c, _) in owner.iter().flatten() {
        count[*c as usize] += 1;
    }
    let small: Vec<bool> = count.iter().map(|&n| n > 0 && n < min).collect();
    if !small.iter().any(|&s| s) {
        return 0;
    }
    let mut neighbours = vec![Vec::new(); owner.len()];
    for tri in triangles {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            if a != b {
                neighbours[a as usize].push(b);
                neighbours[b as usize].push(a);
            }
        }
    }
    let mut absorbed = 0;
    loop {
        let mut changed = false;
        for v in 0..owner.len() {
            let Some((c, _)) = owner[v] else { continue };
            if !small[c as usize] {
                continue;
            }
            let mut tally: Vec<(u32, usize, [f64; 2])> = Vec::new();
            for &w in &neighbours[v] {
                let Some((d, uv)) = owner[w as usize] else {
                    continue;
                };
                if small[d as usize] {
                    continue;
                }
                match tally.iter_mut().find(|t| t.0 == d) {
                    Some(t) => {
                        t.1 += 1;
                        t.2 = [t.2[0] + uv[0], t.2[1] + uv[1]];
                    }
                    None => tally.push((d, 1, uv)),
                }
            }
            let best = tally
                .into_iter()
                .max_by_key(|t| (t.1, std::cmp::Reverse(t.0)));
            if let Some((d, n, sum)) = best {
                owner[v] = Some((d, [sum[0] / n as f64, sum[1] / n as f64]));
                absorbed += 1;
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    absorbed
}

fn layouts(flat: &Flattening, owner: &[Option<(u32, [f64; 2])>]) -> Vec<ChartLayout> {
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
        layout.faces.push(f);
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

fn try_pack(charts: &[ChartLayout], s: f64, opts: &AtlasOptions) -> Option<Vec<Placement>> {
    let sizes: Vec<(u32, u32)> = charts
        .iter()
        .map(|c| {
            let (w, h, _) = c.blocks(s, opts.block);
            (w, h)
        })
        .collect();
    pack(&sizes, opts.width / opts.block, opts.height / opts.block)
}

/// Largest common scale at which every chart's block rectangle fits.
fn best_scale(
    charts: &[ChartLayout],
    opts: &AtlasOptions,
) -> Result<(f64, Vec<Placement>), AtlasError> {
    let Some(at_zero) = try_pack(charts, 0.0, opts) else {
        let blocks = charts
            .iter()
            .map(|c| {
                let (w, h, _) = c.blocks(0.0, opts.block);
                w as usize * h as usize
            })
            .sum();
        return Err(AtlasError::ChartsDoNotFit {
            charts: charts.len(),
            blocks,
            available: ((opts.width / opts.block) * (opts.height / opts.block)) as usize,
            block: opts.block,
            width: opts.width,
            height: opts.height,
        });
    };
    let area: f64 = charts.iter().map(|c| c.stretch.area_2d()).sum();
    let pixels = f64::from(opts.width) * f64::from(opts.height);
    // No chart set fits at a scale where its triangles alone outgrow the lattice.
    let mut hi = if area > 0.0 {
        (pixels / area).sqrt() * 1.01
    } else {
        0.0
    };
    let (mut lo, mut best) = (0.0, at_zero);
    if hi > 0.0 {
        if let Some(p) = try_pack(charts, hi, opts) {
            return Ok((hi, p));
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
        if hi - lo <= 1e-4 * hi {
            break;
        }
    }
    Ok((lo, best))
}

/// Where one chart sits: maps its 2D coordinates to global lattice coordinates.
struct Frame {
    origin: [f64; 2],
    min: [f64; 2],
    offset: [f64; 2],
    scale: f64,
    transposed: bool,
    /// Rectangle in the lattice: x0, y0, width, height (pixels).
    rect: [u32; 4],
}

impl Frame {
    fn to_lattice(&self, uv: [f64; 2]) -> [f64; 2] {
        let local = [0, 1].map(|a| (uv[a] - self.min[a]) * self.scale + self.offset[a]);
        let (x, y) = if self.transposed {
            (local[1], local[0])
        } else {
            (local[0], local[1])
        };
        [self.origin[0] + x, self.origin[1] + y]
    }

    fn clamp_pixel(&self, p: [f64; 2]) -> [u32; 2] {
        let [x0, y0, w, h] = self.rect;
        let cx = p[0].round().clamp(f64::from(x0), f64::from(x0 + w - 1)) as u32;
        let cy = p[1].round().clamp(f64::from(y0), f64::from(y0 + h - 1)) as u32;
        [cx, cy]
    }
}

/// Nearest free pixel of a rectangle to `target`.
fn nearest_free(grid: &[u32], width: u32, rect: [u32; 4], target: [u32; 2]) -> Option<[u32; 2]> {
    let [x0, y0, w, h] = rect;
    let mut best: Option<(i64, [u32; 2])> = None;
    for y in y0..y0 + h {
        for x in x0..x0 + w {
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
    best.map(|(_, p)| p)
}

/// Rasterises a triangle's pixel centres inside `rect`, calling `hit` with
/// the pixel and barycentric weights.
fn rasterise(c: [[f64; 2]; 3], rect: [u32; 4], mut hit: impl FnMut([u32; 2], [f64; 3])) {
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
    let (scale, placements) = best_scale(&charts, opts)?;

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

    for (ci, (layout, place)) in charts.iter().zip(&placements).enumerate() {
        let (bw, bh, px) = layout.blocks(scale, block);
        let (rbw, rbh) = if place.transposed { (bh, bw) } else { (bw, bh) };
        let rect = [place.bx * block, place.by * block, rbw * block, rbh * block];
        for by in place.by..place.by + rbh {
            for bx in place.bx..place.bx + rbw {
                block_chart[(by * blocks_across + bx) as usize] = Some(ci as u32);
            }
        }
        let frame = Frame {
            origin: [f64::from(rect[0]), f64::from(rect[1])],
            min: layout.min,
            offset: [0, 1].map(|a| f64::from(([bw, bh][a] * block).saturating_sub(px[a]) / 2)),
            scale,
            transposed: place.transposed,
            rect,
        };
        for (k, &(v, uv)) in layout.owned.iter().enumerate() {
            let target = if layout.faceless {
                let k = k as u32;
                [rect[0] + k % rect[2], rect[1] + k / rect[2]]
            } else {
                frame.clamp_pixel(frame.to_lattice(uv))
            };
            let mut at = target;
            if grid[(at[1] * width + at[0]) as usize] != NO_VERTEX {
                // The rectangle has a pixel per owned vertex, so this finds one.
                at = nearest_free(&grid, width, rect, target).unwrap_or(target);
                moved += 1;
            }
            grid[(at[1] * width + at[0]) as usize] = v;
            occupancy[(at[1] * width + at[0]) as usize] = Occupancy::Vertex;
            covered[(at[1] * width + at[0]) as usize] = true;
            vertex_pixels[v as usize] = [at[0] as u16, at[1] as u16];
            vertex_chart[v as usize] = ci as u32;
        }
        for &f in &layout.faces {
            let corners = [0, 1, 2].map(|k| frame.to_lattice(flat.corner_uv[f][k]));
            let tri = triangles[f];
            rasterise(corners, rect, |[x, y], w| {
                let i = (y * width + x) as usize;
                if covered[i] {
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
        packed.push(Chart {
            origin: [rect[0], rect[1]],
            size: [rect[2], rect[3]],
            transposed: place.transposed,
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
