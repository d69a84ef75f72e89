//! Everything a caller can choose about an encoding, its defaults, and the checks that refuse
//! nonsense before any work starts (each error names the option's field).

use crate::codec::Codec;
use crate::error::{Error, Result};
use crate::geometry_image::{lattice, Lattice};
use crate::mesh::AnimatedMesh;
use crate::motion::{self, PredictorKind};
use crate::stream::header::Header;

/// Bits per coordinate of the first frame unless the caller or tdct's trials pick others.
pub const DEFAULT_FIRST_FRAME_BITS: u8 = 12;

/// The first-frame bits tdct tries when the caller leaves them open, the default first (it wins
/// ties). The temporal DCT corrects frame 0 too, so a coarser first frame moves bits from the
/// first-frame coder into the residuals' lowest band: which side codes them cheaper depends on the
/// mesh and the step (walking_cat: 8 bits −11 % at quality 10, 10 bits −1.2 % at 90; the cloth
/// fixture, a flat grid the first-frame coder predicts almost exactly: 12 at every quality;
/// docs/results.md, "First-frame bits").
pub const FIRST_FRAME_BITS_TRIED: [u8; 3] = [DEFAULT_FIRST_FRAME_BITS, 10, 8];

/// Default `quality`: the middle of the useful range, a target step of 1/1000 of the first frame's
/// bounding-box diagonal (see [`crate::codec::quality`]).
pub const DEFAULT_QUALITY: u8 = 50;

/// Everything the caller can choose about an encoding.
#[derive(Debug, Clone)]
pub struct EncodeOptions {
    /// The residual codec.
    pub codec: Codec,
    /// Rate knob 1..100 (higher = better).
    pub quality: u8,
    /// The video codec's own quantiser, MPEG-4 qscale (1..=31), HEVC QP (0..=51) or AV1 `crf`
    /// (libaom's constant-quality level, 0..=63); `None` derives it from `quality`.
    pub qscale: Option<u8>,
    /// Bits a sample of the HEVC and AV1 pictures, 10 or 12; `None` picks it from `quality` by the
    /// measured rule of [`crate::codec::deep::auto_depth`] (12 from quality 90). JPEG and MPEG-4
    /// code 8.
    pub bit_depth: Option<u8>,
    /// JPEG's own quality 1..100 for the residual pictures; `None` derives it from `quality`.
    pub jpeg_quality: Option<u8>,
    /// Motion clusters K (k-means only; decimation finds its own).
    pub clusters: usize,
    /// How the vertices are split into motion clusters, or `Auto` (the default): the encoder tries
    /// k-means and decimation and keeps the smaller stream.
    pub segmentation: SegmentationChoice,
    /// The affine coefficients' quantiser step as a multiple `k` of the residual step Δ (the
    /// translation's step is `k·Δ`, the linear part's `k·Δ / r̄` with `r̄` the cluster's RMS radius);
    /// stored in sixteenths, 1/16..=255/16. `None` picks the codec's measured best
    /// ([`default_affine_precision`]).
    pub affine_precision: Option<f64>,
    /// Bits per coordinate of the first frame (1..=24); `None` lets the encoder choose: the
    /// picture codecs take [`DEFAULT_FIRST_FRAME_BITS`], tdct tries each of
    /// [`FIRST_FRAME_BITS_TRIED`] and keeps the smallest stream (`encoder::first_frame_bits`).
    pub first_frame_bits: Option<u8>,
    /// Lattice width and height, or chosen from the mesh.
    pub lattice: Lattice,
    /// Padding of the free pixels; `None` picks the codec's measured best.
    pub padding: Option<padding::Method>,
    /// Frames per group of pictures of MPEG-4, HEVC and AV1: an intra frame, then `gop − 1`
    /// P-frames. 1 makes HEVC and AV1 all-intra (every frame decodes alone, as JPEG's).
    pub gop: usize,
    /// Let the first-frame coder permute vertices.
    pub reorder: bool,
    /// The motion predictor, or `Auto` (the default): the encoder tries each and keeps the smaller
    /// stream.
    pub predictor: PredictorChoice,
    /// Bits per skinning weight, sign included (the paper's 16 by default).
    pub weight_bits: u8,
    /// Quantiser step (tdct) or pixel step (one grey level, image codecs) as a fraction of the
    /// first frame's bounding-box diagonal; `None` derives it from `quality`.
    pub step: Option<f64>,
    /// Bits per texture coordinate over each set's bounding box (1..=24; inputs with UVs only).
    pub uv_bits: u8,
    /// Frames per temporal segment: a longer clip is coded as segments of this many frames, each
    /// with its own temporal DCT or groups of pictures ([`super::segments`]); `None` codes any
    /// clip as one.
    pub segment_frames: Option<usize>,
    /// Segments coded at once (on rayon's threads): memory holds this many segments' working
    /// data, so the default, 1, keeps an encoding of any length within one segment's.
    pub parallel_segments: usize,
}

