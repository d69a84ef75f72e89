//! Regularised least-squares affine fits from one fixed source point set to many target sets.
//!
//! Both the segmentation (eq. 1, a vertex's ring) and the predictor (eq. 2, a cluster) fit many
//! frames against the same frame-0 points, so the normal matrix is factored once per source set.

use crate::mesh::Point;
#[cfg(feature = "encode")]
use nalgebra::{Matrix3, Vector3};

/// An affine map `x ↦ A x + b` as 12 coefficients, row by row: `[a00 a01 a02 b0 a10 … b2]`.
pub type AffineCoefficients = [f64; 12];

/// The identity map.
pub const IDENTITY: AffineCoefficients = [
    1.0, 0.0, 0.0, 0.0, //
    0.0, 1.0, 0.0, 0.0, //
    0.0, 0.0, 1.0, 0.0,
];

/// Applies an affine map to a point.
pub fn apply(h: &AffineCoefficients, p: [f64; 3]) -> [f64; 3] {
    let row = |r: usize| h[4 * r] * p[0] + h[4 * r + 1] * p[1] + h[4 * r + 2] * p[2] + h[4 * r + 3];
    [row(0), row(1), row(2)]
}

/// Maps positions into a unit frame derived only from a reference point set (centre of its bounding
/// box at the origin, its diagonal = 1), so coefficients are dimensionless and well conditioned, and
/// encoder and decoder derive the same frame from the same decoded reference.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UnitFrame {
    centre: [f64; 3],
    scale: f64,
}

impl UnitFrame {
    /// The unit frame of `reference`; a single point (zero diagonal) keeps scale 1.
    pub fn of(reference: &[Point]) -> Self {
        let (lo, hi) = crate::mesh::bounding_box(reference);
        let centre = [0, 1, 2].map(|a| (lo[a] as f64 + hi[a] as f64) / 2.0);
        let diag = (0..3)
            .map(|a| (hi[a] as f64 - lo[a] as f64).powi(2))
            .sum::<f64>()
            .sqrt();
        let scale = if diag.is_finite() && diag > 0.0 {
            diag
        } else {
            1.0
        };
        Self { centre, scale }
    }

    /// A world position in unit coordinates.
    pub fn to_unit(self, p: &Point) -> [f64; 3] {
        [0, 1, 2].map(|a| (p[a] as f64 - self.centre[a]) / self.scale)
    }

    /// A unit-coordinate position back in the world.
    pub fn to_world(self, q: [f64; 3]) -> Point {
        [0, 1, 2].map(|a| (q[a] * self.scale + self.centre[a]) as f32)
    }
}

/// Least-squares affine fits from a fixed source set, with Tikhonov regularisation toward the identity:
/// minimises `Σ‖A p + b − q‖² + λ‖A − I‖²`. Coplanar, colinear or single-point sources thus get the
/// identity in their unconstrained directions (a single point gets a pure translation) instead of NaN.
#[cfg(feature = "encode")]
#[derive(Debug, Clone)]
pub struct AffineSolver {
    mean: Vector3<f64>,
    centred: Vec<Vector3<f64>>,
    lambda: f64,
    inverse: Matrix3<f64>,
    /// For a (nearly) flat source, two tangents and the normal `t1 × t2` of its plane.
    plane: Option<[Vector3<f64>; 3]>,
    /// Whether some direction of the source is seen less than the regularisation weighs.
    degenerate: bool,
}

/// Smallest regularisation per source point, in unit coordinates: keeps a single point invertible.
const LAMBDA_FLOOR: f64 = 1e-12;

#[cfg(feature = "encode")]
impl AffineSolver {
    /// Factors the normal matrix of `source` (unit coordinates). `relative_lambda` scales the
    /// regularisation by the source's mean squared spread; an empty source gives the identity map.
    pub fn new(source: &[[f64; 3]], relative_lambda: f64) -> Self {
        let n = source.len().max(1) as f64;
        let mean = source
            .iter()
            .fold(Vector3::zeros(), |s, p| s + Vector3::from(*p))
            / n;
        let centred: Vec<Vector3<f64>> = source.iter().map(|p| Vector3::from(*p) - mean).collect();
        let scatter = centred
            .iter()
            .fold(Matrix3::zeros(), |s, p| s + p * p.transpose());
        let lambda = relative_lambda * scatter.trace() / 3.0 + LAMBDA_FLOOR * n;
        let regularised = scatter + Matrix3::identity() * lambda;
        // Symmetric positive definite by construction (λ > 0), so the inverse exists; the
        // fallback only guards against overflow in absurd inputs.
        let inverse = regularised
            .try_inverse()
            .unwrap_or_else(|| Matrix3::identity() / lambda);
        Self {
            mean,
            centred,
            lambda,
            inverse,
            plane: flat_plane(&scatter, lambda),
            degenerate: scatter.symmetric_eigenvalues().min() < lambda,
        }
    }

