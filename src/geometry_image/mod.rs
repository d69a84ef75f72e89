//! Geometry images: residuals quantised to 8 bits over stored ranges, placed at each vertex's lattice pixel.

pub mod quantise;
pub mod tile;

pub use quantise::{AxisRange, FrameRanges, RangeMode};
