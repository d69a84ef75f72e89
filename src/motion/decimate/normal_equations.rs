//! The normal equations of a set of vertices, kept as sums so that merging two sets adds their
//! sums, and the closed-form least-squares error of the set's best affine map per frame (eq. 1–2).

use crate::motion::sampled_motion::SampledMotion;
use nalgebra::{Matrix3, Vector3};

/// Numbers kept per set before the per-frame ones: n, Σp (3), Σppᵀ (6, upper triangle), Σ‖x‖².
const HEAD: usize = 11;
/// Numbers per frame: Σ x pᵀ (3 × 3, row-major), Σ x (3).
const PER_FRAME: usize = 12;

/// Vertex trajectories in unit coordinates, vertex-major, and the layout of a set's sums.
pub(super) struct Sums {
    rest: Vec<[f64; 3]>,
    /// `trajectories[v * frames + i]`: vertex v at sampled frame i.
    trajectories: Vec<[f64; 3]>,
    frames: usize,
}

impl Sums {
    pub(super) fn new(motion: &SampledMotion, frames: usize) -> Self {
        let v_count = motion.rest.len();
        let mut trajectories = Vec::with_capacity(v_count * frames);
        for v in 0..v_count {
            trajectories.extend(motion.frames.iter().take(frames).map(|f| f[v]));
        }
        Self {
            rest: motion.rest.clone(),
            trajectories,
            frames,
        }
    }

    pub(super) fn len(&self) -> usize {
        HEAD + PER_FRAME * self.frames
    }

    /// Adds vertex `v`'s terms of the normal equations to `sums`.
    pub(super) fn add_vertex(&self, sums: &mut [f64], v: usize) {
        let p = self.rest[v];
        sums[0] += 1.0;
        for a in 0..3 {
            sums[1 + a] += p[a];
        }
        let mut k = 4;
        for a in 0..3 {
            for b in a..3 {
                sums[k] += p[a] * p[b];
                k += 1;
            }
        }
        let trajectory = &self.trajectories[v * self.frames..(v + 1) * self.frames];
        let mut energy = 0.0;
        for (slot, x) in sums[HEAD..].chunks_exact_mut(PER_FRAME).zip(trajectory) {
            for r in 0..3 {
                energy += x[r] * x[r];
                for c in 0..3 {
                    slot[3 * r + c] += x[r] * p[c];
                }
                slot[9 + r] += x[r];
            }
        }
        sums[10] += energy;
    }

    /// The least-squares error of the best affine map per frame (eq. 1–2) of the set whose sums these are.
    pub(super) fn error(&self, sums: &[f64]) -> f64 {
        let n = sums[0];
        if n <= 1.0 {
            return 0.0;
        }
        let s = Vector3::new(sums[1], sums[2], sums[3]);
        let m = Matrix3::new(
            sums[4], sums[5], sums[6], sums[5], sums[7], sums[8], sums[6], sums[8], sums[9],
        );
        let scatter = m - s * s.transpose() / n;
        let pinv = pseudo_inverse(&scatter, m.trace());
        let mut fitted = 0.0;
        for slot in sums[HEAD..].chunks_exact(PER_FRAME) {
            let sx = Vector3::new(slot[9], slot[10], slot[11]);
            let cross = Matrix3::from_row_slice(&slot[..9]) - sx * s.transpose() / n;
            // The energy the best map explains: the translation part, then the linear part.
            fitted += sx.norm_squared() / n + (cross * pinv * cross.transpose()).trace();
        }
        let energy = sums[10];
        let error = energy - fitted;
        // Below float noise on the uncentred energy the fit is exact: say 0, so ties go to size.
        if error < 1e-13 * energy {
            0.0
        } else {
            error
        }
    }
}

