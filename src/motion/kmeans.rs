//! Segmentation by k-means (MCGV §3.1): each vertex is described by the affine motion of its k-ring,
//! the descriptors are clustered by k-means, then borders are refined and tiny clusters dissolved.

use super::fit::{apply, AffineSolver};
use super::partition::{compact, Partition};
use super::refine::{assign_by_trajectory, refine_borders};
use super::sampled_motion::{welded_adjacency, SampledMotion, SAMPLED_FIT_LAMBDA};
use crate::error::{Error, Result};
use crate::mesh::topology::{KRingScratch, VertexAdjacency};
use crate::mesh::AnimatedMesh;
use super::lloyd;
use std::sync::OnceLock;
use ndarray::{Array2, ArrayView1, Axis};
use rand_xoshiro::rand_core::SeedableRng;
use rand_xoshiro::Xoshiro256Plus;
use rayon::prelude::*;

/// Fewest vertices a cluster needs so that its affine map (12 unknowns, 3 equations per vertex) is determined.
pub const MIN_CLUSTER_SIZE: usize = 4;

/// How to segment.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SegmentOptions {
    /// Number of clusters asked for (K, default 20); fewer come out when vertices are few or motion is simple.
    pub clusters: usize,
    /// Neighbourhood of each vertex's affine fit, in edges (default 3, as in the paper).
    pub ring: usize,
    /// Seed of the k-means++ initialisation: the same input and seed give the same partition.
    pub seed: u64,
    /// At most this many frames, evenly spaced, describe each vertex's motion (default 64): k-means
    /// cost grows with the feature length, and smooth motion is well sampled by far fewer frames.
    pub feature_frames: usize,
    /// Cap on Lloyd iterations of k-means (default 20: with border refinement, more iterations
    /// did not lower the residual energy on the bench sequences, and each costs V × K × 12 × frames).
    pub max_iterations: u64,
    /// Passes of border refinement after k-means (default 4; 0 = the paper's plain k-means): each pass
    /// refits every cluster's affine maps and moves each vertex to the neighbouring cluster (or each
    /// whole single-cluster component to any cluster) that predicts its sampled trajectory best.
    pub refine_passes: usize,
}

impl Default for SegmentOptions {
    fn default() -> Self {
        Self {
            clusters: 20,
            ring: 3,
            seed: 0,
            feature_frames: 64,
            max_iterations: 20,
            refine_passes: 4,
        }
    }
}

/// Segments the vertices into clusters of similar affine motion (MCGV §3.1, eq. 1).
///
/// 1. Each vertex is described by the affine maps, frame 0 → sampled frame i, that best fit its
///    `ring`-ring, in the unit frame of frame 0 (bounding-box centre at the origin, diagonal 1). The
///    linear part is weighted by the RMS radius of the shape so both parts measure displacement: a
///    change δ of a linear coefficient moves a typical vertex by about radius × δ.
/// 2. k-means (k-means++ seeded by `opts.seed`) is trained on the vertices whose ring moves
///    affinely (ring misfit ≤ 4 × median) and is not degenerate (flat, on a line); every vertex
///    then takes its nearest centroid. Rings straddling differently moving parts give far-off
///    descriptors that would otherwise draw centroids away from the parts, and degenerate rings
///    give partly guessed ones; those vertices take the cluster whose affine maps predict their
///    trajectory best instead.
/// 3. `opts.refine_passes` passes move cluster borders to lower the prediction error (see
///    [`SegmentOptions::refine_passes`]).
/// 4. Clusters with fewer than `MIN_CLUSTER_SIZE` vertices are dissolved, smallest first, into the
///    nearest remaining k-means centroid; empty ones vanish; labels are renumbered in order of first vertex.
pub fn segment(mesh: &AnimatedMesh, opts: &SegmentOptions) -> Result<Partition> {
    check(opts)?;
    if opts.clusters.min(mesh.vertex_count()) == 1 {
        return Partition::from_labels(vec![0; mesh.vertex_count()], 1);
    }
    MotionDescriptors::new(mesh, opts).segment(opts)
}

