//! Spatial prediction of a band's levels from the neighbours already coded in that band.
//!
//! Neighbouring vertices of a soft body move almost alike, so their residual trajectories, and so
//! their coefficients in one band, are close. The coder visits the vertices in a fixed order both
//! sides derive from the connectivity (a breadth-first traversal of the first frame's mesh, which the
//! decoder has before any band) and may predict each level by the rounded mean of the levels of the
//! vertex's one-ring neighbours visited before it. The prediction is on levels, so it is exact on
//! both sides (closed loop) and changes bytes only, never the reconstruction.

use crate::error::{Error, Result};
use crate::mesh::topology::VertexAdjacency;
use crate::mesh::Triangle;
use std::collections::VecDeque;

/// How a band's levels are predicted, chosen per band by the encoder (whichever codes smaller) and
/// written as the first bit of the band's chunk.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Spatial {
    /// Every level on its own.
    None,
    /// The rounded mean of the vertex's neighbours visited before it (0 without one).
    Mean,
}

impl Spatial {
    /// Both predictors, in the order of their stream bit.
    pub const ALL: [Spatial; 2] = [Spatial::None, Spatial::Mean];

    #[cfg(any(test, feature = "internals"))]
    /// The stream bit.
    pub fn bit(self) -> u64 {
        match self {
            Spatial::None => 0,
            Spatial::Mean => 1,
        }
    }

    /// The predictor of a stream bit.
    pub fn from_bit(bit: u64) -> Self {
        if bit == 0 {
            Spatial::None
        } else {
            Spatial::Mean
        }
    }
}

/// The order in which a band's vertices are coded, and each vertex's neighbours coded before it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Neighbourhood {
    /// `order[i]`: the vertex coded i-th.
    order: Vec<u32>,
    /// `earlier[offsets[i]..offsets[i + 1]]`: the neighbours of `order[i]` coded before it.
    offsets: Vec<usize>,
    earlier: Vec<u32>,
}

impl Neighbourhood {
    #[cfg(any(test, feature = "internals"))]
    /// `vertices` vertices in index order without neighbours: no spatial prediction possible.
    pub fn isolated(vertices: usize) -> Self {
        Self {
            order: (0..vertices as u32).collect(),
            offsets: vec![0; vertices + 1],
            earlier: Vec::new(),
        }
    }

    /// The neighbourhood of a connectivity; refuses a triangle that names a vertex out of range.
    pub fn new(vertices: usize, triangles: &[Triangle]) -> Result<Self> {
        if let Some(t) = triangles
            .iter()
            .find(|t| t.iter().any(|&i| i as usize >= vertices))
        {
            return Err(Error::Stream(format!(
                "triangle {t:?} names a vertex beyond the {vertices} of the mesh"
            )));
        }
        let adjacency = VertexAdjacency::new(vertices, triangles);
        let order = breadth_first(&adjacency);
        let mut rank = vec![0u32; vertices];
        for (i, &v) in order.iter().enumerate() {
            rank[v as usize] = i as u32;
        }
        let mut offsets = Vec::with_capacity(vertices + 1);
        let mut earlier = Vec::new();
        offsets.push(0);
        for (i, &v) in order.iter().enumerate() {
            let before = adjacency.neighbours(v as usize).iter();
            earlier.extend(before.filter(|&&w| (rank[w as usize] as usize) < i));
            offsets.push(earlier.len());
        }
        Ok(Self {
            order,
            offsets,
            earlier,
        })
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.order.len()
    }

    /// The vertices in coding order, each with its neighbours coded before it.
    pub fn visit(&self) -> impl Iterator<Item = (usize, &[u32])> {
        self.order
            .iter()
            .zip(self.offsets.windows(2))
            .map(|(&v, w)| (v as usize, &self.earlier[w[0]..w[1]]))
    }
}

/// Vertices in breadth-first order, components in order of their lowest vertex, neighbours in index
/// order.
fn breadth_first(adjacency: &VertexAdjacency) -> Vec<u32> {
    let n = adjacency.vertex_count();
    let mut seen = vec![false; n];
    let mut order = Vec::with_capacity(n);
    let mut queue = VecDeque::new();
    for s in 0..n {
        if seen[s] {
            continue;
        }
        seen[s] = true;
        queue.push_back(s as u32);
        while let Some(v) = queue.pop_front() {
            order.push(v);
            for &w in adjacency.neighbours(v as usize) {
                if !seen[w as usize] {
                    seen[w as usize] = true;
                    queue.push_back(w);
                }
            }
        }
    }
    order
}

/// What a vertex's coding reads of its neighbours coded before it in the band, for its three
/// axes at once: one pass over the neighbours instead of four per axis (the bands' context
/// gathering was a fifth of a default encode). Every neighbour's values are final when the vertex
/// is coded (it is not its own earlier neighbour), so one reading serves its three axes.
pub struct Around {
    /// Per axis: the sum of the neighbours' levels (i128: a damaged band's levels are checked only
    /// once it is decoded, and may be near ±2^63).
    sums: [i128; 3],
    /// Per axis: the largest magnitude among the neighbours' levels, and among their coded values.
    largest_level: [u64; 3],
    largest_coded: [u64; 3],
    /// Per axis: the sum of the signs of the neighbours' coded values.
    signs: [i64; 3],
    count: usize,
}

