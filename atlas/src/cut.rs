//! Cuts that open a genus-0 piece with several boundary loops into a disk: shortest paths along
//! mesh edges that join every loop into one tree, grown from the first loop (Dijkstra from all
//! the vertices joined so far to the nearest vertex of a loop not yet joined). An annulus (a band
//! of a tube) gets one cut between its two loops. A disk is what one chart needs: an annulus
//! handed to the unwrapper whole cannot flatten and is shattered into many small charts.

use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap, HashSet};

/// The piece's vertex graph: neighbours and edge lengths.
type Graph = HashMap<u32, Vec<(u32, f64)>>;

fn graph(positions: &[[f32; 3]], triangles: &[[u32; 3]], faces: &[usize]) -> Graph {
    let mut g: Graph = HashMap::new();
    let mut seen: HashSet<(u32, u32)> = HashSet::new();
    for &f in faces {
        let t = triangles[f];
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if a == b || !seen.insert((a.min(b), a.max(b))) {
                continue;
            }
            let (p, q) = (positions[a as usize], positions[b as usize]);
            let len = (0..3)
                .map(|i| f64::from(p[i] - q[i]).powi(2))
                .sum::<f64>()
                .sqrt();
            g.entry(a).or_default().push((b, len));
            g.entry(b).or_default().push((a, len));
        }
    }
    g
}

/// The edges (each as `(low, high)` vertex ids) of a tree of shortest paths joining all `loops`;
/// `None` when some loop cannot be reached through the piece's edges.
pub(crate) fn joining_cuts(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    faces: &[usize],
    loops: &[Vec<u32>],
) -> Option<Vec<(u32, u32)>> {
    let g = graph(positions, triangles, faces);
    let loop_of: HashMap<u32, usize> = loops
        .iter()
        .enumerate()
        .flat_map(|(i, l)| l.iter().map(move |&v| (v, i)))
        .collect();
    let mut joined = vec![false; loops.len()];
    joined[0] = true;
    let mut tree: Vec<u32> = loops.first()?.clone();
    let mut cuts = Vec::new();
    for _ in 1..loops.len() {
        let path = shortest_path(&g, &tree, |v| loop_of.get(&v).is_some_and(|&l| !joined[l]))?;
        let reached = *path.last()?;
        joined[loop_of[&reached]] = true;
        tree.extend(loops[loop_of[&reached]].iter().copied());
        for w in path.windows(2) {
            cuts.push((w[0].min(w[1]), w[0].max(w[1])));
        }
        tree.extend(path);
    }
    Some(cuts)
}

/// Dijkstra from all of `sources` to the nearest vertex where `is_target` holds; the path's
/// vertices from a source to that target.
fn shortest_path(g: &Graph, sources: &[u32], is_target: impl Fn(u32) -> bool) -> Option<Vec<u32>> {
    let mut dist: HashMap<u32, f64> = HashMap::new();
    let mut prev: HashMap<u32, u32> = HashMap::new();
    // Non-negative f64 order like their bit patterns, which makes them heap keys.
    let mut heap = BinaryHeap::new();
    for &s in sources {
        dist.insert(s, 0.0);
        heap.push(Reverse((0u64, s)));
    }
    while let Some(Reverse((bits, v))) = heap.pop() {
        let d = f64::from_bits(bits);
        if d > dist.get(&v).copied().unwrap_or(f64::INFINITY) {
            continue;
        }
        if is_target(v) {
            let mut path = vec![v];
            while let Some(&p) = prev.get(path.last()?) {
                path.push(p);
            }
            path.reverse();
            return Some(path);
        }
        for &(w, len) in g.get(&v).map(Vec::as_slice).unwrap_or(&[]) {
            let nd = d + len;
            if nd < dist.get(&w).copied().unwrap_or(f64::INFINITY) {
                dist.insert(w, nd);
                prev.insert(w, v);
                heap.push(Reverse((nd.to_bits(), w)));
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_annulus_gets_one_cut_between_its_loops() {
        // A square ring: outer loop 0..4, inner loop 4..8, eight quads between them.
        let positions = [
            [0.0, 0.0, 0.0],
            [3.0, 0.0, 0.0],
            [3.0, 3.0, 0.0],
            [0.0, 3.0, 0.0],
            [1.0, 1.0, 0.0],
            [2.0, 1.0, 0.0],
            [2.0, 2.0, 0.0],
            [1.0, 2.0, 0.0],
        ];
        let mut triangles = Vec::new();
        for k in 0..4u32 {
            let (o0, o1, i0, i1) = (k, (k + 1) % 4, 4 + k, 4 + (k + 1) % 4);
            triangles.push([o0, o1, i1]);
            triangles.push([o0, i1, i0]);
        }
        let faces: Vec<usize> = (0..triangles.len()).collect();
        let loops = vec![vec![0, 1, 2, 3], vec![4, 5, 6, 7]];
        let cuts = joining_cuts(&positions, &triangles, &faces, &loops);
        // The shortest join is one diagonal edge from a corner to the inner square.
        assert_eq!(cuts.map(|c| c.len()), Some(1));
    }
}
