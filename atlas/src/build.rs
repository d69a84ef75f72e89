//! From mesh and partition to a packed, injective lattice atlas.

use crate::atlas::{Atlas, AtlasStats, Chart, InteriorSample, Occupancy};
use crate::pack::{pack, Footprint, Orientation, Placement};
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
    /// Faces to rasterise and their 2D corners.
    faces: Vec<(usize, [[f64; 2]; 3])>,
    /// Stretch sums (empty for the face-less chart).
    stretch: StretchSum,
    /// Whether this chart holds the face-less vertices in a plain grid.
    faceless: bool,
}

/// A chart at one scale: its local frame and the blocks it needs.
struct Shape {
    footprint: Footprint,
    /// Local pixel offset of the 2D minimum (centres the chart in its frame).
    offset: [f64; 2],
}

impl ChartLayout {
    /// Local pixel position of a 2D point at scale `s`.
    fn local(&self, uv: [f64; 2], s: f64, offset: [f64; 2]) -> [f64; 2] {
        [0, 1].map(|a| (uv[a] - self.min[a]) * s + offset[a])
    }

    /// The blocks the chart's triangles and vertices touch at scale `s`,
    /// or its whole frame when those hold fewer pixels than it has vertices.
    /// `None` when the frame cannot fit a `grid` of blocks in any orientation.
    fn shape(&self, s: f64, block: u32, grid: [u32; 2]) -> Option<Shape> {
        let n = self.owned.len() as u64;
        let per_block = u64::from(block) * u64::from(block);
        let full = |bw: u32, bh: u32| Footprint {
            width: bw,
            height: bh,
            cells: (0..bh).flat_map(|y| (0..bw).map(move |x| (x, y))).collect(),
        };
        if self.faceless {
            let nb = n.div_ceil(per_block).max(1);
            let bw = (nb as f64).sqrt().ceil().max(1.0) as u32;
            let bh = nb.div_ceil(u64::from(bw)) as u32;
            return Some(Shape {
                footprint: full(bw, bh),
                offset: [0.0; 2],
            });
        }
        let px = self.extent.map(|e| (e * s).round().min(1e6) as u32 + 1);
        let (bw, bh) = (px[0].div_ceil(block), px[1].div_ceil(block));
        if bw.max(bh) > grid[0].max(grid[1]) || bw.min(bh) > grid[0].min(grid[1]) {
            return None;
        }
        let offset = [0, 1].map(|a| f64::from(([bw, bh][a] * block - px[a]) / 2));
        let rect = [0, 0, bw * block, bh * block];
        let mut touched = vec![false; (bw * bh) as usize];
        let mut mark = |p: [u32; 2]| touched[((p[1] / block) * bw + p[0] / block) as usize] = true;
        for (_, uv) in &self.owned {
            mark(clamp_pixel(self.local(*uv, s, offset), rect));
        }
        for (_, corners) in &self.faces {
            let c = corners.map(|uv| self.local(uv, s, offset));
            rasterise(c, rect, |p, _| mark(p));
        }
        let cells: Vec<(u32, u32)> = (0..bh)
            .flat_map(|y| (0..bw).map(move |x| (x, y)))
            .filter(|&(x, y)| touched[(y * bw + x) as usize])
            .collect();
        if cells.len() as u64 * per_block >= n {
            return Some(Shape {
                footprint: Footprint {
                    width: bw,
                    height: bh,
                    cells,
                },
                offset,
            });
        }
        let (mut gw, mut gh) = (u64::from(bw), u64::from(bh));
        while gw * gh * per_block < n {
            if gw <= gh {
                gw += 1;
            } else {
                gh += 1;
            }
        }
        Some(Shape {
            footprint: full(gw as u32, gh as u32),
            offset,
        })
    }
}

/// Nearest pixel of `rect` (x0, y0, width, height) to a point.
fn clamp_pixel(p: [f64; 2], rect: [u32; 4]) -> [u32; 2] {
    let [x0, y0, w, h] = rect;
    let cx = p[0].round().clamp(f64::from(x0), f64::from(x0 + w - 1)) as u32;
    let cy = p[1].round().clamp(f64::from(y0), f64::from(y0 + h - 1)) as u32;
    [cx, cy]
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
    while (side as usize) * (side as usize) < 2 * vertices && side < 16384 {
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
/// otherwise hold a whole block alone. A chart takes in at most as many
/// vertices as it owns, so that on coarse meshes made of small charts one
/// chart does not swallow the rest onto a few pixels (measured on
/// RiggedFigure: without the cap 116 of 130 vertices had to move). Returns how many
/// vertices changed chart.
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
    let mut room = count.clone();
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
                if small[d as usize] || room[d as usize] == 0 {
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
                room[d as usize] -= 1;
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
        layout.faces.push((f, flat.corner_uv[f]));
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
type Packing = (f64, Vec<Shape>, Vec<Placement>);

/// Largest common scale at which every chart's blocks fit (bisection; the
/// greedy packer is not exactly monotonic in the scale, so this is the
/// largest scale found, not a proven optimum).
fn best_scale(charts: &[ChartLayout], opts: &AtlasOptions) -> Result<Packing, AtlasError> {
    let Some(at_zero) = try_pack(charts, 0.0, opts) else {
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
        return Err(AtlasError::ChartsDoNotFit {
            charts: charts.len(),
            blocks,
            available: ((opts.width / opts.block) * (opts.height / opts.block)) as usize,
            block: opts.block,
            width: opts.width,
            height: opts.height,
            suggest,
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

/// Nearest pixel to `target` without a vertex, among the given blocks.
fn nearest_free(
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
