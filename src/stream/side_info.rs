//! Entropy coding of the side information: the partition, the skinning weights, and (in
//! [`super::affine_coding`] and [`super::lattice_coding`]) the affine coefficients and the lattice
//! coordinates. Each is written once as a traversal generic over [`SymbolCoder`], so the encoder
//! and the decoder cannot drift apart.
//!
//! What is exploited: labels are spatially coherent (a vertex usually shares the label most of its
//! already-coded neighbours have); skinning weights vary smoothly over the surface and are large only near the cluster they blend
//! toward.

use crate::error::{Error, Result};
use crate::mesh::topology::{coincident_first, VertexAdjacency};
use crate::mesh::{Point, Triangle};
use crate::motion::{cluster_neighbours, Partition, SkinningWeights};

pub(crate) use super::affine_coding::decode_checked_affine;
#[cfg(any(test, feature = "internals"))]
pub use super::affine_coding::decode_affine;
pub use super::affine_coding::{check_affine, encode_affine};
pub use super::lattice_coding::{decode_lattice, encode_lattice};
use crate::stream::bytes::{ByteReader, ByteWriter};
use crate::stream::entropy::{
    self, BitModel, Decoder, Encoder, IntModel, SymbolCoder, SymbolModel, UIntModel,
};

/// The label most common among `v`'s already-coded neighbours (lowest on ties), if any.
fn predicted_label(
    adj: &VertexAdjacency,
    labels: &[u32],
    v: usize,
    counts: &mut Vec<(u32, u32)>,
) -> Option<u32> {
    counts.clear();
    for &w in adj.neighbours(v).iter().filter(|&&w| (w as usize) < v) {
        let l = labels[w as usize];
        match counts.iter_mut().find(|(lab, _)| *lab == l) {
            Some((_, n)) => *n += 1,
            None => counts.push((l, 1)),
        }
    }
    counts
        .iter()
        .max_by_key(|&&(l, n)| (n, std::cmp::Reverse(l)))
        .map(|&(l, _)| l)
}

/// Labels are guessed, in this order of trust, from the vertex's first copy at its first-frame
/// position (a seam or hard-edge copy moves with it), its already-coded neighbours' commonest
/// label, or the previous vertex's; one hit bit per vertex, a context per kind of guess.
fn code_partition<C: SymbolCoder>(
    c: &mut C,
    labels: &mut [u32],
    clusters: usize,
    (adj, coincident): (&VertexAdjacency, &[Option<u32>]),
) -> Result<()> {
    let mut hit: [BitModel; 3] = Default::default();
    let mut small = SymbolModel::new(clusters);
    let mut large = UIntModel::default();
    let mut counts = Vec::new();
    for v in 0..labels.len() {
        let copy_of = coincident.get(v).copied().flatten();
        let (ctx, guess) = match (copy_of, predicted_label(adj, labels, v, &mut counts)) {
            (Some(f), _) => (2, labels[f as usize]),
            (None, Some(l)) => (0, l),
            (None, None) => (1, if v > 0 { labels[v - 1] } else { 0 }),
        };
        if c.bit(labels[v] == guess, &mut hit[ctx])? {
            labels[v] = guess;
            continue;
        }
        let l = if clusters <= 256 {
            c.symbol(labels[v] as usize, &mut small)? as u64
        } else {
            c.unsigned(labels[v] as u64, &mut large)?
        };
        if l >= clusters as u64 || l == guess as u64 {
            return Err(Error::Stream(format!(
                "partition: vertex {v} has an impossible label"
            )));
        }
        labels[v] = l as u32;
    }
    Ok(())
}

/// Codes the cluster label of each vertex over the decoded first frame (`triangles`, `reference`).
pub fn encode_partition(
    labels: &[u32],
    clusters: usize,
    (triangles, reference): (&[Triangle], &[Point]),
) -> Result<Vec<u8>> {
    let adj = VertexAdjacency::new(labels.len(), triangles);
    let coincident = coincident_first(reference);
    let mut enc = Encoder::new();
    code_partition(&mut enc, &mut labels.to_vec(), clusters, (&adj, &coincident))?;
    enc.finish()
}

