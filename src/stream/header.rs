//! The stream header: everything the decoder must know before it reads any other part.

use crate::codec::Codec;
use crate::error::{Error, Result};
use crate::motion::PredictorKind;
use crate::stream::bytes::{ByteReader, ByteWriter};

/// Stream parameters.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Header {
    /// Vertices per frame `V`.
    pub vertices: u32,
    /// Frames `F`.
    pub frames: u32,
    /// Triangles of the shared connectivity.
    pub triangles: u32,
    /// Motion clusters `K`.
    pub clusters: u32,
    /// Geometry-image lattice width in pixels (0 for tdct, which has no images).
    pub lattice_width: u16,
    /// Geometry-image lattice height in pixels (0 for tdct).
    pub lattice_height: u16,
    /// The residual image codec.
    pub codec: Codec,
    /// The `--quality` the stream was made with (1..100).
    pub quality: u8,
    /// The picture codec's own quantiser: MPEG-4 qscale, JPEG quality, HEVC QP (0 for tdct streams).
    pub qscale: u8,
    /// Frames per group of pictures (MPEG-4: an I-frame starts each group; JPEG: 1).
    pub gop: u32,
    /// The affine coefficients' step as a multiple of the residual step, in sixteenths (16 = 1):
    /// the encoder's `affine_precision` (the affine part stores the step itself).
    pub affine_precision: u8,
    /// Bits per coordinate of the first frame's geometry.
    pub first_frame_bits: u8,
    /// Name of the padding method the encoder used (informational: the decoder does not pad).
    pub padding: String,
    /// The `--clusters` asked for (segmentation may use fewer); lets `inspect` re-run the analysis.
    pub requested_clusters: u32,
    /// Whether the first-frame coder was allowed to reorder vertices.
    pub reorder: bool,
    /// Charts in the atlas (informational).
    pub charts: u32,
    /// Lattice pixels covered by chart blocks (informational: packing efficiency).
    pub chart_pixels: u32,
    /// The source's frames per second (0: unknown, e.g. OBJ sequences): glTF output plays at it.
    pub frame_rate: f32,
    /// The motion predictor: piecewise affine, or skinning (then a weights part follows).
    pub predictor: PredictorKind,
}

fn predictor_id(p: PredictorKind) -> u8 {
    match p {
        PredictorKind::Affine => 0,
        PredictorKind::Skinning => 1,
    }
}

fn predictor_from_id(id: u8) -> Result<PredictorKind> {
    match id {
        0 => Ok(PredictorKind::Affine),
        1 => Ok(PredictorKind::Skinning),
        _ => Err(Error::Stream(format!("unknown predictor id {id}"))),
    }
}

/// Upper bound on any count in the header, far above any real animation and far below what would let
/// a forged header exhaust memory before the parts' real sizes are checked.
const MAX_COUNT: u32 = 1 << 28;

/// Largest lattice side the encoder makes (and the decoder accepts): a forged header cannot make the
/// image decoders allocate pictures of 3 × 65535 × 65535 bytes.
pub const MAX_LATTICE_SIDE: u16 = 4096;

impl Header {
    /// Packing efficiency of the atlas: chart pixels / lattice pixels (0 without a lattice).
    pub fn packing_efficiency(&self) -> f64 {
        let pixels = self.lattice_width as f64 * self.lattice_height as f64;
        if pixels > 0.0 {
            self.chart_pixels as f64 / pixels
        } else {
            0.0
        }
    }

