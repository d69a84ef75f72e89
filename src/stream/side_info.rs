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

/// How far `guess` is the neighbours' verdict: how many labels the coded neighbours carry (0, 1, 2,
/// 3 or more) and whether the guess is all of them, most of them or fewer; a vertex among
/// neighbours of one label almost always shares it, one on a border often does not.
fn agreement(counts: &[(u32, u32)], guess: u32) -> (usize, usize) {
    let total: u32 = counts.iter().map(|&(_, n)| n).sum();
    let votes = counts.iter().find(|&&(l, _)| l == guess).map_or(0, |&(_, n)| n);
    let share = match votes {
        n if n > 0 && n == total => 2,
        n if 2 * n > total => 1,
        _ => 0,
    };
    (counts.len().min(3), share)
}

/// Other labels a missed guess is tried against: the neighbours' other labels, commonest first
/// (lowest on ties), at most [`MISS_CANDIDATES`].
const MISS_CANDIDATES: usize = 4;

/// The adaptive models of the partition part.
struct PartitionModels {
    /// Whether the guess is right, by kind of guess and [`agreement`].
    hit: [[[BitModel; 3]; 4]; 3],
    /// Which of n candidates a missed label is, or n for none (`candidate[n - 1]`).
    candidate: Vec<SymbolModel>,
    /// A label that is no candidate: up to 256 clusters a symbol, more an integer.
    small: SymbolModel,
    large: UIntModel,
}

/// Codes a label that is not `guess` (the encoder's `label`) as one of `candidates` or, failing
/// that, in full; the decoder refuses a full label that a shorter code would have named.
fn code_missed_label<C: SymbolCoder>(
    c: &mut C,
    (label, guess, v): (u32, u32, usize),
    candidates: &[u32],
    clusters: usize,
    models: &mut PartitionModels,
) -> Result<u32> {
    if let Some(model) = candidates.len().checked_sub(1).map(|n| &mut models.candidate[n]) {
        let k = candidates.iter().position(|&l| l == label);
        let k = c.symbol(k.unwrap_or(candidates.len()), model)?;
        if let Some(&l) = candidates.get(k) {
            return Ok(l);
        }
    }
    let l = if clusters <= 256 {
        c.symbol(label as usize, &mut models.small)? as u64
    } else {
        c.unsigned(u64::from(label), &mut models.large)?
    };
    let named = l == u64::from(guess) || candidates.iter().any(|&x| u64::from(x) == l);
    if l >= clusters as u64 || named {
        return Err(Error::Stream(format!(
            "partition: vertex {v} has an impossible label"
        )));
    }
    Ok(l as u32)
}

/// Labels are guessed, in this order of trust, from the vertex's first copy at its first-frame
/// position (a seam or hard-edge copy moves with it), its already-coded neighbours' commonest
/// label, or the previous vertex's; one hit bit per vertex, a context per kind of guess and
/// [`agreement`] (container version 13). A miss names one of the neighbours' other labels, or
/// the label in full.
fn code_partition<C: SymbolCoder>(
    c: &mut C,
    labels: &mut [u32],
    clusters: usize,
    (adj, coincident): (&VertexAdjacency, &[Option<u32>]),
) -> Result<()> {
    let mut models = PartitionModels {
        hit: Default::default(),
        candidate: (1..=MISS_CANDIDATES).map(|n| SymbolModel::new(n + 1)).collect(),
        small: SymbolModel::new(clusters),
        large: UIntModel::default(),
    };
    let (mut counts, mut candidates) = (Vec::new(), Vec::with_capacity(MISS_CANDIDATES));
    for v in 0..labels.len() {
        let copy_of = coincident.get(v).copied().flatten();
        let (kind, guess) = match (copy_of, predicted_label(adj, labels, v, &mut counts)) {
            (Some(f), _) => (2, labels[f as usize]),
            (None, Some(l)) => (0, l),
            (None, None) => (1, if v > 0 { labels[v - 1] } else { 0 }),
        };
        let (distinct, share) = agreement(&counts, guess);
        if c.bit(labels[v] == guess, &mut models.hit[kind][distinct][share])? {
            labels[v] = guess;
            continue;
        }
        counts.sort_by_key(|&(l, n)| (std::cmp::Reverse(n), l));
        candidates.clear();
        let others = counts.iter().map(|&(l, _)| l).filter(|&l| l != guess);
        candidates.extend(others.take(MISS_CANDIDATES));
        let missed = (labels[v], guess, v);
        labels[v] = code_missed_label(c, missed, &candidates, clusters, &mut models)?;
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A grid of quads cut into triangles, with flat positions (no two coincide).
    fn grid(n: u32) -> (Vec<Triangle>, Vec<Point>) {
        let (triangles, pixels) =
            crate::stream::lattice_coding::tests::quads((n, n), |x, y| [x as u16, y as u16]);
        let points = pixels.iter().map(|p| [p[0] as f32, p[1] as f32, 0.0]);
        (triangles, points.collect())
    }

    /// Labels in three regions meeting at ragged borders, a few lone vertices of a fourth and of
    /// labels no neighbour has: every path of the coder (hits, candidates, full labels) comes back,
    /// and a cut part is an error, never a panic.
    #[test]
    fn partition_labels_round_trip_through_candidates_and_full_labels() {
        let n = 24;
        let (triangles, points) = grid(n);
        let labels: Vec<u32> = (0..n * n)
            .map(|i| {
                let (x, y) = (i % n, i / n);
                match (x * 7 + y * 3) % 37 {
                    0 => 3,
                    1 => 4 + i % 5,
                    _ if x + (y * y) % 5 < 10 => 0,
                    _ if y < 12 => 1,
                    _ => 2,
                }
            })
            .collect();
        let bytes = encode_partition(&labels, 9, (&triangles, &points)).unwrap();
        let back = decode_partition(&bytes, labels.len(), 9, (&triangles, &points)).unwrap();
        assert_eq!(back, labels);
        for cut in [0, 4, bytes.len() / 2] {
            let _ = decode_partition(&bytes[..cut], labels.len(), 9, (&triangles, &points));
        }
    }
}
