//! k-means on the rows of a matrix: k-means++ seeding, then Lloyd rounds with the m_k-means
//! update — the algorithm of `linfa-clustering` 0.8 (which the project used before), reproduced to
//! the bit, so that the partition, and with it every stream, stays what it was.
//!
//! Written here rather than called from `linfa-clustering` because linfa measures every
//! point–centroid distance with an element loop: on the motion descriptors (768 dimensions) that
//! was half of a default encode's time. Here a round's nearest centroids come from one matrix
//! product (‖x‖² − 2 x·c + ‖c‖², ndarray's `dot`), and only the centroids that product cannot tell
//! apart from the nearest are measured exactly, in linfa's order of summation: the same labels at a
//! fraction of the cost (docs/design.md, "Speed of the automatic choice").

use ndarray::{Array1, Array2, ArrayView1, Axis};
use rand::distributions::{Distribution, WeightedIndex};
use rand::Rng;
use rayon::prelude::*;

/// Some rows of a matrix, in order: every row, or those listed (the k-means training rows are
/// most of the descriptors' rows; picking them by index spares a copy of the largest matrix of
/// an encode, and lets one [`Centred`] of the whole matrix serve every k-means on it).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Rows<'a> {
    x: &'a Array2<f32>,
    pick: Option<&'a [usize]>,
}

impl<'a> Rows<'a> {
    /// Every row of `x`.
    pub(crate) fn all(x: &'a Array2<f32>) -> Self {
        Self { x, pick: None }
    }

    /// The rows of `x` listed in `pick` (each in range), in that order.
    pub(crate) fn picked(x: &'a Array2<f32>, pick: &'a [usize]) -> Self {
        Self { x, pick: Some(pick) }
    }

    /// Number of rows.
    pub(crate) fn len(&self) -> usize {
        self.pick.map_or(self.x.nrows(), <[usize]>::len)
    }

    /// Row number of the `i`th row in the whole matrix.
    fn index(&self, i: usize) -> usize {
        self.pick.map_or(i, |p| p.get(i).copied().unwrap_or(usize::MAX))
    }

    /// The `i`th row (empty when out of range).
    fn row(&self, i: usize) -> std::borrow::Cow<'a, [f32]> {
        let r = self.index(i);
        if r >= self.x.nrows() {
            return std::borrow::Cow::Borrowed(&[]);
        }
        let row = self.x.row(r);
        match row.to_slice() {
            Some(s) => std::borrow::Cow::Borrowed(s),
            None => std::borrow::Cow::Owned(row.to_vec()),
        }
    }

    /// The rows `which` (numbered among these rows) as a matrix.
    pub(crate) fn select(&self, which: &[usize]) -> Array2<f32> {
        let whole: Vec<usize> = which.iter().map(|&i| self.index(i)).collect();
        self.x.select(Axis(0), &whole)
    }
}

/// The `k` centroids of the rows of `x` (1 ≤ k ≤ rows): k-means++ seeding from `rng`
/// ([`seed_rows`]), then [`kmeans_from`] those seeds.
#[cfg(test)]
pub(crate) fn kmeans(
    x: &Array2<f32>,
    k: usize,
    rng: &mut impl Rng,
    max_rounds: u64,
    tolerance: f32,
) -> Array2<f32> {
    let rows = Rows::all(x);
    let seeds = rows.select(&seed_rows(rows, k, rng));
    kmeans_from(rows, &Centred::new(x), seeds, max_rounds, tolerance)
}

/// The centroids Lloyd rounds reach from the seeds `centroids` on `rows` (rows like theirs):
/// rounds until the centroids (as one vector) move less than `tolerance`, or `max_rounds`. Each
/// update averages a centroid's rows together with the old centroid (m_k-means), so that an
/// emptied centroid stays where it was. `centred` is [`Centred::new`] of the whole matrix `rows`
/// are taken from.
pub(crate) fn kmeans_from(
    rows: Rows<'_>,
    centred: &Centred,
    mut centroids: Array2<f32>,
    max_rounds: u64,
    tolerance: f32,
) -> Array2<f32> {
    for _ in 0..max_rounds.max(1) {
        let labels = centred.nearest(rows, &centroids);
        let moved = means(rows, &labels, &centroids);
        let shift = exact_sq_distance(
            centroids.as_slice().unwrap_or(&[]),
            moved.as_slice().unwrap_or(&[]),
        );
        centroids = moved;
        // linfa's L2 distance: the f32 sum of squares, its root taken in f64.
        if (f64::from(shift).sqrt() as f32) < tolerance {
            break;
        }
    }
    centroids
}

