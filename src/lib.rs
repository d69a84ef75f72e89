//! mcgv-video: Multi-Chart Geometry Video coding of animated triangle meshes.
//!
//! An animation — one connectivity, a position per vertex and frame — becomes one compact `.mcgv`
//! stream and back. The mesh is split into clusters that move nearly rigidly, one affine map per
//! cluster and frame predicts every frame from the first, and a residual codec stores what the
//! prediction misses: a temporal DCT of each vertex's remainder (the default, [`Codec::Tdct`]), or
//! geometry images coded as JPEG, MPEG-4 Part 2, HEVC or AV1 pictures.
//!
//! # Encode and decode
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
//! let options = EncodeOptions { quality: 60, clusters: 2, ..Default::default() };
//! let bytes = encode(&mesh, &options)?.to_bytes();
//!
//! let mut decoder = Decoder::new(&bytes)?;
//! assert_eq!(decoder.codec(), Codec::Tdct);
//! let frame = decoder.decode_frame(7)?;
//! let all = decoder.decode_all()?;
//! assert_eq!(all.frame_count(), 10);
//! assert!((frame[5][2] - mesh.frame(7)[5][2]).abs() < 0.01);
//! # Ok::<(), mcgv_video::Error>(())
//! ```
//!
//! # Where to start
//!
//! - Reading: [`read_animation`] takes an OBJ folder or glob, a PC2 cache with its base OBJ, or a
//!   glTF/GLB clip ([`ReadOptions`]); [`FrameSource`] reads a long clip a run of frames at a time.
//! - Encoding: [`encode`] with [`EncodeOptions`] — the options every codec shares, and in
//!   [`EncodeOptions::codec`] a [`CodecConfig`] holding the chosen codec's own ([`codec`]).
//!   [`Encoded::report`] says what it did; [`encoder::SegmentedEncoder`] codes a long clip's
//!   temporal segments one by one, on any thread or machine. [`encode_to_budget`] finds the
//!   quality whose stream fits a [`Budget`]: bytes, bits per vertex and frame, or an error bound.
//! - Decoding: [`Decoder`] opens a stream, decodes one frame alone or all of them, and
//!   [`Decoder::describe`] says what the codec stored.
//! - Measuring: [`metrics`] (RMSE, Hausdorff, vertex RMSE, KG error), [`inspect`] (the images a
//!   picture codec coded).
//! - Writing meshes: [`mesh`] (OBJ, PC2, glTF).
//!
//! Every failure is one typed [`Error`]. The cargo feature `encode` (default) holds the encoder
//! and what only it needs — the mesh readers and writers, the segmentation, the atlas, the JPEG
//! encoder, [`metrics`] and [`inspect`]; without it the library is a decoder of tdct and JPEG
//! streams in pure Rust, which builds for `wasm32-unknown-unknown` (the project's `web/` crate).
//! The feature `ffmpeg` (default, implies `encode`) adds the MPEG-4, HEVC and AV1 codecs through
//! FFmpeg; without it JPEG and the temporal DCT remain. The feature `internals` makes the
//! pipeline's inner modules public for the project's own tests, benches, fuzzing and examples:
//! they are not a stable API.

#![deny(missing_docs)]
// A decode-only build (without `encode`) keeps the codecs' option types and laws, pure code, so
// that its API reads as the full one; what only the encoder reaches is unused there.
#![cfg_attr(not(feature = "encode"), allow(dead_code, unused_imports))]
// Its front page still describes the whole library, encoder included.
#![cfg_attr(not(feature = "encode"), allow(rustdoc::broken_intra_doc_links))]

/// Declares modules the public API does not expose: crate-private, or public (and unstable) with
/// the `internals` feature.
macro_rules! internal {
    ($($(#[$meta:meta])* $name:ident;)*) => {$(
        $(#[$meta])*
        #[cfg(feature = "internals")]
        pub mod $name;
        $(#[$meta])*
        #[cfg(not(feature = "internals"))]
        pub(crate) mod $name;
    )*};
}

pub mod codec;
mod codec_log;
mod decoder;
#[cfg(feature = "encode")]
pub mod encoder;
mod error;
#[cfg(feature = "encode")]
pub mod inspect;
pub mod mesh;
#[cfg(feature = "encode")]
pub mod metrics;
mod progress;

internal! {
    first_frame;
    geometry_image;
    limits;
    motion;
    #[cfg(feature = "encode")]
    output;
    stream;
}

pub use codec::{Codec, CodecConfig, Description};
pub use codec_log::{set_codec_log, CodecLogSink};
pub use decoder::{DecodeOptions, Decoder, FirstFrame};
#[cfg(feature = "encode")]
pub use encoder::{
    encode, encode_source, encode_to_budget, encode_with_progress, Budget, EncodeOptions,
    EncodeReport, Encoded, PredictorChoice, Segmentation, SegmentationChoice,
};
pub use error::{Error, Result};
pub use geometry_image::Lattice;
pub use limits::DEFAULT_MAX_POSITIONS;
#[cfg(feature = "encode")]
pub use mesh::{read_animation, FrameSource, ReadOptions};
pub use mesh::{AnimatedMesh, Attributes};
pub use motion::PredictorKind;
/// How free pixels of the geometry images are filled (the `padding` crate's methods).
pub use padding::Method as PaddingMethod;
pub use progress::{Progress, Silent};
pub use stream::header::Header;