/// Decodes `vertices` cluster labels in `0..clusters` over the decoded first frame.
pub fn decode_partition(
    bytes: &[u8],
    vertices: usize,
    clusters: usize,
    (triangles, reference): (&[Triangle], &[Point]),
) -> Result<Vec<u32>> {
    entropy::check_capacity(vertices as u64, bytes.len(), "partition")?;
    let adj = VertexAdjacency::new(vertices, triangles);
    let coincident = coincident_first(reference);
    let mut dec = Decoder::new(bytes)?;
    let mut labels = vec![0u32; vertices];
    code_partition(&mut dec, &mut labels, clusters, (&adj, &coincident))?;
    Ok(labels)
}

/// One weight as the coder meets it: what an encoder that chooses the weights by their bits sees
/// ([`choose_weights`]).
pub struct WeightSlot<'a> {
    /// The vertex.
    pub vertex: usize,
    /// The weight's place among the vertex's.
    pub index: usize,
    /// The coder's guess of it.
    pub guess: i64,
    /// The adaptive model that codes its difference from the guess, as it stands.
    pub model: &'a IntModel,
    /// The vertex's weights as they stand (those before `index` already chosen).
    pub values: &'a [i32],
}

/// Picks the value a weight is coded as.
pub type ChooseWeight<'a> = &'a mut dyn FnMut(WeightSlot) -> i64;

/// Per vertex, the weight toward each neighbouring cluster as a difference from a guess: the same
/// weight of the vertex's first copy at its first-frame position when that is in the same cluster,
/// else the rounded mean of the same weight at the vertex's already-coded mesh neighbours of the
/// same cluster (0 if none). Contexts: which guess, whether the target cluster touches the
/// vertex's 1-ring (seam vertices carry the large weights), and how far apart those neighbours'
/// weights are (all zero, all equal, then by powers of two: a smooth stretch of surface leaves
/// small corrections; stream version 7, −2 … −8 % of the part).
///
/// With `choose` (an encoder's), each weight first becomes what it picks.
fn code_weight_values<C: SymbolCoder>(
    c: &mut C,
    w: &mut SkinningWeights,
    labels: &[u32],
    (adj, coincident): (&VertexAdjacency, &[Option<u32>]),
    mut choose: Option<ChooseWeight>,
) -> Result<()> {
    let mut models: [[[IntModel; SPREADS]; 2]; 3] = Default::default();
    let top = SkinningWeights::top(w.bits) as i64;
    let mut offsets = Vec::with_capacity(labels.len());
    let mut next = 0usize;
    for &l in labels {
        offsets.push(next);
        next += w.neighbours.get(l as usize).map_or(0, Vec::len);
    }
    if next != w.values.len() {
        return Err(Error::Stream(
            "skinning weights: count does not match the partition".into(),
        ));
    }
    for v in 0..labels.len() {
        let k = labels[v];
        let Some(neighbours) = w.neighbours.get(k as usize) else {
            continue;
        };
        let ring = adj.neighbours(v);
        let copy_of = coincident.get(v).copied().flatten().map(|f| f as usize);
        let copy_of = copy_of.filter(|&f| labels[f] == k);
        for (idx, &j) in neighbours.iter().enumerate() {
            let (mut sum, mut n) = (0i64, 0i64);
            let (mut lo, mut hi) = (i64::MAX, i64::MIN);
            for &u in ring.iter().filter(|&&u| (u as usize) < v) {
                if labels[u as usize] == k {
                    let x = w.values[offsets[u as usize] + idx] as i64;
                    sum += x;
                    n += 1;
                    lo = lo.min(x);
                    hi = hi.max(x);
                }
            }
            let spread = match n {
                0 => 0,
                _ => spread_class(hi - lo, lo == 0 && hi == 0),
            };
            let (kind, guess) = match copy_of {
                Some(f) => (2, w.values[offsets[f] + idx] as i64),
                None if n > 0 => (1, (sum as f64 / n as f64).round() as i64),
                None => (0, 0),
            };
            let touches = ring.iter().any(|&u| labels[u as usize] == j);
            let model = &mut models[kind][touches as usize][spread];
            let slot = offsets[v] + idx;
            if let Some(choose) = choose.as_mut() {
                let values = &w.values[offsets[v]..offsets[v] + neighbours.len()];
                let (vertex, index, guess) = (v, idx, guess);
                let picked = choose(WeightSlot { vertex, index, guess, model, values });
                w.values[slot] = picked.clamp(-top, top) as i32;
            }
            let value = guess + c.signed(w.values[slot] as i64 - guess, model)?;
            if value.abs() > top {
                return Err(Error::Stream(format!(
                    "skinning weight of vertex {v} does not fit in {} bits",
                    w.bits
                )));
            }
            w.values[slot] = value as i32;
        }
    }
    // The range decoder reads a cut-off stream as if zeros followed, so a truncated part (with a
    // forged checksum) would otherwise decode to plausible weights; a trailing word catches that.
    if c.raw_bits(WEIGHTS_END as u64, 32)? != WEIGHTS_END as u64 {
        return Err(Error::Stream(
            "skinning weights: the coded data end early (truncated or damaged)".into(),
        ));
    }
    Ok(())
}

