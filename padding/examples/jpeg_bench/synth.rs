//! Geometry-image-like test images made from a real mesh sequence, until the encoder's own exist.
//!
//! Charts: frame 0's triangles grouped by the dominant axis of their normal (±x, ±y, ±z), split into
//! edge-connected pieces; each chart is projected orthographically along its axis. Layout: each
//! chart's bounding box, rounded up to whole 8×8 blocks, is shelf-packed into the lattice at the
//! largest scale that fits, so no block mixes charts (as the paper's atlas guarantees). Values: for
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
            return Err(format!("{}: vertex count differs from frame 0", files[index].display()));
        }
        for c in 0..3 {
            let displacement: Vec<f64> = positions.iter().zip(&first).map(|(p, q)| p[c] - q[c]).collect();
            let mean = displacement.iter().sum::<f64>() / displacement.len() as f64;
            let centred: Vec<f64> = displacement.iter().map(|d| d - mean).collect();
            samples.push(layout.rasterise(&centred));
        }
    }
    let name = dir.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    Ok(Sequence { name, samples, per_frame: 3 })
}

fn obj_files(dir: &Path) -> Result<Vec<PathBuf>, String> {
    let mut files: Vec<(u64, PathBuf)> = std::fs::read_dir(dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .filter_map(|p| {
            let digits: String = p.file_stem()?.to_string_lossy().chars().filter(char::is_ascii_digit).collect();
            Some((digits.parse().ok()?, p))
        })
        .collect();
    files.sort();
    if files.len() < 2 {
        return Err(format!("{}: fewer than two numbered .obj frames", dir.display()));
    }
    Ok(files.into_iter().map(|(_, p)| p).collect())
}

fn read_obj(path: &Path, with_triangles: bool) -> Result<(Vec<Point>, Vec<[usize; 3]>), String> {
    let options = tobj::LoadOptions { triangulate: true, ..Default::default() };
    let (models, _) = tobj::load_obj(path, &options).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for model in models {
        let base = positions.len();
        positions.extend(
            model.mesh.positions.chunks_exact(3).map(|p| [f64::from(p[0]), f64::from(p[1]), f64::from(p[2])]),
        );
        if with_triangles {
            triangles.extend(
                model.mesh.indices.chunks_exact(3).map(|t| [base + t[0] as usize, base + t[1] as usize, base + t[2] as usize]),
            );
        }
    }
    Ok((positions, triangles))
}

struct Chart {
    triangles: Vec<usize>,
    /// The two coordinates kept by the projection.
    axes: (usize, usize),
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
            let (lo, hi) = first.iter().fold(([f64::MAX; 3], [f64::MIN; 3]), |(lo, hi), p| {
                (std::array::from_fn(|c| lo[c].min(p[c])), std::array::from_fn(|c| hi[c].max(p[c])))
            });
            (0..3).map(|c| (hi[c] - lo[c]).powi(2)).sum::<f64>().sqrt()
        };
        // Largest scale (pixels per mesh unit) whose shelf packing fits, by bisection.
        let (mut lo, mut hi) = (0.0, 4.0 * side as f64 / diagonal);
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            if pack(&mut charts, mid, side) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        if !pack(&mut charts, lo, side) {
            return Err(format!("{} charts do not fit a {side}x{side} lattice", charts.len()));
        }
        Ok(Layout { side, scale: lo, charts, triangles: triangles.to_vec(), first: first.to_vec() })
    }

    fn pixel(&self, chart: &Chart, v: usize) -> (f64, f64) {
        let p = self.first[v];
        (
            chart.origin.0 as f64 + (p[chart.axes.0] - chart.min.0) * self.scale,
            chart.origin.1 as f64 + (p[chart.axes.1] - chart.min.1) * self.scale,
        )
    }

    fn rasterise(&self, value: &[f64]) -> Sample {
        let side = self.side;
        let mut raw = vec![0.0; side * side];
        let mut fixed = vec![false; side * side];
        for chart in &self.charts {
            for &t in &chart.triangles {
                let [a, b, c] = self.triangles[t];
                let (pa, pb, pc) = (self.pixel(chart, a), self.pixel(chart, b), self.pixel(chart, c));
                let det = (pb.0 - pa.0) * (pc.1 - pa.1) - (pc.0 - pa.0) * (pb.1 - pa.1);
                if det.abs() > 1e-12 {
                    let x0 = pa.0.min(pb.0).min(pc.0).floor().max(0.0) as usize;
                    let x1 = (pa.0.max(pb.0).max(pc.0).ceil() as usize).min(side - 1);
                    let y0 = pa.1.min(pb.1).min(pc.1).floor().max(0.0) as usize;
                    let y1 = (pa.1.max(pb.1).max(pc.1).ceil() as usize).min(side - 1);
                    for y in y0..=y1 {
                        for x in x0..=x1 {
                            let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
                            let wb = ((px - pa.0) * (pc.1 - pa.1) - (pc.0 - pa.0) * (py - pa.1)) / det;
                            let wc = ((pb.0 - pa.0) * (py - pa.1) - (px - pa.0) * (pb.1 - pa.1)) / det;
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
    let label: Vec<usize> = triangles
        .iter()
        .map(|&[a, b, c]| {
            let (p, q, r) = (first[a], first[b], first[c]);
            let u = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
            let v = [r[0] - p[0], r[1] - p[1], r[2] - p[2]];
            let n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
            let axis = (0..3).max_by(|&i, &j| n[i].abs().total_cmp(&n[j].abs())).unwrap_or(0);
            axis * 2 + usize::from(n[axis] < 0.0)
        })
        .collect();
    let mut parent: Vec<usize> = (0..triangles.len()).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let mut edge_owner: HashMap<(usize, usize), usize> = HashMap::new();
    for (t, tri) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            let key = (a.min(b), a.max(b));
            if let Some(&other) = edge_owner.get(&key) {
                if label[other] == label[t] {
                    let (ra, rb) = (root(&mut parent, other), root(&mut parent, t));
                    parent[ra] = rb;
                }
            } else {
                edge_owner.insert(key, t);
            }
        }
    }
    let mut by_root: HashMap<usize, Vec<usize>> = HashMap::new();
    for t in 0..triangles.len() {
        by_root.entry(root(&mut parent, t)).or_default().push(t);
    }
    let mut charts: Vec<Chart> = by_root
        .into_values()
        .map(|tris| {
            let axis = label[tris[0]] / 2;
            let axes = ((axis + 1) % 3, (axis + 2) % 3);
            let mut min = (f64::MAX, f64::MAX);
            let mut max = (f64::MIN, f64::MIN);
            for &t in &tris {
                for &v in &triangles[t] {
                    let p = first[v];
                    min = (min.0.min(p[axes.0]), min.1.min(p[axes.1]));
                    max = (max.0.max(p[axes.0]), max.1.max(p[axes.1]));
                }
            }
            Chart { triangles: tris, axes, min, max, origin: (0, 0) }
        })
        .collect();
    charts.sort_by(|a, b| (b.max.1 - b.min.1).total_cmp(&(a.max.1 - a.min.1)));
    charts
}

/// Shelf packing of block-rounded chart boxes at `scale`; false when they do not fit.
fn pack(charts: &mut [Chart], scale: f64, side: usize) -> bool {
    let blocks = |extent: f64| ((extent * scale).floor() as usize + 1).div_ceil(8) * 8;
    let (mut x, mut y, mut shelf) = (0usize, 0usize, 0usize);
    for chart in charts.iter_mut() {
        let (w, h) = (blocks(chart.max.0 - chart.min.0), blocks(chart.max.1 - chart.min.1));
        if w > side {
            return false;
        }
        if x + w > side {
            x = 0;
            y += shelf;
            shelf = 0;
        }
        if y + h > side {
            return false;
        }
        chart.origin = (x, y);
        x += w;
        shelf = shelf.max(h);
    }
    true
}
