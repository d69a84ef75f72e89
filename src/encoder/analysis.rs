//! The analysis half of the encoder: the first frame the decoder will have, the motion
//! segmentation, and the quantised predictor with every frame's residual against it. `inspect`
//! redoes it on a stream's own partition to show the images the encoder coded.

use super::options::{EncodeOptions, Segmentation};
use super::weights_rd::{self, WeightPlan};
use crate::error::{Error, Result};
use crate::first_frame::{self, EncodedFirstFrame, FirstFrameOptions};
use crate::mesh::{AnimatedMesh, Point};
use crate::motion::{
    self, AffineTrack, DecimateOptions, MotionDescriptors, Partition, PredictorKind, SegmentOptions,
    SkinningWeights,
};
use std::time::Instant;

/// What the segmentation stage did, for reports.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SegmentationReport {
    /// `kmeans` or `decimation`.
    pub method: &'static str,
    /// Clusters found (K).
    pub clusters: usize,
    /// Seconds the segmentation took.
    pub seconds: f64,
    /// Decimation only: the threshold E0 asked for.
    pub e0: Option<f64>,
    /// Decimation only: the RMS affine-fit error per vertex and frame reached, over the bbox diagonal (E_l).
    pub error: Option<f64>,
    /// Decimation only: connected components (seams welded), a lower bound on K.
    pub components: Option<usize>,
}

/// The quantised predictor and every frame's residuals against it.
pub struct Prediction {
    /// The quantised affine track.
    pub track: AffineTrack,
    /// The quantised skinning weights (skinning predictor only).
    pub weights: Option<SkinningWeights>,
    /// `residuals[f][v]`: frame f's residual of vertex v.
    pub residuals: Vec<Vec<[f32; 3]>>,
}

/// Codes the first frame and, when the coder reordered the vertices, permutes the animation the
/// same way: everything after it works in the stream's vertex order.
pub fn first_frame(
    mesh: &AnimatedMesh,
    opts: &EncodeOptions,
) -> Result<(EncodedFirstFrame, Option<AnimatedMesh>)> {
    let ff = first_frame::encode(
        mesh.frame(0),
        mesh.triangles(),
        &FirstFrameOptions {
            bits: opts.first_frame_bits_or_default(),
            reorder: opts.reorder,
        },
    )?;
    let permuted = match &ff.permutation {
        Some(perm) => Some(mesh.permuted(perm)?),
        None => None,
    };
    Ok((ff, permuted))
}

/// The motion segmentation `segmentation` (k-means into `clusters`), and what it did.
pub fn segment(
    mesh: &AnimatedMesh,
    segmentation: Segmentation,
    clusters: usize,
) -> Result<(Partition, SegmentationReport)> {
    Segmenter::new(mesh).segment(segmentation, clusters)
}

/// A partition made, by segmentation and K (0 for decimation), and its report.
type Made = ((Segmentation, usize), (Partition, SegmentationReport));

/// Segments one animation several ways, keeping what every K of k-means shares (the motion
/// descriptors, most of a segmentation's time after k-means itself) and each partition made (a
/// picture codec's choice asks for the segmentations it tries twice: `encoder/auto/rungs.rs`).
pub struct Segmenter<'a> {
    mesh: &'a AnimatedMesh,
    descriptors: std::sync::OnceLock<MotionDescriptors>,
    done: std::sync::Mutex<Vec<Made>>,
}

impl<'a> Segmenter<'a> {
    /// A segmenter of `mesh`; nothing is computed until a segmentation is asked for.
    pub fn new(mesh: &'a AnimatedMesh) -> Self {
        Self {
            mesh,
            descriptors: std::sync::OnceLock::new(),
            done: std::sync::Mutex::new(Vec::new()),
        }
    }

