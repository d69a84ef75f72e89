//! Geometry-image-like test images made from a real mesh sequence, until the encoder's own exist.
//!
//! Charts: frame 0's triangles grouped by the dominant axis of their normal (±x, ±y, ±z), split into
//! edge-connected pieces; each chart is projected orthographically along its axis, turned to its
//! principal axes (2-D PCA of its vertices). Layout: the 8×8 blocks each chart's triangles touch are
//! packed (largest chart first, first free block-aligned spot in raster order) into the lattice at
//! the largest scale that fits, so no block mixes charts (as the paper's atlas guarantees). Values: for
//! frame f and coordinate c, the displacement x_f − x_0 minus its mean over vertices, rasterised
//! over each chart's triangles (barycentric interpolation at pixel centres; every vertex's own pixel
//! too). Those pixels are the fixed ones; the rest of the lattice is free.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use crate::images::{Sample, Sequence};

type Point = [f64; 3];

/// Reads the OBJ sequence in `dir` (frames ordered by the number in the file name) and makes
/// `frames` × 3 images of `side × side`, from frames spread evenly over the sequence (frame 0 excluded).
pub fn from_obj_sequence(dir: &Path, frames: usize, side: usize) -> Result<Sequence, String> {
    let files = obj_files(dir)?;
    let (first, triangles) = read_obj(&files[0], true)?;
    let layout = Layout::new(&first, &triangles, side)?;
    let mut samples = Vec::new();
    let count = frames.min(files.len() - 1);
    for k in 1..=count {
        let index = k * (files.len() - 1) / count;
        let (positions, _) = read_obj(&files[index], false)?;
        if positions.len() != first.len() {
            return Err(format!(
                "{}: vertex count differs from frame 0",
                files[index].display()
            ));
        }
        for c in 0..3 {
            let displacement: Vec<f64> = positions
                .iter()
                .zip(&first)
                .map(|(p, q)| p[c] - q[c])
                .collect();
            let mean = displacement.iter().sum::<f64>() / displacement.len() as f64;
            let centred: Vec<f64> = displacement.iter().map(|d| d - mean).collect();
            samples.push(layout.rasterise(&centred));
        }
    }
    let name = dir
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    Ok(Sequence {
        name,
        samples,
        per_frame: 3,
    })
}

