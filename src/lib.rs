//! mcgv-video: Multi-Chart Geometry Video coding of animated triangle meshes.
//!
//! An animation (one connectivity, a position per vertex and frame) becomes one compact `.mcgv`
//! stream and back. Data flows one way: [`mesh`] → [`motion`] (clusters, predictor, residuals) →
//! [`codec`] (geometry images on an atlas coded as JPEG or MPEG-4 pictures, or a temporal DCT) →
//! [`stream`]; [`first_frame`] codes the connectivity and first frame, [`metrics`] measures the
//! result. The library knows nothing of command lines or terminals.
//!
//! ```
//! use mcgv_video::{encode, AnimatedMesh, Codec, Decoder, EncodeOptions};
//!
//! // A strip of four triangles bending over ten frames.
//! let triangles = vec![[0, 1, 2], [1, 3, 2], [2, 3, 4], [3, 5, 4]];
//! let frames: Vec<Vec<[f32; 3]>> = (0..10)
//!     .map(|f| {
//!         let bend = 0.05 * f as f32;
//!         (0..6)
//!             .map(|v| [(v % 2) as f32, (v / 2) as f32, bend * (v / 2) as f32])
//!             .collect()
//!     })
//!     .collect();
//! let mesh = AnimatedMesh::new(triangles, frames)?;
//!
//! let options = EncodeOptions { codec: Codec::Tdct.into(), quality: 60, clusters: 2, ..Default::default() };
//! let bytes = encode(&mesh, &options)?.to_bytes();
//!
//! let mut decoder = Decoder::new(&bytes)?;
//! let frame = decoder.decode_frame(7)?;
//! let all = decoder.decode_all()?;
//! assert_eq!(all.frame_count(), 10);
//! assert!((frame[5][2] - mesh.frame(7)[5][2]).abs() < 0.01);
//! # Ok::<(), mcgv_video::Error>(())
//! ```
//!
//! Reading a file: [`read_animation`] takes an OBJ folder or glob, a PC2 cache with its base OBJ,
//! or a glTF/GLB clip. FFmpeg (for MPEG-4) sits behind the `mpeg4` cargo feature, on by default.

pub mod codec;
pub mod decoder;
pub mod encoder;
pub mod error;
pub mod first_frame;
pub mod geometry_image;
pub mod inspect;
pub mod limits;
pub mod mesh;
pub mod metrics;
pub mod motion;
pub mod output;
pub mod progress;
pub mod stream;

pub use codec::pictures::DEFAULT_GOP;
pub use codec::Codec;
pub use decoder::{DecodeOptions, Decoder};
pub use encoder::{
    encode, encode_source, encode_with_progress, EncodeOptions, EncodeReport, Encoded,
    PredictorChoice, Segmentation, SegmentationChoice,
};
pub use error::{Error, Result};
pub use geometry_image::Lattice;
pub use limits::DEFAULT_MAX_POSITIONS;
pub use mesh::{read_animation, AnimatedMesh, Attributes, FrameSource, ReadOptions};
pub use motion::PredictorKind;
/// How free pixels of the geometry images are filled (the `padding` crate's methods).
pub use padding::Method as PaddingMethod;
pub use progress::{Progress, Silent};