fn check(opts: &SegmentOptions) -> Result<()> {
    if opts.clusters == 0 {
        return Err(Error::Usage(
            "the number of clusters must be at least 1".into(),
        ));
    }
    if opts.feature_frames == 0 || opts.max_iterations == 0 {
        return Err(Error::Usage(
            "segmentation needs at least one feature frame and one k-means iteration".into(),
        ));
    }
    Ok(())
}

/// What k-means segments an animation on, whatever K (steps 1 and 2's training set of
/// [`segment`]): made once, it serves several K (the automatic choice's ladder).
pub struct MotionDescriptors {
    sampled: SampledMotion,
    adjacency: VertexAdjacency,
    features: Array2<f32>,
    /// The training rows: these (the inliers'), or every row when fewer than K are inliers.
    inliers: Vec<usize>,
    spread: f32,
    /// The features ready for k-means' products, made on first use and shared by every K.
    centred: OnceLock<lloyd::Centred>,
    /// Seeds grown ahead for the largest K of a ladder ([`MotionDescriptors::prepare_seeds`]).
    prepared: OnceLock<Prepared>,
}

/// k-means++ seeds picked ahead, and what they were picked for.
struct Prepared {
    seed: u64,
    /// Whether they are rows of the inliers' (`training`) or of every row.
    inliers: bool,
    /// The rows picked, in order ([`lloyd::seed_rows`]).
    picked: Vec<usize>,
}

impl MotionDescriptors {
    /// The descriptors of `mesh` with `opts`'s ring and feature frames.
    pub fn new(mesh: &AnimatedMesh, opts: &SegmentOptions) -> Self {
        let sampled = SampledMotion::new(mesh, opts.feature_frames.max(1));
        let adjacency = welded_adjacency(mesh, &sampled);
        let (features, misfit) = motion_features(&adjacency, &sampled, opts.ring);
        let inliers = affine_rings(&misfit);
        let spread = if inliers.is_empty() {
            feature_spread(&features)
        } else {
            feature_spread(&features.select(Axis(0), &inliers))
        };
        Self {
            sampled,
            adjacency,
            features,
            inliers,
            spread,
            centred: OnceLock::new(),
            prepared: OnceLock::new(),
        }
    }

    /// Grows the k-means++ seeds of `clusters` with `seed` ahead of [`MotionDescriptors::segment`]
    /// calls for that many or fewer: the first k seeds of a seeding for K > k are the k seeds, so
    /// a ladder of K's seeds once, for its largest, instead of once per K. Called before the
    /// ladder's segmentations run in parallel, which then only read the seeds (a second call
    /// changes nothing).
    pub fn prepare_seeds(&self, clusters: usize, seed: u64) {
        let Some((training, inliers)) = self.training_rows(clusters) else {
            return;
        };
        self.prepared.get_or_init(|| Prepared {
            seed,
            inliers,
            picked: seed_rows(training, clusters.min(training.len()), seed),
        });
    }

    /// The rows k-means into `clusters` trains on, and whether they are the inliers', for a K
    /// k-means can make (1 < K); `None` otherwise.
    fn training_rows(&self, clusters: usize) -> Option<(lloyd::Rows<'_>, bool)> {
        let k = clusters.min(self.features.nrows());
        if k <= 1 {
            None
        } else if self.inliers.len() >= k {
            Some((lloyd::Rows::picked(&self.features, &self.inliers), true))
        } else {
            Some((lloyd::Rows::all(&self.features), false))
        }
    }

    fn centred(&self) -> &lloyd::Centred {
        self.centred
            .get_or_init(|| lloyd::Centred::new(&self.features))
    }