fn obj_files(dir: &Path) -> Result<Vec<PathBuf>, String> {
    let mut files: Vec<(u64, PathBuf)> = std::fs::read_dir(dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .filter_map(|p| {
            let digits: String = p
                .file_stem()?
                .to_string_lossy()
                .chars()
                .filter(char::is_ascii_digit)
                .collect();
            Some((digits.parse().ok()?, p))
        })
        .collect();
    files.sort();
    if files.len() < 2 {
        return Err(format!(
            "{}: fewer than two numbered .obj frames",
            dir.display()
        ));
    }
    Ok(files.into_iter().map(|(_, p)| p).collect())
}

fn read_obj(path: &Path, with_triangles: bool) -> Result<(Vec<Point>, Vec<[usize; 3]>), String> {
    let options = tobj::LoadOptions {
        triangulate: true,
        ..Default::default()
    };
    let (models, _) =
        tobj::load_obj(path, &options).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for model in models {
        let base = positions.len();
        positions.extend(
            model
                .mesh
                .positions
                .chunks_exact(3)
                .map(|p| [f64::from(p[0]), f64::from(p[1]), f64::from(p[2])]),
        );
        if with_triangles {
            triangles.extend(model.mesh.indices.chunks_exact(3).map(|t| {
                [
                    base + t[0] as usize,
                    base + t[1] as usize,
                    base + t[2] as usize,
                ]
            }));
        }
    }
    Ok((positions, triangles))
}

struct Chart {
    triangles: Vec<usize>,
    /// The projection: two orthonormal directions in the plane orthogonal to the chart's axis,
    /// turned to the chart's principal axes so that its bounding box is tight.
    directions: [Point; 2],
    min: (f64, f64),
    max: (f64, f64),
    /// Block-aligned top-left corner in the lattice, in pixels.
    origin: (usize, usize),
}

/// Where every chart sits in the lattice, fixed for the whole sequence.
struct Layout {
    side: usize,
    scale: f64,
    charts: Vec<Chart>,
    triangles: Vec<[usize; 3]>,
    first: Vec<Point>,
}

impl Layout {
    fn new(first: &[Point], triangles: &[[usize; 3]], side: usize) -> Result<Layout, String> {
        let mut charts = make_charts(first, triangles);
        let diagonal = {
            let (lo, hi) = first
                .iter()
                .fold(([f64::MAX; 3], [f64::MIN; 3]), |(lo, hi), p| {
                    (
                        std::array::from_fn(|c| lo[c].min(p[c])),
                        std::array::from_fn(|c| hi[c].max(p[c])),
                    )
                });
            (0..3).map(|c| (hi[c] - lo[c]).powi(2)).sum::<f64>().sqrt()
        };
        // Largest scale (pixels per mesh unit) whose block packing fits, by bisection.
        let (mut lo, mut hi) = (0.0, 4.0 * side as f64 / diagonal);
        for _ in 0..24 {
            let mid = 0.5 * (lo + hi);
            if pack(&mut charts, first, triangles, mid, side) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        if !pack(&mut charts, first, triangles, lo, side) {
            return Err(format!(
                "{} charts do not fit a {side}x{side} lattice",
                charts.len()
            ));
        }
        Ok(Layout {
            side,
            scale: lo,
            charts,
            triangles: triangles.to_vec(),
            first: first.to_vec(),
        })
    }

    fn pixel(&self, chart: &Chart, v: usize) -> (f64, f64) {
        let (u, w) = project(&chart.directions, self.first[v]);
        (
            chart.origin.0 as f64 + (u - chart.min.0) * self.scale,
            chart.origin.1 as f64 + (w - chart.min.1) * self.scale,
        )
    }

    fn rasterise(&self, value: &[f64]) -> Sample {
        let side = self.side;
        let mut raw = vec![0.0; side * side];
        let mut fixed = vec![false; side * side];
        for chart in &self.charts {
            for &t in &chart.triangles {
                let [a, b, c] = self.triangles[t];
                let (pa, pb, pc) = (
                    self.pixel(chart, a),
                    self.pixel(chart, b),
                    self.pixel(chart, c),
                );
                let det = (pb.0 - pa.0) * (pc.1 - pa.1) - (pc.0 - pa.0) * (pb.1 - pa.1);
                if det.abs() > 1e-12 {
                    let x0 = pa.0.min(pb.0).min(pc.0).floor().max(0.0) as usize;
                    let x1 = (pa.0.max(pb.0).max(pc.0).ceil() as usize).min(side - 1);
                    let y0 = pa.1.min(pb.1).min(pc.1).floor().max(0.0) as usize;
                    let y1 = (pa.1.max(pb.1).max(pc.1).ceil() as usize).min(side - 1);
                    for y in y0..=y1 {
                        for x in x0..=x1 {
                            let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
                            let wb =
                                ((px - pa.0) * (pc.1 - pa.1) - (pc.0 - pa.0) * (py - pa.1)) / det;
                            let wc =
                                ((pb.0 - pa.0) * (py - pa.1) - (px - pa.0) * (pb.1 - pa.1)) / det;
                            let wa = 1.0 - wb - wc;
                            if wa >= 0.0 && wb >= 0.0 && wc >= 0.0 {
                                raw[y * side + x] = wa * value[a] + wb * value[b] + wc * value[c];
                                fixed[y * side + x] = true;
                            }
                        }
                    }
                }
                for v in [a, b, c] {
                    let (x, y) = self.pixel(chart, v);
                    let (x, y) = ((x as usize).min(side - 1), (y as usize).min(side - 1));
                    raw[y * side + x] = value[v];
                    fixed[y * side + x] = true;
                }
            }
        }
        Sample::quantised(side, side, &raw, fixed)
    }
}

/// Triangles grouped by dominant normal axis and sign, then split into edge-connected pieces.
fn make_charts(first: &[Point], triangles: &[[usize; 3]]) -> Vec<Chart> {
    let mut label = normal_labels(first, triangles);
    let neighbours = edge_neighbours(triangles);
    let pieces = merge_small_pieces(&mut label, &neighbours);
    let mut by_root: HashMap<usize, Vec<usize>> = HashMap::new();
    for (t, &p) in pieces.iter().enumerate() {
        by_root.entry(p).or_default().push(t);
    }
    let mut charts: Vec<Chart> = by_root
        .into_values()
        .map(|tris| {
            let axis = label[tris[0]] / 2;
            project_chart(tris, axis, first, triangles)
        })
        .collect();
    charts.sort_by(|a, b| (b.max.1 - b.min.1).total_cmp(&(a.max.1 - a.min.1)));
    charts
}

/// Per triangle, the dominant axis of its normal and its sign: `axis * 2 + (negative)`.
fn normal_labels(first: &[Point], triangles: &[[usize; 3]]) -> Vec<usize> {
    triangles
        .iter()
        .map(|&[a, b, c]| {
            let (p, q, r) = (first[a], first[b], first[c]);
            let u = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
            let v = [r[0] - p[0], r[1] - p[1], r[2] - p[2]];
            let n = [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ];
            let axis = (0..3)
                .max_by(|&i, &j| n[i].abs().total_cmp(&n[j].abs()))
                .unwrap_or(0);
            axis * 2 + usize::from(n[axis] < 0.0)
        })
        .collect()
}

/// Per triangle, the triangles sharing an edge with it (each pair found through the edge's
/// first triangle).
fn edge_neighbours(triangles: &[[usize; 3]]) -> Vec<Vec<usize>> {
    let mut edge_owner: HashMap<(usize, usize), usize> = HashMap::new();
    let mut neighbours: Vec<Vec<usize>> = vec![Vec::new(); triangles.len()];
    for (t, tri) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            match edge_owner.entry((a.min(b), a.max(b))) {
                std::collections::hash_map::Entry::Occupied(e) => {
                    neighbours[t].push(*e.get());
                    neighbours[*e.get()].push(t);
                }
                std::collections::hash_map::Entry::Vacant(e) => {
                    e.insert(t);
                }
            }
        }
    }
    neighbours
}

