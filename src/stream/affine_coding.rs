//! Entropy coding of the affine track: each of a cluster's 12 stored coefficients (see
//! [`crate::motion::AffineTrack`]) is a trajectory of integer levels over the frames, coded as the
//! residual of a temporal predictor.
//!
//! Each cluster starts with its [`LinearForm`] (entries, or rotation and stretch), one adaptive
//! symbol. Per trajectory the encoder picks a choice (`motion/trajectory.rs`), one adaptive
//! symbol: the predictor order that codes smallest (1: the previous level, 2: linear
//! extrapolation, 3: quadratic), and whether the prediction adds the *innovation* of the same
//! coefficient of a reference cluster, scaled to this cluster's step (container version 8), or,
//! for a translation, the innovation of the reference's whole map at this cluster's centroid
//! (version 11: the reference's turn times the lever between the centroids, which a chain of limbs
//! shares as their translations do not). The reference is one of the `REFERENCES` (4) nearest
//! earlier-coded clusters (by centroid on the decoded frame 0; for the linear part, of the same
//! form), named by its rank, nearest first, in a second adaptive symbol; its innovation is its
//! level less its extrapolation at the *following trajectory's* order, so that the difference of
//! the two is what that order extrapolates (container version 14; before, the nearest alone, at
//! its own order). The first frame is
//! predicted by the identity map (frame 0 is fitted from the decoded frame 0 itself). Residuals go
//! through adaptive integer models chosen by the coefficient's kind (entry, rotation, stretch or
//! translation) and the size of the trajectory's previous residual, which tracks how busy the
//! motion is.
//!
//! The extrapolation codes smaller than a temporal DCT of each trajectory
//! (docs/design.md, "Affine precision per codec"); the levels are uniform scalar quantisation of
//! each frame's map, so every decoded coefficient is within half its step of the fitted one.

use crate::error::{Error, Result};
use crate::mesh::Point;
use crate::motion::trajectory::{
    best_choice, extrapolate, innovation, scaled, Choice, Follow, Way, CHOICES, LINEAR_CHOICES,
    ORDERS, REFERENCES,
};
use crate::motion::{
    identity_levels, AffineTrack, ClusterGeometry, LinearForm, Partition, QuantisedAffine,
    MAX_AFFINE_LEVEL,
};
use crate::stream::bytes::{ByteReader, ByteWriter};
use crate::stream::entropy::{self, Decoder, Encoder, IntModel, SymbolCoder, SymbolModel};

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

/// What a stored coefficient is (see [`ClusterGeometry::steps`]): each kind has its own models,
/// since a turning part's rotation moves while its stretch barely does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Entry = 0,
    Rotation = 1,
    Stretch = 2,
    Translation = 3,
}

const KINDS: usize = 4;

impl Kind {
    /// The kind of stored coefficient `coeff` (0..12) of a cluster in `form`.
    fn of(coeff: usize, form: LinearForm) -> Self {
        match (coeff, form) {
            (3 | 7 | 11, _) => Kind::Translation,
            (_, LinearForm::Entries) => Kind::Entry,
            (0..=2, LinearForm::RotationStretch) => Kind::Rotation,
            (_, LinearForm::RotationStretch) => Kind::Stretch,
        }
    }
}

/// The adaptive models of the traversal: the clusters' forms, and per coefficient [`Kind`].
struct Models {
    form: SymbolModel,
    choice: [SymbolModel; KINDS],
    /// A following trajectory's reference, by its rank among the nearest.
    reference: [SymbolModel; KINDS],
    first: [IntModel; KINDS],
    residual: [[IntModel; MAGNITUDES]; KINDS],
}

impl Models {
    fn new() -> Self {
        Self {
            form: SymbolModel::new(LinearForm::ALL.len()),
            // Only a translation may follow its reference's whole map.
            choice: std::array::from_fn(|kind| {
                SymbolModel::new(if kind == Kind::Translation as usize {
                    CHOICES
                } else {
                    LINEAR_CHOICES
                })
            }),
            reference: std::array::from_fn(|_| SymbolModel::new(REFERENCES)),
            first: Default::default(),
            residual: Default::default(),
        }
    }
}

/// Earlier clusters searched for a reference: a window, so that the search stays linear in the
/// clusters (a forged or a huge partition must not cost their square); the nearest of any
/// cluster's 256 predecessors is nearly always near enough.
const REFERENCE_WINDOW: usize = 256;

/// An earlier cluster a trajectory may follow, with the steps of its coefficients.
struct Reference {
    cluster: usize,
    steps: [f64; 12],
}

/// Each cluster's reference clusters, by the decoded frame 0's centroids, nearest first (at
/// most [`REFERENCES`]): for its translations, among the earlier clusters (the last
/// [`REFERENCE_WINDOW`]); for its linear part, among those of the same form (their numbers mean
/// the same only then). Ties go to the lower number.
struct References {
    translation: Vec<Reference>,
    linear: Vec<Reference>,
}

