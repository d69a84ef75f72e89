//! Looking inside a stream: its bit budget per part, and the residual images its encoder made
//! (redone from the original animation by the encoder's own analysis and image code, so what is
//! shown is what was coded).

use crate::decoder::Decoder;
use crate::encoder::{analysis, EncodeOptions};
use crate::error::{Error, Result};
use crate::mesh::AnimatedMesh;
use crate::stream::container::{FILE_HEADER_LEN, PART_HEADER_LEN};
use std::io::{Read, Seek};

/// Bytes each part of an opened stream takes in the file (its part header included), in file
/// order, after the file header; the parts of one kind in a segmented stream are summed.
pub fn part_bytes<R: Read + Seek>(decoder: &Decoder<R>) -> Vec<(String, u64)> {
    let mut parts = vec![("file header".to_string(), FILE_HEADER_LEN as u64)];
    for p in decoder.container().parts() {
        let bytes = p.len + PART_HEADER_LEN as u64;
        match parts.iter_mut().find(|(name, _)| name == p.tag.name()) {
            Some((_, total)) => *total += bytes,
            None => parts.push((p.tag.name().to_string(), bytes)),
        }
    }
    parts
}

/// One frame's residual images as the encoder made them: levels in `0..=255`, x, y, z.
pub struct EncoderImages {
    /// The frame.
    pub frame: usize,
    /// The quantised residuals at the vertices' pixels, every other pixel 0.
    pub raw: [Vec<f32>; 3],
    /// After padding: what the picture codec was given.
    pub padded: [Vec<f32>; 3],
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
    let pictures = header.codec.pictures()?.ok_or_else(|| {
        Error::Usage(format!(
            "a {} stream has no geometry images",
            header.codec.name()
        ))
    })?;
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
    let opts = EncodeOptions::from_header(header, decoder.weights().map(|w| w.bits))?;
    let redone = analysis::redo(original, &opts, decoder.partition())?;
    let residuals = &redone.prediction.residuals;
    let layout = decoder
        .images()
        .ok_or_else(|| Error::Usage("the stream has no geometry images".into()))?;
    // The stream's own step, ranges and corrections: the encoder's option (`step`) is not recorded.
    let mut images = crate::codec::geometry_video::images_of(
        pictures.as_ref(),
        &redone.reference,
        &redone.triangles,
        decoder.partition(),
        residuals,
        &opts,
        layout.pixel_step,
    )?;
    images.ranges = layout.ranges.clone();
    images.depth = layout.depth;
    images.corrections = layout.corrections.clone();
    frames
        .iter()
        .map(|&f| {
            Ok(EncoderImages {
                frame: f,
                raw: images.raw(&residuals[f], f)?,
                padded: images.padded_alone(residuals, f)?,
            })
        })
        .collect()
}
