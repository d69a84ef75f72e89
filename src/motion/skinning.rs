//! The skinning predictor (follow-up paper, §3.2, eq. 7–10): every vertex moves by a weighted blend
//! of the affine maps of its own cluster and of the clusters next to it, instead of by its cluster's
//! map alone (eq. 8, the piecewise affine predictor), which removes the jumps at cluster borders.
//!
//! Reading of the paper followed here:
//! - "Neighbouring patches" (`V(υ)`, eq. 10) are the clusters adjacent to the vertex's cluster in the
//!   cluster graph: two clusters are adjacent when a mesh edge joins them. Every vertex of a cluster
//!   thus has the same candidate set, which the decoder derives from the partition and connectivity.
//! - The prediction `Σ_j α_j A_i^j χ_0` is a point only if `Σ_j α_j = 1` (the homogeneous coordinate
//!   of eq. 7 must stay 1, as the residual's fourth component of eq. 11 is 0), so the weights are
//!   constrained to sum to 1. The paper states no sign constraint and solves by pseudo-inverse, so
//!   weights may be negative.
//! - Writing `α_k = 1 − Σ_{j≠k} β_j` for the own cluster `k`, the prediction is
//!   `p_k + Σ_{j≠k} β_j (p_j − p_k)`: the piecewise affine prediction plus a correction, and
//!   `β = 0` is exactly eq. 8. The `β` are found by least squares over all frames (eq. 9) with a
//!   small ridge toward 0, which only decides directions the data do not see (neighbour maps
//!   that agree with the own one at this vertex); without it those weights are arbitrary and large.
//! - The `β` are quantised uniformly to [`WEIGHT_BITS`] signed bits over `[−limit, limit]`, `limit`
//!   the largest `|β|` of the stream (stored as an `f32`); the own weight is implied, so the
//!   quantised weights still sum to exactly 1.
//!
//! The weights are fitted against the dequantised affine maps and the decoded frame 0, and the
//! prediction is computed by one function from the quantised weights on both sides: encoder and
//! decoder predictions are bit-identical.

use super::affine::AffineTrack;
use super::fit::{apply, AffineCoefficients, UnitFrame};
use super::partition::Partition;
#[cfg(feature = "encode")]
use super::weight_fits::WeightFits;
use crate::error::{Error, Result};
use crate::mesh::{Point, Triangle};
#[cfg(feature = "encode")]
use nalgebra::{DMatrix, DVector};
#[cfg(feature = "encode")]
use rayon::prelude::*;

/// Bits per quantised weight, sign included (the paper's 16).
pub const WEIGHT_BITS: u8 = 16;

/// Ridge of the weight fits, relative to the mean diagonal of the normal matrix: far below what
/// changes a well-determined weight, enough to keep weights of indistinguishable maps near 0.
pub const DEFAULT_RIDGE: f64 = 1e-4;

/// Largest weight magnitude kept; larger fits (from near-degenerate normal matrices) are clamped,
/// which keeps the 16-bit step fine for the ordinary weights of the stream.
pub const MAX_WEIGHT: f64 = 8.0;

/// For every cluster, the sorted clusters joined to it by a mesh edge (itself excluded).
pub fn cluster_neighbours(partition: &Partition, triangles: &[Triangle]) -> Vec<Vec<u32>> {
    let labels = partition.labels();
    let mut out = vec![Vec::new(); partition.clusters()];
    for t in triangles {
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            let (Some(&ka), Some(&kb)) = (labels.get(a as usize), labels.get(b as usize)) else {
                continue;
            };
            if ka != kb {
                out[ka as usize].push(kb);
                out[kb as usize].push(ka);
            }
        }
    }
    for n in &mut out {
        n.sort_unstable();
        n.dedup();
    }
    out
}

/// What a weight fit reads: the original frames, the decoded frame 0, the clusters, the
/// connectivity and the quantised affine track.
#[cfg(feature = "encode")]
pub type FitInput<'a> = (
    &'a [Vec<Point>],
    &'a [Point],
    &'a Partition,
    &'a [Triangle],
    &'a AffineTrack,
);

