//! Motion analysis (MCGV §3.1–3.2): segmentation of the vertices by affine motion (k-means, or the
//! skinning paper's decimation), the piecewise affine predictor of every frame from the decoded
//! frame 0, the skinning predictor of the follow-up paper (§3.2, eq. 7–10) that blends
//! neighbouring clusters' maps per vertex, and the residuals.
//!
//! ```text
//! segment(mesh) | decimate(mesh) ─► Partition ─► AffineTrack::fit(frames, decoded frame 0) ─► predict(i) ─► residuals
//! ```
//!
//! - `sampled_motion`: frame 0 and sampled frames in unit coordinates, the seam-welded vertex graph
//! - `kmeans`: segmentation by k-means of per-vertex ring motion (MCGV §3.1)
//! - `decimate`: segmentation by half-edge collapses (skinning paper §3.1)
//! - `refine`: border refinement by trajectory prediction error, shared by both segmentations
//! - `partition`: the cluster id per vertex that segmentation yields
//! - `fit`: regularised least-squares affine fits and the unit frame
//! - `affine`: the piecewise affine predictor, fitted and quantised (MCGV §3.2)
//! - `linear_form`: how a map's linear part is stored: its entries, or a rotation and a stretch
//! - `trajectory`: temporal prediction of a coefficient's levels, and the estimate of their bits
//! - `skinning`: the skinning predictor's per-vertex weights (follow-up paper §3.2)
//! - `weight_fits`: what moving a quantised weight away from its fit costs in prediction error
//! - `predictor`: which predictor a stream uses, and the one prediction both codec sides call
//! - `residual`: prediction residuals and their energy

mod affine;
#[cfg(feature = "encode")]
mod decimate;
mod fit;
#[cfg(feature = "encode")]
mod kmeans;
#[cfg(feature = "encode")]
mod lloyd;
mod partition;
mod predictor;
#[cfg(feature = "encode")]
mod refine;
#[cfg(feature = "encode")]
mod residual;
mod linear_form;
#[cfg(feature = "encode")]
mod sampled_motion;
mod skinning;
pub(crate) mod trajectory;
#[cfg(feature = "encode")]
mod weight_fits;

pub use linear_form::LinearForm;
pub use affine::{
    identity_levels, AffineTrack, ClusterGeometry, QuantisedAffine, DEFAULT_AFFINE_PRECISION,
    MAX_AFFINE_LEVEL, MAX_AFFINE_STEP, MIN_AFFINE_STEP,
};
#[cfg(all(feature = "encode", any(test, feature = "internals")))]
pub use decimate::Decimation;
#[cfg(feature = "encode")]
pub use decimate::{decimate, DecimateOptions, DEFAULT_E0};
#[cfg(feature = "encode")]
pub use kmeans::{segment, MotionDescriptors, SegmentOptions};
pub use partition::Partition;
pub use predictor::{predict_frame, PredictorKind};
#[cfg(all(feature = "encode", any(test, feature = "internals")))]
pub use residual::energy;
#[cfg(feature = "encode")]
pub use residual::residuals;
pub use skinning::{cluster_neighbours, SkinningWeights, DEFAULT_RIDGE, WEIGHT_BITS};
#[cfg(feature = "encode")]
pub use weight_fits::WeightFits;
