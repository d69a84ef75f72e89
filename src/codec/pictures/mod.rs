//! The picture path: residuals as geometry images coded by a picture codec.
//!
//! [`geometry_video`] splats each frame's residuals onto a multi-chart atlas, pads and tiles them
//! into one picture per frame and hands the pictures to a [`geometry_video::PictureCodec`]: JPEG
//! ([`jpeg`], every frame alone), or through FFmpeg (cargo feature `ffmpeg`) MPEG-4 Part 2
//! ([`mpeg4`]) and HEVC and AV1 at 10 or 12 bits a sample ([`hevc`], [`av1`], sharing [`deep`]).

pub mod abbreviated;
#[cfg(feature = "ffmpeg")]
pub mod av1;
#[cfg(feature = "ffmpeg")]
pub mod deep;
pub mod geometry_video;
#[cfg(feature = "ffmpeg")]
pub mod hevc;
pub mod jpeg;
#[cfg(feature = "ffmpeg")]
mod libav;
#[cfg(feature = "ffmpeg")]
pub mod mpeg4;

use super::quality::jpeg_law;
use super::quality::{self, PictureLaw};
#[cfg(feature = "ffmpeg")]
use super::quality::{av1_law, hevc_law, mpeg4_law};
use super::StreamLayout;
use super::{Codec, CodecParams, CodedResiduals, ResidualDecoder, ResidualEncoder, ResidualInput};
pub use crate::geometry_image::Plane;
