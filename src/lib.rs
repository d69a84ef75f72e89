//! mcgv-video: Multi-Chart Geometry Video coding of animated triangle meshes.
//!
//! Data flows one way: [`mesh`] → [`motion`] → `atlas` → [`geometry_image`] → [`codec`] → [`stream`],
//! and back for decoding. [`metrics`] measures the result.

pub mod cli;
pub mod codec;
pub mod commands;
pub mod decoder;
pub mod encoder;
pub mod error;
pub mod geometry_image;
pub mod mesh;
pub mod metrics;
pub mod motion;
pub mod output;
pub mod progress;
pub mod stream;

pub use error::{Error, Result};
pub use mesh::AnimatedMesh;
