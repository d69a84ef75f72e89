//! How sharply the welded surface folds at each edge, from the decoded positions: exporters split
//! a vertex wherever its normal changes (a hard edge), so copies run along creases, and the copies
//! coder (`weld`) reads this as a context. The decoder knows the positions before the copies.

use std::collections::HashMap;

use super::quantise::Cell;
use super::traversal::{by_edge, undirected};
use crate::mesh::Triangle;

/// Fold classes of an edge: smooth, bent, sharp (or a border, or more than two triangles).
pub(super) const CLASSES: usize = 3;
/// Cosines of the angle between the two triangles' normals that bound the classes.
const SMOOTH_COS: f64 = 0.95;
const BENT_COS: f64 = 0.7;

/// The fold class of every edge of `triangles` (welded indices into `cells`), by
/// [`undirected`] key.
pub(super) fn classify(triangles: &[Triangle], cells: &[Cell]) -> HashMap<u64, u8> {
    by_edge(triangles)
        .into_iter()
        .map(|(edge, on)| {
            let class = match on[..] {
                [s, t] => fold([triangles[s as usize], triangles[t as usize]], edge, cells),
                _ => 2,
            };
            (edge, class)
        })
        .collect()
}

/// The fold class between two triangles sharing `edge`: smooth, bent or sharp by the cosine
/// between their normals (sharp when either is degenerate or off the cells).
fn fold([s, t]: [Triangle; 2], edge: u64, cells: &[Cell]) -> u8 {
    let (Some(m), Some(n)) = (normal(s, cells), normal(t, cells)) else {
        return 2;
    };
    // Consistently oriented neighbours run their shared edge in opposite directions.
    let sign = if runs_up(s, edge) == runs_up(t, edge) {
        -1.0
    } else {
        1.0
    };
    let dot: f64 = (0..3).map(|i| m[i] * n[i]).sum();
    let norms = (m.iter().map(|x| x * x).sum::<f64>() * n.iter().map(|x| x * x).sum::<f64>()).sqrt();
    let cos = if norms > 0.0 { sign * dot / norms } else { -1.0 };
    if cos > SMOOTH_COS {
        0
    } else if cos > BENT_COS {
        1
    } else {
        2
    }
}

/// Whether `tri` runs `edge` from its smaller index to its larger.
fn runs_up(tri: Triangle, edge: u64) -> bool {
    (0..3).any(|k| {
        let (a, b) = (tri[k], tri[(k + 1) % 3]);
        a < b && undirected(a, b) == edge
    })
}

/// The (unnormalised) normal of `tri`, `None` when a corner is off the cells.
fn normal(tri: Triangle, cells: &[Cell]) -> Option<[f64; 3]> {
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