    /// Whether the source leaves some direction of the map to the regularisation (flat, on a line,
    /// a single point): the fitted map is then a guess in that direction.
    pub fn is_degenerate(&self) -> bool {
        self.degenerate
    }

    /// The best map from the source onto `target` (unit coordinates, same order and length as the source).
    pub fn solve(&self, target: impl IntoIterator<Item = [f64; 3]>) -> AffineCoefficients {
        let mut cross = Matrix3::identity() * self.lambda;
        let mut sum = Vector3::zeros();
        let mut count = 0usize;
        for (q, p) in target.into_iter().zip(&self.centred) {
            let q = Vector3::from(q);
            cross += q * p.transpose();
            sum += q;
            count += 1;
        }
        if count == 0 {
            return IDENTITY;
        }
        let mut a = cross * self.inverse;
        if let Some([t1, t2, n]) = self.plane {
            // The data do not see the normal direction; instead of leaving it at the identity (which
            // makes a rotated flat patch look unlike the rest of its rigid part), send the normal
            // where a similarity would: onto the cross product of the mapped tangents.
            let mapped = (a * t1).cross(&(a * t2));
            let size = mapped.norm();
            if size > 0.0 && size.is_finite() {
                let target = mapped / size.sqrt();
                a += (target - a * n) * n.transpose();
            }
        }
        let b = sum / count as f64 - a * self.mean;
        let mut h = [0.0; 12];
        for r in 0..3 {
            for c in 0..3 {
                h[4 * r + c] = a[(r, c)];
            }
            h[4 * r + 3] = b[r];
        }
        h
    }
}

/// The plane of a source whose scatter has exactly one direction the regularisation dominates.
#[cfg(feature = "encode")]
fn flat_plane(scatter: &Matrix3<f64>, lambda: f64) -> Option<[Vector3<f64>; 3]> {
    let eigen = scatter.symmetric_eigen();
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| eigen.eigenvalues[i].total_cmp(&eigen.eigenvalues[j]));
    let flat = eigen.eigenvalues[order[0]] < lambda && eigen.eigenvalues[order[1]] >= lambda;
    if !flat {
        return None;
    }
    let t1 = eigen.eigenvectors.column(order[2]).into_owned();
    let t2 = eigen.eigenvectors.column(order[1]).into_owned();
    Some([t1, t2, t1.cross(&t2)])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_an_exact_affine_map() {
        let src = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.3, 0.2, 0.9],
        ];
        let h = [
            0.9, 0.1, -0.2, 0.5, -0.1, 1.1, 0.3, -0.2, 0.2, 0.0, 0.8, 0.1,
        ];
        let solver = AffineSolver::new(&src, 0.0);
        let got = solver.solve(src.iter().map(|&p| apply(&h, p)));
        for (g, w) in got.iter().zip(&h) {
            assert!((g - w).abs() < 1e-9, "{got:?}");
        }
    }

    #[test]
    fn degenerate_sources_are_finite() {
        let plane = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
        ];
        let shift = |p: [f64; 3]| [p[0] + 1.0, p[1], p[2] + 2.0];
        for src in [&plane[..], &plane[..2], &plane[..1]] {
            let h = AffineSolver::new(src, 1e-3).solve(src.iter().map(|&p| shift(p)));
            assert!(h.iter().all(|c| c.is_finite()));
            for &p in src {
                let q = apply(&h, p);
                let want = shift(p);
                assert!(
                    (0..3).all(|a| (q[a] - want[a]).abs() < 1e-2),
                    "{q:?} vs {want:?}"
                );
            }
        }
        assert_eq!(AffineSolver::new(&[], 0.0).solve([]), IDENTITY);
    }

    #[test]
    fn a_rotated_flat_patch_gets_the_whole_rotation() {
        let plane = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.5, 0.2, 0.0],
        ];
        let (c, s) = (0.6f64.cos(), 0.6f64.sin());
        let h = [1.0, 0.0, 0.0, 0.3, 0.0, c, -s, 0.1, 0.0, s, c, -0.2];
        let got = AffineSolver::new(&plane, 1e-3).solve(plane.iter().map(|&p| apply(&h, p)));
        for (g, w) in got.iter().zip(&h) {
            assert!((g - w).abs() < 1e-2, "{got:?}");
        }
    }
}