impl Default for EncodeOptions {
    fn default() -> Self {
        Self {
            // The command line's default: the smallest stream at equal error.
            codec: Codec::Tdct,
            quality: DEFAULT_QUALITY,
            qscale: None,
            bit_depth: None,
            jpeg_quality: None,
            clusters: 20,
            // Automatic since issue 18: the smallest stream at the quality's step, and on the
            // media samples at equal error too (docs/results.md), for 15–70 % more encoding time.
            segmentation: SegmentationChoice::auto(),
            affine_precision: None,
            first_frame_bits: None,
            lattice: Lattice::Auto,
            padding: None,
            gop: 50,
            reorder: false,
            predictor: PredictorChoice::Auto,
            weight_bits: motion::WEIGHT_BITS,
            step: None,
            uv_bits: 12,
            segment_frames: Some(DEFAULT_SEGMENT_FRAMES),
            parallel_segments: 1,
        }
    }
}

/// Frames per temporal segment unless asked otherwise: the shortest length that costs at most 2 %
/// more bits at equal error than one segment on every media sequence longer than it, for tdct and
/// MPEG-4 at the default quality (`examples/segment_cost`, docs/results.md "Temporal segments").
/// At 128: chickenCrossing tdct −17 %, MPEG-4 +1.3 %; pcow −0.7 / −1.3 %; pdance −1.0 / −1.9 %. At 64
/// MPEG-4 on chickenCrossing costs +3.8 %; at 32 tdct on horse-gallop +29 %, on pdance +42 %.
pub const DEFAULT_SEGMENT_FRAMES: usize = 128;

