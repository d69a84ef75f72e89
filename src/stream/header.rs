//! The stream header: what every decoder must know before it reads any other part, whatever the
//! residual codec. A codec's own fields are in its set-up part, not here.

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
    /// The residual codec's stream id (`codec::Codec::id`).
    pub codec: u8,
    /// The `--quality` the stream was made with (1..100).
    pub quality: u8,
    /// The affine coefficients' step as a multiple of the residual step, in sixteenths (16 = 1):
    /// the encoder's `affine_precision` (the affine part stores the step itself).
    pub affine_precision: u8,
    /// Bits per coordinate of the first frame's geometry.
    pub first_frame_bits: u8,
    /// The `--clusters` asked for (segmentation may use fewer).
    pub requested_clusters: u32,
    /// Whether the first-frame coder was allowed to reorder vertices.
    pub reorder: bool,
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

impl Header {
    /// Serialises the header.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = ByteWriter::new();
        w.u32(self.vertices)
            .u32(self.frames)
            .u32(self.triangles)
            .u32(self.clusters)
            .u8(self.codec)
            .u8(self.quality)
            .u8(self.affine_precision)
            .u8(self.first_frame_bits)
            .u32(self.requested_clusters)
            .u8(self.reorder as u8)
            .f32(self.frame_rate)
            .u8(predictor_id(self.predictor));
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
            codec: r.u8()?,
            quality: r.u8()?,
            affine_precision: r.u8()?,
            first_frame_bits: r.u8()?,
            requested_clusters: r.u32()?,
            reorder: r.u8()? != 0,
            frame_rate: r.f32()?,
            predictor: predictor_from_id(r.u8()?)?,
        };
        r.finish()?;
        h.check_counts()?;
        if h.affine_precision == 0 || !(1..=24).contains(&h.first_frame_bits) {
            return Err(Error::Stream(
                "header has out-of-range quantisation parameters".into(),
            ));
        }
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
            codec: 1,
            quality: 75,
            affine_precision: 16,
            first_frame_bits: 12,
            requested_clusters: 20,
            reorder: false,
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
        let mut bytes = skin.to_bytes();
        assert_eq!(Header::from_bytes(&bytes).unwrap(), skin);
        if let Some(last) = bytes.last_mut() {
            *last = 7;
        }
        assert!(Header::from_bytes(&bytes).is_err());
    }

    #[test]
    fn refuses_absurd_counts_and_quantisers_before_allocating() {
        let mut h = sample();
        h.vertices = 1_000_000_000;
        assert!(Header::from_bytes(&h.to_bytes()).is_err());
        let mut h = sample();
        h.clusters = 0;
        assert!(Header::from_bytes(&h.to_bytes()).is_err());
        let mut h = sample();
        h.first_frame_bits = 25;
        assert!(Header::from_bytes(&h.to_bytes()).is_err());
        let bytes = sample().to_bytes();
        for cut in 0..bytes.len() {
            assert!(Header::from_bytes(&bytes[..cut]).is_err());
        }
        let mut longer = bytes;
        longer.push(0);
        assert!(Header::from_bytes(&longer).is_err());
    }
}
