//! The decoder's access to the geometry pictures of the picture codecs (JPEG, MPEG-4, HEVC, AV1):
//! each vertex's lattice pixel, the residual ranges, a frame's coded picture as the stream holds
//! it and its decoded plane, and decoding a frame from a picture decoded elsewhere (the web
//! player's WebCodecs). `inspect` and the bindings read pictures through these.

use super::{closed, finite, Decoder};
use crate::codec::geometry_video::ImageLayout;
use crate::codec::Plane;
use crate::error::{Error, Result};
use crate::geometry_image::FrameRanges;
use crate::mesh::Point;
use crate::stream::container::Tag;
use crate::stream::frame_index::ChunkEntry;
use std::io::{Read, Seek};

impl<R: Read + Seek> Decoder<R> {
    /// The geometry-image side of the open segment (`None` for codecs without images).
    pub(crate) fn images(&self) -> Option<&ImageLayout> {
        self.open.as_ref().and_then(|o| o.residuals.images())
    }

    /// Lattice pixel of every vertex (empty for codecs without a lattice).
    pub fn vertex_pixels(&self) -> &[[u16; 2]] {
        self.images().map_or(&[], |i| &i.pixels)
    }

    /// The residual range of every frame of the open segment and coordinate (empty for codecs
    /// without images).
    pub fn ranges(&self) -> &[FrameRanges] {
        self.images().map_or(&[], |i| &i.ranges)
    }

    /// Frame `f`'s residual range per coordinate (`None` for codecs without images).
    pub fn frame_ranges(&mut self, f: usize) -> Result<Option<FrameRanges>> {
        let local = self.seek_frame(f)?;
        Ok(self.ranges().get(local).copied())
    }

    /// Where frame `f`'s coded picture lies in its segment's images part (`f` must be a frame of
    /// the open segment: see [`Decoder::seek_segment`]).
    pub fn frame_entry(&self, f: usize) -> Result<ChunkEntry> {
        let Some(images) = self.images() else {
            return Err(Error::Usage(format!(
                "a {} stream has no pictures",
                self.codec.name()
            )));
        };
        match self.open_segment().map(|s| &self.segments[s]) {
            Some(frames) if frames.contains(&f) => images.index.entry(f - frames.start),
            _ => Err(Error::Usage(format!(
                "frame {f} is not in the open segment: seek its segment first"
            ))),
        }
    }

    /// The decoded picture (x | y | z residual images side by side) of frame `f`.
    pub fn decoded_plane(&mut self, f: usize) -> Result<Plane<u16>> {
        let local = self.seek_frame(f)?;
        let open = self.open.as_mut().ok_or_else(closed)?;
        open.residuals.picture(&mut self.reader, local)
    }

    /// Frame `f`'s coded picture as the stream holds it, and whether it is a key frame (decoding
    /// may start there), for codecs that code pictures: an MPEG-4, HEVC or AV1 packet (an AV1
    /// temporal unit with the sequence header on key frames), or JPEG's scan with its tables.
    /// With [`Decoder::decode_frame_from_picture`] a picture decoder outside the library (a
    /// browser's WebCodecs) does what this build's cannot.
    pub fn coded_picture(&mut self, f: usize) -> Result<(Vec<u8>, bool)> {
        let local = self.seek_frame(f)?;
        let Some(images) = self.images() else {
            return Err(Error::Usage(format!(
                "a {} stream has no pictures",
                self.codec.name()
            )));
        };
        let e = images.index.entry(local)?;
        let what = format!("frame {f}");
        let bytes = self
            .reader
            .chunk(Tag::FRAMES, e.offset, e.len, e.crc, &what)?;
        Ok((bytes, e.key))
    }

    /// Decodes frame `f` from its picture decoded outside the library (x | y | z residual images
    /// side by side: for HEVC and AV1 the Y, U and V planes of the 4:4:4 picture, each
    /// [`PicturesDescription::lattice`](crate::codec::PicturesDescription) wide, samples of the
    /// stream's bit depth); the rest — prediction, dequantisation, corrections — as
    /// [`Decoder::decode_frame`] does. A picture of another size, or a sample above the depth's
    /// largest, is an error.
    pub fn decode_frame_from_picture(
        &mut self,
        f: usize,
        picture: &Plane<u16>,
    ) -> Result<Vec<Point>> {
        let local = self.seek_frame(f)?;
        let mut out = self.predict(local)?;
        let open = self.open.as_ref().ok_or_else(closed)?;
        open.residuals.add_picture(local, picture, &mut out)?;
        finite(f, &out)?;
        Ok(out)
    }
}
