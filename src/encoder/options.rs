//! Everything a caller can choose about an encoding, its defaults, and the checks that refuse
//! nonsense before any work starts (each error names the option's field). The options every codec
//! shares are fields here; a codec's own are in its [`CodecConfig`].

use crate::codec::{CodecConfig, Rate, RatePlan};
use crate::error::{Error, Result};
use crate::mesh::AnimatedMesh;
use crate::motion::{self, PredictorKind};

/// Bits per coordinate of the first frame unless the caller or the codec's trials pick others.
pub const DEFAULT_FIRST_FRAME_BITS: u8 = 12;

/// The first-frame bits the encoder tries when the caller leaves them open and the codec's trials
/// are cheap, the default first (it wins ties): a coarser first frame moves bits from the
/// first-frame coder into the residuals' lowest band, and which side codes them cheaper depends on
/// the mesh and the step (docs/design.md, "First-frame bits trials and k-means ladder").
pub const FIRST_FRAME_BITS_TRIED: [u8; 3] = [DEFAULT_FIRST_FRAME_BITS, 10, 8];

/// Segments coded at once unless asked otherwise ([`EncodeOptions::parallel_segments`]).
pub const DEFAULT_PARALLEL_SEGMENTS: usize = 2;

/// Default `quality`: the middle of the useful range, a target step of 1/1000 of the first frame's
/// bounding-box diagonal.
pub const DEFAULT_QUALITY: u8 = 50;

/// Frames per temporal segment unless asked otherwise: the shortest length that costs at most 2 %
/// more bits at equal error than one segment on every media sequence longer than it
/// (docs/design.md, "Temporal segments: 128 frames").
pub const DEFAULT_SEGMENT_FRAMES: usize = 128;

/// Everything the caller can choose about an encoding.
#[derive(Debug, Clone)]
pub struct EncodeOptions {
    /// The residual codec and its own options.
    pub codec: CodecConfig,
    /// Rate knob 1..100 (higher = better).
    pub quality: u8,
    /// A quality between the integers, 1.0..=100.0, as a budget search finds it
    /// ([`super::encode_to_budget`]): every codec's law is read at it instead of at `quality`,
    /// and the stream header records it rounded. `None` (the default) reads `quality`.
    pub fine_quality: Option<f64>,
    /// Quantiser step (tdct) or pixel step (one grey level, picture codecs) as a fraction of the
    /// first frame's bounding-box diagonal; `None` derives it from `quality`.
    pub step: Option<f64>,
    /// The affine coefficients' quantiser step as a multiple `k` of the residual step Δ (the
    /// translation's step is `k·Δ`, the linear part's `k·Δ / r̄` with `r̄` the cluster's RMS radius);
    /// stored in sixteenths, 1/16..=255/16. `None` takes the codec's measured best.
    pub affine_precision: Option<f64>,
    /// Motion clusters K (k-means only; decimation finds its own).
    pub clusters: usize,
    /// How the vertices are split into motion clusters, or `Auto` (the default): the encoder tries
    /// k-means and decimation and keeps the smaller stream.
    pub segmentation: SegmentationChoice,
    /// The motion predictor, or `Auto` (the default): the encoder tries each and keeps the smaller
    /// stream.
    pub predictor: PredictorChoice,
    /// Bits per skinning weight, sign included (the paper's 16 by default).
    pub weight_bits: u8,
    /// Bits per coordinate of the first frame (1..=24); `None` lets the encoder choose: the
    /// default, or with a codec of cheap trials (tdct) each of [`FIRST_FRAME_BITS_TRIED`],
    /// keeping the smallest stream.
    pub first_frame_bits: Option<u8>,
    /// Let the first-frame coder permute vertices.
    pub reorder: bool,
    /// Bits per texture coordinate over each set's bounding box (1..=24; inputs with UVs only).
    pub uv_bits: u8,
    /// Frames per temporal segment: a longer clip is coded as segments of this many frames, each
    /// with its own temporal DCT or groups of pictures ([`super::SegmentedEncoder`]); `None` codes any
    /// clip as one.
    pub segment_frames: Option<usize>,
    /// Segments coded at once (on rayon's threads): memory holds this many segments' working
    /// data, so the default, [`DEFAULT_PARALLEL_SEGMENTS`], keeps an encoding of any length
    /// within two segments' while a 2-core machine codes them side by side.
    pub parallel_segments: usize,
}

impl Default for EncodeOptions {
    fn default() -> Self {
        Self {
            codec: CodecConfig::default(),
            quality: DEFAULT_QUALITY,
            fine_quality: None,
            step: None,
            affine_precision: None,
            clusters: 20,
            segmentation: SegmentationChoice::auto(),
            predictor: PredictorChoice::Auto,
            weight_bits: motion::WEIGHT_BITS,
            first_frame_bits: None,
            reorder: false,
            uv_bits: 12,
            segment_frames: Some(DEFAULT_SEGMENT_FRAMES),
            parallel_segments: DEFAULT_PARALLEL_SEGMENTS,
        }
    }
}

