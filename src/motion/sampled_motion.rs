//! What both segmentations (k-means and decimation) and border refinement work on: frame 0 and
//! evenly sampled frames in the unit frame of frame 0, and the vertex graph with seams welded.

use super::fit::UnitFrame;
use crate::mesh::topology::VertexAdjacency;
use crate::mesh::{AnimatedMesh, Triangle};

/// Regularisation of the affine fits on sampled motion (a vertex's ring in k-means, a cluster's
/// members in border refinement), relative to the source's spread: large enough that nearly flat
/// rings do not turn noise into wild out-of-plane coefficients, small enough not to bias real motion.
pub(super) const SAMPLED_FIT_LAMBDA: f64 = 1e-3;

/// Most copies of one position that are welded: seams make a few; more is collapsed geometry
/// (e.g. hidden parts parked at one point), and welding it would join unrelated parts through one hub.
const MAX_WELD_GROUP: usize = 8;

/// The mesh's vertex adjacency, plus an edge between vertices at the very same frame-0 position
/// that stay together (within float noise) in every sampled frame. Exporters split vertices along
/// UV and normal seams (glTF meshes often fall into dozens of pieces, a triangle soup at worst);
/// without these edges the rings would stop at every seam, down to a lone flat triangle.
pub(super) fn welded_adjacency(mesh: &AnimatedMesh, motion: &SampledMotion) -> VertexAdjacency {
    let mut groups: std::collections::HashMap<[u32; 3], Vec<u32>> =
        std::collections::HashMap::new();
    for (v, p) in mesh.frame(0).iter().enumerate() {
        groups
            .entry(p.map(f32::to_bits))
            .or_default()
            .push(v as u32);
    }
    let together = |a: u32, b: u32| {
        motion.frames.iter().all(|f| {
            let (p, q) = (f[a as usize], f[b as usize]);
            (0..3).all(|i| (p[i] - q[i]).abs() <= 1e-6)
        })
    };
    let mut edges: Vec<Triangle> = mesh.triangles().to_vec();
    for group in groups
        .values()
        .filter(|g| (2..=MAX_WELD_GROUP).contains(&g.len()))
    {
        for &v in &group[1..] {
            if together(group[0], v) {
                // A degenerate triangle contributes just the edge.
                edges.push([group[0], v, v]);
            }
        }
    }
    VertexAdjacency::new(mesh.vertex_count(), &edges)
}

/// Frame 0 and the sampled frames of an animation, in the unit frame of frame 0.
pub(super) struct SampledMotion {
    /// Frame 0.
    pub(super) rest: Vec<[f64; 3]>,
    /// The sampled frames.
    pub(super) frames: Vec<Vec<[f64; 3]>>,
}

impl SampledMotion {
    /// Frame 0 and up to `wanted` evenly spread frames (see [`feature_frames`]), in unit coordinates.
    pub(super) fn new(mesh: &AnimatedMesh, wanted: usize) -> Self {
        let unit = UnitFrame::of(mesh.frame(0));
        let to_unit = |f: &[crate::mesh::Point]| f.iter().map(|p| unit.to_unit(p)).collect();
        Self {
            rest: to_unit(mesh.frame(0)),
            frames: feature_frames(mesh.frame_count(), wanted)
                .into_iter()
                .map(|f| to_unit(mesh.frame(f)))
                .collect(),
        }
    }
}

/// Up to `wanted` frames spread evenly over `1..frame_count` (frame 0 is the identity for every vertex).
pub(super) fn feature_frames(frame_count: usize, wanted: usize) -> Vec<usize> {
    if frame_count <= 1 {
        return vec![0];
    }
    let last = frame_count - 1;
    let m = wanted.min(last);
    (1..=m).map(|j| (j * last + m / 2) / m).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn feature_frames_are_spread_and_distinct() {
        assert_eq!(feature_frames(1, 64), vec![0]);
        assert_eq!(feature_frames(5, 64), vec![1, 2, 3, 4]);
        let f = feature_frames(201, 64);
        assert_eq!(f.len(), 64);
        assert_eq!(f.last(), Some(&200));
        assert!(f.windows(2).all(|w| w[0] < w[1]));
    }
}