/// The pieces (see [`components`]) after pieces under MIN_TRIANGLES take the label of their
/// largest neighbouring piece, for up to 6 rounds (as an atlas builder merges slivers), which stops
/// hundreds of one-triangle charts from each taking a block. Updates `label`.
fn merge_small_pieces(label: &mut [usize], neighbours: &[Vec<usize>]) -> Vec<usize> {
    const MIN_TRIANGLES: usize = 24;
    let triangles = label.len();
    let mut pieces = components(label, neighbours);
    for _ in 0..6 {
        let sizes = pieces
            .iter()
            .fold(vec![0usize; triangles], |mut sizes, &p| {
                sizes[p] += 1;
                sizes
            });
        let mut relabel: HashMap<usize, (usize, usize)> = HashMap::new();
        for t in 0..triangles {
            if sizes[pieces[t]] >= MIN_TRIANGLES {
                continue;
            }
            for &n in &neighbours[t] {
                let size = sizes[pieces[n]];
                if pieces[n] != pieces[t] && size > sizes[pieces[t]] {
                    let best = relabel.entry(pieces[t]).or_insert((0, label[t]));
                    if size > best.0 {
                        *best = (size, label[n]);
                    }
                }
            }
        }
        if relabel.is_empty() {
            break;
        }
        for t in 0..triangles {
            if let Some(&(_, l)) = relabel.get(&pieces[t]) {
                label[t] = l;
            }
        }
        pieces = components(label, neighbours);
    }
    pieces
}

