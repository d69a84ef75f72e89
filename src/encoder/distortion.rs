//! Rate and distortion of a candidate stream, for the automatic choice ([`super::auto`]).
//!
//! The candidates of a choice are coded at one quality, hence one step, but a picture codec's
//! error at that step is not the same for each: where a candidate's residuals outgrow the sample
//! range, its step is widened for that frame or group (`geometry_image::quantise`), so it spends
//! fewer bits *and* misses the quality's error. Comparing bytes alone then keeps the coarser
//! stream (docs/design.md, "Automatic choice: bits at equal error"). So the choice compares bits
//! at equal error: each candidate's vertex RMSE is measured by decoding its stream, and its cost is
//! the rate it would need at a common error on a rate–distortion curve of slope −[`RD_SLOPE`] in
//! log-log (RMSE ∝ rate^−RD_SLOPE), i.e. the candidate with the least `bits × RMSE^(1/RD_SLOPE)`
//! is kept.

use super::Encoded;
use crate::decoder::Decoder;
use crate::error::{Error, Result};
use crate::mesh::AnimatedMesh;
use crate::metrics;

/// The log-log slope of the codecs' rate–distortion curves the choice assumes: RMSE ∝
/// rate^−RD_SLOPE, within the range the picture codecs' curves measure. A flatter assumed slope
/// weighs error more and keeps larger streams than their error is worth
/// (docs/design.md, "Automatic choice: bits at equal error").
pub const RD_SLOPE: f64 = 2.0;

/// The vertex RMSE of a whole encoding of `mesh` ([`vertex_rmse`]) and its [`cost`]: what two
/// encodings coded whole are compared by.
pub fn whole_cost(mesh: &AnimatedMesh, encoded: &Encoded) -> Result<(f64, f64)> {
    let rmse = vertex_rmse(mesh, encoded)?;
    Ok((cost(8.0 * encoded.report.bytes as f64, Some(rmse)), rmse))
}

/// RMS distance over frames and vertices between `mesh` (in the stream's vertex order) and
/// `encoded` as the decoder reconstructs it, in model units ([`metrics::vertex_errors`], what
/// `eval` reports as vertex RMSE before normalising).
pub fn vertex_rmse(mesh: &AnimatedMesh, encoded: &Encoded) -> Result<f64> {
    stream_rmse(mesh, &encoded.to_bytes())
}

/// [`vertex_rmse`] of a stream's bytes.
pub fn stream_rmse(mesh: &AnimatedMesh, bytes: &[u8]) -> Result<f64> {
    let decoded = Decoder::new(bytes)?.decode_all()?;
    let errors = metrics::vertex_errors(mesh, &decoded).ok_or_else(|| {
        Error::Codec(format!(
            "a trial stream decoded to {} frames of {} vertices for {} of {}",
            decoded.frame_count(),
            decoded.vertex_count(),
            mesh.frame_count(),
            mesh.vertex_count()
        ))
    })?;
    Ok(errors.rmse)
}

/// A candidate's cost, compared between candidates (lower is better): `log2(bits)` plus
/// `log2` of its RMS error ([`vertex_rmse`]) over [`RD_SLOPE`]. A difference of one is twice the
/// bits at equal error. Without an error (tdct's candidates), the bits alone.
pub fn cost(bits: f64, rmse: Option<f64>) -> f64 {
    let rate = bits.max(1.0).log2();
    match rmse {
        Some(e) => rate + e.max(f64::MIN_POSITIVE).log2() / RD_SLOPE,
        None => rate,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_larger_stream_wins_only_with_an_error_lower_than_the_curve_gives() {
        let base = cost(8000.0, Some(1.0));
        // Twice the bits at a quarter of the RMSE (slope 2): a tie.
        assert!((cost(16000.0, Some(0.25)) - base).abs() < 1e-12);
        // 57 % more bits for 39 % less RMSE loses (horse-gallop, AV1 quality 10); so do 30 %
        // more for 30 % less (walking cat, AV1 quality 30).
        assert!(cost(12560.0, Some(0.61)) > base);
        assert!(cost(10400.0, Some(0.70)) > base);
        // 16 % more bits for 44 % less RMSE wins (horse-gallop, AV1 quality 70).
        assert!(cost(9280.0, Some(0.56)) < base);
        assert_eq!(cost(7920.0, None), 7920f64.log2());
        assert!(cost(1.0, Some(0.0)).is_finite());
    }
}