/// Each row's nearest centroid (ties: the lowest index), measured as [`exact_sq_distance`] does;
/// `centred` is [`Centred::new`] of the whole matrix `rows` are taken from.
pub(crate) fn nearest(rows: Rows<'_>, centred: &Centred, centroids: &Array2<f32>) -> Vec<usize> {
    centred.nearest(rows, centroids)
}

/// The squared distance of two equally long vectors, summed in f32 from the first element on:
/// the value linfa's (ndarray-stats') `sq_l2_dist` gives, on which its choices depend.
fn exact_sq_distance(a: &[f32], b: &[f32]) -> f32 {
    exact_sq_distances([a], [b])[0]
}

/// [`exact_sq_distance`] of `L` pairs at once (over the shorter of each pair), each lane summed
/// in f32 from the first element on, as that function's value is defined. One pair's sum is a
/// chain of dependent additions that waits on each add's latency; `L` independent chains keep
/// the processor's adders busy (k-means++ seeding and the exact checks of `nearest` were a tenth
/// of a default tdct encode).
fn exact_sq_distances<const L: usize>(a: [&[f32]; L], b: [&[f32]; L]) -> [f32; L] {
    let len = (0..L).map(|l| a[l].len().min(b[l].len())).min().unwrap_or(0);
    let (a, b) = (a.map(|r| &r[..len]), b.map(|r| &r[..len]));
    let mut sums = [0f32; L];
    for j in 0..len {
        for l in 0..L {
            let d = a[l][j] - b[l][j];
            sums[l] += d * d;
        }
    }
    sums
}

/// The largest magnitude of an element, infinite if one is not finite.
fn largest_magnitude(x: &Array2<f32>) -> f32 {
    x.iter().fold(0f32, |m, v| {
        if v.is_finite() {
            m.max(v.abs())
        } else {
            f32::INFINITY
        }
    })
}

/// Rows measured side by side in the seeding's exact distances.
const LANES: usize = 8;

fn row_norms(x: &Array2<f32>) -> Array1<f32> {
    x.map_axis(Axis(1), |r| r.dot(&r))
}

/// The rows k-means++ picks as the `k` seeds of `x` (1 ≤ k ≤ rows), in order: the first a row
/// drawn uniformly from `rng` (as a weighted draw over weights one), each next one a row drawn
/// with probability proportional to its squared distance to the nearest seed so far (the first
/// row if every distance is zero). The first k seeds of K > k are the k seeds (the same draws in
/// the same order), so the seeds of a ladder's largest K serve every K of it.
pub(crate) fn seed_rows(x: Rows<'_>, k: usize, rng: &mut impl Rng) -> Vec<usize> {
    let rows = x.len();
    let first = WeightedIndex::new(std::iter::repeat_n(1f32, rows)).map_or(0, |w| w.sample(rng));
    let mut picked = vec![first];
    let mut nearest_d2 = vec![f32::INFINITY; rows];
    while picked.len() < k {
        let newest = x.row(picked[picked.len() - 1]);
        let newest = &newest[..];
        nearest_d2
            .par_chunks_mut(LANES)
            .enumerate()
            .for_each(|(c, ds)| {
                let first = c * LANES;
                if ds.len() == LANES {
                    let rows: [_; LANES] = std::array::from_fn(|l| x.row(first + l));
                    let d = exact_sq_distances(std::array::from_fn(|l| &rows[l][..]), [newest; LANES]);
                    ds.iter_mut().zip(d).for_each(|(m, d)| *m = m.min(d));
                } else {
                    for (l, m) in ds.iter_mut().enumerate() {
                        *m = m.min(exact_sq_distance(&x.row(first + l), newest));
                    }
                }
            });
        picked.push(draw_by_distance(&nearest_d2, rng));
    }
    picked
}