/// The chart of triangles `tris` projected along `axis`, turned to its 2-D principal axes.
fn project_chart(
    tris: Vec<usize>,
    axis: usize,
    first: &[Point],
    triangles: &[[usize; 3]],
) -> Chart {
    let unit = |c: usize| -> Point { std::array::from_fn(|i| f64::from(u8::from(i == c))) };
    let plane = [unit((axis + 1) % 3), unit((axis + 2) % 3)];
    let corners: Vec<(f64, f64)> = tris
        .iter()
        .flat_map(|&t| triangles[t])
        .map(|v| project(&plane, first[v]))
        .collect();
    let n = corners.len() as f64;
    let (mu, mv) = corners
        .iter()
        .fold((0.0, 0.0), |(a, b), &(u, v)| (a + u / n, b + v / n));
    let (suu, svv, suv) = corners.iter().fold((0.0, 0.0, 0.0), |(a, b, c), &(u, v)| {
        (
            a + (u - mu) * (u - mu),
            b + (v - mv) * (v - mv),
            c + (u - mu) * (v - mv),
        )
    });
    let angle = 0.5 * (2.0 * suv).atan2(suu - svv);
    let (sin, cos) = angle.sin_cos();
    let directions = [
        std::array::from_fn(|i| cos * plane[0][i] + sin * plane[1][i]),
        std::array::from_fn(|i| -sin * plane[0][i] + cos * plane[1][i]),
    ];
    let mut min = (f64::MAX, f64::MAX);
    let mut max = (f64::MIN, f64::MIN);
    for &t in &tris {
        for &v in &triangles[t] {
            let (u, w) = project(&directions, first[v]);
            min = (min.0.min(u), min.1.min(w));
            max = (max.0.max(u), max.1.max(w));
        }
    }
    Chart {
        triangles: tris,
        directions,
        min,
        max,
        origin: (0, 0),
    }
}

fn project(directions: &[Point; 2], p: Point) -> (f64, f64) {
    let dot = |d: &Point| d[0] * p[0] + d[1] * p[1] + d[2] * p[2];
    (dot(&directions[0]), dot(&directions[1]))
}

/// For each triangle, a representative of its piece: triangles joined across shared edges when
/// they carry the same label.
fn components(label: &[usize], neighbours: &[Vec<usize>]) -> Vec<usize> {
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let mut parent: Vec<usize> = (0..label.len()).collect();
    for (t, list) in neighbours.iter().enumerate() {
        for &n in list {
            if label[n] == label[t] {
                let (a, b) = (root(&mut parent, n), root(&mut parent, t));
                parent[a] = b;
            }
        }
    }
    (0..label.len()).map(|t| root(&mut parent, t)).collect()
}

/// Places each chart (largest first) at the first block-aligned position, in raster order, where
/// the blocks its triangles touch are all unused; false when some chart finds no place.
fn pack(
    charts: &mut [Chart],
    first: &[Point],
    triangles: &[[usize; 3]],
    scale: f64,
    side: usize,
) -> bool {
    let grid = side / 8;
    let footprints: Vec<Vec<(usize, usize)>> = charts
        .iter()
        .map(|chart| {
            let mut blocks: Vec<(usize, usize)> = chart
                .triangles
                .iter()
                .flat_map(|&t| {
                    let corners = triangles[t].map(|v| {
                        let (u, w) = project(&chart.directions, first[v]);
                        ((u - chart.min.0) * scale, (w - chart.min.1) * scale)
                    });
                    let x0 = corners.iter().map(|c| c.0).fold(f64::MAX, f64::min) as usize / 8;
                    let x1 = corners.iter().map(|c| c.0).fold(0.0, f64::max) as usize / 8;
                    let y0 = corners.iter().map(|c| c.1).fold(f64::MAX, f64::min) as usize / 8;
                    let y1 = corners.iter().map(|c| c.1).fold(0.0, f64::max) as usize / 8;
                    (y0..=y1).flat_map(move |y| (x0..=x1).map(move |x| (x, y)))
                })
                .collect();
            blocks.sort_unstable();
            blocks.dedup();
            blocks
        })
        .collect();
    let mut order: Vec<usize> = (0..charts.len()).collect();
    order.sort_by_key(|&c| std::cmp::Reverse(footprints[c].len()));
    let mut used = vec![false; grid * grid];
    for c in order {
        let footprint = &footprints[c];
        let (w, h) = footprint
            .iter()
            .fold((0, 0), |(w, h), &(x, y)| (w.max(x + 1), h.max(y + 1)));
        if w > grid || h > grid {
            return false;
        }
        let spot = (0..=grid - h)
            .flat_map(|by| (0..=grid - w).map(move |bx| (bx, by)))
            .find(|&(bx, by)| {
                footprint
                    .iter()
                    .all(|&(x, y)| !used[(by + y) * grid + bx + x])
            });
        let Some((bx, by)) = spot else {
            return false;
        };
        footprint
            .iter()
            .for_each(|&(x, y)| used[(by + y) * grid + bx + x] = true);
        charts[c].origin = (bx * 8, by * 8);
    }
    true
}
