//! How sharply the welded surface folds at each edge, from the decoded positions: exporters split
//! a vertex wherever its normal changes (a hard edge), so copies run along creases, and the copies
//! coder (`weld`) reads this as a context. The decoder knows the positions before the copies.

use std::collections::HashMap;

use super::quantise::Cell;
use super::traversal::undirected;
use crate::mesh::Triangle;

/// Fold classes of an edge: smooth, bent, sharp (or a border, or more than two triangles).
pub(super) const CLASSES: usize = 3;
/// Cosines of the angle between the two triangles' normals that bound the classes.
const SMOOTH_COS: f64 = 0.95;
const BENT_COS: f64 = 0.7;

/// The fold class of every edge of `triangles` (welded indices into `cells`), by
/// [`undirected`] key.
pub(super) fn classify(triangles: &[Triangle], cells: &[Cell]) -> HashMap<u64, u8> {
    let normal = |tri: &Triangle| -> Option<[f64; 3]> {
        let p = tri.map(|v| cells.get(v as usize).map(|c| c.map(f64::from)));
        let [Some(a), Some(b), Some(c)] = p else {
            return None;
        };
        let (u, w) = ([0, 1, 2].map(|i| b[i] - a[i]), [0, 1, 2].map(|i| c[i] - a[i]));
        Some([
            u[1] * w[2] - u[2] * w[1],
            u[2] * w[0] - u[0] * w[2],
            u[0] * w[1] - u[1] * w[0],
        ])
    };
    let mut sides: HashMap<u64, Vec<(usize, bool)>> = HashMap::new();
    for (t, tri) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            sides.entry(undirected(a, b)).or_default().push((t, a < b));
        }
    }
    sides
        .into_iter()
        .map(|(edge, on)| {
            let class = match on[..] {
                [(s, forward_s), (t, forward_t)] => {
                    let cos = (normal(&triangles[s]), normal(&triangles[t]));
                    match cos {
                        (Some(m), Some(n)) => {
                            // Consistently oriented neighbours run the edge in opposite directions.
                            let sign = if forward_s == forward_t { -1.0 } else { 1.0 };
                            let dot: f64 = (0..3).map(|i| m[i] * n[i]).sum();
                            let norms = (m.iter().map(|x| x * x).sum::<f64>()
                                * n.iter().map(|x| x * x).sum::<f64>())
                            .sqrt();
                            let cos = if norms > 0.0 { sign * dot / norms } else { -1.0 };
                            if cos > SMOOTH_COS {
                                0
                            } else if cos > BENT_COS {
                                1
                            } else {
                                2
                            }
                        }
                        _ => 2,
                    }
                }
                _ => 2,
            };
            (edge, class)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edges_are_classed_by_the_fold_between_their_triangles() {
        // Two triangles on the edge 0-1, the second's far corner lifted by `h`: flat, bent by
        // about 27 degrees, folded square.
        let class_of = |h: i32| {
            let cells = [[0, 0, 0], [10, 0, 0], [5, 10, 0], [5, -10, h]];
            let triangles = [[0, 1, 2], [1, 0, 3]];
            let folds = classify(&triangles, &cells);
            (folds[&undirected(0, 1)], folds[&undirected(1, 2)])
        };
        assert_eq!(class_of(0), (0, 2), "flat; 1-2 is a border");
        assert_eq!(class_of(5), (1, 2));
        assert_eq!(class_of(-10_000), (2, 2));
        // Inconsistently oriented neighbours are compared as if they agreed.
        let cells = [[0, 0, 0], [10, 0, 0], [5, 10, 0], [5, -10, 0]];
        let folds = classify(&[[0, 1, 2], [0, 1, 3]], &cells);
        assert_eq!(folds[&undirected(0, 1)], 0);
    }
}