/// The quantised skinning weights: for each vertex, one signed integer per neighbouring cluster of
/// its own cluster (in the order of [`cluster_neighbours`]); the own cluster's weight is implied.
#[derive(Debug, Clone, PartialEq)]
pub struct SkinningWeights {
    /// Bits per weight, sign included (1..=31).
    pub bits: u8,
    /// Weights are `value × limit / (2^(bits−1) − 1)`.
    pub limit: f32,
    /// Neighbouring clusters of each cluster.
    pub neighbours: Vec<Vec<u32>>,
    /// Quantised weights, vertex by vertex, `neighbours[label].len()` each.
    pub values: Vec<i32>,
}

impl SkinningWeights {
    /// Largest quantised magnitude.
    pub fn top(bits: u8) -> i32 {
        ((1i64 << (bits.clamp(1, 31) - 1)) - 1).max(1) as i32
    }

    /// The weight one quantisation step stands for.
    pub fn step(&self) -> f64 {
        self.limit as f64 / Self::top(self.bits) as f64
    }

    /// How many weights a vertex of each cluster has, summed over `labels`.
    pub fn expected_count(neighbours: &[Vec<u32>], labels: &[u32]) -> Option<usize> {
        labels.iter().try_fold(0usize, |s, &l| {
            neighbours.get(l as usize).map(|n| s + n.len())
        })
    }

    /// Checks stored weights against the partition they apply to (e.g. after reading a stream).
    pub fn check(&self, partition: &Partition) -> Result<()> {
        if !(2..=31).contains(&self.bits) {
            return Err(Error::Stream(format!(
                "skinning weights: {} bits is outside 2..=31",
                self.bits
            )));
        }
        if !(self.limit.is_finite() && self.limit > 0.0 && self.limit as f64 <= MAX_WEIGHT) {
            return Err(Error::Stream(format!(
                "skinning weights: limit {} is not in (0, {MAX_WEIGHT}]",
                self.limit
            )));
        }
        if self.neighbours.len() != partition.clusters() {
            return Err(Error::Stream(format!(
                "skinning weights: neighbour lists for {} clusters, the partition has {}",
                self.neighbours.len(),
                partition.clusters()
            )));
        }
        if Self::expected_count(&self.neighbours, partition.labels()) != Some(self.values.len()) {
            return Err(Error::Stream(format!(
                "skinning weights: {} values do not match the partition's neighbourhoods",
                self.values.len()
            )));
        }
        let top = Self::top(self.bits);
        if let Some(i) = self.values.iter().position(|q| q.abs() > top) {
            return Err(Error::Stream(format!(
                "skinning weights: value {i} does not fit in {} bits",
                self.bits
            )));
        }
        Ok(())
    }

    /// Fits the weights of every vertex (eq. 9 under eq. 10 and `Σα = 1`) from `reference` (the
    /// decoded frame 0) to the original `frames`, with the dequantised maps of `track`, and quantises them.
    #[cfg(feature = "encode")]
    pub fn fit(
        frames: &[Vec<Point>],
        reference: &[Point],
        partition: &Partition,
        triangles: &[Triangle],
        track: &AffineTrack,
    ) -> Result<Self> {
        Self::fit_with(
            frames,
            reference,
            partition,
            triangles,
            track,
            DEFAULT_RIDGE,
            WEIGHT_BITS,
        )
    }

    /// [`SkinningWeights::fit`] with another relative ridge and bits per weight (2..=31; the
    /// motion bench measures their effect on residual energy and weight bits).
    #[cfg(feature = "encode")]
    #[allow(clippy::too_many_arguments)]
    pub fn fit_with(
        frames: &[Vec<Point>],
        reference: &[Point],
        partition: &Partition,
        triangles: &[Triangle],
        track: &AffineTrack,
        ridge: f64,
        bits: u8,
    ) -> Result<Self> {
        let input = (frames, reference, partition, triangles, track);
        Ok(Self::fit_exact(input, ridge, bits)?.0)
    }

