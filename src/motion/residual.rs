//! Prediction residuals (MCGV eq. 4), what the geometry images carry, and their energy.

use crate::mesh::Point;

/// `frame − predicted`, vertex by vertex (over the shorter of the two, which callers keep equal).
pub fn residuals(frame: &[Point], predicted: &[Point]) -> Vec<[f32; 3]> {
    frame
        .iter()
        .zip(predicted)
        .map(|(x, p)| [x[0] - p[0], x[1] - p[1], x[2] - p[2]])
        .collect()
}

#[cfg(any(test, feature = "internals"))]
/// Sum of squared lengths of a set of displacement vectors.
pub fn energy(vectors: &[[f32; 3]]) -> f64 {
    vectors
        .iter()
        .map(|d| d.iter().map(|&c| (c as f64) * (c as f64)).sum::<f64>())
        .sum()
}
