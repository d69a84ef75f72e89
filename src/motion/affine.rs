//! The piecewise affine predictor (MCGV §3.2): one affine map per cluster and frame, fitted from the
//! decoded frame 0 (eq. 2), quantised for the stream, and applied with the dequantised coefficients.
//!
//! Quantisation follows the residuals' quality law instead of a fixed bit count: the encoder
//! predicts from the *dequantised* maps (closed loop), so a map's error only has to be small
//! against the residual quantiser step Δ, not against the map itself. Each map `x ↦ A x + b` is
//! stored as its linear part `A` (nine numbers in the cluster's [`LinearForm`]: entries, or a
//! rotation and a symmetric stretch) and the image `t = A c + b` of its cluster's centroid `c`:
//! an error in `t` moves every vertex of the cluster alike, with no share of `A`'s error, and an
//! error `e` in one of `A`'s numbers moves a vertex by about `e` times its offset from the
//! centroid. `t` is quantised with the track's step `s` and each of `A`'s numbers with `s` over
//! √3 times the cluster's RMS lever for it ([`ClusterGeometry::steps`]), so that together they
//! move the cluster's vertices by about as much as `t` does. The decoder derives centroids and spreads
//! from the decoded frame 0 and the partition, which it has before the maps.

use super::fit::{apply, AffineCoefficients, UnitFrame};
#[cfg(feature = "encode")]
use super::fit::AffineSolver;
use super::partition::Partition;
use super::linear_form::LinearForm;
#[cfg(feature = "encode")]
use super::trajectory::best_order;
use crate::error::{Error, Result};
use crate::mesh::Point;
#[cfg(feature = "encode")]
use rayon::prelude::*;

/// Regularisation of the cluster fits, relative to the cluster's spread: only there to give flat or
/// tiny clusters the identity in their unconstrained directions, far below any effect on residuals.
const CLUSTER_LAMBDA: f64 = 1e-9;

/// The affine step as a multiple of the residual step Δ (`step_affine = k·Δ` for translations,
/// `k·Δ / r̄` for the linear part): fine enough against Δ for the closed loop, coarse enough to
/// cost few bytes (docs/design.md, "Affine precision per codec"). The picture codecs' default;
/// the temporal DCT's is finer (`codec::tdct::AFFINE_PRECISION`).
pub const DEFAULT_AFFINE_PRECISION: f64 = 0.25;

/// Smallest and largest base step accepted (unit coordinates: fractions of the diagonal). Below
/// 1e-9 the f64 coefficients would need more than 2^40 levels; above 16 nothing is predicted.
pub const MIN_AFFINE_STEP: f64 = 1e-9;
/// See [`MIN_AFFINE_STEP`].
pub const MAX_AFFINE_STEP: f64 = 16.0;

/// Spreads below this (unit coordinates) count as this: a cluster of (nearly) one point would
/// otherwise get an unbounded linear step, and the skinning predictor applies a cluster's map to
/// vertices of the neighbouring clusters too.
const MIN_SPREAD: f64 = 1e-3;

/// The coarsest linear-part step: keeps maps of tiny clusters meaningful for those neighbours.
const MAX_LINEAR_STEP: f64 = 1.0 / 64.0;

/// Largest quantised magnitude: far above any sensible step, far below where i64 arithmetic of
/// the predictors or f64 dequantisation lose meaning.
pub const MAX_AFFINE_LEVEL: i64 = 1 << 40;

/// Per cluster, its centroid and RMS distance from it on the decoded frame 0, in the unit frame:
/// what both sides need to turn the base step into per-coefficient steps.
#[derive(Debug, Clone, PartialEq)]
pub struct ClusterGeometry {
    /// Centroid of each cluster's vertices.
    pub centroids: Vec<[f64; 3]>,
    /// RMS distance of each cluster's vertices from its centroid (0 for an empty cluster).
    pub spreads: Vec<f64>,
    /// RMS offset of each cluster's vertices from its centroid along each axis: column `j` of the
    /// linear part moves a vertex by its offset along axis `j`, so a thin cluster's columns
    /// across it are quantised coarser (stream version 6).
    pub axis_spreads: Vec<[f64; 3]>,
}

