//! Connectivity helpers: vertex adjacency, k-ring neighbourhoods, connected components, manifoldness.
//!
//! Non-manifold and multi-component meshes are normal input: everything here works on any triangle soup.

use super::{Point, Triangle};
use std::collections::HashMap;

/// For each vertex, the first vertex at exactly its position, when that is an earlier one: the
/// copies a mesh made for rendering splits at seams and hard edges. Coders that know the decoded
/// first frame predict a copy's data from its first (`codec/tdct/copies.rs`, `stream/side_info.rs`).
pub fn coincident_first(positions: &[Point]) -> Vec<Option<u32>> {
    let mut first: HashMap<[u32; 3], u32> = HashMap::with_capacity(positions.len());
    (positions.iter().enumerate())
        .map(|(v, p)| {
            let f = *first.entry(p.map(f32::to_bits)).or_insert(v as u32);
            (f as usize != v).then_some(f)
        })
        .collect()
}

/// Vertex adjacency in compressed-sparse-row form: the neighbours of `v` are `neighbours(v)`, sorted, no repeats.
#[derive(Debug, Clone)]
pub struct VertexAdjacency {
    offsets: Vec<usize>,
    targets: Vec<u32>,
}

impl VertexAdjacency {
    /// Builds the adjacency of `vertex_count` vertices from the triangles' edges; degenerate
    /// triangles (repeated index) contribute only their real edges.
    pub fn new(vertex_count: usize, triangles: &[Triangle]) -> Self {
        let mut pairs: Vec<(u32, u32)> = Vec::with_capacity(triangles.len() * 6);
        for t in triangles {
            for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                if a != b {
                    pairs.push((a, b));
                    pairs.push((b, a));
                }
            }
        }
        pairs.sort_unstable();
        pairs.dedup();
        let mut offsets = vec![0usize; vertex_count + 1];
        for &(a, _) in &pairs {
            offsets[a as usize + 1] += 1;
        }
        for i in 0..vertex_count {
            offsets[i + 1] += offsets[i];
        }
        let targets = pairs.into_iter().map(|(_, b)| b).collect();
        Self { offsets, targets }
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.offsets.len() - 1
    }

    /// The sorted neighbours of vertex `v`.
    pub fn neighbours(&self, v: usize) -> &[u32] {
        &self.targets[self.offsets[v]..self.offsets[v + 1]]
    }

    #[cfg(any(test, feature = "internals"))]
    /// All vertices within `k` edges of `v`, `v` itself first, then by increasing distance.
    pub fn k_ring(&self, v: usize, k: usize) -> Vec<u32> {
        let mut scratch = KRingScratch::new(self.vertex_count());
        scratch.k_ring(self, v, k).to_vec()
    }

    /// Connected components: a label per vertex (0-based, in order of first vertex) and their count.
    /// Isolated vertices are components of their own.
    pub fn components(&self) -> (Vec<u32>, usize) {
        let n = self.vertex_count();
        let mut label = vec![u32::MAX; n];
        let mut count = 0u32;
        let mut stack = Vec::new();
        for s in 0..n {
            if label[s] != u32::MAX {
                continue;
            }
            label[s] = count;
            stack.push(s as u32);
            while let Some(v) = stack.pop() {
                for &w in self.neighbours(v as usize) {
                    if label[w as usize] == u32::MAX {
                        label[w as usize] = count;
                        stack.push(w);
                    }
                }
            }
            count += 1;
        }
        (label, count as usize)
    }
}

/// Reusable buffers for many k-ring queries on one mesh (avoids an allocation per vertex).
#[derive(Debug, Clone)]
pub struct KRingScratch {
    mark: Vec<u32>,
    stamp: u32,
    out: Vec<u32>,
}

impl KRingScratch {
    /// Scratch space for a mesh of `vertex_count` vertices.
    pub fn new(vertex_count: usize) -> Self {
        Self {
            mark: vec![0; vertex_count],
            stamp: 0,
            out: Vec::new(),
        }
    }

    /// All vertices within `k` edges of `v` (breadth-first, `v` first); valid until the next call.
    pub fn k_ring(&mut self, adj: &VertexAdjacency, v: usize, k: usize) -> &[u32] {
        self.stamp = self.stamp.wrapping_add(1);
        if self.stamp == 0 {
            self.mark.iter_mut().for_each(|m| *m = 0);
            self.stamp = 1;
        }
        self.out.clear();
        self.out.push(v as u32);
        self.mark[v] = self.stamp;
        let mut begin = 0;
        for _ in 0..k {
            let end = self.out.len();
            for i in begin..end {
                let u = self.out[i] as usize;
                for &w in adj.neighbours(u) {
                    if self.mark[w as usize] != self.stamp {
                        self.mark[w as usize] = self.stamp;
                        self.out.push(w);
                    }
                }
            }
            if end == self.out.len() {
                break;
            }
            begin = end;
        }
        &self.out
    }
}