    /// The motion segmentation `segmentation` (k-means into `clusters`), and what it did; a
    /// partition made before is handed out again (both segmentations are deterministic).
    pub fn segment(
        &self,
        segmentation: Segmentation,
        clusters: usize,
    ) -> Result<(Partition, SegmentationReport)> {
        // Decimation ignores `clusters` (it finds its own count): one entry whatever is asked.
        let key = match segmentation {
            Segmentation::KMeans => (segmentation, clusters),
            Segmentation::Decimation { .. } => (segmentation, 0),
        };
        if let Some(found) = self.made(key) {
            return Ok(found);
        }
        let made = self.segment_now(segmentation, clusters)?;
        if let Ok(mut list) = self.done.lock() {
            list.push((key, made.clone()));
        }
        Ok(made)
    }

    /// The partition made before for `key`, if any.
    fn made(&self, key: (Segmentation, usize)) -> Option<(Partition, SegmentationReport)> {
        let list = self.done.lock().ok()?;
        let found = list.iter().find(|(k, _)| *k == key);
        found.map(|(_, made)| made.clone())
    }

    /// [`Self::segment`], computed.
    fn segment_now(
        &self,
        segmentation: Segmentation,
        clusters: usize,
    ) -> Result<(Partition, SegmentationReport)> {
        let start = Instant::now();
        let (partition, e0, error, components) = match segmentation {
            Segmentation::KMeans => (self.kmeans(clusters)?, None, None, None),
        Segmentation::Decimation { e0 } => {
            let options = DecimateOptions {
                e0,
                ..DecimateOptions::default()
            };
            let d = motion::decimate(self.mesh, &options)?;
            (d.partition, Some(e0), Some(d.error), Some(d.components))
        }
    };
        let report = SegmentationReport {
            method: segmentation.name(),
            clusters: partition.clusters(),
            seconds: start.elapsed().as_secs_f64(),
            e0,
            error,
            components,
        };
        Ok((partition, report))
    }

    /// Makes ahead what every k-means segmentation into at most `largest` clusters shares: the
    /// motion descriptors and the k-means++ seeds for `largest` (the first k of which are the
    /// seeds of k). For a ladder of K segmented in parallel, which then only read them.
    pub fn prepare_kmeans(&self, largest: usize) {
        if largest.min(self.mesh.vertex_count()) <= 1 {
            return;
        }
        let options = SegmentOptions {
            clusters: largest,
            ..SegmentOptions::default()
        };
        self.descriptors(&options)
            .prepare_seeds(largest, options.seed);
    }

    /// The motion descriptors, made at the first call (with `options`' ring and feature frames,
    /// the defaults').
    fn descriptors(&self, options: &SegmentOptions) -> &MotionDescriptors {
        self.descriptors
            .get_or_init(|| MotionDescriptors::new(self.mesh, options))
    }

    /// k-means into `clusters` on the descriptors made at the first call.
    fn kmeans(&self, clusters: usize) -> Result<Partition> {
        let options = SegmentOptions {
            clusters,
            ..SegmentOptions::default()
        };
        if clusters.min(self.mesh.vertex_count()) <= 1 {
            return motion::segment(self.mesh, &options);
        }
        self.descriptors(&options).segment(&options)
    }
}

/// The quantised predictor `kind` (affine track at base step `affine_step`, skinning weights as
/// `weights` plans them) and every frame's residuals against it, as the decoder will rebuild them:
/// closed loop.
pub fn predict(
    mesh: &AnimatedMesh,
    reference: &[Point],
    partition: &Partition,
    (affine_step, weights): (f64, WeightPlan),
    kind: PredictorKind,
) -> Result<Prediction> {
    let track = fit_track(mesh, reference, partition, affine_step)?;
    predict_on(mesh, reference, partition, weights, kind, track)
}

/// The quantised affine track every predictor builds on (skinning blends its maps), at base step
/// `affine_step` (a fraction of the first frame's bounding-box diagonal).
pub fn fit_track(
    mesh: &AnimatedMesh,
    reference: &[Point],
    partition: &Partition,
    affine_step: f64,
) -> Result<AffineTrack> {
    AffineTrack::fit(mesh.frames(), reference, partition, affine_step)
}

