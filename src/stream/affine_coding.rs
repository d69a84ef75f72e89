//! Entropy coding of the affine track: each of a cluster's 12 stored coefficients (see
//! [`crate::motion::AffineTrack`]) is a trajectory of integer levels over the frames, coded as the
//! residual of a temporal predictor.
//!
//! Per trajectory the encoder picks the predictor order that codes smallest (1: the previous
//! level, 2: linear extrapolation, 3: quadratic), one adaptive symbol; the first frame is
//! predicted by the identity map (frame 0 is fitted from the decoded frame 0 itself). Residuals go
//! through adaptive integer models chosen by the coefficient's kind (linear part or translation)
//! and the size of the trajectory's previous residual, which tracks how busy the motion is.
//!
//! The extrapolation codes smaller than a temporal DCT of each trajectory
//! (docs/design.md, "Affine precision per codec"); the levels are uniform scalar quantisation of
//! each frame's map, so every decoded coefficient is within half its step of the fitted one.

use crate::error::{Error, Result};
use crate::mesh::Point;
use crate::motion::{
    identity_levels, AffineTrack, ClusterGeometry, Partition, QuantisedAffine, MAX_AFFINE_LEVEL,
};
use crate::stream::bytes::{ByteReader, ByteWriter};
use crate::stream::entropy::{self, Decoder, Encoder, IntModel, SymbolCoder, SymbolModel};

/// Predictor orders a trajectory may use (1..=ORDERS).
const ORDERS: usize = 3;

/// Classes of the previous residual's magnitude: 0, 1, 2–3, 4–15, 16+.
const MAGNITUDES: usize = 5;

/// Coded after the last level, checked by the decoder: the range decoder reads a cut-off stream
/// as if zeros followed, which would otherwise decode to a plausible track.
const AFFINE_END: u32 = 0xAFF1_9E0D;

fn magnitude_class(r: i64) -> usize {
    match r.unsigned_abs() {
        0 => 0,
        1 => 1,
        2..=3 => 2,
        4..=15 => 3,
        _ => 4,
    }
}

/// The level `order` predicts from `history` (most recent last; shorter histories lower the order).
fn extrapolate(order: usize, history: &[i64]) -> i64 {
    let n = history.len();
    let at = |back: usize| history[n - back];
    match order.min(n) {
        0 => 0,
        1 => at(1),
        2 => 2 * at(1) - at(2),
        _ => 3 * at(1) - 3 * at(2) + at(3),
    }
}

/// Rough cost in bits of coding `residual` (the encoder's choice of order only).
fn cost(residual: i64) -> f64 {
    2.0 * (1.0 + residual.unsigned_abs() as f64).log2() + 1.0
}

/// The order (1..=ORDERS) that codes `trajectory` smallest, by [`cost`].
fn best_order(trajectory: &[i64]) -> usize {
    (1..=ORDERS)
        .map(|order| {
            let bits: f64 = (1..trajectory.len())
                .map(|f| cost(trajectory[f] - extrapolate(order, &trajectory[..f])))
                .sum();
            (order, bits)
        })
        .fold(
            (1, f64::INFINITY),
            |best, c| if c.1 < best.1 { c } else { best },
        )
        .0
}

/// The adaptive models of the traversal: per coefficient kind (linear, translation).
struct Models {
    order: [SymbolModel; 2],
    first: [IntModel; 2],
    residual: [[IntModel; MAGNITUDES]; 2],
}

impl Models {
    fn new() -> Self {
        Self {
            order: [SymbolModel::new(ORDERS), SymbolModel::new(ORDERS)],
            first: Default::default(),
            residual: Default::default(),
        }
    }
}

/// Codes the levels cluster by cluster, coefficient by coefficient, each trajectory over all
/// frames; `orders[k * 12 + c]` is trajectory (k, c)'s predictor order (filled when decoding).
/// With `q.values` empty, a decoder reads every level and keeps none: a dry run that checks the
/// part (its end word included) in constant memory before its levels are given room.
fn code_trajectories<C: SymbolCoder>(
    c: &mut C,
    q: &mut QuantisedAffine,
    orders: &mut [usize],
    identity: &[[i64; 12]],
) -> Result<()> {
    let mut models = Models::new();
    let (frames, clusters) = (q.frames, q.clusters);
    if identity.len() != clusters || orders.len() != clusters * 12 {
        return Err(Error::Stream(format!(
            "affine coefficients: {clusters} clusters, the partition has {}",
            identity.len()
        )));
    }
    for (k, start) in identity.iter().enumerate() {
        for (coeff, &first) in start.iter().enumerate() {
            let kind = usize::from(coeff % 4 == 3);
            let slot = k * 12 + coeff;
            let order = 1 + c.symbol(orders[slot] - 1, &mut models.order[kind])?;
            orders[slot] = order;
            // The last ORDERS levels, oldest first: all that `extrapolate` looks back at.
            let mut history = [0i64; ORDERS];
            let mut class = 0;
            for f in 0..frames {
                let i = (f * clusters + k) * 12 + coeff;
                let (guess, model) = match f {
                    0 => (first, &mut models.first[kind]),
                    _ => (
                        extrapolate(order, &history[ORDERS - f.min(ORDERS)..]),
                        &mut models.residual[kind][class],
                    ),
                };
                let target = q.values.get(i).copied().unwrap_or(guess);
                let r = c.signed(target.wrapping_sub(guess), model)?;
                let value = guess.checked_add(r).filter(|v| v.abs() <= MAX_AFFINE_LEVEL);
                let Some(value) = value else {
                    return Err(Error::Stream(format!(
                        "affine coefficients: level of cluster {k}, coefficient {coeff}, frame \
                         {f} is beyond ±2^40"
                    )));
                };
                if let Some(slot) = q.values.get_mut(i) {
                    *slot = value;
                }
                history.rotate_left(1);
                history[ORDERS - 1] = value;
                class = magnitude_class(r);
            }
        }
    }
    if c.raw_bits(u64::from(AFFINE_END), 32)? != u64::from(AFFINE_END) {
        return Err(Error::Stream(format!(
            "affine coefficients: the coded data end before the levels of {frames} frames of \
             {clusters} clusters do (truncated, damaged, or a forged frame count)"
        )));
    }
    Ok(())
}