    /// The first `k` k-means++ seeds of `training` with `seed`: the prepared ones when they
    /// cover them, else seeded now.
    fn seeds(&self, training: lloyd::Rows<'_>, inliers: bool, k: usize, seed: u64) -> Array2<f32> {
        match self.prepared.get() {
            Some(p) if (p.seed, p.inliers) == (seed, inliers) && p.picked.len() >= k => {
                training.select(&p.picked[..k])
            }
            _ => training.select(&seed_rows(training, k, seed)),
        }
    }

    /// The partition into `opts.clusters` (steps 2 to 4 of [`segment`]).
    pub fn segment(&self, opts: &SegmentOptions) -> Result<Partition> {
        check(opts)?;
        let v_count = self.features.nrows();
        let k = opts.clusters.min(v_count);
        let (training, from_inliers) = self
            .training_rows(k)
            .unwrap_or((lloyd::Rows::all(&self.features), false));
        let spread = if self.inliers.len() >= k {
            self.spread
        } else {
            feature_spread(&self.features)
        };
        if k == 1 || spread == 0.0 {
            // One cluster, or every vertex moves alike: k-means would only split ties.
            return Partition::from_labels(vec![0; v_count], 1);
        }
        let tolerance = (1e-4 * spread).max(f32::MIN_POSITIVE);
        let seeds = self.seeds(training, from_inliers, k, opts.seed);
        let centred = self.centred();
        let centroids =
            lloyd::kmeans_from(training, centred, seeds, opts.max_iterations, tolerance);
        let mut labels = lloyd::nearest(lloyd::Rows::all(&self.features), centred, &centroids);
        if self.inliers.len() >= k && self.inliers.len() < v_count {
            assign_by_trajectory(&mut labels, &self.inliers, &self.sampled, k);
        }
        if opts.refine_passes > 0 {
            refine_borders(
                &mut labels,
                &self.adjacency,
                &self.sampled,
                k,
                opts.refine_passes,
                true,
            );
        }
        let labels = dissolve_small_clusters(labels, &self.features, &centroids, k);
        compact(labels)
    }
}

/// The vertices whose ring moves affinely, up to the typical deviation: those whose ring misfit is
/// at most a few times the median. The others straddle parts that move differently (seams); their
/// torn fits are far-off points that would pull k-means centroids away from the real parts.
fn affine_rings(misfit: &[f32]) -> Vec<usize> {
    let mut sorted = misfit.to_vec();
    sorted.sort_by(f32::total_cmp);
    let median = sorted.get(sorted.len() / 2).copied().unwrap_or(0.0);
    // The floor is float noise in unit coordinates: exact motion must not make every vertex an outlier.
    let threshold = 4.0 * median + 1e-6;
    (0..misfit.len())
        .filter(|&v| misfit[v] <= threshold)
        .collect()
}