/// The motion segmentation of an encoding.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Segmentation {
    /// k-means on per-vertex affine motion with border refinement, K = `EncodeOptions::clusters` (MCGV §3.1).
    KMeans,
    /// Half-edge collapses by affine-motion cost until the RMS fit error reaches `e0` of the
    /// bounding-box diagonal (skinning paper §3.1); K falls out of it.
    Decimation {
        /// The error threshold E0 (the paper's 0.003).
        e0: f64,
    },
}

impl Segmentation {
    /// The name used in reports.
    pub fn name(&self) -> &'static str {
        match self {
            Segmentation::KMeans => "kmeans",
            Segmentation::Decimation { .. } => "decimation",
        }
    }
}

/// The motion predictor of an encoding: fixed by the caller, or chosen by the encoder.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PredictorChoice {
    /// This predictor.
    Fixed(PredictorKind),
    /// Each predictor is tried at the encoding's step; the smallest stream is kept.
    Auto,
}

impl PredictorChoice {
    /// The predictors the encoder tries, the default first (it wins ties).
    pub fn candidates(self) -> Vec<PredictorKind> {
        match self {
            PredictorChoice::Fixed(kind) => vec![kind],
            PredictorChoice::Auto => vec![PredictorKind::Affine, PredictorKind::Skinning],
        }
    }
}

impl From<PredictorKind> for PredictorChoice {
    fn from(kind: PredictorKind) -> Self {
        PredictorChoice::Fixed(kind)
    }
}

/// The motion segmentation of an encoding: fixed by the caller, or chosen by the encoder.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SegmentationChoice {
    /// This segmentation.
    Fixed(Segmentation),
    /// k-means (K = `EncodeOptions::clusters` and the larger K of `kmeans_ladder`) and
    /// decimation down to `e0` are tried at the encoding's step; the smallest stream at equal
    /// error is kept.
    Auto {
        /// Decimation's error threshold E0.
        e0: f64,
    },
}

impl SegmentationChoice {
    /// `Auto` with decimation's default threshold (the paper's E0).
    pub fn auto() -> Self {
        SegmentationChoice::Auto {
            e0: motion::DEFAULT_E0,
        }
    }

    /// The segmentations the encoder tries, the default (k-means) first: it wins ties.
    pub fn candidates(self) -> Vec<Segmentation> {
        match self {
            SegmentationChoice::Fixed(segmentation) => vec![segmentation],
            SegmentationChoice::Auto { e0 } => {
                vec![Segmentation::KMeans, Segmentation::Decimation { e0 }]
            }
        }
    }

    /// Decimation's threshold, when decimation may run.
    fn e0(self) -> Option<f64> {
        match self {
            SegmentationChoice::Fixed(Segmentation::Decimation { e0 })
            | SegmentationChoice::Auto { e0 } => Some(e0),
            SegmentationChoice::Fixed(Segmentation::KMeans) => None,
        }
    }
}

impl From<Segmentation> for SegmentationChoice {
    fn from(segmentation: Segmentation) -> Self {
        SegmentationChoice::Fixed(segmentation)
    }
}

/// One predictor and one segmentation: what a stream is coded with (one candidate of an
/// automatic choice).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionModel {
    /// The predictor.
    pub predictor: PredictorKind,
    /// The segmentation.
    pub segmentation: Segmentation,
    /// k-means's K (decimation finds its own; there it is `EncodeOptions::clusters`, unused).
    pub clusters: usize,
}

/// The k-means cluster counts an automatic segmentation tries, from the caller's `k`: k, 1.5 k
/// and 2 k (a rung only when the one below paid: `encoder/ladder.rs`; a picture codec tries the
/// one tdct's estimates rank first: `encoder/auto/rungs.rs`). More clusters fit the motion more closely for more side
/// information; which wins depends on the animation and the step
/// (docs/design.md, "First-frame bits trials and k-means ladder").
pub fn kmeans_ladder(k: usize) -> Vec<usize> {
    let mut ladder = vec![k, k + k.div_ceil(2), 2 * k];
    ladder.dedup();
    ladder
}

impl MotionModel {
    /// `predictor+segmentation`, as reports name it.
    pub fn name(&self) -> String {
        format!("{}+{}", self.predictor.name(), self.segmentation.name())
    }
}

impl EncodeOptions {
    /// The motion models the encoder tries: one unless a choice is `Auto`; segmentation by
    /// segmentation (each partition serves every predictor), the defaults first.
    pub fn motion_models(&self) -> Vec<MotionModel> {
        let predictors = self.predictor.candidates();
        let ladder = match self.segmentation {
            SegmentationChoice::Auto { .. } => kmeans_ladder(self.clusters),
            _ => vec![self.clusters],
        };
        let partitions = self.segmentation.candidates().into_iter().flat_map(|s| {
            let ks = match s {
                Segmentation::KMeans => ladder.clone(),
                Segmentation::Decimation { .. } => vec![self.clusters],
            };
            ks.into_iter().map(move |k| (s, k))
        });
        partitions
            .flat_map(|(segmentation, clusters)| {
                predictors.iter().map(move |&predictor| MotionModel {
                    predictor,
                    segmentation,
                    clusters,
                })
            })
            .collect()
    }

