//! The picture codecs' set-up part: what a geometry-video decoder reads before any picture — the
//! lattice, the codec's quantiser, groups of pictures and sample depth, the padding and atlas
//! figures `inspect` reports, and the codec's own bytes (JPEG's shared headers, the planes of
//! HEVC and AV1). One part for the whole stream; it starts with its own version.

use super::PicturePlan;
use crate::codec::Codec;
use crate::error::{Error, Result};
use crate::geometry_image::lattice::MAX_LATTICE_SIDE;
use crate::geometry_image::Lattice;
use crate::stream::bytes::{ByteReader, ByteWriter};

/// The version of the set-up part this build writes and reads (2: the ranges part entropy-coded,
/// `geometry_image::range_coding`; 3: lattice coordinates guessed from the nearest group of
/// coded neighbours, `stream::lattice_coding`; 4: a guessed vertex coded as its rank among the free
/// pixels around the guess).
const VERSION: u8 = 4;

/// A geometry-video stream's set-up.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PictureSetup {
    /// Lattice width and height in pixels.
    pub lattice: (u16, u16),
    /// The codec's own quantiser: JPEG quality, MPEG-4 qscale, HEVC QP or AV1 `crf`.
    pub quantiser: u8,
    /// Frames per group of pictures (1: every frame alone).
    pub gop: u32,
    /// Bits a sample of the pictures.
    pub depth: u8,
    /// The padding the encoder used (the decoder does not pad; `inspect` redoes it).
    pub padding: padding::Method,
    /// Charts in the atlas.
    pub charts: u32,
    /// Lattice pixels covered by chart blocks.
    pub chart_pixels: u32,
    /// The picture codec's own bytes: the rest of the part.
    pub codec_data: Vec<u8>,
}

impl PictureSetup {
    /// The payload of the part.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = ByteWriter::new();
        w.u8(VERSION)
            .u16(self.lattice.0)
            .u16(self.lattice.1)
            .u8(self.quantiser)
            .u32(self.gop)
            .u8(self.depth)
            .blob(self.padding.name().as_bytes())
            .u32(self.charts)
            .u32(self.chart_pixels)
            .raw(&self.codec_data);
        w.into_bytes()
    }

    /// Parses and checks a set-up part of a stream of `vertices` vertices: the lattice must give
    /// every vertex its own pixel, and be one the encoder makes.
    pub fn from_bytes(bytes: &[u8], vertices: u32) -> Result<Self> {
        let mut r = ByteReader::new(bytes, "picture set-up");
        let version = r.u8()?;
        if version != VERSION {
            return Err(Error::Stream(format!(
                "picture set-up version {version}; this build reads version {VERSION}"
            )));
        }
        let lattice = (r.u16()?, r.u16()?);
        let (quantiser, gop, depth) = (r.u8()?, r.u32()?, r.u8()?);
        let name = String::from_utf8_lossy(r.blob()?).into_owned();
        let padding = name
            .parse()
            .map_err(|e| Error::Stream(format!("picture set-up: padding {name}: {e}")))?;
        let setup = Self {
            lattice,
            quantiser,
            gop,
            depth,
            padding,
            charts: r.u32()?,
            chart_pixels: r.u32()?,
            codec_data: r.take(r.remaining())?.to_vec(),
        };
        r.finish()?;
        setup.check(vertices)?;
        Ok(setup)
    }

    /// Refuses a lattice too small for the vertices or not one the encoder makes, no groups, and
    /// depths the codecs do not code.
    fn check(&self, vertices: u32) -> Result<()> {
        let (w, h) = self.lattice;
        let side = |s: u16| s != 0 && s % 16 == 0 && s <= MAX_LATTICE_SIDE;
        if !(side(w) && side(h)) {
            return Err(Error::Stream(format!(
                "lattice {w}x{h} is not a multiple of 16 between 16 and {MAX_LATTICE_SIDE}"
            )));
        }
        if u64::from(vertices) > u64::from(w) * u64::from(h) {
            return Err(Error::Stream(format!(
                "the stream has {vertices} vertices, more than the {w}x{h} lattice has pixels"
            )));
        }
        if self.gop == 0 || !matches!(self.depth, 8 | 10 | 12) {
            return Err(Error::Stream(format!(
                "picture set-up: {} frames a group at {} bits a sample",
                self.gop, self.depth
            )));
        }
        Ok(())
    }

    /// Chart pixels over lattice pixels.
    pub fn packing_efficiency(&self) -> f64 {
        let pixels = f64::from(self.lattice.0) * f64::from(self.lattice.1);
        f64::from(self.chart_pixels) / pixels.max(1.0)
    }

    /// The plan that made these pictures (for redoing the encoder's images).
    pub fn plan(&self, codec: Codec) -> PicturePlan {
        PicturePlan {
            codec,
            quantiser: self.quantiser,
            gop: self.gop as usize,
            depth: self.depth,
            padding: self.padding,
            lattice: Lattice::Fixed(self.lattice.0, self.lattice.1),
            deeper: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> PictureSetup {
        PictureSetup {
            lattice: (256, 256),
            quantiser: 4,
            gop: 50,
            depth: 8,
            padding: padding::Method::Cg,
            charts: 31,
            chart_pixels: 40_000,
            codec_data: vec![1, 2, 3],
        }
    }

    #[test]
    fn round_trips_and_refuses_a_cut_before_the_codec_bytes() {
        let setup = sample();
        let bytes = setup.to_bytes();
        assert_eq!(PictureSetup::from_bytes(&bytes, 3030).unwrap(), setup);
        // The codec's bytes are the rest of the part (its CRC guards them): a cut before them is
        // an error.
        for cut in 0..bytes.len() - setup.codec_data.len() {
            assert!(PictureSetup::from_bytes(&bytes[..cut], 3030).is_err());
        }
        let mut newer = bytes;
        newer[0] = VERSION + 1;
        assert!(PictureSetup::from_bytes(&newer, 3030).is_err());
    }

    #[test]
    fn the_lattice_must_hold_every_vertex_and_be_one_the_encoder_makes() {
        for lattice in [(0, 256), (256, 0), (250, 256), (4112, 16)] {
            let bad = PictureSetup {
                lattice,
                ..sample()
            };
            assert!(PictureSetup::from_bytes(&bad.to_bytes(), 3030).is_err());
        }
        let small = PictureSetup {
            lattice: (16, 16),
            ..sample()
        };
        assert!(PictureSetup::from_bytes(&small.to_bytes(), 257).is_err());
        assert!(PictureSetup::from_bytes(&small.to_bytes(), 256).is_ok());
        for (gop, depth) in [(0, 8), (50, 9), (50, 16)] {
            let bad = PictureSetup {
                gop,
                depth,
                ..sample()
            };
            assert!(PictureSetup::from_bytes(&bad.to_bytes(), 3030).is_err());
        }
    }
}