/// The identity map's levels of every cluster: the first frame's prediction.
fn identity_of(geometry: &ClusterGeometry, step: f32) -> Vec<[i64; 12]> {
    (0..geometry.centroids.len())
        .map(|k| identity_levels(geometry.centroid(k), &geometry.steps(k, f64::from(step))))
        .collect()
}

/// Codes the affine track: its base step, then the level trajectories.
pub fn encode_affine(track: &AffineTrack) -> Result<Vec<u8>> {
    let mut q = track.quantised().clone();
    let (frames, clusters) = (q.frames, q.clusters);
    let mut orders: Vec<usize> = (0..clusters * 12)
        .map(|slot| {
            let (k, coeff) = (slot / 12, slot % 12);
            let trajectory: Vec<i64> = (0..frames)
                .map(|f| q.values[(f * clusters + k) * 12 + coeff])
                .collect();
            best_order(&trajectory)
        })
        .collect();
    let identity = identity_of(track.geometry(), q.step);
    let mut w = ByteWriter::new();
    w.f32(q.step);
    let mut enc = Encoder::new();
    code_trajectories(&mut enc, &mut q, &mut orders, &identity)?;
    w.raw(&enc.finish()?);
    Ok(w.into_bytes())
}

#[cfg(any(test, feature = "internals"))]
/// Decodes the affine track of `frames` frames for `partition`'s clusters on the decoded frame 0
/// `reference` (whose cluster geometry sets the steps). The part is read twice: once keeping no
/// level (as [`check_affine`]), then into a track, so that its 12 levels a frame and cluster (96
/// bytes) are allocated only for a part that holds them all; a byte of zeros decodes to thousands
/// of levels, so its length alone proves little.
pub fn decode_affine(
    bytes: &[u8],
    frames: usize,
    partition: &Partition,
    reference: &[Point],
) -> Result<AffineTrack> {
    check_affine(bytes, frames, partition, reference)?;
    decode_checked_affine(bytes, frames, partition, reference)
}

/// [`decode_affine`] of a part that [`check_affine`] has passed: read once.
pub(crate) fn decode_checked_affine(
    bytes: &[u8],
    frames: usize,
    partition: &Partition,
    reference: &[Point],
) -> Result<AffineTrack> {
    let mut part = AffinePart::open(bytes, frames, partition, reference)?;
    part.q.values = vec![0; frames * part.q.clusters * 12];
    part.read()?;
    AffineTrack::from_quantised(part.q, part.geometry)
}

/// Checks that the affine part holds `frames` frames of `partition`'s clusters, end word
/// included, in memory that does not grow with the frames (the levels are read and dropped).
pub fn check_affine(
    bytes: &[u8],
    frames: usize,
    partition: &Partition,
    reference: &[Point],
) -> Result<()> {
    AffinePart::open(bytes, frames, partition, reference)?.read()
}

/// An affine part whose step and length are checked, ready to read.
struct AffinePart<'a> {
    /// The track read so far: no levels until they are given room.
    q: QuantisedAffine,
    geometry: ClusterGeometry,
    /// The identity's levels of every cluster, which predict frame 0.
    identity: Vec<[i64; 12]>,
    coded: &'a [u8],
}

impl<'a> AffinePart<'a> {
    fn open(
        bytes: &'a [u8],
        frames: usize,
        partition: &Partition,
        reference: &[Point],
    ) -> Result<Self> {
        let mut r = ByteReader::new(bytes, "affine coefficients");
        let step = r.f32()?;
        let coded = r.take(r.remaining())?;
        let clusters = partition.clusters();
        let count = (frames as u64)
            .saturating_mul(clusters as u64)
            .saturating_mul(12);
        if count > entropy::max_symbols(coded.len()) {
            return Err(Error::Stream(format!(
                "affine coefficients: {count} values cannot fit in {} bytes",
                coded.len()
            )));
        }
        // The step sets the identity's levels below: refuse a forged one first.
        QuantisedAffine::check_step(step)?;
        let geometry = ClusterGeometry::of(reference, partition);
        let identity = identity_of(&geometry, step);
        let q = QuantisedAffine {
            step,
            frames,
            clusters,
            values: Vec::new(),
        };
        Ok(Self {
            q,
            geometry,
            identity,
            coded,
        })
    }

    /// Reads every level and the end word, keeping the levels where `q.values` has room.
    fn read(&mut self) -> Result<()> {
        let mut orders = vec![1usize; self.q.clusters * 12];
        let mut dec = Decoder::new(self.coded)?;
        code_trajectories(&mut dec, &mut self.q, &mut orders, &self.identity)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extrapolation_follows_polynomials() {
        let line = [3, 5, 7, 9];
        assert_eq!(extrapolate(2, &line), 11);
        assert_eq!(extrapolate(1, &line), 9);
        let square = [0, 1, 4, 9];
        assert_eq!(extrapolate(3, &square), 16);
        // What the coder passes: the last three levels at most.
        assert_eq!(extrapolate(3, &square[1..]), 16);
        assert_eq!(extrapolate(3, &square[..1]), 0);
        assert_eq!(best_order(&[0, 1, 4, 9, 16, 25, 36]), 3);
        assert_eq!(best_order(&[4, 4, 4, 4]), 1);
    }
}