impl ClusterGeometry {
    /// The geometry of `partition`'s clusters on `reference` (sums in vertex order, so encoder
    /// and decoder compute the same numbers); labels out of range are skipped.
    pub fn of(reference: &[Point], partition: &Partition) -> Self {
        let unit = UnitFrame::of(reference);
        let k = partition.clusters();
        let (mut sum, mut count) = (vec![[0.0f64; 3]; k], vec![0usize; k]);
        for (p, &l) in reference.iter().zip(partition.labels()) {
            if let (Some(s), Some(n)) = (sum.get_mut(l as usize), count.get_mut(l as usize)) {
                let u = unit.to_unit(p);
                (0..3).for_each(|a| s[a] += u[a]);
                *n += 1;
            }
        }
        let centroids: Vec<[f64; 3]> = sum
            .iter()
            .zip(&count)
            .map(|(s, &n)| s.map(|x| x / n.max(1) as f64))
            .collect();
        let mut squares = vec![[0.0f64; 3]; k];
        for (p, &l) in reference.iter().zip(partition.labels()) {
            if let (Some(s), Some(c)) = (squares.get_mut(l as usize), centroids.get(l as usize)) {
                let u = unit.to_unit(p);
                (0..3).for_each(|a| s[a] += (u[a] - c[a]).powi(2));
            }
        }
        let spreads = squares
            .iter()
            .zip(&count)
            .map(|(s, &n)| (s.iter().sum::<f64>() / n.max(1) as f64).sqrt())
            .collect();
        let axis_spreads = squares
            .iter()
            .zip(&count)
            .map(|(s, &n)| s.map(|x| (x / n.max(1) as f64).sqrt()))
            .collect();
        Self {
            centroids,
            spreads,
            axis_spreads,
        }
    }

    /// The 12 quantiser steps of `cluster`'s map in `form` for base step `step`, in stored
    /// order (`[x0 x1 x2 t0, x3 x4 x5 t1, x6 x7 x8 t2]`, `x` the linear part's nine numbers,
    /// [`LinearForm::values`], and `t` the centroid's image): `step` for `t`, and for `x_i`
    /// `step` over √3 times its lever ([`LinearForm::levers`]). Three numbers of the nine then
    /// move the vertices by as much as the translation does, with fewer levels across thin
    /// clusters (per-axis levers since stream version 6).
    pub fn steps(&self, cluster: usize, step: f64, form: LinearForm) -> [f64; 12] {
        let spreads = self.axis_spreads.get(cluster).copied().unwrap_or([0.0; 3]);
        let linear = form
            .levers(spreads)
            .map(|l| (step / (3f64.sqrt() * l).max(MIN_SPREAD)).min(MAX_LINEAR_STEP));
        std::array::from_fn(|c| match c % 4 {
            3 => step,
            col => linear[3 * (c / 4) + col],
        })
    }

    /// `cluster`'s centroid (the origin for a cluster out of range).
    pub fn centroid(&self, cluster: usize) -> [f64; 3] {
        self.centroids.get(cluster).copied().unwrap_or([0.0; 3])
    }
}

/// The identity map in stored form for a cluster: `A = I` in `form`, `t = c`, in levels of
/// `steps`.
pub fn identity_levels(centroid: [f64; 3], steps: &[f64; 12], form: LinearForm) -> [i64; 12] {
    let values = stored_values(&form.identity(), centroid);
    std::array::from_fn(|c| level(values[c] / steps[c]))
}

/// The 12 stored numbers of a map: linear part `x` and centroid image `t` interleaved as rows.
fn stored_values(x: &[f64; 9], t: [f64; 3]) -> [f64; 12] {
    std::array::from_fn(|c| match c % 4 {
        3 => t[c / 4],
        col => x[3 * (c / 4) + col],
    })
}

/// The nearest level, clamped to ±[`MAX_AFFINE_LEVEL`] (NaN gives 0).
fn level(x: f64) -> i64 {
    let bound = MAX_AFFINE_LEVEL as f64;
    if x.is_nan() {
        0
    } else {
        x.round().clamp(-bound, bound) as i64
    }
}

/// The affine maps as they are stored: integer levels of `A` (in each cluster's form) and `t`
/// (see the module notes).
#[derive(Debug, Clone, PartialEq)]
pub struct QuantisedAffine {
    /// Base step in the unit frame (a fraction of the decoded frame 0's diagonal): the step of
    /// the translations, which [`ClusterGeometry::steps`] turns into the linear part's.
    pub step: f32,
    /// Number of frames.
    pub frames: usize,
    /// Number of clusters.
    pub clusters: usize,
    /// How each cluster stores its linear part.
    pub forms: Vec<LinearForm>,
    /// Levels, frame by frame, cluster by cluster, 12 each (see [`ClusterGeometry::steps`]).
    pub values: Vec<i64>,
}

