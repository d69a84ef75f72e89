//! Geometry images: the residuals placed at each vertex's pixel of a multi-chart atlas, quantised
//! to 8 bits at one step around stored offsets, and padded so that the image codecs see smooth pictures.
//!
//! - [`lattice`]: the atlas on a lattice sized from the vertex count (grown until the charts fit).
//! - [`quantise`]: the pixel step, per-frame (or per-group) offsets and the 0..255 levels around them.
//! - [`corrections`]: the residuals that do not fit, sent apart.
//! - [`images`]: one frame's three residual images, raw or padded.
//! - [`tile`]: the x | y | z images side by side in one picture ([`Plane`]), and back.

pub mod corrections;
#[cfg(feature = "encode")]
pub mod images;
pub mod lattice;
mod plane;
pub mod quantise;
pub mod range_coding;
pub mod tile;

pub use corrections::Corrections;
#[cfg(feature = "encode")]
pub use images::GeometryImages;
pub use lattice::Lattice;
pub use plane::Plane;
pub use quantise::{AxisRange, FrameRanges, RangeMode};