/// The per-vertex motion descriptors α^v (one row per vertex, 12 per sampled frame) and how far each
/// vertex's ring is from moving affinely (RMS fit error, unit coordinates).
fn motion_features(
    adjacency: &VertexAdjacency,
    motion: &SampledMotion,
    ring: usize,
) -> (Array2<f32>, Vec<f32>) {
    let v_count = adjacency.vertex_count();
    let rest = &motion.rest;
    let radius = (rest
        .iter()
        .map(|p| p.iter().map(|c| c * c).sum::<f64>())
        .sum::<f64>()
        / v_count as f64)
        .sqrt()
        .max(1e-6);
    let dim = 12 * motion.frames.len();
    let mut data = vec![0f32; v_count * dim];
    let mut misfit = vec![0f32; v_count];
    data.par_chunks_mut(dim)
        .zip(misfit.par_iter_mut())
        .enumerate()
        .for_each_init(
            || (KRingScratch::new(v_count), Vec::new()),
            |(scratch, source), (v, (row, misfit))| {
                let ring = scratch.k_ring(adjacency, v, ring);
                source.clear();
                source.extend(ring.iter().map(|&u| rest[u as usize]));
                let solver = AffineSolver::new(source, SAMPLED_FIT_LAMBDA);
                let mut error = 0.0;
                for (slot, target) in row.chunks_exact_mut(12).zip(&motion.frames) {
                    let h = solver.solve(ring.iter().map(|&u| target[u as usize]));
                    error += ring
                        .iter()
                        .map(|&u| {
                            let q = apply(&h, rest[u as usize]);
                            let t = target[u as usize];
                            (0..3).map(|a| (q[a] - t[a]).powi(2)).sum::<f64>()
                        })
                        .sum::<f64>();
                    for (c, (out, value)) in slot.iter_mut().zip(h).enumerate() {
                        let weight = if c % 4 == 3 { 1.0 } else { radius };
                        *out = (value * weight) as f32;
                    }
                }
                let samples = (ring.len() * motion.frames.len()).max(1);
                // A degenerate ring's descriptor is partly the regulariser's guess: keep it out of
                // k-means training like a torn ring, and let its trajectory decide its cluster.
                *misfit = if solver.is_degenerate() {
                    f32::INFINITY
                } else {
                    (error / samples as f64).sqrt() as f32
                };
            },
        );
    // The shape is (V, dim) by construction.
    let features = Array2::from_shape_vec((v_count, dim), data)
        .unwrap_or_else(|_| Array2::zeros((v_count, dim)));
    (features, misfit)
}

/// The k-means++ seeds of `training` drawn with `seed` ([`lloyd::seed_rows`]).
fn seed_rows(training: lloyd::Rows<'_>, k: usize, seed: u64) -> Vec<usize> {
    lloyd::seed_rows(training, k, &mut Xoshiro256Plus::seed_from_u64(seed))
}

/// RMS distance of the feature rows to their mean: the scale k-means' tolerance is relative to.
fn feature_spread(features: &Array2<f32>) -> f32 {
    let Some(mean) = features.mean_axis(Axis(0)) else {
        return 0.0;
    };
    let total: f64 = features
        .rows()
        .into_iter()
        .map(|r| squared_distance(r, mean.view()) as f64)
        .sum();
    (total / features.nrows().max(1) as f64).sqrt() as f32
}

fn squared_distance(a: ArrayView1<f32>, b: ArrayView1<f32>) -> f32 {
    a.iter().zip(b.iter()).map(|(x, y)| (x - y) * (x - y)).sum()
}

/// Moves the vertices of clusters too small for an affine fit to the nearest surviving centroid,
/// smallest cluster first (ties: lowest id), until every non-empty cluster is big enough or one is left.
fn dissolve_small_clusters(
    mut labels: Vec<usize>,
    features: &Array2<f32>,
    centroids: &Array2<f32>,
    k: usize,
) -> Vec<usize> {
    let mut sizes = vec![0usize; k];
    for &l in &labels {
        if let Some(s) = sizes.get_mut(l) {
            *s += 1;
        }
    }
    loop {
        let alive = sizes.iter().filter(|&&s| s > 0).count();
        let victim = sizes
            .iter()
            .enumerate()
            .filter(|&(_, &s)| s > 0 && s < MIN_CLUSTER_SIZE)
            .min_by_key(|&(c, &s)| (s, c))
            .map(|(c, _)| c);
        let Some(victim) = victim.filter(|_| alive > 1) else {
            return labels;
        };
        sizes[victim] = 0;
        for (v, label) in labels.iter_mut().enumerate() {
            if *label != victim {
                continue;
            }
            let row = features.row(v);
            let nearest = (0..k)
                .filter(|&c| sizes[c] > 0)
                .map(|c| (c, squared_distance(row, centroids.row(c))))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .map_or(victim, |(c, _)| c);
            *label = nearest;
        }
        sizes.iter_mut().for_each(|s| *s = 0);
        for &l in &labels {
            if let Some(s) = sizes.get_mut(l) {
                *s += 1;
            }
        }
    }
}