impl References {
    /// Cluster `k`'s, given the forms of clusters `0..=k` and the base step.
    fn of(geometry: &ClusterGeometry, k: usize, forms: &[LinearForm], step: f64) -> Self {
        let here = geometry.centroid(k);
        // A NaN (non-finite centroids of a forged first frame) sorts last whatever its sign bit,
        // which differs between machines.
        let distance = |j: usize| {
            let c = geometry.centroid(j);
            let d = (0..3).map(|a| (c[a] - here[a]) * (c[a] - here[a])).sum::<f64>();
            if d.is_nan() {
                f64::INFINITY
            } else {
                d
            }
        };
        let mut earlier: Vec<(f64, usize)> = (k.saturating_sub(REFERENCE_WINDOW)..k)
            .map(|j| (distance(j), j))
            .collect();
        earlier.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let reference = |j: usize| Reference {
            cluster: j,
            steps: geometry.steps(j, step, forms[j]),
        };
        let translation = earlier.iter().take(REFERENCES).map(|&(_, j)| reference(j));
        let same_form = earlier.iter().filter(|&&(_, j)| forms.get(j) == forms.get(k));
        let linear = same_form.take(REFERENCES).map(|&(_, j)| reference(j));
        Self {
            translation: translation.collect(),
            linear: linear.collect(),
        }
    }

    /// The references of stored coefficient `coeff` of a cluster in `form` whose steps are `own`,
    /// nearest first, each with the ratio of its step to the cluster's own (what its innovation
    /// is scaled by).
    fn for_coeff(&self, coeff: usize, form: LinearForm, own: &[f64; 12]) -> Vec<(usize, f64)> {
        let found = match Kind::of(coeff, form) {
            Kind::Translation => &self.translation,
            _ => &self.linear,
        };
        let of = |r: &Reference| (r.cluster, r.steps[coeff] / own[coeff]);
        found.iter().map(of).collect()
    }
}

