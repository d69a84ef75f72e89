//! Seed charts: each motion cluster split into its edge-connected pieces.

use std::collections::HashMap;

/// Per-face cluster and seed piece.
pub(crate) struct Seeds {
    /// Cluster of each face: the majority cluster of its corners, or the first
    /// corner's when all three differ.
    pub face_cluster: Vec<u32>,
    /// Dense piece id of each face: faces of one cluster joined through shared edges.
    pub face_piece: Vec<u32>,
    /// Number of pieces.
    pub pieces: u32,
}

/// The cluster a face belongs to (majority vote, first corner on a three-way tie).
pub(crate) fn face_cluster(tri: &[u32; 3], partition: &[u32]) -> u32 {
    let c = tri.map(|v| partition.get(v as usize).copied().unwrap_or(0));
    if c[1] == c[2] {
        c[1]
    } else {
        c[0]
    }
}

/// Union-find with path halving; a few lines, so no crate for it.
pub(crate) struct Dsu(Vec<u32>);

impl Dsu {
    pub(crate) fn new(n: usize) -> Self {
        Dsu((0..n as u32).collect())
    }
    pub(crate) fn find(&mut self, mut x: u32) -> u32 {
        while self.0[x as usize] != x {
            let parent = self.0[self.0[x as usize] as usize];
            self.0[x as usize] = parent;
            x = parent;
        }
        x
    }
    pub(crate) fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            self.0[ra.max(rb) as usize] = ra.min(rb);
        }
    }
}

/// Splits the clusters (faces voting with their corners' clusters in `partition`) into pieces
/// connected through the edges of `welded`, the same triangles on welded vertex ids.
pub(crate) fn seeds(triangles: &[[u32; 3]], welded: &[[u32; 3]], partition: &[u32]) -> Seeds {
    let face_cluster: Vec<u32> = triangles
        .iter()
        .map(|t| face_cluster(t, partition))
        .collect();
    let (face_piece, pieces) = components(welded, &face_cluster);
    Seeds {
        face_cluster,
        face_piece,
        pieces,
    }
}

/// The faces that share a label, split into pieces connected through edges: a dense piece id per
/// face and the number of pieces. Edges shared by more than two faces (non-manifold) join every
/// face of the same label on them.
pub(crate) fn components(triangles: &[[u32; 3]], face_label: &[u32]) -> (Vec<u32>, u32) {
    let mut dsu = Dsu::new(triangles.len());
    let mut first_on_edge: HashMap<(u32, u32, u32), u32> = HashMap::new();
    for (f, tri) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            if a == b {
                continue;
            }
            let key = (a.min(b), a.max(b), face_label[f]);
            match first_on_edge.get(&key) {
                Some(&g) => dsu.union(g, f as u32),
                None => {
                    first_on_edge.insert(key, f as u32);
                }
            }
        }
    }
    let mut dense: HashMap<u32, u32> = HashMap::new();
    let face_piece = (0..triangles.len() as u32)
        .map(|f| {
            let root = dsu.find(f);
            let next = dense.len() as u32;
            *dense.entry(root).or_insert(next)
        })
        .collect();
    (face_piece, dense.len() as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clusters_split_into_edge_connected_pieces() {
        // Two triangles of cluster 0 touching only at vertex 2, one of cluster 1 sharing an edge.
        let tris = [[0, 1, 2], [2, 3, 4], [1, 5, 2]];
        let part = [0, 0, 0, 0, 0, 1];
        let s = seeds(&tris, &tris, &part);
        assert_eq!(s.pieces, 2);
        assert_ne!(s.face_piece[0], s.face_piece[1]);
        // Face 2 has corners in clusters 0, 1, 0: majority is 0, and it shares edge 1-2 with face 0.
        assert_eq!(s.face_cluster[2], 0);
        assert_eq!(s.face_piece[2], s.face_piece[0]);
    }

    #[test]
    fn three_way_tie_takes_first_corner() {
        assert_eq!(face_cluster(&[0, 1, 2], &[7, 8, 9]), 7);
    }
}
