//! Vertex normals recomputed on decode: the stream stores no normals.
//!
//! Area-weighted (each triangle adds its unnormalised cross product to its corners), summed over the
//! vertices that share a frame-0 position, so a glTF seam — a vertex split because its UVs differ on
//! each side — stays smooth, as the sources' seams are. Hard edges of a source are smoothed: the
//! stream does not say which split vertices were hard edges.

use crate::mesh::{position_key, Point, Triangle};
use crate::mesh::vector::{cross, sub};
use rustc_hash::FxHashMap;

/// Vertices grouped by identical frame-0 position: `group[v]` is the group of vertex `v`.
pub(super) struct Welding {
    group: Vec<u32>,
    groups: usize,
}

impl Welding {
    /// Groups the vertices of `frame0` whose coordinates are bit-for-bit equal.
    pub(super) fn new(frame0: &[Point]) -> Self {
        let mut seen: FxHashMap<[u32; 3], u32> = FxHashMap::default();
        let group = frame0
            .iter()
            .map(|p| {
                let key = position_key(p);
                let next = seen.len() as u32;
                *seen.entry(key).or_insert(next)
            })
            .collect();
        Self {
            group,
            groups: seen.len(),
        }
    }
}

/// Unit normal of every vertex of `positions` ((0, 0, 1) where every adjacent triangle is degenerate).
pub(super) fn vertex_normals(
    triangles: &[Triangle],
    positions: &[Point],
    welding: &Welding,
) -> Vec<Point> {
    let mut sums = vec![[0.0f64; 3]; welding.groups];
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize].map(f64::from));
        let n = cross(sub(b, a), sub(c, a));
        for &i in t {
            let s = &mut sums[welding.group[i as usize] as usize];
            for k in 0..3 {
                s[k] += n[k];
            }
        }
    }
    welding
        .group
        .iter()
        .map(|&g| {
            let s = sums[g as usize];
            let len = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
            if len > 1e-30 {
                s.map(|c| (c / len) as f32)
            } else {
                [0.0, 0.0, 1.0]
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_vertices_share_one_normal() {
        // Two triangles folded along the edge 1-2; vertex 3 repeats vertex 1's position (a seam).
        let positions = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 1.0],
        ];
        let triangles = [[0, 1, 2], [3, 4, 2]];
        let normals = vertex_normals(&triangles, &positions, &Welding::new(&positions));
        assert_eq!(normals[1], normals[3]);
        for n in normals {
            let len: f32 = n.iter().map(|c| c * c).sum();
            assert!((len - 1.0).abs() < 1e-5);
        }
    }
}