/// Classes of the spread of a weight's already-coded neighbours: none or all 0, all one other
/// value, 1, 2–3, 4–7, 8–15, 16+.
const SPREADS: usize = 7;

fn spread_class(spread: i64, zeros: bool) -> usize {
    match spread {
        0 => usize::from(!zeros),
        _ => (65 - spread.unsigned_abs().leading_zeros() as usize).min(SPREADS - 1),
    }
}

/// [`code_weight_values`] over `partition`'s vertices, their neighbours and first copies on the
/// decoded first frame: what the encoder, the encoder's choice and the decoder each go through.
fn traverse_weights<C: SymbolCoder>(
    c: &mut C,
    w: &mut SkinningWeights,
    partition: &Partition,
    (triangles, reference): (&[Triangle], &[Point]),
    choose: Option<ChooseWeight>,
) -> Result<()> {
    let adj = VertexAdjacency::new(partition.vertex_count(), triangles);
    let coincident = coincident_first(reference);
    let mesh = (&adj, &coincident[..]);
    code_weight_values(c, w, partition.labels(), mesh, choose)
}

/// Coded after the last skinning weight, checked by the decoder.
const WEIGHTS_END: u32 = 0x5EED_C0DE;

/// Codes the quantised skinning weights: bits and limit, then the weights (the neighbour lists are
/// not stored: the decoder derives them from the partition and the connectivity).
pub fn encode_weights(
    weights: &SkinningWeights,
    partition: &Partition,
    (triangles, reference): (&[Triangle], &[Point]),
) -> Result<Vec<u8>> {
    weights.check(partition)?;
    let mut w = ByteWriter::new();
    w.u8(weights.bits).f32(weights.limit);
    let mut enc = Encoder::new();
    let shape = (triangles, reference);
    traverse_weights(&mut enc, &mut weights.clone(), partition, shape, None)?;
    w.raw(&enc.finish()?);
    Ok(w.into_bytes())
}

/// Goes through `weights` in the order [`encode_weights`] codes them, each weight becoming what
/// `choose` picks from the coder's guess and model at that point: an encoder's rate–distortion
/// choice with the coder's own costs.
#[cfg(feature = "encode")]
pub fn choose_weights(
    weights: &mut SkinningWeights,
    partition: &Partition,
    (triangles, reference): (&[Triangle], &[Point]),
    choose: ChooseWeight,
) -> Result<()> {
    weights.check(partition)?;
    let mut dry = Encoder::new();
    traverse_weights(&mut dry, weights, partition, (triangles, reference), Some(choose))
}

/// Decodes the skinning weights of `partition` on the decoded first frame.
pub fn decode_weights(
    bytes: &[u8],
    partition: &Partition,
    (triangles, reference): (&[Triangle], &[Point]),
) -> Result<SkinningWeights> {
    let mut r = ByteReader::new(bytes, "skinning weights");
    let bits = r.u8()?;
    let limit = r.f32()?;
    let neighbours = cluster_neighbours(partition, triangles);
    let count = SkinningWeights::expected_count(&neighbours, partition.labels())
        .ok_or_else(|| Error::Stream("skinning weights: partition out of range".into()))?;
    let rest = r.take(r.remaining())?;
    entropy::check_capacity(count as u64, rest.len(), "skinning weights")?;
    let mut weights = SkinningWeights {
        bits,
        limit,
        neighbours,
        values: vec![0; count],
    };
    // Bits and limit first: the coder's range check depends on them.
    weights.check(partition)?;
    let mut dec = Decoder::new(rest)?;
    traverse_weights(&mut dec, &mut weights, partition, (triangles, reference), None)?;
    weights.check(partition)?;
    Ok(weights)
}