impl Around {
    /// The neighbours `earlier` in `levels` and `coded` (both `[3w + a]`).
    pub fn of(levels: &[i64], coded: &[i64], earlier: &[u32]) -> Self {
        let mut around = Self {
            sums: [0; 3],
            largest_level: [0; 3],
            largest_coded: [0; 3],
            signs: [0; 3],
            count: earlier.len(),
        };
        for &w in earlier {
            let at = 3 * w as usize;
            for a in 0..3 {
                let (level, value) = (levels[at + a], coded[at + a]);
                around.sums[a] += i128::from(level);
                around.largest_level[a] = around.largest_level[a].max(level.unsigned_abs());
                around.largest_coded[a] = around.largest_coded[a].max(value.unsigned_abs());
                around.signs[a] += value.signum();
            }
        }
        around
    }

    /// The prediction of axis `a`: the mean of the neighbours' levels rounded half towards zero,
    /// 0 without neighbours.
    pub fn mean(&self, a: usize) -> i64 {
        if self.count == 0 {
            return 0;
        }
        let (sum, n) = (self.sums[a], self.count as i128);
        // The sum of a few levels (each at most `MAX_LEVEL`) fits 64 bits, whose division is a
        // fraction of the 128-bit one's cost (it was 2 % of an encode); the wide one stays for the rest.
        let m = match (u64::try_from(sum.unsigned_abs()), u64::try_from(n)) {
            (Ok(s), Ok(n)) if s < 1 << 61 && n < 1 << 30 => ((2 * s + n - 1) / (2 * n)) as i128,
            _ => (2 * sum.abs() + n - 1) / (2 * n),
        };
        (if sum < 0 { -m } else { m }) as i64
    }

    /// The neighbourhood part of axis `a`'s magnitude context: the mean, rounded up, of the
    /// largest level and the largest coded value among the neighbours (0 without neighbours).
    pub fn magnitude(&self, a: usize) -> u64 {
        self.largest_level[a]
            .saturating_add(self.largest_coded[a])
            .div_ceil(2)
    }

    /// Axis `a`'s sign class (0: zero, 1: positive, 2: negative) of the sum of the signs of the
    /// neighbours' coded values: the coder's sign context. Neighbouring vertices move alike, so
    /// their coded values tend to share a sign, with or without the mean predictor.
    pub fn sign_class(&self, a: usize) -> usize {
        match self.signs[a].signum() {
            0 => 0,
            1 => 1,
            _ => 2,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn breadth_first_neighbourhood() {
        // A strip of two triangles: 0-1-2, 1-3-2, plus an isolated vertex 4.
        let n = Neighbourhood::new(5, &[[0, 1, 2], [1, 3, 2]]).unwrap();
        let visited: Vec<(usize, Vec<u32>)> = n.visit().map(|(v, e)| (v, e.to_vec())).collect();
        assert_eq!(
            visited,
            vec![
                (0, vec![]),
                (1, vec![0]),
                (2, vec![0, 1]),
                (3, vec![1, 2]),
                (4, vec![])
            ]
        );
        assert!(Neighbourhood::new(3, &[[0, 1, 3]]).is_err());
        let levels = [1, 0, -3, 2, 0, -2, 0, 0, 0];
        let mean = |earlier: &[u32], a| Around::of(&levels, &levels, earlier).mean(a);
        assert_eq!(mean(&[0, 1], 0), 1);
        assert_eq!(mean(&[0, 1], 2), -2);
        assert_eq!(mean(&[0, 2], 0), 0);
        assert_eq!(mean(&[0, 1, 2], 2), -2);
        assert_eq!(mean(&[], 0), 0);
    }

    #[test]
    fn around_is_each_axis_measured_alone() {
        // The per-axis definitions the coder used before the pass was shared (same streams).
        let largest = |values: &[i64], earlier: &[u32], a: usize| {
            earlier.iter().map(|&w| values[3 * w as usize + a].unsigned_abs()).max().unwrap_or(0)
        };
        let signs = |values: &[i64], earlier: &[u32], a: usize| {
            let sum: i64 = earlier.iter().map(|&w| values[3 * w as usize + a].signum()).sum();
            [0, 1, 2][(sum.signum() + 3) as usize % 3]
        };
        let levels = [5, -7, 0, i64::MAX, -3, 1, i64::MAX, 2, -1, -4, 0, 9];
        let coded = [0, 3, -1, -2, 0, 4, 1, -6, 0, 2, 2, -2];
        for earlier in [&[][..], &[0], &[1, 3], &[0, 1, 2, 3], &[0, 3]] {
            let around = Around::of(&levels, &coded, earlier);
            for a in 0..3 {
                let near = largest(&levels, earlier, a).saturating_add(largest(&coded, earlier, a));
                assert_eq!(around.magnitude(a), near.div_ceil(2), "{earlier:?} {a}");
                assert_eq!(around.sign_class(a), signs(&coded, earlier, a), "{earlier:?} {a}");
            }
        }
        // Levels near 2^63 sum in i128: the mean of two is i64::MAX, not an overflow.
        assert_eq!(Around::of(&levels, &coded, &[1, 2]).mean(0), i64::MAX);
    }
}
