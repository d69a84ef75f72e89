//! Looking inside a stream: the residual images its encoder made, redone from the original
//! animation by the encoder's own analysis and image code, so that what is shown is what was
//! coded. (The bit budget per part is [`Decoder::part_bytes`], what the codec stored
//! [`Decoder::describe`].)

use crate::codec::pictures::geometry_video;
pub use crate::codec::Plane;
use crate::decoder::Decoder;
use crate::encoder::analysis::{self, StreamChoices};
use crate::error::{Error, Result};
use crate::first_frame::FirstFrameOptions;
use crate::geometry_image::tile;
pub use crate::geometry_image::{AxisRange, FrameRanges};
use crate::mesh::AnimatedMesh;
use std::io::{Read, Seek};

/// One frame's residual images as the encoder made them: x | y | z side by side, levels of the
/// stream's sample depth.
pub struct EncoderImages {
    /// The frame.
    pub frame: usize,
    /// The quantised residuals at the vertices' pixels and the charts' interiors, every other
    /// pixel 0.
    pub raw: Plane<u16>,
    /// After padding: what the picture codec was given.
    pub padded: Plane<u16>,
    /// The pixels that carry data (the vertices' and the charts' interiors); the others are padding.
    pub fixed: Vec<bool>,
}

/// The residual images the encoder made for `frames` of a geometry-video stream, redone from the
/// `original` animation with the stream's own options, partition and ranges.
pub fn encoder_images<R: Read + Seek>(
    decoder: &Decoder<R>,
    original: &AnimatedMesh,
    frames: &[usize],
) -> Result<Vec<EncoderImages>> {
    let header = decoder.header();
    if decoder.segments().len() > 1 {
        return Err(Error::Usage(
            "the encoder's images of a stream cut into temporal segments are not redone (later \
             segments are predicted from the first one's analysis); leave out the original"
                .into(),
        ));
    }
    let codec = decoder.codec();
    let pictures = codec
        .pictures()?
        .ok_or_else(|| Error::Usage(format!("a {} stream has no geometry images", codec.name())))?;
    if original.vertex_count() != header.vertices as usize
        || original.frame_count() != header.frames as usize
    {
        return Err(Error::Usage(format!(
            "the original has {} vertices x {} frames; the stream has {} x {}",
            original.vertex_count(),
            original.frame_count(),
            header.vertices,
            header.frames
        )));
    }
    if let Some(&bad) = frames.iter().find(|&&f| f >= header.frames as usize) {
        return Err(Error::Usage(format!(
            "frame {bad}: the stream has frames 0 to {}",
            header.frames - 1
        )));
    }
    let layout = decoder
        .images()
        .ok_or_else(|| Error::Usage("the stream has no geometry images".into()))?;
    let choices = StreamChoices {
        first_frame: FirstFrameOptions {
            bits: header.first_frame_bits,
            reorder: header.reorder,
        },
        partition: decoder.partition(),
        predictor: header.predictor,
        affine_step: decoder.affine_step().ok_or_else(closed)?,
        weights: decoder.weights(),
    };
    let redone = analysis::redo(original, &choices)?;
    let residuals = &redone.prediction.residuals;
    let plan = layout.setup.plan(codec);
    // The stream's own step, ranges and corrections.
    let shape = (
        redone.reference.as_slice(),
        redone.triangles.as_slice(),
        decoder.partition(),
    );
    let codec = (pictures, &plan);
    let mut images = geometry_video::images(codec, layout.pixel_step, shape, residuals, None)?;
    images.ranges = layout.ranges.clone();
    images.depth = layout.depth();
    let (w, h) = layout.lattice();
    let (w, h) = (usize::from(w), usize::from(h));
    let compose = |levels: [Vec<f32>; 3]| {
        tile::compose([&levels[0], &levels[1], &levels[2]], w, h, images.depth)
    };
    images.corrections = layout.corrections.clone();
    frames
        .iter()
        .map(|&f| {
            Ok(EncoderImages {
                frame: f,
                raw: compose(images.raw(&residuals[f], f)?),
                padded: compose(images.padded_alone(residuals, f)?),
                fixed: images.padding.fixed().to_vec(),
            })
        })
        .collect()
}

/// The error of a figure asked of a stream with no open segment.
fn closed() -> Error {
    Error::Stream("no segment is open".into())
}