/// [`predict`] on an affine track already fitted to `partition` ([`fit_track`]), skinning weights
/// as `weights` plans them.
pub fn predict_on(
    mesh: &AnimatedMesh,
    reference: &[Point],
    partition: &Partition,
    weights: WeightPlan,
    kind: PredictorKind,
    track: AffineTrack,
) -> Result<Prediction> {
    let weights = match kind {
        PredictorKind::Affine => None,
        PredictorKind::Skinning => Some(weights_rd::fit(
            mesh, reference, partition, &track, weights,
        )?),
    };
    prediction_with(mesh, reference, partition, track, weights)
}

/// The predictor of `track` blended by `weights` (skinning) and every frame's residuals against it.
fn prediction_with(
    mesh: &AnimatedMesh,
    reference: &[Point],
    partition: &Partition,
    track: AffineTrack,
    weights: Option<SkinningWeights>,
) -> Result<Prediction> {
    let residuals = residuals_of(mesh, reference, partition, &track, weights.as_ref())?;
    Ok(Prediction {
        track,
        weights,
        residuals,
    })
}

/// Every frame's residual against its prediction by `track` (blended by `weights` for skinning).
pub fn residuals_of(
    mesh: &AnimatedMesh,
    reference: &[Point],
    partition: &Partition,
    track: &AffineTrack,
    weights: Option<&SkinningWeights>,
) -> Result<Vec<Vec<[f32; 3]>>> {
    (0..mesh.frame_count())
        .map(|f| {
            let predicted = motion::predict_frame(track, weights, f, reference, partition)?;
            Ok(motion::residuals(mesh.frame(f), &predicted))
        })
        .collect()
}

/// The encoder's analysis of `original` redone with a stream's choices and partition.
pub struct Redone {
    /// The decoded first frame.
    pub reference: Vec<Point>,
    /// The connectivity in the stream's vertex order.
    pub triangles: Vec<[u32; 3]>,
    /// The predictor and the residuals the stream's residual codec was given.
    pub prediction: Prediction,
}

/// What a stream records of the choices its encoder made, which redoing its analysis needs.
pub struct StreamChoices<'a> {
    /// The first frame's precision and vertex order.
    pub first_frame: FirstFrameOptions,
    /// The motion clusters.
    pub partition: &'a Partition,
    /// The predictor.
    pub predictor: PredictorKind,
    /// The affine track's base step (a fraction of the bounding-box diagonal).
    pub affine_step: f64,
    /// The stream's skinning weights (the skinning predictor's): the encoder's own choice, which
    /// fitting them again would not find (the stream stores the bits it settled on, not the most
    /// it was allowed).
    pub weights: Option<&'a SkinningWeights>,
}

/// Redoes the encoder's analysis of `original` with a stream's recorded choices: the residuals
/// the stream's codec was given, in the stream's vertex order.
pub fn redo(original: &AnimatedMesh, choices: &StreamChoices) -> Result<Redone> {
    let ff = first_frame::encode(
        original.frame(0),
        original.triangles(),
        &choices.first_frame,
    )?;
    let permuted = match &ff.permutation {
        Some(perm) => Some(original.permuted(perm)?),
        None => None,
    };
    let mesh = permuted.as_ref().unwrap_or(original);
    let partition = choices.partition;
    if partition.labels().len() != mesh.vertex_count() {
        return Err(Error::Usage(format!(
            "the original has {} vertices; the stream's partition {}",
            mesh.vertex_count(),
            partition.labels().len()
        )));
    }
    let reference = &ff.decoded_positions;
    let track = fit_track(mesh, reference, partition, choices.affine_step)?;
    let weights = match choices.predictor {
        PredictorKind::Affine => None,
        PredictorKind::Skinning => Some(choices.weights.cloned().ok_or_else(|| {
            Error::Usage("a skinning stream without skinning weights".into())
        })?),
    };
    let prediction = prediction_with(mesh, reference, partition, track, weights)?;
    Ok(Redone {
        triangles: mesh.triangles().to_vec(),
        reference: ff.decoded_positions,
        prediction,
    })
}