/// A row drawn with probability proportional to `d2` (the first row when every weight is zero).
/// Should the weights sum beyond f32 (rows far apart), they are drawn relative to the largest
/// (the infinite ones alone when some are infinite): rand panics on an infinite total. Finite
/// sums take the plain draw, so ordinary inputs draw exactly as before.
fn draw_by_distance(d2: &[f32], rng: &mut impl Rng) -> usize {
    let mut draw = |w: Result<WeightedIndex<f32>, _>| w.map_or(0, |w| w.sample(rng));
    if d2.iter().sum::<f32>().is_finite() {
        return draw(WeightedIndex::new(d2.iter()));
    }
    let largest = d2.iter().copied().fold(0f32, f32::max);
    draw(WeightedIndex::new(d2.iter().map(|&d| match largest.is_finite() {
        true => d / largest,
        false => f32::from(u8::from(d == f32::INFINITY)),
    })))
}

/// The rows of a matrix ready for the matrix product: moved so that their mean is the origin
/// (distances do not change, and the product's rounding, relative to the norms, shrinks to the
/// spread of the rows), with their squared norms. Made once per matrix, it serves every k-means
/// and every K on that matrix or on rows of it: the labels are the exact nearest centroids
/// whichever mean the rows were moved by (the product only shortlists them).
#[derive(Debug)]
pub(crate) struct Centred {
    mean: Array1<f32>,
    centred: Array2<f32>,
    norms: Array1<f32>,
    /// [`largest_magnitude`] of the matrix.
    largest: f32,
}

impl Centred {
    /// `x` moved to its mean.
    pub(crate) fn new(x: &Array2<f32>) -> Self {
        let mean = x.mean_axis(Axis(0)).unwrap_or_else(|| Array1::zeros(x.ncols()));
        let centred = x - &mean;
        let norms = row_norms(&centred);
        let largest = largest_magnitude(x);
        Self {
            mean,
            centred,
            norms,
            largest,
        }
    }

    /// The nearest centroid of each of `rows` (rows of the matrix this was made from). The
    /// product's distances carry rounding of the order of dim·ε(‖x‖² + ‖c‖²); every centroid within
    /// a wide margin of that around the product's nearest is measured exactly, and the first of the
    /// exact minima wins, as in linfa.
    fn nearest(&self, rows: Rows<'_>, centroids: &Array2<f32>) -> Vec<usize> {
        let moved = centroids - &self.mean;
        let cross = self.centred.dot(&moved.t());
        let centroid_norms = row_norms(&moved);
        let largest_norm = centroid_norms.iter().copied().fold(0.0, f32::max);
        let centroid_rows: Vec<Vec<f32>> =
            centroids.rows().into_iter().map(|r| r.to_vec()).collect();
        let dim = self.centred.ncols().max(1) as f32;
        // Whether every exact distance is finite: each squared difference is at most
        // (2 × the largest magnitude among the rows and centroids)², and the factor 2 covers the
        // summation's rounding.
        let largest = self.largest.max(largest_magnitude(centroids));
        let distances_finite = largest.is_finite()
            && f64::from(dim) * (2.0 * f64::from(largest)).powi(2) * 2.0 < f64::from(f32::MAX);
        (0..rows.len())
            .into_par_iter()
            .map(|i| {
                let whole = rows.index(i);
                let (Some(&n), Some(products)) = (
                    self.norms.get(whole),
                    (whole < cross.nrows()).then(|| cross.row(whole)),
                ) else {
                    return 0;
                };
                let approx: Vec<f32> = products
                    .iter()
                    .zip(&centroid_norms)
                    .map(|(&xc, &cc)| n - 2.0 * xc + cc)
                    .collect();
                let lowest = approx.iter().copied().fold(f32::INFINITY, f32::min);
                let margin = 64.0 * dim * f32::EPSILON * (n + largest_norm);
                let row = rows.row(i);
                // NaN (a non-finite descriptor) is measured too, as linfa would.
                let close: Vec<usize> = (0..approx.len())
                    .filter(|&j| {
                        approx[j].partial_cmp(&(lowest + margin))
                            != Some(std::cmp::Ordering::Greater)
                    })
                    .collect();
                if close.len() == 1 && distances_finite {
                    // The only candidate: its exact distance, finite, would be the minimum.
                    return close[0];
                }
                let mut best = (0, f32::INFINITY);
                for group in close.chunks(4) {
                    // A short group repeats its last centroid: the same distance, not a new best.
                    let pick = |l: usize| group[l.min(group.len() - 1)];
                    let d = exact_sq_distances(
                        [&row[..]; 4],
                        std::array::from_fn(|l| centroid_rows[pick(l)].as_slice()),
                    );
                    for (l, &d) in d.iter().enumerate().take(group.len()) {
                        if d < best.1 {
                            best = (group[l], d);
                        }
                    }
                }
                best.0
            })
            .collect()
    }
}