/// Codes the levels cluster by cluster (its [`LinearForm`] first), coefficient by coefficient,
/// each trajectory over all frames; `choices[k * 12 + c]` is trajectory (k, c)'s [`Choice`] and
/// `q.forms[k]` cluster k's form (both filled when decoding). With `q.values` empty, a
/// decoder reads every level and keeps none: a dry run that checks the part (its end word
/// included) in constant memory before its levels are given room.
fn code_trajectories<C: SymbolCoder>(
    c: &mut C,
    q: &mut QuantisedAffine,
    choices: &mut [Choice],
    geometry: &ClusterGeometry,
) -> Result<()> {
    let mut models = Models::new();
    let (frames, clusters) = (q.frames, q.clusters);
    if geometry.centroids.len() != clusters
        || q.forms.len() != clusters
        || choices.len() != clusters * 12
    {
        return Err(Error::Stream(format!(
            "affine coefficients: {clusters} clusters, the partition has {}",
            geometry.centroids.len()
        )));
    }
    let step = f64::from(q.step);
    for k in 0..clusters {
        let form = LinearForm::ALL[c.symbol(q.forms[k] as usize, &mut models.form)?];
        q.forms[k] = form;
        let steps = geometry.steps(k, step, form);
        let identity = identity_levels(geometry.centroid(k), &steps, form);
        let references = References::of(geometry, k, &q.forms, step);
        for (coeff, &first) in identity.iter().enumerate() {
            let trajectory = Trajectory {
                cluster: k,
                coeff,
                first,
                kind: Kind::of(coeff, form),
                references: references.for_coeff(coeff, form, &steps),
            };
            code_trajectory(c, q, choices, &trajectory, geometry, &mut models)?;
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

/// One coefficient's trajectory: where it is, its identity level (frame 0's prediction), and the
/// clusters it may follow, nearest first, each with the ratio of its step to this one's.
struct Trajectory {
    cluster: usize,
    coeff: usize,
    first: i64,
    kind: Kind,
    references: Vec<(usize, f64)>,
}

/// Trajectory (`cluster`, `coeff`)'s innovation at frame `f` under `order`, from its levels in
/// `q` (0 at the first frame): what the coder adds to a follower's prediction, and what the
/// encoder's choice weighs.
fn level_innovation(q: &QuantisedAffine, cluster: usize, coeff: usize, order: usize, f: usize) -> i64 {
    let at = |g: usize| {
        q.values
            .get((g * q.clusters + cluster) * 12 + coeff)
            .copied()
            .unwrap_or(0)
    };
    let from = f.saturating_sub(ORDERS);
    let mut before = [0i64; ORDERS];
    for (slot, g) in before.iter_mut().zip(from..f) {
        *slot = at(g);
    }
    innovation(order, &before[..f - from], at(f))
}

/// What [`Follow::Map`] adds to translation `coeff` of cluster `k` at frame `f`: the innovation
/// under `order` of reference `j`'s whole map at `k`'s centroid, in levels of the base step (which
/// every translation shares): `j`'s translation innovation plus its linear part's, dequantised,
/// applied to the lever from `j`'s centroid to `k`'s, rounded. Dequantising and extrapolating take
/// + − × / alone (IEEE-exact), so encoder and decoder agree to the bit.
fn map_innovation(
    q: &QuantisedAffine,
    geometry: &ClusterGeometry,
    (k, j): (usize, usize),
    coeff: usize,
    order: usize,
    f: usize,
) -> i64 {
    let translation = level_innovation(q, j, coeff, order, f);
    let Some(&form) = q.forms.get(j) else {
        return translation;
    };
    let step = f64::from(q.step);
    let steps = geometry.steps(j, step, form);
    let row = coeff / 4;
    // Row `row` of j's linear part at frame g.
    let linear = |g: usize| -> [f64; 3] {
        let x: [f64; 9] = std::array::from_fn(|i| {
            let c = 4 * (i / 3) + i % 3;
            let level = q.values.get((g * q.clusters + j) * 12 + c).copied();
            level.unwrap_or(0) as f64 * steps[c]
        });
        form.linear(&x)[row]
    };
    // As `extrapolate` over the last ORDERS frames: the order falls with a shorter past.
    let guess: [f64; 3] = match order.min(f.min(ORDERS)) {
        0 => return translation,
        1 => linear(f - 1),
        2 => {
            let (a, b) = (linear(f - 1), linear(f - 2));
            std::array::from_fn(|c| 2.0 * a[c] - b[c])
        }
        _ => {
            let (a, b, d) = (linear(f - 1), linear(f - 2), linear(f - 3));
            std::array::from_fn(|c| 3.0 * a[c] - 3.0 * b[c] + d[c])
        }
    };
    let now = linear(f);
    let (to, from) = (geometry.centroid(k), geometry.centroid(j));
    let moved: f64 = (0..3).map(|c| (now[c] - guess[c]) * (to[c] - from[c])).sum();
    // Saturating (and 0 for a NaN) like every level conversion.
    translation.saturating_add((moved / step).round() as i64)
}

/// What following reference `j` the way `follows` adds to trajectory (`k`, `coeff`) at frame `f`,
/// `j`'s trajectory extrapolated by `order` (the follower's own) and its steps `ratio` times this
/// one's: the one definition the encoder's choice and the coder share.
fn lift(
    q: &QuantisedAffine,
    geometry: &ClusterGeometry,
    follows: Follow,
    (k, j): (usize, usize),
    coeff: usize,
    (order, ratio): (usize, f64),
    f: usize,
) -> i64 {
    match follows {
        Follow::No => 0,
        Follow::Coefficient => scaled(level_innovation(q, j, coeff, order, f), ratio),
        Follow::Map => map_innovation(q, geometry, (k, j), coeff, order, f),
    }
}

/// Codes `t`'s choice (`choices[cluster * 12 + coeff]`: order and way, then, when it follows
/// and has more than one reference, the reference's rank), then its level at every frame as the
/// residual of the prediction. With the levels kept (`q.values` not empty) a trajectory that
/// follows its reference adds the reference's innovation, recomputed from the reference's levels
/// at this trajectory's order; a dry run reads the same symbols.
fn code_trajectory<C: SymbolCoder>(
    c: &mut C,
    q: &mut QuantisedAffine,
    choices: &mut [Choice],
    t: &Trajectory,
    geometry: &ClusterGeometry,
    models: &mut Models,
) -> Result<()> {
    let (frames, clusters, kind) = (q.frames, q.clusters, t.kind as usize);
    let slot = t.cluster * 12 + t.coeff;
    let coded = c.symbol(choices[slot].symbol(), &mut models.choice[kind])?;
    let mut choice = Choice::of_symbol(coded);
    if choice.follows != Follow::No && t.references.len() > 1 {
        choice.reference = c.symbol(choices[slot].reference, &mut models.reference[kind])?;
    }
    choices[slot] = choice;
    let reference = match (choice.follows, t.references.get(choice.reference)) {
        (Follow::No, _) => None,
        (Follow::Map, _) if t.kind != Kind::Translation => {
            return Err(Error::Stream(format!(
                "affine coefficients: cluster {}, coefficient {} follows a map, which only a \
                 translation may",
                t.cluster, t.coeff
            )))
        }
        (follows, Some(&(j, ratio))) => Some((j, ratio, follows)),
        (_, None) => {
            return Err(Error::Stream(format!(
                "affine coefficients: cluster {}, coefficient {} follows reference {} of the {} it \
                 has",
                t.cluster,
                t.coeff,
                choice.reference,
                t.references.len()
            )))
        }
    };
    let keep = !q.values.is_empty();
    // The last ORDERS levels, oldest first: all that `extrapolate` looks back at.
    let mut history = [0i64; ORDERS];
    let mut class = 0;
    for f in 0..frames {
        let i = (f * clusters + t.cluster) * 12 + t.coeff;
        let (own, model) = match f {
            0 => (t.first, &mut models.first[kind]),
            _ => (
                extrapolate(choice.order, &history[ORDERS - f.min(ORDERS)..]),
                &mut models.residual[kind][class],
            ),
        };
        let lift = match reference {
            Some((j, ratio, follows)) if f > 0 && keep => lift(
                q,
                geometry,
                follows,
                (t.cluster, j),
                t.coeff,
                (choice.order, ratio),
                f,
            ),
            _ => 0,
        };
        let guess = own.saturating_add(lift);
        let target = q.values.get(i).copied().unwrap_or(guess);
        let r = c.signed(target.wrapping_sub(guess), model)?;
        let value = guess.checked_add(r).filter(|v| v.abs() <= MAX_AFFINE_LEVEL);
        let value = match (value, keep) {
            (Some(v), _) => v,
            // A dry run does not know the references' innovations, so its levels are not the
            // real ones: only the real read checks their range.
            (None, false) => 0,
            (None, true) => {
                return Err(Error::Stream(format!(
                    "affine coefficients: level of cluster {}, coefficient {}, frame {f} is \
                     beyond ±2^40",
                    t.cluster, t.coeff
                )))
            }
        };
        if let Some(slot) = q.values.get_mut(i) {
            *slot = value;
        }
        history.rotate_left(1);
        history[ORDERS - 1] = value;
        class = magnitude_class(r);
    }
    Ok(())
}

/// Each trajectory's [`Choice`] by the estimate: its own extrapolation, or following one of its
/// references in one of the ways its kind may, at each order.
fn choose(q: &QuantisedAffine, geometry: &ClusterGeometry) -> Vec<Choice> {
    let (frames, clusters) = (q.frames, q.clusters);
    let step = f64::from(q.step);
    let mut choices = vec![Choice::FIRST; clusters * 12];
    for k in 0..clusters {
        let steps = geometry.steps(k, step, q.forms[k]);
        let references = References::of(geometry, k, &q.forms, step);
        for coeff in 0..12 {
            let levels: Vec<i64> = (0..frames)
                .map(|f| q.values[(f * clusters + k) * 12 + coeff])
                .collect();
            let allowed: &[Follow] = if Kind::of(coeff, q.forms[k]) == Kind::Translation {
                &[Follow::Coefficient, Follow::Map]
            } else {
                &[Follow::Coefficient]
            };
            let mut ways = Vec::new();
            let found = references.for_coeff(coeff, q.forms[k], &steps);
            for (reference, &(j, ratio)) in found.iter().enumerate() {
                for &follows in allowed {
                    for order in 1..=ORDERS {
                        let at = |f| lift(q, geometry, follows, (k, j), coeff, (order, ratio), f);
                        let lift = (0..frames).map(at).collect();
                        ways.push(Way { follows, reference, order, lift });
                    }
                }
            }
            choices[k * 12 + coeff] = best_choice(&levels, &ways).0;
        }
    }
    choices
}

/// Codes the affine track: its base step, then the level trajectories.
pub fn encode_affine(track: &AffineTrack) -> Result<Vec<u8>> {
    let mut q = track.quantised().clone();
    let mut choices = choose(&q, track.geometry());
    let mut w = ByteWriter::new();
    w.f32(q.step);
    let mut enc = Encoder::new();
    code_trajectories(&mut enc, &mut q, &mut choices, track.geometry())?;
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
        entropy::check_capacity(count, coded.len(), "affine coefficients")?;
        // The step sets the identity's levels below: refuse a forged one first.
        QuantisedAffine::check_step(step)?;
        let geometry = ClusterGeometry::of(reference, partition);
        let q = QuantisedAffine {
            step,
            frames,
            clusters,
            forms: vec![LinearForm::Entries; clusters],
            values: Vec::new(),
        };
        Ok(Self {
            q,
            geometry,
            coded,
        })
    }

    /// Reads every level and the end word, keeping the levels where `q.values` has room.
    fn read(&mut self) -> Result<()> {
        let mut choices = vec![Choice::FIRST; self.q.clusters * 12];
        let mut dec = Decoder::new(self.coded)?;
        code_trajectories(&mut dec, &mut self.q, &mut choices, &self.geometry)
    }
}
