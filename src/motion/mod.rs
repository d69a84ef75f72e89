//! Motion analysis (MCGV §3.1–3.2): segmentation of the vertices by affine motion, the piecewise
//! affine predictor of every frame from the decoded frame 0, and its residuals.
//!
//! ```text
//! segment(mesh) ─► Partition ─► AffineTrack::fit(frames, decoded frame 0) ─► predict(i) ─► residuals
//! ```

mod affine;
mod fit;
mod predict;
mod refine;
mod render;
mod segment;

pub use affine::{AffineTrack, QuantisedAffine, DEFAULT_AFFINE_BITS, MAX_AFFINE_BITS};
pub use fit::AffineCoefficients;
pub use predict::{energy, residuals};
pub use render::render_partition_png;
pub use segment::{segment, Partition, SegmentOptions, MIN_CLUSTER_SIZE};
