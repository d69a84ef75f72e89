//! Copies: vertices the temporal DCT does not code, because they move exactly as another.
//!
//! Meshes made for rendering split a vertex wherever its texture coordinates or normals jump
//! (seams, hard edges, flat shading): the split vertices lie at one position and move together.
//! On the three.js birds and horse 83 % of the vertices are such copies, on CesiumMan 29 %
//! (docs/design.md, "Copies"); coding each copy's residual trajectory again costs as much as
//! coding the first.
//!
//! Both sides group the vertices by their position in the reference (the decoded first frame,
//! which the decoder has before any band). Each vertex after the first of its group is a
//! *candidate*; one adaptive bit per candidate, in the band index, says whether it is a copy of
//! its group's first vertex. The encoder sets it when the two input trajectories are equal to the
//! bit, so giving the copy the first one's decoded positions loses nothing; coincident vertices
//! that part later (lips, slits, cloth touching itself) are coded as before. The bands then hold
//! the kept vertices only, over the connectivity with every copy merged into its first: the
//! seams close, and the spatial prediction sees across them.

use crate::mesh::topology::coincident_first;
use crate::mesh::{Point, Triangle};

/// The vertices after the first at their reference position, each with that first vertex, in
/// vertex order: what a copy bit is coded for.
pub fn candidates(reference: &[Point]) -> Vec<(u32, u32)> {
    (coincident_first(reference).into_iter().enumerate())
        .filter_map(|(v, f)| Some((v as u32, f?)))
        .collect()
}

/// The encoder's copy bit of each candidate: whether its trajectory in `frames` equals its first
/// vertex's, to the bit.
pub fn equal_trajectories(candidates: &[(u32, u32)], frames: &[Vec<Point>]) -> Vec<bool> {
    let bits = |p: &Point| p.map(f32::to_bits);
    candidates
        .iter()
        .map(|&(v, f)| {
            (frames.iter()).all(|frame| bits(&frame[v as usize]) == bits(&frame[f as usize]))
        })
        .collect()
}

/// Which vertices the bands hold, and where each vertex's positions come from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Copies {
    /// `source[v]`: the vertex whose decoded positions `v` takes (itself unless a copy).
    source: Vec<u32>,
    /// `slot[v]`: the index among the kept vertices of `source[v]`.
    slot: Vec<u32>,
    /// The kept vertices, in vertex order.
    kept: Vec<u32>,
}

impl Copies {
    /// The copies of `vertices` vertices: candidate `i` is a copy when `bits[i]`.
    pub fn new(vertices: usize, candidates: &[(u32, u32)], bits: &[bool]) -> Self {
        let mut source: Vec<u32> = (0..vertices as u32).collect();
        for (&(v, first), _) in candidates.iter().zip(bits).filter(|(_, &b)| b) {
            source[v as usize] = first;
        }
        let kept: Vec<u32> = (0..vertices as u32)
            .filter(|&v| source[v as usize] == v)
            .collect();
        let mut slot = vec![0u32; vertices];
        for (i, &v) in kept.iter().enumerate() {
            slot[v as usize] = i as u32;
        }
        for v in 0..vertices {
            slot[v] = slot[source[v] as usize];
        }
        Self { source, slot, kept }
    }

    /// Whether any vertex is a copy.
    pub fn any(&self) -> bool {
        self.kept.len() < self.source.len()
    }

    /// Number of vertices the bands hold.
    pub fn kept_count(&self) -> usize {
        self.kept.len()
    }

    /// Each frame's residuals of the kept vertices only.
    pub fn keep_residuals(&self, residuals: &[Vec<[f32; 3]>]) -> Vec<Vec<[f32; 3]>> {
        (residuals.iter())
            .map(|frame| self.kept.iter().map(|&v| frame[v as usize]).collect())
            .collect()
    }

    /// The connectivity over the kept vertices: every copy merged into its first, the triangles
    /// that merging collapses left out.
    pub fn merged_triangles(&self, triangles: &[Triangle]) -> Vec<Triangle> {
        (triangles.iter())
            .filter_map(|t| {
                let [a, b, c] = t.map(|v| self.slot.get(v as usize).copied().unwrap_or(u32::MAX));
                (a != b && b != c && a != c && a != u32::MAX && b != u32::MAX && c != u32::MAX)
                    .then_some([a, b, c])
            })
            .collect()
    }

    /// Adds the kept vertices' residuals (`sums[3 · slot + axis]`) to their predictions in
    /// `frame`, then gives every copy its first vertex's decoded position.
    pub fn add_to_frame(&self, frame: &mut [Point], sums: &[f64]) {
        for (&v, s) in self.kept.iter().zip(sums.chunks_exact(3)) {
            if let Some(p) = frame.get_mut(v as usize) {
                for a in 0..3 {
                    p[a] += s[a] as f32;
                }
            }
        }
        self.copy_into(frame);
    }

    /// Gives every copy its first vertex's position.
    pub fn copy_into(&self, frame: &mut [Point]) {
        for (v, &s) in self.source.iter().enumerate() {
            if s as usize != v && (s as usize) < frame.len() && v < frame.len() {
                frame[v] = frame[s as usize];
            }
        }
    }

    /// The kept vertex at `slot`.
    pub fn kept_vertex(&self, slot: usize) -> usize {
        self.kept[slot] as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_coincident_vertices_that_move_alike_are_copies() {
        // 0 and 2 coincide and move alike; 1 and 3 coincide in the reference but part in frame 1.
        let reference: Vec<Point> = vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0; 3], [1.0, 0.0, 0.0]];
        let frames = vec![
            reference.clone(),
            vec![[0.5; 3], [1.0, 1.0, 0.0], [0.5; 3], [1.0, -1.0, 0.0]],
        ];
        let c = candidates(&reference);
        assert_eq!(c, vec![(2, 0), (3, 1)]);
        let bits = equal_trajectories(&c, &frames);
        assert_eq!(bits, vec![true, false]);
        let copies = Copies::new(4, &c, &bits);
        assert!(copies.any());
        assert_eq!(copies.kept_count(), 3);
        // A triangle over a seam becomes one over the kept vertices; one collapsed by the merge goes.
        let merged = copies.merged_triangles(&[[0, 1, 3], [2, 1, 3], [0, 2, 1]]);
        assert_eq!(merged, vec![[0, 1, 2], [0, 1, 2]]);
        let mut frame = vec![[0.0; 3]; 4];
        copies.add_to_frame(&mut frame, &[1.0, 1.0, 1.0, 2.0, 2.0, 2.0, 3.0, 3.0, 3.0]);
        assert_eq!(frame, vec![[1.0; 3], [2.0; 3], [1.0; 3], [3.0; 3]]);
    }
}