/// The affine precision `k` (step = k·Δ) a codec with groups of `gop` pictures gets unless asked
/// otherwise, measured by total bytes at equal vertex RMSE: 1/4 for tdct (CesiumMan, RiggedFigure,
/// walking_cat; 1/8 and 1/2 within a few per cent) and JPEG (q50: CesiumMan 389 856 bytes at 1/4,
/// 398 653 at 1/16, 413 960 with 17-bit maps, equal RMSE). MPEG-4 needs finer maps: their
/// quantisation noise is white in time and spoils its P-frame prediction (CesiumMan q30: 91 418
/// bytes with 17-bit maps, 111 733 at 1/4, 80 564 at 1/16, all at RMSE 7.9e-4).
pub fn default_affine_precision(codec: Codec, gop: usize) -> f64 {
    match codec {
        // All-intra AV1 (`gop` 1) has no P-frame to spoil, so it takes JPEG's 1/4: at equal
        // surface RMSE, qualities 40/65, 1–12 % fewer bits than at 1/16 (walking_cat,
        // horse-gallop, pcow; docs/results.md, "Bits at equal error in the automatic choice").
        // HEVC takes 1/4 with P-frames too: 0–11 % fewer bits at qualities 30/50 (ibid.; CesiumMan
        // q50 had measured 3.045 bpvf at 1/16, 3.055 at 1/4, at equal RMSE).
        Codec::Av1 if gop == 1 => motion::DEFAULT_AFFINE_PRECISION,
        Codec::Hevc => motion::DEFAULT_AFFINE_PRECISION,
        // AV1's P-frames as MPEG-4's: 1/4 saved 8–13 % on pcow at qualities 30/50 but cost 16 %
        // more bits at 9 % more error on horse-gallop at quality 70.
        Codec::Mpeg4 | Codec::Av1 => 1.0 / 16.0,
        _ => motion::DEFAULT_AFFINE_PRECISION,
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
    /// k-means (K = `EncodeOptions::clusters`; with tdct also the larger K of
    /// [`kmeans_ladder`]) and decimation down to `e0` are tried at the encoding's step; the
    /// smallest stream is kept.
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

/// The k-means cluster counts an automatic segmentation tries with tdct, from the caller's `k`:
/// k, 1.5 k and 2 k. More clusters fit the motion more closely (smaller residuals) for more side
/// information, and which wins depends on the animation and the step: at equal vertex RMSE the
/// walking cat kept 30 of 20/30/40 at every quality, the cloth fixture 40 from quality 30, Fox
/// 40 at quality 90 (docs/results.md, "k-means ladder"). tdct's trials are cheap next to the
/// segmentations; the picture codecs', coded whole (MPEG-4, HEVC, AV1), are not, so they try k.
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
        let ladder = match (self.segmentation, self.codec) {
            (SegmentationChoice::Auto { .. }, Codec::Tdct) => kmeans_ladder(self.clusters),
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

    /// The options a stream was encoded with, as far as its header records them: enough to redo
    /// the encoder's analysis on the stream's own partition (`weight_bits` is in the weights part).
    pub fn from_header(header: &Header, weight_bits: Option<u8>) -> Result<Self> {
        Ok(Self {
            codec: header.codec,
            quality: header.quality,
            qscale: match header.codec {
                Codec::Mpeg4 => Some(header.qscale).filter(|&q| q > 0),
                Codec::Hevc | Codec::Av1 => Some(header.qscale),
                _ => None,
            },
            // In the codec's set-up part, not the header: the pictures' decoder reads it.
            bit_depth: None,
            jpeg_quality: Some(header.qscale).filter(|&q| q > 0 && header.codec == Codec::Jpeg),
            clusters: header.requested_clusters as usize,
            // The segmentation is not redone: the stream carries its partition.
            segmentation: SegmentationChoice::Fixed(Segmentation::KMeans),
            affine_precision: Some(f64::from(header.affine_precision) / 16.0),
            first_frame_bits: Some(header.first_frame_bits),
            lattice: Lattice::Fixed(header.lattice_width, header.lattice_height),
            padding: match header.codec.has_images() {
                true => Some(
                    header
                        .padding
                        .parse()
                        .map_err(|e| Error::Stream(format!("padding {}: {e}", header.padding)))?,
                ),
                false => None,
            },
            gop: header.gop as usize,
            reorder: header.reorder,
            predictor: PredictorChoice::Fixed(header.predictor),
            weight_bits: weight_bits.unwrap_or(motion::WEIGHT_BITS),
            step: None,
            uv_bits: 12,
            segment_frames: None,
            parallel_segments: 1,
        })
    }

    /// Fails, naming the field, when an option is out of range or does not apply to the codec.
    pub fn check(&self, mesh: &AnimatedMesh) -> Result<()> {
        self.check_ranges()?;
        self.check_step()?;
        if self.codec == Codec::Tdct {
            self.check_tdct()?;
        }
        if !self.codec.available() {
            return Err(Error::option(
                "codec",
                format!("{}: this build has no such codec", self.codec.name()),
            ));
        }
        if mesh.triangles().is_empty() {
            return Err(Error::Mesh(
                "the mesh has no triangles: nothing to parameterize".into(),
            ));
        }
        Ok(())
    }

    fn check_ranges(&self) -> Result<()> {
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
        if let Lattice::Fixed(w, h) = self.lattice {
            lattice::check(w, h)?;
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
        if let Some(q) = self.jpeg_quality {
            if !(1..=100).contains(&q) {
                return Err(Error::option("jpeg_quality", "must be between 1 and 100"));
            }
        }
        if self.gop == 0 {
            return Err(Error::option("gop", "must be at least 1"));
        }
        if let Some(depth) = self.bit_depth {
            if !matches!(depth, 10 | 12) {
                return Err(Error::option("bit_depth", "must be 10 or 12"));
            }
        }
        match (self.codec, self.qscale) {
            (Codec::Hevc, Some(q)) if q > 51 => {
                return Err(Error::option(
                    "qscale",
                    "must be between 0 and 51 for hevc (its QP)",
                ));
            }
            (Codec::Av1, Some(q)) if q > 63 => {
                return Err(Error::option(
                    "qscale",
                    "must be between 0 and 63 for av1 (libaom's crf)",
                ));
            }
            _ => {}
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

    /// `affine_precision` as the header stores it: in sixteenths, 1..=255.
    pub fn affine_precision_code(&self) -> u8 {
        let k = self
            .affine_precision
            .unwrap_or_else(|| default_affine_precision(self.codec, self.gop));
        (k * 16.0).round().clamp(1.0, 255.0) as u8
    }

    /// The affine track's base step in the unit frame (a fraction of the diagonal): the residual
    /// step's fraction (`step`, or the one `quality` maps to) times the stored precision. Image
    /// codecs use the same law, which is finer than their residual error at equal quality.
    pub fn affine_step(&self) -> f64 {
        let fraction = self
            .step
            .unwrap_or_else(|| crate::codec::quality::target_step(self.quality, 1.0));
        let k = f64::from(self.affine_precision_code()) / 16.0;
        (fraction * k).clamp(motion::MIN_AFFINE_STEP, motion::MAX_AFFINE_STEP)
    }

    fn check_step(&self) -> Result<()> {
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

    fn check_tdct(&self) -> Result<()> {
        let no_images = |option| {
            Err(Error::option(
                option,
                "applies to the image codecs: tdct has no geometry images",
            ))
        };
        if let Lattice::Fixed(..) = self.lattice {
            return no_images("lattice");
        }
        if self.jpeg_quality.is_some() {
            return no_images("jpeg_quality");
        }
        if self.padding.is_some() {
            return no_images("padding");
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn affine_precision_is_fine_only_for_p_frames_that_suffer_from_coarse_maps() {
        let code = |codec, gop| {
            let opts = EncodeOptions {
                codec,
                gop,
                ..EncodeOptions::default()
            };
            opts.affine_precision_code()
        };
        // In sixteenths: 4 = 1/4, 1 = 1/16.
        for (codec, gop, expected) in [
            (Codec::Tdct, 50, 4),
            (Codec::Jpeg, 50, 4),
            (Codec::Hevc, 1, 4),
            (Codec::Hevc, 50, 4),
            (Codec::Av1, 1, 4),
            (Codec::Av1, 50, 1),
            (Codec::Mpeg4, 50, 1),
        ] {
            assert_eq!(code(codec, gop), expected, "{codec:?} gop {gop}");
        }
        let asked = EncodeOptions {
            codec: Codec::Av1,
            affine_precision: Some(0.5),
            ..EncodeOptions::default()
        };
        assert_eq!(asked.affine_precision_code(), 8);
    }
}
