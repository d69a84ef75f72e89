//! Rate and distortion of a candidate stream, for the automatic choice ([`super::auto`]).
//!
//! The candidates of a choice are coded at one quality, hence one step, but a picture codec's
//! error at that step is not the same for each: where a candidate's residuals outgrow the sample
//! range, its step is widened for that frame or group (`geometry_image::quantise`), so it spends
//! fewer bits *and* misses the quality's error. Comparing bytes alone then keeps the coarser
//! stream (measured: horse-gallop, AV1 quality 70 with 1/4 affine precision kept affine maps on
//! k-means, 206 382 bytes at vertex RMSE 5.9e-4, over skinning on decimation, 239 334 bytes at
//! 3.3e-4). So the choice compares bits at equal error: each
//! candidate's squared error is measured by decoding its stream, and its cost is where it would
//! land at a common error on a rate–distortion curve of slope −[`RMSE_EXPONENT`] in log-log
//! (the RMSE falls as a power of the rate), i.e. the candidate with the least
//! `bits × RMSE^RMSE_EXPONENT` is kept.

use super::Encoded;
use crate::decoder::Decoder;
use crate::error::{Error, Result};
use crate::mesh::AnimatedMesh;

/// The log-log slope of the codecs' rate–distortion curves the choice assumes: RMSE ∝
/// rate^−RMSE_EXPONENT. The picture codecs' curves between qualities 30 and 75 measure 1.0 (JPEG
/// on horse-gallop) to 2.5 (MPEG-4 on the walking cat); the flattest keeps a larger stream only
/// when its error is lower in at least the same proportion, which every measured curve confirms,
/// and the bits alone (slope 0) misranked candidates by up to 1.7× in error.
pub const RMSE_EXPONENT: f64 = 1.0;

/// Sum over frames and vertices of the squared distance between `mesh` (in the stream's vertex
/// order) and `encoded` as the decoder reconstructs it, in model units.
pub fn squared_error(mesh: &AnimatedMesh, encoded: &Encoded) -> Result<f64> {
    let bytes = encoded.to_bytes();
    let decoded = Decoder::new(&bytes)?.decode_all()?;
    if decoded.frame_count() != mesh.frame_count() || decoded.vertex_count() != mesh.vertex_count()
    {
        return Err(Error::Codec(format!(
            "a trial stream decoded to {} frames of {} vertices for {} of {}",
            decoded.frame_count(),
            decoded.vertex_count(),
            mesh.frame_count(),
            mesh.vertex_count()
        )));
    }
    let sum = mesh
        .frames()
        .iter()
        .zip(decoded.frames())
        .flat_map(|(a, b)| a.iter().zip(b))
        .map(|(p, q)| (0..3).map(|c| f64::from(p[c] - q[c]).powi(2)).sum::<f64>())
        .sum();
    Ok(sum)
}

/// A candidate's cost, compared between candidates (lower is better): `log2(bits)` plus
/// [`RMSE_EXPONENT`] × `log2` of its RMS error (from `squared_error`; the vertex count cancels). A
/// difference of one is twice the bits at equal error. Without an error (a sampled trial), the
/// bits alone.
pub fn cost(bits: f64, squared_error: Option<f64>) -> f64 {
    let rate = bits.max(1.0).log2();
    match squared_error {
        Some(e) => rate + 0.5 * RMSE_EXPONENT * e.max(f64::MIN_POSITIVE).log2(),
        None => rate,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_larger_stream_wins_only_with_a_lower_error_in_at_least_the_same_proportion() {
        let base = cost(8000.0, Some(1.0));
        // Twice the bits at half the RMSE (a quarter of the squared error): a tie.
        assert!((cost(16000.0, Some(0.25)) - base).abs() < 1e-12);
        // 30 % more bits for 12.5 % less RMSE loses (horse-gallop, AV1 quality 30).
        assert!(cost(10400.0, Some(0.875f64.powi(2))) > base);
        // 16 % more bits for 44 % less RMSE wins (horse-gallop, AV1 quality 70).
        assert!(cost(9280.0, Some(0.56f64.powi(2))) < base);
        assert_eq!(cost(7920.0, None), 7920f64.log2());
        assert!(cost(1.0, Some(0.0)).is_finite());
    }
}
