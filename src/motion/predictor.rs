//! The predictor dispatch: which predictor a stream uses ([`PredictorKind`], recorded in its
//! header) and the one function, [`predict_frame`], through which encoder and decoder predict a frame.

use super::affine::AffineTrack;
use super::partition::Partition;
use super::skinning::SkinningWeights;
use crate::error::Result;
use crate::mesh::Point;

/// The predictors an encoder can choose; recorded in the stream header.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum PredictorKind {
    /// One affine map per cluster and frame (MCGV eq. 3; the follow-up paper's eq. 8).
    #[default]
    Affine,
    /// Per-vertex weights over the own and neighbouring clusters' maps (follow-up paper eq. 7–10).
    Skinning,
}

impl PredictorKind {
    /// The name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            PredictorKind::Affine => "affine",
            PredictorKind::Skinning => "skinning",
        }
    }
}

/// Frame `frame` as the stream's predictor sees it: the skinning blend when `weights` are given,
/// else the piecewise affine prediction. Encoder and decoder both predict through this function.
pub fn predict_frame(
    track: &AffineTrack,
    weights: Option<&SkinningWeights>,
    frame: usize,
    reference: &[Point],
    partition: &Partition,
) -> Result<Vec<Point>> {
    match weights {
        Some(w) => w.try_predict(frame, track, reference, partition),
        None => track.try_predict(frame, reference, partition),
    }
}