/// What is non-manifold about a mesh, counted.
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
pub struct ManifoldReport {
    /// Edges shared by more than two triangles.
    pub non_manifold_edges: usize,
    /// Vertices whose triangle fan is not a single disc or half-disc.
    pub non_manifold_vertices: usize,
    /// Edges used by exactly one triangle.
    pub boundary_edges: usize,
    /// Triangles with a repeated vertex index.
    pub degenerate_triangles: usize,
    /// Vertices no triangle uses.
    pub isolated_vertices: usize,
}

impl ManifoldReport {
    /// Examines the triangles of a mesh with `vertex_count` vertices.
    pub fn new(vertex_count: usize, triangles: &[Triangle]) -> Self {
        let mut report = ManifoldReport::default();
        let mut edge_use: HashMap<(u32, u32), u32> =
            HashMap::with_capacity(triangles.len() * 3 / 2);
        let mut used = vec![false; vertex_count];
        // For the vertex test: each corner contributes the edge between its two other vertices to the
        // vertex's link; a manifold vertex's link is one path or one cycle.
        let mut link: Vec<Vec<(u32, u32)>> = vec![Vec::new(); vertex_count];
        for t in triangles {
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                report.degenerate_triangles += 1;
                continue;
            }
            for c in 0..3 {
                let (a, b) = (t[c], t[(c + 1) % 3]);
                *edge_use.entry((a.min(b), a.max(b))).or_insert(0) += 1;
                used[t[c] as usize] = true;
                link[t[c] as usize].push((t[(c + 1) % 3], t[(c + 2) % 3]));
            }
        }
        for &n in edge_use.values() {
            match n {
                1 => report.boundary_edges += 1,
                2 => {}
                _ => report.non_manifold_edges += 1,
            }
        }
        report.isolated_vertices = used.iter().filter(|&&u| !u).count();
        report.non_manifold_vertices = link
            .iter()
            .filter(|edges| !edges.is_empty() && !is_single_fan(edges))
            .count();
        report
    }

    /// True when every edge has at most two triangles, every vertex fan is one disc, and no triangle is degenerate.
    pub fn is_manifold(&self) -> bool {
        self.non_manifold_edges == 0
            && self.non_manifold_vertices == 0
            && self.degenerate_triangles == 0
    }
}

/// Whether the link edges of one vertex form a single connected path or cycle.
fn is_single_fan(edges: &[(u32, u32)]) -> bool {
    let mut degree: HashMap<u32, u32> = HashMap::new();
    for &(a, b) in edges {
        *degree.entry(a).or_insert(0) += 1;
        *degree.entry(b).or_insert(0) += 1;
    }
    if degree.values().any(|&d| d > 2) {
        return false;
    }
    // Connectedness of the link graph by union-find over its few vertices.
    let keys: Vec<u32> = degree.keys().copied().collect();
    let index: HashMap<u32, usize> = keys.iter().enumerate().map(|(i, &k)| (k, i)).collect();
    let mut parent: Vec<usize> = (0..keys.len()).collect();
    fn find(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    for &(a, b) in edges {
        let (ra, rb) = (find(&mut parent, index[&a]), find(&mut parent, index[&b]));
        parent[ra] = rb;
    }
    let root = find(&mut parent, 0);
    (0..keys.len()).all(|i| find(&mut parent, i) == root)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two triangles sharing an edge, plus a separate triangle.
    fn two_parts() -> Vec<Triangle> {
        vec![[0, 1, 2], [2, 1, 3], [4, 5, 6]]
    }

    #[test]
    fn adjacency_and_rings() {
        let adj = VertexAdjacency::new(7, &two_parts());
        assert_eq!(adj.neighbours(1), &[0, 2, 3]);
        assert_eq!(adj.k_ring(0, 0), vec![0]);
        let mut r1 = adj.k_ring(0, 1);
        r1.sort();
        assert_eq!(r1, vec![0, 1, 2]);
        let mut r2 = adj.k_ring(0, 2);
        r2.sort();
        assert_eq!(r2, vec![0, 1, 2, 3]);
    }

    #[test]
    fn components_count_parts_and_isolated_vertices() {
        let adj = VertexAdjacency::new(8, &two_parts());
        let (labels, n) = adj.components();
        assert_eq!(n, 3);
        assert_eq!(labels[0], labels[3]);
        assert_ne!(labels[0], labels[4]);
        assert_eq!(labels[7], 2);
    }

    #[test]
    fn manifold_report_finds_fin_and_bowtie() {
        let closed = ManifoldReport::new(4, &[[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]]);
        assert!(closed.is_manifold());
        assert_eq!(closed.boundary_edges, 0);
        // Three triangles on edge (0,1): a fin.
        let fin = ManifoldReport::new(5, &[[0, 1, 2], [1, 0, 3], [0, 1, 4]]);
        assert_eq!(fin.non_manifold_edges, 1);
        assert!(!fin.is_manifold());
        // Two triangles touching at vertex 0 only: a bow-tie.
        let bowtie = ManifoldReport::new(5, &[[0, 1, 2], [0, 3, 4]]);
        assert_eq!(bowtie.non_manifold_edges, 0);
        assert_eq!(bowtie.non_manifold_vertices, 1);
        assert_eq!(ManifoldReport::new(4, &[[0, 0, 1]]).degenerate_triangles, 1);
    }
}