impl QuantisedAffine {
    /// Refuses a stored base step outside [`MIN_AFFINE_STEP`]..=[`MAX_AFFINE_STEP`] (or NaN).
    pub fn check_step(step: f32) -> Result<()> {
        // Compared as the f32 the stream stores, which the encoder's f64 bounds round to.
        if !(MIN_AFFINE_STEP as f32..=MAX_AFFINE_STEP as f32).contains(&step) {
            return Err(Error::Stream(format!(
                "affine coefficients: step {step:e} is outside {MIN_AFFINE_STEP:e}..={MAX_AFFINE_STEP}"
            )));
        }
        Ok(())
    }

    fn check(&self) -> Result<()> {
        Self::check_step(self.step)?;
        if self.frames == 0 || self.clusters == 0 {
            return Err(Error::Stream(
                "affine coefficients: no frames or no clusters".into(),
            ));
        }
        if self.forms.len() != self.clusters {
            return Err(Error::Stream(format!(
                "affine coefficients: {} linear forms for {} clusters",
                self.forms.len(),
                self.clusters
            )));
        }
        let expected = self
            .frames
            .checked_mul(self.clusters)
            .and_then(|n| n.checked_mul(12));
        if expected != Some(self.values.len()) {
            return Err(Error::Stream(format!(
                "affine coefficients: {} values for {} frames × {} clusters × 12",
                self.values.len(),
                self.frames,
                self.clusters
            )));
        }
        if let Some(i) = self
            .values
            .iter()
            .position(|q| q.unsigned_abs() > MAX_AFFINE_LEVEL as u64)
        {
            return Err(Error::Stream(format!(
                "affine coefficients: level {i} is beyond ±2^40"
            )));
        }
        Ok(())
    }

    /// The map `[A | b]` of levels `q` of a cluster in `form` with `steps` and `centroid`:
    /// `b = t − A c`.
    fn dequantise(
        q: &[i64],
        steps: &[f64; 12],
        centroid: [f64; 3],
        form: LinearForm,
    ) -> AffineCoefficients {
        let x: [f64; 12] = std::array::from_fn(|c| q[c] as f64 * steps[c]);
        let a = form.linear(&std::array::from_fn(|i| x[4 * (i / 3) + i % 3]));
        let mut h = [0.0; 12];
        for row in 0..3 {
            h[4 * row..4 * row + 3].copy_from_slice(&a[row]);
            let ac: f64 = (0..3).map(|col| a[row][col] * centroid[col]).sum();
            h[4 * row + 3] = x[4 * row + 3] - ac;
        }
        h
    }

    /// Levels of the exact map `h` in `form`: `A`'s nine numbers, `t = A c + b` (none if `A`
    /// has no such form, [`LinearForm::values`]).
    #[cfg(feature = "encode")]
    fn quantise(
        h: &AffineCoefficients,
        steps: &[f64; 12],
        centroid: [f64; 3],
        form: LinearForm,
    ) -> Option<[i64; 12]> {
        let a: [[f64; 3]; 3] = std::array::from_fn(|r| [h[4 * r], h[4 * r + 1], h[4 * r + 2]]);
        let t = std::array::from_fn(|r| {
            h[4 * r + 3] + (0..3).map(|j| h[4 * r + j] * centroid[j]).sum::<f64>()
        });
        let values = stored_values(&form.values(&a)?, t);
        Some(std::array::from_fn(|c| level(values[c] / steps[c])))
    }
}

/// Per frame and cluster, the dequantised affine map predicting that frame from the decoded frame 0.
///
/// Only the levels are kept (96 bytes a frame and cluster); a frame's maps are dequantised when
/// it is predicted, so a decoder holding a long segment's track keeps half what it would with
/// the maps stored beside the levels.
#[derive(Debug, Clone, PartialEq)]
pub struct AffineTrack {
    quantised: QuantisedAffine,
    geometry: ClusterGeometry,
    /// Per cluster, the steps of its 12 levels.
    steps: Vec<[f64; 12]>,
}