    /// [`SkinningWeights::fit_with`], and the fits the weights were quantised from, which say
    /// what moving a weight costs ([`WeightFits::growth`]).
    #[cfg(feature = "encode")]
    pub fn fit_exact(input: FitInput, ridge: f64, bits: u8) -> Result<(Self, WeightFits)> {
        let (frames, reference, partition, triangles, track) = input;
        if !(2..=31).contains(&bits) {
            return Err(Error::Usage(format!(
                "skinning weights: {bits} bits is outside 2..=31"
            )));
        }
        if !(ridge.is_finite() && ridge >= 0.0) {
            return Err(Error::Usage(format!(
                "skinning ridge {ridge} is not a non-negative number"
            )));
        }
        track.check_fits(reference, partition)?;
        if frames.len() != track.frame_count() {
            return Err(Error::Usage(format!(
                "{} frames for a {}-frame affine track",
                frames.len(),
                track.frame_count()
            )));
        }
        if let Some(f) = frames.iter().position(|f| f.len() != reference.len()) {
            return Err(Error::Usage(format!(
                "frame {f} has a different vertex count than the reference frame"
            )));
        }
        let neighbours = cluster_neighbours(partition, triangles);
        let unit = UnitFrame::of(reference);
        let maps = track.maps();
        let fitted: Vec<Solved> = (0..reference.len())
            .into_par_iter()
            .map(|v| {
                let k = partition.labels()[v] as usize;
                let problem = VertexFit {
                    frames,
                    reference,
                    maps: &maps,
                    clusters: track.cluster_count(),
                    unit,
                    ridge,
                };
                problem.solve(v, k, &neighbours[k])
            })
            .collect();
        let effect: f64 = fitted.iter().map(|f| f.effect).sum();
        let (exact, grams): (Vec<Vec<f64>>, Vec<Vec<f64>>) =
            fitted.into_iter().map(|f| (f.weights, f.normal)).unzip();
        let largest = exact
            .iter()
            .flatten()
            .fold(0f64, |m, w| m.max(w.abs()))
            .min(MAX_WEIGHT);
        // A stream without any weight (or with all zero) still needs a valid, positive limit.
        let limit = if largest > 0.0 { largest as f32 } else { 1.0 };
        let (bits, limit) = bits_by_effect(limit, bits, effect, reference.len(), track);
        let top = Self::top(bits);
        let step = limit as f64 / top as f64;
        let values = exact
            .iter()
            .flatten()
            .map(|w| ((w / step).round() as i64).clamp(-(top as i64), top as i64) as i32)
            .collect();
        let weights = Self {
            bits,
            limit,
            neighbours,
            values,
        };
        weights.check(partition)?;
        let fits = WeightFits { exact, grams, step };
        Ok((weights, fits))
    }

    /// Predicts frame `frame` (eq. 7) from the quantised weights and `track`'s dequantised maps.
    /// Checks that frame, reference, partition and weights fit together.
    pub fn try_predict(
        &self,
        frame: usize,
        track: &AffineTrack,
        reference: &[Point],
        partition: &Partition,
    ) -> Result<Vec<Point>> {
        track.check_fits(reference, partition)?;
        if frame >= track.frame_count() {
            return Err(Error::Usage(format!(
                "frame {frame} asked of a {}-frame prediction",
                track.frame_count()
            )));
        }
        self.check(partition)?;
        let unit = UnitFrame::of(reference);
        let step = self.step();
        let maps = track.frame_maps(frame);
        let mut offset = 0usize;
        let mut out = Vec::with_capacity(reference.len());
        for (p, &k) in reference.iter().zip(partition.labels()) {
            let x = unit.to_unit(p);
            let own = maps.get(k as usize).map_or(x, |h| apply(h, x));
            let mut q = own;
            let neighbours = &self.neighbours[k as usize];
            for (&j, &w) in neighbours.iter().zip(&self.values[offset..]) {
                if w == 0 {
                    continue;
                }
                let other = maps.get(j as usize).map_or(x, |h| apply(h, x));
                let w = w as f64 * step;
                for a in 0..3 {
                    q[a] += w * (other[a] - own[a]);
                }
            }
            offset += neighbours.len();
            out.push(unit.to_world(q));
        }
        Ok(out)
    }

