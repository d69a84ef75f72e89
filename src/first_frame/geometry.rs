//! Position coding after the connectivity, in traversal order, so that each vertex is predicted
//! from every parallelogram its already-coded neighbourhood offers (multi-parallelogram), as
//! Draco does, rather than from the single triangle it was reached through.

use super::quantise::{Cell, Grid};
use super::traversal::{by_edge, undirected};
use crate::error::{Error, Result};
use crate::mesh::Triangle;
use crate::stream::entropy::{IntModel, SymbolCoder};

/// Adaptive residual contexts, per predictor and axis.
#[derive(Default)]
struct Models {
    /// One parallelogram, two or more.
    parallelogram: [[IntModel; 3]; 2],
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

/// Codes the positions of vertices `0..vertex_count` (traversal order); `actual` holds them on
/// the encoder and is empty on the decoder. `triangles` index traversal order.
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
    // Triangles around each vertex, as compressed rows, for the vertices of some triangle: those in
    // none follow and have no row. Sized by the decoded triangles, not by the header's vertex
    // count, which only the positions decoded below prove.
    let touched = triangles
        .iter()
        .flatten()
        .max()
        .map_or(0, |&v| v as usize + 1);
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
    let by_edge = by_edge(triangles);

    let mut models = Models::default();
    // Grown as positions decode (the encoder knows them all).
    let mut cells: Vec<Cell> = Vec::with_capacity(actual.len().max(touched));
    for v in 0..vertex_count as u32 {
        let row = start
            .get(v as usize..v as usize + 2)
            .map_or(0..0, |r| r[0]..r[1]);
        let (mut par_sum, mut par_n) = ([0i64; 3], 0i64);
        let (mut nb_sum, mut nb_n) = ([0i64; 3], 0i64);
        for &t in &around[row] {
            let tri = triangles[t as usize];
            let Some(k) = tri.iter().position(|&x| x == v) else {
                continue;
            };
            let (a, b) = (tri[(k + 1) % 3], tri[(k + 2) % 3]);
            for n in [a, b] {
                if n < v {
                    let c = cells[n as usize];
                    for i in 0..3 {
                        nb_sum[i] += i64::from(c[i]);
                    }
                    nb_n += 1;
                }
            }
            if a >= v || b >= v {
                continue;
            }
            for &u in by_edge.get(&undirected(a, b)).map_or(&[][..], |l| &l[..]) {
                if u == t {
                    continue;
                }
                let other = triangles[u as usize];
                let Some(&c) = other.iter().find(|&&x| x != a && x != b) else {
                    continue;
                };
                if c >= v {
                    continue;
                }
                let (pa, pb, pc) = (cells[a as usize], cells[b as usize], cells[c as usize]);
                for i in 0..3 {
                    par_sum[i] += i64::from(pa[i]) + i64::from(pb[i]) - i64::from(pc[i]);
                }
                par_n += 1;
            }
        }
        let (prediction, axis_models) = if par_n > 0 {
            let slot = usize::from(par_n > 1);
            (mean(par_sum, par_n, grid), &mut models.parallelogram[slot])
        } else if nb_n > 0 {
            (mean(nb_sum, nb_n, grid), &mut models.neighbours)
        } else {
            let previous = cells
                .last()
                .copied()
                .unwrap_or([(grid.max_level() + 1) / 2; 3]);
            (previous, &mut models.delta)
        };
        let target = actual.get(v as usize).copied().unwrap_or(prediction);
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
        cells.push(cell);
    }
    Ok(cells)
}
