//! k-means by Lloyd's algorithm on the rows of a matrix, seeded by k-means++.
//!
//! Written here rather than taken from `linfa-clustering`: linfa measures every point–centroid
//! distance with a pairwise element loop, which was half of a default encode's time on the motion
//! descriptors (hundreds of dimensions); here a round's distances are one matrix product
//! (‖x‖² − 2 x·c + ‖c‖², ndarray's `dot`), the same rounds at a fraction of the cost
//! (docs/design.md, "Speed of the automatic choice").

use ndarray::{Array1, Array2, Axis};
use rand_xoshiro::rand_core::RngCore;

/// The `k` centroids of the rows of `x` (k ≥ 1, at most the rows): k-means++ seeding from `rng`,
/// then Lloyd rounds until no round moves the centroids (as one vector) more than `tolerance`,
/// or `max_rounds`. A centroid that loses every row keeps its place.
pub(crate) fn kmeans(
    x: &Array2<f32>,
    k: usize,
    rng: &mut impl RngCore,
    max_rounds: u64,
    tolerance: f32,
) -> Array2<f32> {
    let norms = row_norms(x);
    let mut centroids = seed(x, &norms, k, rng);
    for _ in 0..max_rounds {
        let labels = nearest_with(x, &norms, &centroids);
        let moved = means(x, &labels, &centroids);
        let shift = (&moved - &centroids).mapv(|d| d * d).sum().sqrt();
        centroids = moved;
        if shift <= tolerance {
            break;
        }
    }
    centroids
}

/// Each row's nearest centroid (ties: the lowest index).
pub(crate) fn nearest(x: &Array2<f32>, centroids: &Array2<f32>) -> Vec<usize> {
    nearest_with(x, &row_norms(x), centroids)
}

fn row_norms(x: &Array2<f32>) -> Array1<f32> {
    x.map_axis(Axis(1), |r| r.dot(&r))
}

/// Squared distances from every row to `c` through one matrix–vector product.
fn distances_to(x: &Array2<f32>, norms: &Array1<f32>, c: &Array1<f32>) -> Array1<f32> {
    let cc = c.dot(c);
    let xc = x.dot(c);
    ndarray::Zip::from(norms)
        .and(&xc)
        .map_collect(|&n, &d| (n - 2.0 * d + cc).max(0.0))
}

/// k-means++: the first centroid a uniformly drawn row, each next one a row drawn with
/// probability proportional to its squared distance to the nearest centroid so far.
fn seed(x: &Array2<f32>, norms: &Array1<f32>, k: usize, rng: &mut impl RngCore) -> Array2<f32> {
    let rows = x.nrows();
    let mut centroids = Array2::zeros((k, x.ncols()));
    let first = (rng.next_u64() % rows as u64) as usize;
    centroids.row_mut(0).assign(&x.row(first));
    let mut d2 = distances_to(x, norms, &x.row(first).to_owned());
    for j in 1..k {
        let total: f64 = d2.iter().map(|&d| f64::from(d)).sum();
        let pick = if total > 0.0 {
            let mut target = unit(rng) * total;
            d2.iter()
                .position(|&d| {
                    target -= f64::from(d);
                    target < 0.0
                })
                .unwrap_or(rows - 1)
        } else {
            (rng.next_u64() % rows as u64) as usize
        };
        let chosen = x.row(pick).to_owned();
        centroids.row_mut(j).assign(&chosen);
        let to_new = distances_to(x, norms, &chosen);
        ndarray::Zip::from(&mut d2)
            .and(&to_new)
            .for_each(|d, &n| *d = d.min(n));
    }
    centroids
}

/// A uniform number in [0, 1) from 53 random bits.
fn unit(rng: &mut impl RngCore) -> f64 {
    (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64
}

fn nearest_with(x: &Array2<f32>, norms: &Array1<f32>, centroids: &Array2<f32>) -> Vec<usize> {
    let cross = x.dot(&centroids.t());
    let centroid_norms = row_norms(centroids);
    cross
        .rows()
        .into_iter()
        .zip(norms)
        .map(|(row, &n)| {
            let mut best = (0, f32::INFINITY);
            for (j, (&xc, &cc)) in row.iter().zip(&centroid_norms).enumerate() {
                let d = n - 2.0 * xc + cc;
                if d < best.1 {
                    best = (j, d);
                }
            }
            best.0
        })
        .collect()
}

/// The mean of each centroid's rows; a centroid without rows stays where it is.
fn means(x: &Array2<f32>, labels: &[usize], centroids: &Array2<f32>) -> Array2<f32> {
    let mut sums = Array2::<f64>::zeros(centroids.raw_dim());
    let mut counts = vec![0usize; centroids.nrows()];
    for (row, &l) in x.rows().into_iter().zip(labels) {
        let mut sum = sums.row_mut(l);
        sum.zip_mut_with(&row, |s, &v| *s += f64::from(v));
        counts[l] += 1;
    }
    let mut moved = centroids.clone();
    for (j, &count) in counts.iter().enumerate() {
        if count > 0 {
            let mean = sums.row(j).mapv(|s| (s / count as f64) as f32);
            moved.row_mut(j).assign(&mean);
        }
    }
    moved
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_xoshiro::rand_core::SeedableRng;
    use rand_xoshiro::Xoshiro256Plus;

    /// Three well-separated blobs in 5 dimensions.
    fn blobs() -> (Array2<f32>, Vec<usize>) {
        let mut rng = Xoshiro256Plus::seed_from_u64(7);
        let centres = [[0.0f32; 5], [10.0; 5], [-10.0, 10.0, -10.0, 10.0, 0.0]];
        let mut rows = Vec::new();
        let mut truth = Vec::new();
        for i in 0..300 {
            let c = i % 3;
            truth.push(c);
            for &m in &centres[c] {
                rows.push(m + (unit(&mut rng) as f32 - 0.5));
            }
        }
        (Array2::from_shape_vec((300, 5), rows).unwrap(), truth)
    }

    #[test]
    fn separated_blobs_are_found_and_the_result_repeats() {
        let (x, truth) = blobs();
        let run = || {
            let mut rng = Xoshiro256Plus::seed_from_u64(0);
            kmeans(&x, 3, &mut rng, 20, 1e-6)
        };
        let centroids = run();
        assert_eq!(centroids, run());
        let labels = nearest(&x, &centroids);
        // Every blob in one cluster, every cluster one blob.
        for c in 0..3 {
            let of_blob: Vec<usize> = (0..300).filter(|&i| truth[i] == c).map(|i| labels[i]).collect();
            assert!(of_blob.iter().all(|&l| l == of_blob[0]), "blob {c}");
        }
        let mut seen: Vec<usize> = (0..3).map(|c| labels[c]).collect();
        seen.sort_unstable();
        assert_eq!(seen, vec![0, 1, 2]);
    }

    #[test]
    fn identical_rows_and_more_clusters_than_distinct_points() {
        let x = Array2::from_elem((10, 4), 1.5f32);
        let mut rng = Xoshiro256Plus::seed_from_u64(3);
        let centroids = kmeans(&x, 4, &mut rng, 10, 0.0);
        assert!(centroids.iter().all(|&v| v == 1.5));
        assert!(nearest(&x, &centroids).iter().all(|&l| l < 4));
    }
}
