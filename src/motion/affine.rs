//! The piecewise affine predictor (MCGV §3.2): one affine map per cluster and frame, fitted from the
//! decoded frame 0 (eq. 2), quantised for the stream, and applied with the dequantised coefficients.

use super::fit::{apply, AffineCoefficients, AffineSolver, UnitFrame};
use super::partition::Partition;
use crate::error::{Error, Result};
use crate::mesh::Point;
use rayon::prelude::*;

/// Regularisation of the cluster fits, relative to the cluster's spread: only there to give flat or
/// tiny clusters the identity in their unconstrained directions, far below any effect on residuals.
const CLUSTER_LAMBDA: f64 = 1e-9;

/// Bits per coefficient the paper uses, and this tool's default.
pub const DEFAULT_AFFINE_BITS: u8 = 17;

/// Most bits per coefficient accepted; beyond about 24 the f32 ranges limit precision anyway.
pub const MAX_AFFINE_BITS: u8 = 31;

/// The affine maps as they are stored: integers plus the range of each of the 12 coefficient indices.
///
/// The maps act in the unit frame of the decoded frame 0 (its bounding-box centre at the origin,
/// diagonal 1), so coefficients are dimensionless and the decoder rebuilds the frame from what it has.
#[derive(Debug, Clone, PartialEq)]
pub struct QuantisedAffine {
    /// Bits per coefficient (1..=31).
    pub bits: u8,
    /// Number of frames.
    pub frames: usize,
    /// Number of clusters.
    pub clusters: usize,
    /// `(min, max)` of each coefficient index over all clusters and frames.
    pub ranges: [(f32, f32); 12],
    /// Quantised coefficients, frame by frame, cluster by cluster, 12 each (row-major `[A | b]`).
    pub values: Vec<u32>,
}

impl QuantisedAffine {
    fn levels(&self) -> f64 {
        ((1u64 << self.bits) - 1) as f64
    }

    /// Coefficient `c` of a quantised value.
    fn dequantise(&self, c: usize, q: u32) -> f64 {
        let (lo, hi) = self.ranges[c];
        lo as f64 + q as f64 * (hi as f64 - lo as f64) / self.levels()
    }

    fn quantise(&self, c: usize, x: f64) -> u32 {
        let (lo, hi) = self.ranges[c];
        let width = hi as f64 - lo as f64;
        if width <= 0.0 {
            return 0;
        }
        ((x - lo as f64) / width * self.levels())
            .round()
            .clamp(0.0, self.levels()) as u32
    }

    fn check(&self) -> Result<()> {
        if self.bits == 0 || self.bits > MAX_AFFINE_BITS {
            return Err(Error::Stream(format!(
                "affine coefficients: {} bits is outside 1..={MAX_AFFINE_BITS}",
                self.bits
            )));
        }
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
        if let Some((c, _)) = self
            .ranges
            .iter()
            .enumerate()
            .find(|(_, (lo, hi))| !(lo.is_finite() && hi.is_finite() && lo <= hi))
        {
            return Err(Error::Stream(format!(
                "affine coefficients: range of coefficient {c} is not a finite interval"
            )));
        }
        let top = (1u64 << self.bits) - 1;
        if let Some(i) = self.values.iter().position(|&q| q as u64 > top) {
            return Err(Error::Stream(format!(
                "affine coefficients: value {i} does not fit in {} bits",
                self.bits
            )));
        }
        Ok(())
    }
}

/// Per frame and cluster, the dequantised affine map predicting that frame from the decoded frame 0.
#[derive(Debug, Clone, PartialEq)]
pub struct AffineTrack {
    quantised: QuantisedAffine,
    maps: Vec<AffineCoefficients>,
}

impl AffineTrack {
    /// Fits `H_i^k` (eq. 2) for every frame `i` of `frames` and cluster `k`, from `reference` (the
    /// frame 0 the decoder will have) to the original frame, then quantises to `bits` per coefficient.
    pub fn fit(
        frames: &[Vec<Point>],
        reference: &[Point],
        partition: &Partition,
        bits: u8,
    ) -> Result<Self> {
        if bits == 0 || bits > MAX_AFFINE_BITS {
            return Err(Error::Usage(format!(
                "affine bits must be in 1..={MAX_AFFINE_BITS}, not {bits}"
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
        let mut ranges = [(f32::INFINITY, f32::NEG_INFINITY); 12];
        for h in &exact {
            for (r, &x) in ranges.iter_mut().zip(h) {
                r.0 = r.0.min(x as f32);
                r.1 = r.1.max(x as f32);
            }
        }
        let mut quantised = QuantisedAffine {
            bits,
            frames: frames.len(),
            clusters: partition.clusters(),
            ranges,
            values: Vec::with_capacity(exact.len() * 12),
        };
        let values: Vec<u32> = exact
            .iter()
            .flat_map(|h| (0..12).map(|c| quantised.quantise(c, h[c])))
            .collect();
        quantised.values = values;
        Self::from_quantised(quantised)
    }

    /// Rebuilds the predictor from stored integers and ranges; fails on inconsistent input.
    pub fn from_quantised(quantised: QuantisedAffine) -> Result<Self> {
        quantised.check()?;
        let maps = quantised
            .values
            .chunks_exact(12)
            .map(|q| std::array::from_fn(|c| quantised.dequantise(c, q[c])))
            .collect();
        Ok(Self { quantised, maps })
    }

    /// The stored form: integers and ranges.
    pub fn quantised(&self) -> &QuantisedAffine {
        &self.quantised
    }

    /// Number of frames.
    pub fn frame_count(&self) -> usize {
        self.quantised.frames
    }

    /// Number of clusters.
    pub fn cluster_count(&self) -> usize {
        self.quantised.clusters
    }

    /// The dequantised map of `cluster` at `frame`, in the unit frame of the reference.
    pub fn map(&self, frame: usize, cluster: usize) -> Option<&AffineCoefficients> {
        if cluster >= self.quantised.clusters {
            return None;
        }
        self.maps.get(frame * self.quantised.clusters + cluster)
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
        reference
            .iter()
            .zip(partition.labels())
            .map(|(p, &k)| match self.map(frame, k as usize) {
                Some(h) => unit.to_world(apply(h, unit.to_unit(p))),
                None => *p,
            })
            .collect()
    }
}