impl AffineTrack {
    /// Fits `H_i^k` (eq. 2) for every frame `i` of `frames` and cluster `k`, from `reference` (the
    /// frame 0 the decoder will have) to the original frame, then quantises with base step `step`
    /// (unit frame, see [`QuantisedAffine::step`]; rounded to the `f32` the stream stores).
    #[cfg(feature = "encode")]
    pub fn fit(
        frames: &[Vec<Point>],
        reference: &[Point],
        partition: &Partition,
        step: f64,
    ) -> Result<Self> {
        if !(step.is_finite() && (MIN_AFFINE_STEP..=MAX_AFFINE_STEP).contains(&step)) {
            return Err(Error::Usage(format!(
                "the affine step must be in {MIN_AFFINE_STEP:e}..={MAX_AFFINE_STEP}, not {step}"
            )));
        }
        if frames.is_empty() {
            return Err(Error::Usage("no frames to predict".into()));
        }
        let v = reference.len();
        if partition.vertex_count() != v {
            return Err(Error::Usage(format!(
                "the partition has {} vertices but the reference frame {v}",
                partition.vertex_count()
            )));
        }
        if let Some(f) = frames.iter().position(|f| f.len() != v) {
            return Err(Error::Usage(format!(
                "frame {f} has a different vertex count than the reference frame ({v})"
            )));
        }
        let unit = UnitFrame::of(reference);
        let members = partition.members();
        let solvers: Vec<AffineSolver> = members
            .iter()
            .map(|m| {
                let source: Vec<[f64; 3]> = m
                    .iter()
                    .map(|&u| unit.to_unit(&reference[u as usize]))
                    .collect();
                AffineSolver::new(&source, CLUSTER_LAMBDA)
            })
            .collect();
        let exact: Vec<AffineCoefficients> = frames
            .par_iter()
            .flat_map_iter(|frame| {
                solvers.iter().zip(&members).map(move |(solver, m)| {
                    solver.solve(m.iter().map(|&u| unit.to_unit(&frame[u as usize])))
                })
            })
            .collect();
        if exact.iter().flatten().any(|x| !x.is_finite()) {
            return Err(Error::Mesh(
                "an affine fit is not finite (non-finite vertex coordinates?)".into(),
            ));
        }
        let geometry = ClusterGeometry::of(reference, partition);
        let stored = step as f32;
        let quantised = quantise_track(&exact, frames.len(), &geometry, stored)?;
        Self::from_quantised(quantised, geometry)
    }

    /// Rebuilds the predictor from stored levels and the clusters' geometry on the decoded frame 0
    /// ([`ClusterGeometry::of`]); fails on inconsistent input.
    pub fn from_quantised(quantised: QuantisedAffine, geometry: ClusterGeometry) -> Result<Self> {
        quantised.check()?;
        if geometry.centroids.len() != quantised.clusters
            || geometry.spreads.len() != quantised.clusters
            || geometry.axis_spreads.len() != quantised.clusters
        {
            return Err(Error::Stream(format!(
                "affine coefficients: {} clusters, the partition has {}",
                quantised.clusters,
                geometry.centroids.len()
            )));
        }
        let step = f64::from(quantised.step);
        let steps: Vec<[f64; 12]> = (0..quantised.clusters)
            .map(|k| geometry.steps(k, step, quantised.forms[k]))
            .collect();
        Ok(Self {
            quantised,
            geometry,
            steps,
        })
    }

    /// The stored form: levels and base step.
    pub fn quantised(&self) -> &QuantisedAffine {
        &self.quantised
    }

    /// The clusters' centroids and spreads the steps derive from.
    pub fn geometry(&self) -> &ClusterGeometry {
        &self.geometry
    }

    /// Number of frames.
    pub fn frame_count(&self) -> usize {
        self.quantised.frames
    }

    /// Number of clusters.
    pub fn cluster_count(&self) -> usize {
        self.quantised.clusters
    }

    /// The levels of every cluster at `frame`, 12 a cluster (none past the last frame).
    fn frame_levels(&self, frame: usize) -> Option<&[i64]> {
        let per_frame = self.quantised.clusters * 12;
        let start = frame.checked_mul(per_frame)?;
        self.quantised
            .values
            .get(start..start.checked_add(per_frame)?)
    }

    /// The dequantised map of `cluster` at `frame`, in the unit frame of the reference.
    pub fn map(&self, frame: usize, cluster: usize) -> Option<AffineCoefficients> {
        let levels = self
            .frame_levels(frame)?
            .get(cluster.checked_mul(12)?..)?
            .get(..12)?;
        let steps = self.steps.get(cluster)?;
        let form = *self.quantised.forms.get(cluster)?;
        Some(QuantisedAffine::dequantise(
            levels,
            steps,
            self.geometry.centroid(cluster),
            form,
        ))
    }

    /// The track of `frames` alone, in that order (a sample of a clip as a clip of its own).
    pub fn select(&self, frames: &[usize]) -> Result<Self> {
        let q = &self.quantised;
        let mut values = Vec::with_capacity(frames.len() * q.clusters * 12);
        for &f in frames {
            let levels = self.frame_levels(f).ok_or_else(|| {
                Error::Usage(format!("frame {f} asked of a {}-frame track", q.frames))
            })?;
            values.extend_from_slice(levels);
        }
        let selected = QuantisedAffine {
            step: q.step,
            frames: frames.len(),
            clusters: q.clusters,
            forms: q.forms.clone(),
            values,
        };
        Self::from_quantised(selected, self.geometry.clone())
    }

