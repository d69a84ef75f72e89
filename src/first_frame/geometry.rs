//! Position coding after the connectivity, so that each vertex is predicted from the
//! parallelograms its already-coded neighbourhood offers rather than from the single triangle it
//! was reached through. As Draco at its highest compression level: vertices go in order of
//! prediction degree (most parallelograms first), and the encoder picks which of up to four
//! parallelograms to average, signalled by a flag each (constrained multi-parallelogram).

use super::quantise::{Cell, Grid};
use std::collections::HashMap;

use super::traversal::{by_edge, undirected};
use crate::error::{Error, Result};
use crate::mesh::Triangle;
use crate::stream::entropy::{BitModel, IntModel, SymbolCoder};

/// At most this many parallelograms are offered to a vertex, as in Draco (the first ones found).
const MAX_PARALLELOGRAMS: usize = 4;

/// Adaptive residual contexts, per predictor and axis.
#[derive(Default)]
struct Models {
    /// One parallelogram used, two or more.
    parallelogram: [[IntModel; 3]; 2],
    /// Whether parallelogram k of n is used: `used[n - 1][k]`.
    used: [[BitModel; MAX_PARALLELOGRAMS]; MAX_PARALLELOGRAMS],
    /// Mean of the coded neighbours (no complete parallelogram yet).
    neighbours: [IntModel; 3],
    /// The previous vertex (a new component or a vertex in no triangle).
    delta: [IntModel; 3],
}

fn corrupt(what: &str) -> Error {
    Error::Stream(format!("first frame geometry: {what}"))
}

/// Rounded mean of `sum / n` on each axis, clamped to the grid.
fn mean(sum: [i64; 3], n: i64, grid: &Grid) -> Cell {
    sum.map(|s| {
        (2 * s + n)
            .div_euclid(2 * n)
            .clamp(0, i64::from(grid.max_level())) as i32
    })
}

/// The triangles around each vertex and on each edge: what predictions are made from.
struct Neighbourhood<'a> {
    triangles: &'a [Triangle],
    /// Triangles of vertex v: `around[start[v]..start[v + 1]]`.
    start: Vec<usize>,
    around: Vec<u32>,
    by_edge: HashMap<u64, Vec<u32>>,
}

/// What the coded vertices around one offer: parallelogram predictions and neighbours.
#[derive(Default)]
struct Offer {
    parallelograms: Vec<[i64; 3]>,
    nb_sum: [i64; 3],
    nb_n: i64,
}

impl Offer {
    /// Coding priority: more parallelograms first, then vertices with coded neighbours.
    fn priority(&self) -> usize {
        match (self.parallelograms.len(), self.nb_n) {
            (0, 0) => 0,
            (0, _) => 1,
            (n, _) => 1 + n.min(3),
        }
    }
}

const PRIORITIES: usize = 5;
/// Bounds the work of keeping priorities on hostile meshes (fans of thousands of triangles, edges
/// shared by thousands): a vertex with more triangles than this is only ever "has a coded
/// neighbour", and only this many triangles across an edge are rescored.
const RESCORED_TRIANGLES: usize = 32;
const RESCORED_PER_EDGE: usize = 8;

impl<'a> Neighbourhood<'a> {
    fn new(triangles: &'a [Triangle], touched: usize) -> Self {
        let mut start = vec![0usize; touched + 1];
        for &v in triangles.iter().flatten() {
            start[v as usize + 1] += 1;
        }
        for k in 0..touched {
            start[k + 1] += start[k];
        }
        let mut fill = start.clone();
        let mut around = vec![0u32; start[touched]];
        for (t, tri) in triangles.iter().enumerate() {
            for &v in tri {
                around[fill[v as usize]] = t as u32;
                fill[v as usize] += 1;
            }
        }
        Self {
            triangles,
            start,
            around,
            by_edge: by_edge(triangles),
        }
    }

    fn around(&self, v: u32) -> &[u32] {
        self.start
            .get(v as usize..v as usize + 2)
            .map_or(&[][..], |r| &self.around[r[0]..r[1]])
    }

