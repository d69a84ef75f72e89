//! Opening cuts in the mesh handed to the unwrapper. Around each vertex on a cut, the piece's
//! faces fall into fans separated by the cut edges; every fan but the first gets its own copy of
//! the vertex, so the two sides of a cut share no vertex and flatten apart.
//!
//! `uvunwrap` welds vertices whose positions are bit-identical (for meshes split by normals or
//! UVs), which would glue the sides of a cut back together: each copy is therefore moved by one
//! unit in the last place of its x coordinate (a relative change of 1e-7, far below anything the
//! parameterisation or the stretch measure sees). Only the unwrapper sees the copies; the atlas
//! keeps the mesh's own vertex ids, and each face's corners keep their own 2D positions.

use crate::seed::Dsu;
use std::collections::{HashMap, HashSet};

/// The mesh the unwrapper gets: the input with the cut vertices duplicated.
pub(crate) struct OpenMesh {
    pub positions: Vec<[f32; 3]>,
    pub triangles: Vec<[u32; 3]>,
}

/// A piece's faces and its cut edges as `(low, high)` vertex ids.
pub(crate) type PieceCuts = (Vec<usize>, Vec<(u32, u32)>);

/// Opens the cuts of each piece.
pub(crate) fn open(positions: &[[f32; 3]], triangles: &[[u32; 3]], cuts: &[PieceCuts]) -> OpenMesh {
    let mut mesh = OpenMesh {
        positions: positions.to_vec(),
        triangles: triangles.to_vec(),
    };
    let mut taken: HashSet<[u32; 3]> = positions.iter().map(|p| p.map(f32::to_bits)).collect();
    for (faces, edges) in cuts {
        open_piece(&mut mesh, &mut taken, faces, edges);
    }
    mesh
}

fn open_piece(
    mesh: &mut OpenMesh,
    taken: &mut HashSet<[u32; 3]>,
    faces: &[usize],
    edges: &[(u32, u32)],
) {
    let cut: HashSet<(u32, u32)> = edges.iter().copied().collect();
    let mut fans: HashMap<u32, Vec<usize>> = HashMap::new();
    for &(a, b) in edges {
        fans.insert(a, Vec::new());
        fans.insert(b, Vec::new());
    }
    for &f in faces {
        for v in corners(&mesh.triangles[f]) {
            if let Some(fan) = fans.get_mut(&v) {
                fan.push(f);
            }
        }
    }
    let mut cut_vertices: Vec<u32> = fans.keys().copied().collect();
    cut_vertices.sort_unstable();
    for v in cut_vertices {
        let groups = fan_groups(&mesh.triangles, v, &fans[&v], &cut);
        for group in groups.iter().skip(1) {
            let copy = nudged_copy(mesh, taken, v);
            for &f in group {
                for c in mesh.triangles[f].iter_mut().filter(|c| **c == v) {
                    *c = copy;
                }
            }
        }
    }
}

/// A face's corners, each vertex once.
fn corners(t: &[u32; 3]) -> Vec<u32> {
    let mut c = t.to_vec();
    c.sort_unstable();
    c.dedup();
    c
}

/// The faces around `v` grouped into fans joined through edges `(v, w)` that are not cut;
/// groups in order of their first face.
fn fan_groups(
    triangles: &[[u32; 3]],
    v: u32,
    fan: &[usize],
    cut: &HashSet<(u32, u32)>,
) -> Vec<Vec<usize>> {
    let mut dsu = Dsu::new(fan.len());
    let mut by_edge: HashMap<u32, usize> = HashMap::new();
    for (i, &f) in fan.iter().enumerate() {
        for &w in triangles[f].iter().filter(|&&w| w != v) {
            if cut.contains(&(v.min(w), v.max(w))) {
                continue;
            }
            match by_edge.get(&w) {
                Some(&j) => dsu.union(i as u32, j as u32),
                None => {
                    by_edge.insert(w, i);
                }
            }
        }
    }
    let mut groups: Vec<Vec<usize>> = Vec::new();
    let mut group_of: HashMap<u32, usize> = HashMap::new();
    for (i, &f) in fan.iter().enumerate() {
        let root = dsu.find(i as u32);
        let next = groups.len();
        let g = *group_of.entry(root).or_insert(next);
        if g == groups.len() {
            groups.push(Vec::new());
        }
        groups[g].push(f);
    }
    groups
}

/// A new vertex at `v`'s position moved by `k` ulps in x (away from zero, or towards it where
/// that would overflow), with the smallest `k` that no vertex has yet.
fn nudged_copy(mesh: &mut OpenMesh, taken: &mut HashSet<[u32; 3]>, v: u32) -> u32 {
    let mut p = mesh.positions[v as usize];
    let base = p[0].to_bits();
    for k in 1u32.. {
        let away = f32::from_bits(base.wrapping_add(k));
        p[0] = if away.is_finite() {
            away
        } else {
            f32::from_bits(base.wrapping_sub(k))
        };
        if taken.insert(p.map(f32::to_bits)) {
            break;
        }
    }
    mesh.positions.push(p);
    (mesh.positions.len() - 1) as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_slit_splits_its_boundary_end_only() {
        // A fan of four triangles around vertex 0 (boundary loop 1-2-3-4), slit along 0-1: the
        // slit's inner tip (0) stays one vertex, its boundary end (1) gets one copy.
        let positions = [
            [0.0f32; 3],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, -1.0, 0.0],
        ];
        let triangles = [[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]];
        let faces: Vec<usize> = (0..4).collect();
        let m = open(&positions, &triangles, &[(faces, vec![(0, 1)])]);
        assert_eq!(m.positions.len(), 6);
        assert_eq!(m.triangles[0][0], m.triangles[3][0]);
        assert_ne!(m.triangles[0][1], m.triangles[3][2]);
        assert_eq!(m.positions[5][1..], [0.0, 0.0]);
        assert!(m.positions[5][0] > 1.0);
    }
}
