//! The piecewise affine predictor (MCGV §3.2): one affine map per cluster and frame, fitted from the
//! decoded frame 0 (eq. 2), quantised for the stream, and applied with the dequantised coefficients.
//!
//! Quantisation follows the residuals' quality law instead of a fixed bit count: the encoder
//! predicts from the *dequantised* maps (closed loop), so a map's error only has to be small
//! against the residual quantiser step Δ, not against the map itself. Each map `x ↦ A x + b` is
//! stored as its linear part `A` and the image `t = A c + b` of its cluster's centroid `c`: an
//! error `e` in an entry of `A` then moves a vertex at distance `r` from the centroid by about
//! `e·r`, and an error in `t` moves every vertex of the cluster alike, with no share of `A`'s
//! error. `t` is quantised with the track's step `s` and `A` with `s / r̄`, `r̄` the cluster's
//! RMS distance from its centroid ([`ClusterGeometry`]), so both move the cluster's vertices by
//! about `s`. The decoder derives centroids and spreads from the decoded frame 0 and the
//! partition, which it has before the maps.

use super::fit::{apply, AffineCoefficients, UnitFrame};
#[cfg(feature = "encode")]
use super::fit::AffineSolver;
use super::partition::Partition;
use crate::error::{Error, Result};
use crate::mesh::Point;
#[cfg(feature = "encode")]
use rayon::prelude::*;

/// Regularisation of the cluster fits, relative to the cluster's spread: only there to give flat or
/// tiny clusters the identity in their unconstrained directions, far below any effect on residuals.
const CLUSTER_LAMBDA: f64 = 1e-9;

/// The affine step as a multiple of the residual step Δ (`step_affine = k·Δ` for translations,
/// `k·Δ / r̄` for the linear part): fine enough against Δ for the closed loop, coarse enough to
/// cost few bytes (docs/design.md, "Affine precision per codec").
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

    /// The 12 quantiser steps of `cluster`'s map for base step `step`, in coefficient order
    /// (`[a00 a01 a02 t0 a10 …]`): `step` for the translations, `step / (√3 σ_j)` for column `j`
    /// of the linear part, `σ_j` the cluster's RMS offset along axis `j`. An error `e` in such an
    /// entry moves the vertices by `e σ_j` RMS, so the three columns of a row together move them
    /// as much as the translation does (as `step / r̄` did for every column, `r̄² = Σ σ_j²`), with
    /// fewer levels where the cluster is thin.
    pub fn steps(&self, cluster: usize, step: f64) -> [f64; 12] {
        let spreads = self.axis_spreads.get(cluster).copied().unwrap_or([0.0; 3]);
        let linear = spreads
            .map(|s| (step / (3f64.sqrt() * s).max(MIN_SPREAD)).min(MAX_LINEAR_STEP));
        std::array::from_fn(|c| if c % 4 == 3 { step } else { linear[c % 4] })
    }

    /// `cluster`'s centroid (the origin for a cluster out of range).
    pub fn centroid(&self, cluster: usize) -> [f64; 3] {
        self.centroids.get(cluster).copied().unwrap_or([0.0; 3])
    }
}

/// The identity map in stored form for `cluster`: `A = I`, `t = c`, in levels of `steps`.
pub fn identity_levels(centroid: [f64; 3], steps: &[f64; 12]) -> [i64; 12] {
    std::array::from_fn(|c| {
        let (row, col) = (c / 4, c % 4);
        let x = match col {
            3 => centroid[row],
            _ if col == row => 1.0,
            _ => 0.0,
        };
        level(x / steps[c])
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

/// The affine maps as they are stored: integer levels of `A` and `t` (see the module notes).
#[derive(Debug, Clone, PartialEq)]
pub struct QuantisedAffine {
    /// Base step in the unit frame (a fraction of the decoded frame 0's diagonal): the step of
    /// the translations, which [`ClusterGeometry::steps`] turns into the linear part's.
    pub step: f32,
    /// Number of frames.
    pub frames: usize,
    /// Number of clusters.
    pub clusters: usize,
    /// Levels, frame by frame, cluster by cluster, 12 each (row-major `[A | t]`).
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

    /// The map `[A | b]` of levels `q` of a cluster with `steps` and `centroid`: `b = t − A c`.
    fn dequantise(q: &[i64], steps: &[f64; 12], centroid: [f64; 3]) -> AffineCoefficients {
        let mut h: AffineCoefficients = std::array::from_fn(|c| q[c] as f64 * steps[c]);
        for row in 0..3 {
            let ac: f64 = (0..3).map(|col| h[4 * row + col] * centroid[col]).sum();
            h[4 * row + 3] -= ac;
        }
        h
    }

    /// Levels of the exact map `h`: `A` as it is, `t = A c + b`.
    fn quantise(h: &AffineCoefficients, steps: &[f64; 12], centroid: [f64; 3]) -> [i64; 12] {
        std::array::from_fn(|c| {
            let (row, col) = (c / 4, c % 4);
            let x = match col {
                3 => h[c] + (0..3).map(|j| h[4 * row + j] * centroid[j]).sum::<f64>(),
                _ => h[c],
            };
            level(x / steps[c])
        })
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
        let clusters = partition.clusters();
        let steps: Vec<[f64; 12]> = (0..clusters)
            .map(|k| geometry.steps(k, f64::from(stored)))
            .collect();
        let values = exact
            .iter()
            .enumerate()
            .flat_map(|(i, h)| {
                let k = i % clusters;
                QuantisedAffine::quantise(h, &steps[k], geometry.centroid(k))
            })
            .collect();
        let quantised = QuantisedAffine {
            step: stored,
            frames: frames.len(),
            clusters,
            values,
        };
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
            .map(|k| geometry.steps(k, step))
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
        Some(QuantisedAffine::dequantise(
            levels,
            steps,
            self.geometry.centroid(cluster),
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