/// m_k-means update: each centroid becomes the mean of its rows and its old self, the rows summed
/// in f32 in row order and the sum divided by the count, as linfa does.
fn means(x: Rows<'_>, labels: &[usize], centroids: &Array2<f32>) -> Array2<f32> {
    let mut sums = Array2::<f32>::zeros(centroids.raw_dim());
    let mut counts = vec![1usize; centroids.nrows()];
    for (i, &l) in labels.iter().enumerate().take(x.len()) {
        let row = x.row(i);
        let mut sum = sums.row_mut(l);
        sum += &ArrayView1::from(&row[..]);
        counts[l] += 1;
    }
    sums += centroids;
    for (mut sum, &count) in sums.rows_mut().into_iter().zip(&counts) {
        sum /= count as f32;
    }
    sums
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
                rows.push(m + rng.gen_range(-0.5f32..0.5));
            }
        }
        (Array2::from_shape_vec((300, 5), rows).unwrap(), truth)
    }

    #[test]
    fn seeds_of_rows_too_far_apart_for_f32_are_drawn_without_panicking() {
        // Squared distances of 1e30-apart rows overflow f32: the total seed weight was infinite
        // and rand's uniform sampler panicked ("range overflow").
        for far in [1e18f32, 1.4e19, 1e30, f32::MAX] {
            let x = Array2::from_shape_vec((4, 2), vec![0.0, 0.0, far, 0.0, 0.0, far, 1.0, 1.0])
                .unwrap();
            let rows = Rows::all(&x);
            let picked = seed_rows(rows, 3, &mut Xoshiro256Plus::seed_from_u64(1));
            assert_eq!(picked.len(), 3);
            assert!(picked.iter().all(|&r| r < 4), "{picked:?}");
        }
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
        let labels = nearest(Rows::all(&x), &Centred::new(&x), &centroids);
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
    fn nearest_agrees_with_exact_distances_on_near_ties() {
        // Rows almost equidistant from two far-off centroids: the product's rounding is larger than
        // the gap, the exact measure decides.
        let centroids = Array2::from_shape_vec((2, 3), vec![1e4, 0.0, 0.0, -1e4, 0.0, 0.0]).unwrap();
        let rows: Vec<f32> = (0..40).flat_map(|i| [(i as f32 - 20.0) * 1e-3, 5.0, 5.0]).collect();
        let x = Array2::from_shape_vec((40, 3), rows).unwrap();
        let labels = nearest(Rows::all(&x), &Centred::new(&x), &centroids);
        for (i, &l) in labels.iter().enumerate() {
            let row = x.row(i).to_vec();
            let d: Vec<f32> = centroids
                .rows()
                .into_iter()
                .map(|c| exact_sq_distance(&row, c.as_slice().unwrap()))
                .collect();
            let want = if d[1] < d[0] { 1 } else { 0 };
            assert_eq!(l, want, "row {i}: {d:?}");
        }
    }

    #[test]
    fn identical_rows_and_more_clusters_than_distinct_points() {
        let x = Array2::from_elem((10, 4), 1.5f32);
        let mut rng = Xoshiro256Plus::seed_from_u64(3);
        let centroids = kmeans(&x, 4, &mut rng, 10, 0.0);
        assert!(centroids.iter().all(|&v| v == 1.5));
        assert!(nearest(Rows::all(&x), &Centred::new(&x), &centroids)
            .iter()
            .all(|&l| l < 4));
    }
}