/// Pseudo-inverse of a symmetric positive semi-definite 3 × 3 matrix. Directions below the noise of
/// forming it from uncentred sums (`magnitude` = trace of Σppᵀ) or far below its largest eigenvalue
/// are dropped: the fit is free along them, as the least-squares minimum of a flat set is.
fn pseudo_inverse(scatter: &Matrix3<f64>, magnitude: f64) -> Matrix3<f64> {
    let eigen = scatter.symmetric_eigen();
    let largest = eigen.eigenvalues.max();
    let floor = (1e-10 * largest)
        .max(1e-14 * magnitude)
        .max(f64::MIN_POSITIVE);
    let mut out = Matrix3::zeros();
    for k in 0..3 {
        let lambda = eigen.eigenvalues[k];
        if lambda > floor {
            let e = eigen.eigenvectors.column(k);
            out += e * e.transpose() / lambda;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::fit::{apply, AffineSolver};

    fn sums_of(points: &[[f64; 3]], frames: &[Vec<[f64; 3]>]) -> (Sums, Vec<f64>) {
        let motion = SampledMotion {
            rest: points.to_vec(),
            frames: frames.to_vec(),
        };
        let sums = Sums::new(&motion, frames.len());
        let mut s = vec![0.0; sums.len()];
        for v in 0..points.len() {
            sums.add_vertex(&mut s, v);
        }
        (sums, s)
    }

    /// The closed form agrees with a direct least-squares fit, for a full-rank set and a flat one.
    #[test]
    fn error_matches_a_direct_fit() {
        let points = [
            [0.1, 0.0, 0.2],
            [0.3, 0.1, -0.1],
            [-0.2, 0.25, 0.05],
            [0.05, -0.3, 0.1],
            [0.2, 0.2, 0.3],
            [-0.1, -0.1, -0.2],
        ];
        let wobble = |p: [f64; 3], k: usize| {
            [
                0.9 * p[0] + 0.1 * p[1] + 0.02 * (k as f64 * 1.7).sin(),
                p[1] + 0.3 * p[2] * p[2],
                p[2] - 0.2 + 0.01 * (k as f64).cos(),
            ]
        };
        let frames: Vec<Vec<[f64; 3]>> = (0..2)
            .map(|f| {
                (0..points.len())
                    .map(|k| wobble(points[k], k + f))
                    .collect()
            })
            .collect();
        let (sums, s) = sums_of(&points, &frames);
        let direct: f64 = frames
            .iter()
            .map(|f| {
                let solver = AffineSolver::new(&points, 0.0);
                let h = solver.solve(f.iter().copied());
                points
                    .iter()
                    .zip(f)
                    .map(|(&p, q)| {
                        let r = apply(&h, p);
                        (0..3).map(|a| (r[a] - q[a]).powi(2)).sum::<f64>()
                    })
                    .sum::<f64>()
            })
            .sum();
        let closed = sums.error(&s);
        assert!(direct > 1e-6, "the test motion must not be affine");
        assert!(
            (closed - direct).abs() < 1e-9 * direct.max(1.0),
            "{closed} vs {direct}"
        );

        // Four coplanar points moving out of their plane non-affinely: the minimum is not zero,
        // and three of them alone (always exactly affine) have zero error.
        let flat = [
            [0.0, 0.0, 0.0],
            [0.2, 0.0, 0.0],
            [0.0, 0.2, 0.0],
            [0.2, 0.2, 0.0],
        ];
        let bent = vec![vec![
            [0.0, 0.0, 0.0],
            [0.2, 0.0, 0.0],
            [0.0, 0.2, 0.0],
            [0.2, 0.2, 0.1],
        ]];
        let (sums, s) = sums_of(&flat, &bent);
        // Best fit spreads the 0.1 offset: residuals ±0.025 on all four in z: 4 × 0.025².
        assert!(
            (sums.error(&s) - 4.0 * 0.025f64.powi(2)).abs() < 1e-12,
            "{}",
            sums.error(&s)
        );
        let (sums, s) = sums_of(&flat[..3], &[bent[0][..3].to_vec()]);
        assert_eq!(sums.error(&s), 0.0);
    }

    /// Coincident frame-0 points that part later cannot share an affine map.
    #[test]
    fn coincident_points_that_part_have_an_error() {
        let points = [[0.1, 0.1, 0.1], [0.1, 0.1, 0.1]];
        let frames = vec![vec![[0.1, 0.1, 0.1], [0.3, 0.1, 0.1]]];
        let (sums, s) = sums_of(&points, &frames);
        assert!((sums.error(&s) - 2.0 * 0.1f64.powi(2)).abs() < 1e-12);
    }
}