    /// Fails, naming the field, when an option is out of range: what [`EncodeOptions::check`]
    /// checks without the animation, so that a caller can refuse nonsense before any work.
    pub fn validate(&self) -> Result<()> {
        self.check_ranges()?;
        self.check_step()?;
        self.codec.check()?;
        let codec = self.codec.codec();
        if !codec.available() {
            return Err(Error::option(
                "codec",
                format!("{}: this build has no such codec", codec.name()),
            ));
        }
        Ok(())
    }

    /// Fails, naming the field, when an option is out of range or does not fit `mesh`.
    pub fn check(&self, mesh: &AnimatedMesh) -> Result<()> {
        self.validate()?;
        if mesh.triangles().is_empty() {
            return Err(Error::Mesh(
                "the mesh has no triangles: nothing to parameterize".into(),
            ));
        }
        Ok(())
    }

    fn check_ranges(&self) -> Result<()> {
        if !(1..=100).contains(&self.quality) {
            return Err(Error::option(
                "quality",
                format!("must be between 1 and 100, not {}", self.quality),
            ));
        }
        if self.segment_frames == Some(0) {
            return Err(Error::option("segment_frames", "must be at least 1"));
        }
        if self.parallel_segments == 0 {
            return Err(Error::option("parallel_segments", "must be at least 1"));
        }
        if self.clusters == 0 {
            return Err(Error::option("clusters", "must be at least 1"));
        }
        if let Some(e0) = self.segmentation.e0() {
            if !(e0.is_finite() && e0 > 0.0) {
                return Err(Error::option(
                    "e0",
                    format!("must be a positive fraction of the bounding-box diagonal, not {e0}"),
                ));
            }
        }
        if let Some(k) = self.affine_precision {
            if !(1.0 / 16.0..=255.0 / 16.0).contains(&k) {
                return Err(Error::option(
                    "affine_precision",
                    format!(
                        "must be between 1/16 and 255/16 (a multiple of the residual step), not {k}"
                    ),
                ));
            }
        }
        if let Some(bits) = self.first_frame_bits.filter(|b| !(1..=24).contains(b)) {
            return Err(Error::option(
                "first_frame_bits",
                format!("must be between 1 and 24 bits per coordinate, not {bits}"),
            ));
        }
        if !(2..=31).contains(&self.weight_bits) {
            return Err(Error::option("weight_bits", "must be between 2 and 31"));
        }
        if !(1..=24).contains(&self.uv_bits) {
            return Err(Error::option("uv_bits", "must be between 1 and 24"));
        }
        Ok(())
    }

    /// The first frame's bits per coordinate of one encoding: the caller's, else the default.
    pub fn first_frame_bits_or_default(&self) -> u8 {
        self.first_frame_bits.unwrap_or(DEFAULT_FIRST_FRAME_BITS)
    }

    /// The rate plan of an encoding whose first frame's bounding-box diagonal is `diagonal`:
    /// every step and setting, by the codec's law ([`RatePlan`]).
    pub fn plan(&self, diagonal: f64) -> Result<RatePlan> {
        let rate = Rate {
            quality: self.quality,
            fine_quality: self.fine_quality,
            step: self.step,
            affine_precision: self.affine_precision,
        };
        self.codec.plan(&rate, diagonal)
    }

    fn check_step(&self) -> Result<()> {
        if let Some(q) = self.fine_quality {
            if !(1.0..=100.0).contains(&q) {
                return Err(Error::option(
                    "fine_quality",
                    format!("{q}: expected a quality between 1 and 100"),
                ));
            }
        }
        if let Some(step) = self.step {
            if !(step.is_finite() && step > 0.0 && step <= 1.0) {
                return Err(Error::option(
                    "step",
                    format!("{step}: expected a fraction of the bounding-box diagonal in (0, 1]"),
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quality_outside_1_to_100_is_refused_by_its_name() {
        // A triangle is all `check` needs of the mesh.
        let mesh = AnimatedMesh::new(
            vec![[0, 1, 2]],
            vec![vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]],
        );
        let mesh = mesh.unwrap();
        for quality in [0, 101, 255] {
            let opts = EncodeOptions {
                quality,
                ..EncodeOptions::default()
            };
            match opts.check(&mesh) {
                Err(Error::InvalidOption { option, .. }) => assert_eq!(option, "quality"),
                other => panic!("quality {quality}: {other:?}"),
            }
        }
        for quality in [1, 50, 100] {
            let opts = EncodeOptions {
                quality,
                ..EncodeOptions::default()
            };
            assert!(opts.check(&mesh).is_ok(), "quality {quality}");
        }
    }
}