    /// Number of vertices that have at least one non-zero neighbour weight.
    pub fn blended_vertices(&self, partition: &Partition) -> usize {
        let mut offset = 0usize;
        let mut n = 0;
        for &k in partition.labels() {
            let len = self.neighbours.get(k as usize).map_or(0, Vec::len);
            if self
                .values
                .get(offset..offset + len)
                .is_some_and(|w| w.iter().any(|&q| q != 0))
            {
                n += 1;
            }
            offset += len;
        }
        n
    }
}

/// The bits (at most `most`) and limit of weights whose largest magnitude is `limit`: the fewest
/// bits whose step can move the vertices no more than the affine maps' quantisation does (the
/// closed loop hands both errors to the residual coder, so weights finer than the maps cost bits
/// and buy nothing), and the limit widened so that the step is exactly that (the stored limit
/// sets the step: a step that follows the maps' step smoothly, where the bits alone would halve
/// it at each threshold). `effect` is `Σ_v Σ_j Σ_i ‖p_j^i − p_k^i‖²` (unit frame), so a weight
/// step `w` moves the vertices by `w² effect / 12` squared in all; the maps move each vertex by
/// about three translation steps `s`: `3 s² / 12` a vertex and frame.
#[cfg(feature = "encode")]
fn bits_by_effect(
    limit: f32,
    most: u8,
    effect: f64,
    vertices: usize,
    track: &AffineTrack,
) -> (u8, f32) {
    let step = f64::from(track.quantised().step);
    let per_vertex_frame = effect / (vertices.max(1) * track.frame_count().max(1)) as f64;
    if !(per_vertex_frame > 0.0 && per_vertex_frame.is_finite()) {
        return (most, limit);
    }
    let target = step * (3.0 / per_vertex_frame).sqrt();
    let Some(bits) =
        (2..most).find(|&b| f64::from(limit) / f64::from(SkinningWeights::top(b)) <= target)
    else {
        return (most, limit);
    };
    let widened = (target * f64::from(SkinningWeights::top(bits))).min(MAX_WEIGHT) as f32;
    (bits, widened.max(limit))
}

/// One vertex's fit: its weights, what an error of one in every weight moves it by (squared,
/// summed over the frames), and the normal matrix without the ridge (`m × m`, symmetric).
#[cfg(feature = "encode")]
#[derive(Default)]
struct Solved {
    weights: Vec<f64>,
    effect: f64,
    normal: Vec<f64>,
}

/// What every vertex's weight fit shares.
#[cfg(feature = "encode")]
struct VertexFit<'a> {
    frames: &'a [Vec<Point>],
    reference: &'a [Point],
    /// The track's maps, frame by frame, `clusters` a frame.
    maps: &'a [AffineCoefficients],
    clusters: usize,
    unit: UnitFrame,
    ridge: f64,
}