    /// Serialises the header.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = ByteWriter::new();
        w.u32(self.vertices)
            .u32(self.frames)
            .u32(self.triangles)
            .u32(self.clusters)
            .u16(self.lattice_width)
            .u16(self.lattice_height)
            .u8(self.codec.id())
            .u8(self.quality)
            .u8(self.qscale)
            .u32(self.gop)
            .u8(self.affine_precision)
            .u8(self.first_frame_bits)
            .blob(self.padding.as_bytes())
            .u32(self.requested_clusters)
            .u8(self.reorder as u8)
            .u32(self.charts)
            .u32(self.chart_pixels)
            .f32(self.frame_rate);
        // The predictor byte is written only when it is not the affine default, so affine streams
        // stay byte-identical to (and readable by) builds from before the skinning predictor, and
        // those builds refuse a skinning stream (trailing header bytes) instead of mispredicting it.
        if self.predictor != PredictorKind::Affine {
            w.u8(predictor_id(self.predictor));
        }
        w.into_bytes()
    }

    /// Parses and sanity-checks a header.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self> {
        let mut r = ByteReader::new(bytes, "header");
        let h = Header {
            vertices: r.u32()?,
            frames: r.u32()?,
            triangles: r.u32()?,
            clusters: r.u32()?,
            lattice_width: r.u16()?,
            lattice_height: r.u16()?,
            codec: Codec::from_id(r.u8()?)?,
            quality: r.u8()?,
            qscale: r.u8()?,
            gop: r.u32()?,
            affine_precision: r.u8()?,
            first_frame_bits: r.u8()?,
            padding: String::from_utf8_lossy(r.blob()?).into_owned(),
            requested_clusters: r.u32()?,
            reorder: r.u8()? != 0,
            charts: r.u32()?,
            chart_pixels: r.u32()?,
            frame_rate: r.f32()?,
            predictor: if r.remaining() > 0 {
                predictor_from_id(r.u8()?)?
            } else {
                PredictorKind::Affine
            },
        };
        r.finish()?;
        h.check_counts()?;
        h.check_lattice()?;
        h.check_quantisation()?;
        if !(h.frame_rate.is_finite() && h.frame_rate >= 0.0) {
            return Err(Error::Stream(format!(
                "header frame rate {} is not a non-negative number",
                h.frame_rate
            )));
        }
        Ok(h)
    }

    /// Refuses element counts past the limits or inconsistent with one another.
    fn check_counts(&self) -> Result<()> {
        let h = self;
        for (what, n) in [
            ("vertices", h.vertices),
            ("frames", h.frames),
            ("triangles", h.triangles),
            ("clusters", h.clusters),
        ] {
            if n > MAX_COUNT {
                return Err(Error::Stream(format!(
                    "header claims {n} {what} (limit {MAX_COUNT})"
                )));
            }
        }
        if h.vertices == 0 || h.frames == 0 || h.clusters == 0 || h.clusters > h.vertices {
            return Err(Error::Stream(format!(
                "header is inconsistent: {} vertices, {} frames, {} clusters",
                h.vertices, h.frames, h.clusters
            )));
        }
        Ok(())
    }

    /// Refuses a lattice the codec cannot have, or one too small for the vertices.
    fn check_lattice(&self) -> Result<()> {
        let h = self;
        if !h.codec.has_images() {
            // No images, so no lattice: a lattice here means the header is not what it claims.
            if h.lattice_width != 0 || h.lattice_height != 0 || h.charts != 0 {
                return Err(Error::Stream(format!(
                    "a {} stream has no lattice, but the header gives {}x{} with {} charts",
                    h.codec.name(),
                    h.lattice_width,
                    h.lattice_height,
                    h.charts
                )));
            }
        } else if h.lattice_width == 0
            || h.lattice_height == 0
            || h.lattice_width % 16 != 0
            || h.lattice_height % 16 != 0
            || h.lattice_width > MAX_LATTICE_SIDE
            || h.lattice_height > MAX_LATTICE_SIDE
        {
            return Err(Error::Stream(format!(
                "lattice {}x{} is not a multiple of 16 between 16 and {MAX_LATTICE_SIDE}",
                h.lattice_width, h.lattice_height
            )));
        }
        // Every vertex has its own lattice pixel.
        if h.codec.has_images()
            && u64::from(h.vertices) > u64::from(h.lattice_width) * u64::from(h.lattice_height)
        {
            return Err(Error::Stream(format!(
                "header claims {} vertices, more than the {}x{} lattice has pixels",
                h.vertices, h.lattice_width, h.lattice_height
            )));
        }
        Ok(())
    }

    /// Refuses quantisation parameters outside what the coders accept.
    fn check_quantisation(&self) -> Result<()> {
        if self.affine_precision == 0 || !(1..=24).contains(&self.first_frame_bits) || self.gop == 0
        {
            return Err(Error::Stream(
                "header has out-of-range quantisation parameters".into(),
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Header {
        Header {
            vertices: 3030,
            frames: 400,
            triangles: 5664,
            clusters: 20,
            lattice_width: 256,
            lattice_height: 256,
            codec: Codec::Mpeg4,
            quality: 75,
            qscale: 4,
            gop: 50,
            affine_precision: 16,
            first_frame_bits: 12,
            padding: "cg".into(),
            requested_clusters: 20,
            reorder: false,
            charts: 31,
            chart_pixels: 40_000,
            frame_rate: 24.0,
            predictor: PredictorKind::Affine,
        }
    }

    #[test]
    fn round_trip() {
        let h = sample();
        assert_eq!(Header::from_bytes(&h.to_bytes()).unwrap(), h);
        let skin = Header {
            predictor: PredictorKind::Skinning,
            ..sample()
        };
        let bytes = skin.to_bytes();
        assert_eq!(bytes.len(), h.to_bytes().len() + 1);
        assert_eq!(Header::from_bytes(&bytes).unwrap(), skin);
        let mut unknown = bytes;
        if let Some(last) = unknown.last_mut() {
            *last = 7;
        }
        assert!(Header::from_bytes(&unknown).is_err());
    }

    fn tdct() -> Header {
        Header {
            lattice_width: 0,
            lattice_height: 0,
            codec: Codec::Tdct,
            qscale: 0,
            gop: 1,
            padding: "none".into(),
            charts: 0,
            chart_pixels: 0,
            ..sample()
        }
    }

    #[test]
    fn lattice_checks_follow_the_codec() {
        let t = tdct();
        assert_eq!(Header::from_bytes(&t.to_bytes()).unwrap(), t);
        assert_eq!(t.packing_efficiency(), 0.0);
        // tdct has no lattice: any lattice (or chart) is refused …
        for bad in [
            Header {
                lattice_width: 256,
                lattice_height: 256,
                ..tdct()
            },
            Header {
                lattice_height: 16,
                ..tdct()
            },
            Header {
                charts: 3,
                ..tdct()
            },
        ] {
            assert!(Header::from_bytes(&bad.to_bytes()).is_err());
        }
        // … and the image codecs still need one that holds every vertex.
        for codec in [Codec::Jpeg, Codec::Mpeg4] {
            let none = Header {
                codec,
                lattice_width: 0,
                lattice_height: 0,
                ..sample()
            };
            assert!(Header::from_bytes(&none.to_bytes()).is_err());
            let small = Header {
                codec,
                lattice_width: 16,
                lattice_height: 16,
                ..sample()
            };
            assert!(Header::from_bytes(&small.to_bytes()).is_err());
        }
    }

    #[test]
    fn refuses_absurd_counts_before_allocating() {
        let mut h = sample();
        h.vertices = 1_000_000_000;
        assert!(Header::from_bytes(&h.to_bytes()).is_err());
        let mut h = sample();
        h.clusters = 0;
        assert!(Header::from_bytes(&h.to_bytes()).is_err());
        let bytes = sample().to_bytes();
        for cut in 0..bytes.len() {
            assert!(Header::from_bytes(&bytes[..cut]).is_err());
        }
    }
}