    /// The predictions the coded vertices (`cells[x]` where `coded[x]`) offer vertex `v`.
    fn offer(&self, v: u32, cells: &[Cell], coded: &[bool]) -> Offer {
        let is_coded = |x: u32| coded.get(x as usize).copied().unwrap_or(false);
        let mut offer = Offer::default();
        for &t in self.around(v) {
            let tri = self.triangles[t as usize];
            let Some(k) = tri.iter().position(|&x| x == v) else {
                continue;
            };
            let (a, b) = (tri[(k + 1) % 3], tri[(k + 2) % 3]);
            for n in [a, b] {
                if is_coded(n) {
                    for (sum, &c) in offer.nb_sum.iter_mut().zip(&cells[n as usize]) {
                        *sum += i64::from(c);
                    }
                    offer.nb_n += 1;
                }
            }
            if !is_coded(a) || !is_coded(b) {
                continue;
            }
            let across = self.by_edge.get(&undirected(a, b)).map_or(&[][..], |l| &l[..]);
            // Bounded on hostile fins (thousands of triangles on one edge), like the rescoring.
            for &u in across.iter().take(4 * RESCORED_PER_EDGE) {
                if u == t {
                    continue;
                }
                let other = self.triangles[u as usize];
                let Some(&c) = other.iter().find(|&&x| x != a && x != b) else {
                    continue;
                };
                if !is_coded(c) || c == v || offer.parallelograms.len() == MAX_PARALLELOGRAMS {
                    continue;
                }
                let (pa, pb, pc) = (cells[a as usize], cells[b as usize], cells[c as usize]);
                offer
                    .parallelograms
                    .push(std::array::from_fn(|i| {
                        i64::from(pa[i]) + i64::from(pb[i]) - i64::from(pc[i])
                    }));
            }
        }
        offer
    }

    /// The uncoded vertices whose offer changes when `u` is coded: those of its triangles and
    /// those across the edges of its triangles.
    fn affected(&self, u: u32, out: &mut Vec<u32>) {
        out.clear();
        for &t in self.around(u) {
            let tri = self.triangles[t as usize];
            out.extend(tri.iter().copied().filter(|&x| x != u));
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                let across = self.by_edge.get(&undirected(a, b)).map_or(&[][..], |l| &l[..]);
                for &w in across.iter().take(RESCORED_PER_EDGE) {
                    let other = self.triangles[w as usize];
                    out.extend(other.iter().copied().filter(|&x| x != a && x != b));
                }
            }
        }
    }
}

/// Codes the positions of vertices `0..vertex_count` (traversal order); `actual` holds them on
/// the encoder and is empty on the decoder. `triangles` index traversal order.
///
/// Vertices of triangles are coded in order of prediction degree (as Draco's
/// `MaxPredictionDegreeTraverser`): the uncoded vertex offering the most parallelograms next,
/// else the first uncoded one in traversal order. Those in no triangle follow in order.
pub(super) fn code_positions<C: SymbolCoder>(
    coder: &mut C,
    grid: &Grid,
    triangles: &[Triangle],
    vertex_count: usize,
    actual: &[Cell],
) -> Result<Vec<Cell>> {
    if triangles
        .iter()
        .flatten()
        .any(|&v| v as usize >= vertex_count)
    {
        return Err(corrupt("triangle indexes a missing vertex"));
    }
    // Sized by the decoded triangles, not by the header's vertex count, which only the positions
    // decoded below prove.
    let touched = triangles
        .iter()
        .flatten()
        .max()
        .map_or(0, |&v| v as usize + 1);
    let hood = Neighbourhood::new(triangles, touched);
    let mut models = Models::default();
    let mut cells: Vec<Cell> = vec![[0; 3]; touched];
    let mut coded = vec![false; touched];
    let mut priority = vec![0usize; touched];
    let mut buckets: [Vec<u32>; PRIORITIES] = Default::default();
    let (mut next, mut previous) = (0usize, None::<Cell>);
    let mut affected = Vec::new();
    loop {
        let popped = (0..PRIORITIES).rev().find_map(|p| {
            while let Some(v) = buckets[p].pop() {
                if !coded[v as usize] && priority[v as usize] == p {
                    return Some(v);
                }
            }
            None
        });
        let v = match popped {
            Some(v) => v,
            None => {
                while next < touched && coded[next] {
                    next += 1;
                }
                if next == touched {
                    break;
                }
                next as u32
            }
        };
        let offer = hood.offer(v, &cells, &coded);
        let cell = code_one(coder, &mut models, grid, &offer, previous, actual.get(v as usize))?;
        cells[v as usize] = cell;
        coded[v as usize] = true;
        previous = Some(cell);
        hood.affected(v, &mut affected);
        for &w in &affected {
            if coded[w as usize] {
                continue;
            }
            let p = if hood.around(w).len() > RESCORED_TRIANGLES {
                1
            } else {
                hood.offer(w, &cells, &coded).priority()
            };
            if p != priority[w as usize] {
                priority[w as usize] = p;
                buckets[p].push(w);
            }
        }
    }
    for v in touched..vertex_count {
        let offer = Offer::default();
        let cell = code_one(coder, &mut models, grid, &offer, previous, actual.get(v))?;
        cells.push(cell);
        previous = Some(cell);
    }
    Ok(cells)
}