    /// Every cluster's dequantised map at `frame`, cluster by cluster (none past the last frame).
    pub fn frame_maps(&self, frame: usize) -> Vec<AffineCoefficients> {
        (0..self.quantised.clusters)
            .map_while(|k| self.map(frame, k))
            .collect()
    }

    /// Every frame's maps, frame by frame, cluster by cluster: a table for fits that visit every
    /// frame many times (96 bytes a frame and cluster).
    pub fn maps(&self) -> Vec<AffineCoefficients> {
        (0..self.quantised.frames)
            .flat_map(|f| self.frame_maps(f))
            .collect()
    }

    /// Predicts frame `frame` (eq. 3): each vertex of `reference` moved by its cluster's dequantised
    /// map. Checks that frame, reference and partition fit this track.
    pub fn try_predict(
        &self,
        frame: usize,
        reference: &[Point],
        partition: &Partition,
    ) -> Result<Vec<Point>> {
        if frame >= self.quantised.frames {
            return Err(Error::Usage(format!(
                "frame {frame} asked of a {}-frame prediction",
                self.quantised.frames
            )));
        }
        self.check_fits(reference, partition)?;
        Ok(self.predict(frame, reference, partition))
    }

    /// Fails unless `partition` has this track's clusters and `reference`'s vertices.
    pub fn check_fits(&self, reference: &[Point], partition: &Partition) -> Result<()> {
        if partition.clusters() != self.quantised.clusters
            || partition.vertex_count() != reference.len()
        {
            return Err(Error::Usage(format!(
                "partition ({} vertices, {} clusters) does not match the reference ({} vertices) \
                 and the affine track ({} clusters)",
                partition.vertex_count(),
                partition.clusters(),
                reference.len(),
                self.quantised.clusters
            )));
        }
        Ok(())
    }

    /// Predicts frame `frame` (eq. 3) like [`AffineTrack::try_predict`], for callers that have
    /// already checked the sizes: a vertex without a map (frame or cluster out of range) stays at
    /// its reference position, and vertices beyond the partition are left out; it never panics.
    pub fn predict(&self, frame: usize, reference: &[Point], partition: &Partition) -> Vec<Point> {
        let unit = UnitFrame::of(reference);
        let maps = self.frame_maps(frame);
        reference
            .iter()
            .zip(partition.labels())
            .map(|(p, &k)| match maps.get(k as usize) {
                Some(h) => unit.to_world(apply(h, unit.to_unit(p))),
                None => *p,
            })
            .collect()
    }
}

/// Quantises `exact` (frame by frame, cluster by cluster) at base step `step`, each cluster in
/// the [`LinearForm`] whose nine linear trajectories the affine coder's estimate finds smaller
/// (the translations are the same either way; a tie keeps the entries).
#[cfg(feature = "encode")]
fn quantise_track(
    exact: &[AffineCoefficients],
    frames: usize,
    geometry: &ClusterGeometry,
    step: f32,
) -> Result<QuantisedAffine> {
    let clusters = geometry.centroids.len();
    let mut values = vec![0i64; frames * clusters * 12];
    let mut forms = Vec::with_capacity(clusters);
    for k in 0..clusters {
        let centroid = geometry.centroid(k);
        // Each form's levels over the frames and the estimated bits of its nine linear
        // trajectories; a form some frame's map does not have is out.
        let candidates = LinearForm::ALL.map(|form| {
            let steps = geometry.steps(k, f64::from(step), form);
            let levels: Option<Vec<[i64; 12]>> = (0..frames)
                .map(|f| QuantisedAffine::quantise(&exact[f * clusters + k], &steps, centroid, form))
                .collect();
            levels.map(|levels| {
                let bits: f64 = (0..12)
                    .filter(|c| c % 4 != 3)
                    .map(|c| best_order(&levels.iter().map(|l| l[c]).collect::<Vec<_>>()).1)
                    .sum();
                (form, levels, bits)
            })
        });
        // The first of the smallest: a tie keeps the entries, which every map has (only the
        // decomposition can fail), so a cluster without a form cannot happen.
        let (form, levels, _) = candidates
            .into_iter()
            .flatten()
            .min_by(|a, b| a.2.total_cmp(&b.2))
            .ok_or_else(|| Error::Mesh(format!("cluster {k}'s maps have no stored form")))?;
        forms.push(form);
        for (f, l) in levels.iter().enumerate() {
            values[(f * clusters + k) * 12..][..12].copy_from_slice(l);
        }
    }
    Ok(QuantisedAffine {
        step,
        frames,
        clusters,
        forms,
        values,
    })
}