#[cfg(feature = "encode")]
impl VertexFit<'_> {
    /// The unconstrained weights `β` of vertex `v` of cluster `k`: least squares of
    /// `Σ_i ‖Σ_j β_j (p_j^i − p_k^i) − (x_i − p_k^i)‖²` plus the ridge; `Σ_j Σ_i ‖p_j^i −
    /// p_k^i‖²`, what an error of one in every weight would move the vertex by (squared, summed
    /// over the frames); and the normal matrix.
    fn solve(&self, v: usize, k: usize, neighbours: &[u32]) -> Solved {
        let Self {
            frames,
            reference,
            maps,
            clusters,
            unit,
            ridge,
        } = *self;
        let m = neighbours.len();
        if m == 0 {
            return Solved::default();
        }
        let x0 = unit.to_unit(&reference[v]);
        let mut gram = DMatrix::<f64>::zeros(m, m);
        let mut rhs = DVector::<f64>::zeros(m);
        let mut d = vec![[0f64; 3]; m];
        for (i, frame) in frames.iter().enumerate() {
            let own = maps.get(i * clusters + k).map_or(x0, |h| apply(h, x0));
            let target = unit.to_unit(&frame[v]);
            let r = [0, 1, 2].map(|a| target[a] - own[a]);
            for (dj, &j) in d.iter_mut().zip(neighbours) {
                let other = maps
                    .get(i * clusters + j as usize)
                    .map_or(x0, |h| apply(h, x0));
                *dj = [0, 1, 2].map(|a| other[a] - own[a]);
            }
            for a in 0..m {
                rhs[a] += (0..3).map(|c| d[a][c] * r[c]).sum::<f64>();
                for b in a..m {
                    gram[(a, b)] += (0..3).map(|c| d[a][c] * d[b][c]).sum::<f64>();
                }
            }
        }
        for a in 0..m {
            for b in 0..a {
                gram[(a, b)] = gram[(b, a)];
            }
        }
        let effect = gram.trace();
        let normal: Vec<f64> = gram.iter().copied().collect();
        let lambda = ridge * effect / m as f64 + 1e-30;
        for a in 0..m {
            gram[(a, a)] += lambda;
        }
        let weights = match gram.cholesky() {
            Some(ch) => ch
                .solve(&rhs)
                .iter()
                .map(|&w| {
                    if w.is_finite() {
                        w.clamp(-MAX_WEIGHT, MAX_WEIGHT)
                    } else {
                        0.0
                    }
                })
                .collect(),
            // Not positive definite only if the maps are non-finite: keep the piecewise affine prediction.
            None => vec![0.0; m],
        };
        Solved {
            weights,
            effect: if effect.is_finite() { effect } else { 0.0 },
            normal,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::{energy, residuals};

    /// A strip along x bent at x = 0 over the frames: the left half stays, the right half rotates
    /// about the z axis through the seam, and vertices near the seam follow a smooth blend of the two
    /// (as a skinned elbow does), which no single map per half reproduces.
    fn bend() -> (Vec<Point>, Vec<Triangle>, Vec<Vec<Point>>, Partition) {
        let (nx, ny) = (21usize, 4usize);
        let mut rest = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                let x = -1.0 + 2.0 * i as f32 / (nx - 1) as f32;
                let z = if (i + j) % 2 == 0 { 0.05 } else { -0.05 };
                rest.push([x, 0.1 * j as f32, z]);
            }
        }
        let mut tris = Vec::new();
        for j in 0..ny - 1 {
            for i in 0..nx - 1 {
                let a = (j * nx + i) as u32;
                let (b, c, d) = (a + 1, a + nx as u32, a + nx as u32 + 1);
                tris.push([a, b, d]);
                tris.push([a, d, c]);
            }
        }
        let frames: Vec<Vec<Point>> = (0..12)
            .map(|f| {
                let angle = 0.08 * f as f32;
                rest.iter()
                    .map(|p| {
                        // Linear-blend weight of the right bone: 0 left of −0.3, 1 right of 0.3.
                        let w = ((p[0] + 0.3) / 0.6).clamp(0.0, 1.0);
                        let (c, s) = (angle.cos(), angle.sin());
                        let rotated = [c * p[0] - s * p[1], s * p[0] + c * p[1], p[2]];
                        [0, 1, 2].map(|a| (1.0 - w) * p[a] + w * rotated[a])
                    })
                    .collect()
            })
            .collect();
        let labels = rest.iter().map(|p| (p[0] > 0.0) as u32).collect();
        let partition = Partition::from_labels(labels, 2).unwrap();
        (rest, tris, frames, partition)
    }

    #[test]
    fn skinning_beats_piecewise_affine_at_the_seam() {
        let (rest, tris, frames, partition) = bend();
        assert_eq!(
            cluster_neighbours(&partition, &tris),
            vec![vec![1], vec![0]]
        );
        let track = AffineTrack::fit(&frames, &rest, &partition, 1e-6).unwrap();
        let weights = SkinningWeights::fit(&frames, &rest, &partition, &tris, &track).unwrap();
        assert_eq!(weights.values.len(), rest.len());
        let (mut affine_seam, mut skin_seam, mut affine_all, mut skin_all) = (0.0, 0.0, 0.0, 0.0);
        for (f, frame) in frames.iter().enumerate() {
            let a = residuals(frame, &track.predict(f, &rest, &partition));
            let s = residuals(
                frame,
                &weights.try_predict(f, &track, &rest, &partition).unwrap(),
            );
            affine_all += energy(&a);
            skin_all += energy(&s);
            let seam: Vec<usize> = (0..rest.len())
                .filter(|&v| rest[v][0].abs() < 0.3)
                .collect();
            affine_seam += energy(&seam.iter().map(|&v| a[v]).collect::<Vec<_>>());
            skin_seam += energy(&seam.iter().map(|&v| s[v]).collect::<Vec<_>>());
        }
        assert!(
            affine_seam > 1e-4,
            "the bend must defeat the affine predictor"
        );
        assert!(
            skin_seam < 0.2 * affine_seam,
            "seam energy: skinning {skin_seam}, affine {affine_seam}"
        );
        assert!(skin_all < 0.5 * affine_all, "{skin_all} vs {affine_all}");
        // Seam vertices blend; weights sum to 1 by construction, so the own weight is 1 − β.
        assert!(weights.blended_vertices(&partition) > 10);
    }

    #[test]
    fn weights_are_no_finer_than_the_maps_and_still_blend_the_seam() {
        let (rest, tris, frames, partition) = bend();
        let fit = |step| {
            let track = AffineTrack::fit(&frames, &rest, &partition, step).unwrap();
            let w = SkinningWeights::fit(&frames, &rest, &partition, &tris, &track).unwrap();
            (track, w)
        };
        let ((_, fine), (coarse_track, coarse)) = (fit(1e-6), fit(1e-2));
        assert!(fine.bits >= 14, "{} bits at step 1e-6", fine.bits);
        assert!(coarse.bits + 4 <= fine.bits, "{} bits at step 1e-2", coarse.bits);
        // The coarse weights still remove most of the seam's error of the coarse maps (0.22 of it
        // remains with their step exactly at the maps' effect).
        let (mut affine_seam, mut skin_seam) = (0.0, 0.0);
        let seam: Vec<usize> = (0..rest.len())
            .filter(|&v| rest[v][0].abs() < 0.3)
            .collect();
        for (f, frame) in frames.iter().enumerate() {
            let a = residuals(frame, &coarse_track.predict(f, &rest, &partition));
            let s = residuals(
                frame,
                &coarse
                    .try_predict(f, &coarse_track, &rest, &partition)
                    .unwrap(),
            );
            affine_seam += energy(&seam.iter().map(|&v| a[v]).collect::<Vec<_>>());
            skin_seam += energy(&seam.iter().map(|&v| s[v]).collect::<Vec<_>>());
        }
        assert!(
            skin_seam < 0.3 * affine_seam,
            "seam energy: skinning {skin_seam}, affine {affine_seam}"
        );
    }

    #[test]
    fn zero_weights_are_the_piecewise_affine_predictor() {
        let (rest, tris, frames, partition) = bend();
        let track = AffineTrack::fit(&frames, &rest, &partition, 1e-6).unwrap();
        let mut weights = SkinningWeights::fit(&frames, &rest, &partition, &tris, &track).unwrap();
        weights.values.iter_mut().for_each(|w| *w = 0);
        for f in [0, 5, 11] {
            assert_eq!(
                weights.try_predict(f, &track, &rest, &partition).unwrap(),
                track.predict(f, &rest, &partition)
            );
        }
    }

    #[test]
    fn inconsistent_weights_are_refused() {
        let (rest, tris, frames, partition) = bend();
        let track = AffineTrack::fit(&frames, &rest, &partition, 1e-6).unwrap();
        let good = SkinningWeights::fit(&frames, &rest, &partition, &tris, &track).unwrap();
        let mut short = good.clone();
        short.values.pop();
        assert!(short.check(&partition).is_err());
        let mut big = good.clone();
        big.values[0] = SkinningWeights::top(big.bits) + 1;
        assert!(big.check(&partition).is_err());
        let mut nan = good.clone();
        nan.limit = f32::NAN;
        assert!(nan.try_predict(0, &track, &rest, &partition).is_err());
        assert!(good.try_predict(99, &track, &rest, &partition).is_err());
    }
}