/// Codes one position against the best prediction `offer` makes, else the previous position.
fn code_one<C: SymbolCoder>(
    coder: &mut C,
    models: &mut Models,
    grid: &Grid,
    offer: &Offer,
    previous: Option<Cell>,
    actual: Option<&Cell>,
) -> Result<Cell> {
    let (prediction, axis_models) = if !offer.parallelograms.is_empty() {
        let used = code_used(coder, models, grid, &offer.parallelograms, actual)?;
        let (prediction, n) = subset_mean(&offer.parallelograms, used, grid);
        (prediction, &mut models.parallelogram[usize::from(n > 1)])
    } else if offer.nb_n > 0 {
        (mean(offer.nb_sum, offer.nb_n, grid), &mut models.neighbours)
    } else {
        let centre = [(grid.max_level() + 1) / 2; 3];
        (previous.unwrap_or(centre), &mut models.delta)
    };
    let target = actual.copied().unwrap_or(prediction);
    let mut cell = [0; 3];
    for i in 0..3 {
        let r = coder.signed(i64::from(target[i] - prediction[i]), &mut axis_models[i])?;
        cell[i] = i64::from(prediction[i])
            .checked_add(r)
            .and_then(|c| i32::try_from(c).ok())
            .ok_or_else(|| corrupt("position off the grid"))?;
    }
    if !grid.contains(cell) {
        return Err(corrupt("position off the grid"));
    }
    Ok(cell)
}

/// The mean of the parallelograms whose bit is set in `used`, and how many there are.
fn subset_mean(parallelograms: &[[i64; 3]], used: usize, grid: &Grid) -> (Cell, usize) {
    let (mut sum, mut n) = ([0i64; 3], 0);
    for (k, p) in parallelograms.iter().enumerate() {
        if used >> k & 1 == 1 {
            for i in 0..3 {
                sum[i] += p[i];
            }
            n += 1;
        }
    }
    (mean(sum, n.max(1) as i64, grid), n)
}

/// Codes which of the offered parallelograms predict (Draco's constrained multi-parallelogram:
/// one across a crease predicts badly). The encoder picks the non-empty subset whose flags and
/// residual cost the fewest bits under the current models; a bitmask.
fn code_used<C: SymbolCoder>(
    coder: &mut C,
    models: &mut Models,
    grid: &Grid,
    parallelograms: &[[i64; 3]],
    actual: Option<&Cell>,
) -> Result<usize> {
    let n = parallelograms.len().min(MAX_PARALLELOGRAMS);
    let flags = &mut models.used[n - 1];
    let mut best = (1usize << n) - 1;
    if let Some(target) = actual {
        let mut best_cost = f64::INFINITY;
        for used in 1..1usize << n {
            let (prediction, m) = subset_mean(parallelograms, used, grid);
            let axis = &mut models.parallelogram[usize::from(m > 1)];
            let mut cost: f64 = (0..n).map(|k| flags[k].cost(used >> k & 1 == 1)).sum();
            for i in 0..3 {
                cost += axis[i]
                    .parts()
                    .cost(i64::from(target[i] - prediction[i]));
            }
            if cost < best_cost {
                (best, best_cost) = (used, cost);
            }
        }
    }
    let mut used = 0;
    for (k, flag) in flags.iter_mut().enumerate().take(n) {
        // The last flag is implied when no other parallelogram is used.
        let bit = if k + 1 == n && used == 0 {
            true
        } else {
            coder.bit(best >> k & 1 == 1, flag)?
        };
        used |= usize::from(bit) << k;
    }
    Ok(used)
}
