//! The temporal transform and quantiser of `--codec tdct`: each vertex/axis residual sequence
//! through an orthonormal DCT-II over all frames (so that squared error in the coefficients equals
//! squared error in time), then one uniform step with a dead zone. [`super::coefficients`] codes the
//! levels.

use super::coefficients::MAX_LEVEL;
use crate::error::{Error, Result};
use rustdct::DctPlanner;

/// The dead-zone offset θ of the quantiser: level = sign(c)·⌊|c|/Δ + 0.5 − θ⌋. Only the encoder
/// uses it (the decoder reconstructs level·Δ). The encoder rounds by rate and distortion instead;
/// 0.15, the best θ against plain rounding, is the baseline that rounding is measured against,
/// and the automatic choice's estimates use it (one pass, no rate–distortion pricing)
/// (`measure_dead_zone`, `measure_rounding` in `tests/it/tdct.rs`;
/// docs/design.md, "Temporal-DCT coder (rounding, contexts, spatial prediction)").
pub const DEAD_ZONE: f64 = 0.15;

/// The orthonormal DCT-II of every vertex/axis residual sequence, band-major: `out[k][3v + a]` is
/// coefficient k of vertex v's axis a. `residuals[f][v]` is frame f's residual of vertex v.
pub fn forward(residuals: &[Vec<[f32; 3]>]) -> Result<Vec<Vec<f64>>> {
    let frames = residuals.len();
    let vertices = residuals.first().map_or(0, Vec::len);
    if frames == 0 || residuals.iter().any(|r| r.len() != vertices) {
        return Err(Error::Codec(
            "temporal DCT: residual frames differ in vertex count".into(),
        ));
    }
    let dct = DctPlanner::new().plan_dct2(frames);
    let mut scratch = vec![0.0f64; dct.get_scratch_len()];
    let (s0, sk) = orthonormal_scales(frames);
    let mut out = vec![vec![0.0f64; 3 * vertices]; frames];
    // Vertices a block at a time: each frame's slice of the block is read once, contiguously, and
    // each band's written once, instead of one scattered value per frame and sequence (the
    // gather was most of this function's time). The transforms see the same values either way.
    let mut tile = vec![0.0f64; frames * 3 * BLOCK];
    let mut buf = vec![0.0f64; frames];
    for first in (0..vertices).step_by(BLOCK) {
        let count = (vertices - first).min(BLOCK);
        let width = 3 * count;
        for (row, r) in tile.chunks_exact_mut(3 * BLOCK).zip(residuals) {
            for (t, p) in row.chunks_exact_mut(3).zip(&r[first..first + count]) {
                for (t, &x) in t.iter_mut().zip(p) {
                    *t = f64::from(x);
                }
            }
        }
        for j in 0..width {
            for (b, row) in buf.iter_mut().zip(tile.chunks_exact(3 * BLOCK)) {
                *b = row[j];
            }
            dct.process_dct2_with_scratch(&mut buf, &mut scratch);
            for (row, &c) in tile.chunks_exact_mut(3 * BLOCK).zip(&buf) {
                row[j] = c;
            }
        }
        for (k, (band, row)) in out.iter_mut().zip(tile.chunks_exact(3 * BLOCK)).enumerate() {
            let scale = if k == 0 { s0 } else { sk };
            for (o, &c) in band[3 * first..3 * first + width].iter_mut().zip(row) {
                *o = c * scale;
            }
        }
    }
    Ok(out)
}

/// Vertices per block of [`forward`].
const BLOCK: usize = 16;

/// `rustdct` does not normalise: these turn its DCT-II output into the orthonormal transform
/// (√(1/F) for the DC term, √(2/F) for the others).
fn orthonormal_scales(frames: usize) -> (f64, f64) {
    let f = frames as f64;
    ((1.0 / f).sqrt(), (2.0 / f).sqrt())
}

/// Value of orthonormal DCT basis function `k` at frame `n` of `frames`.
///
/// Written out because random access needs one output sample of the inverse transform, which
/// `rustdct` (whole-buffer transforms only) does not offer; `decode_all` uses `rustdct`'s DCT-III.
pub fn basis(k: usize, n: usize, frames: usize) -> f64 {
    let (s0, sk) = orthonormal_scales(frames);
    if k == 0 {
        s0
    } else {
        let angle = std::f64::consts::PI * k as f64 * (2 * n + 1) as f64 / (2 * frames) as f64;
        sk * angle.cos()
    }
}

/// The inverse of [`forward`] for one sequence: orthonormal coefficients in, `frames` samples out
/// (`coefficients` shorter than `frames` is zero-extended).
pub struct Inverse {
    dct: std::sync::Arc<dyn rustdct::TransformType2And3<f64>>,
    frames: usize,
    buf: Vec<f64>,
}

impl Inverse {
    /// An inverse transform of length `frames` (≥ 1).
    pub fn new(frames: usize) -> Self {
        Self {
            dct: DctPlanner::new().plan_dct3(frames.max(1)),
            frames: frames.max(1),
            buf: vec![0.0; frames.max(1)],
        }
    }

    /// The time samples of the orthonormal coefficients `c(k)`, k in 0..frames.
    pub fn run(&mut self, c: impl Fn(usize) -> f64) -> &[f64] {
        let (s0, sk) = orthonormal_scales(self.frames);
        // rustdct's DCT-III is x_n = Y_0/2 + Σ Y_k cos(…): Y_0 = 2·c_0·√(1/F), Y_k = c_k·√(2/F).
        for (k, y) in self.buf.iter_mut().enumerate() {
            *y = c(k) * if k == 0 { 2.0 * s0 } else { sk };
        }
        self.dct.process_dct3(&mut self.buf);
        &self.buf
    }
}

#[cfg(any(test, feature = "internals"))]
/// Uniform quantisation with step `step` and dead-zone offset `dead_zone` (0 = plain rounding).
pub fn quantise(coefficients: &[Vec<f64>], step: f64, dead_zone: f64) -> Result<Vec<Vec<i64>>> {
    coefficients
        .iter()
        .map(|band| quantise_band(band, step, dead_zone))
        .collect()
}

/// [`quantise`] of one band: the coders quantise a band at a time, so that a clip's levels are
/// never all held beside its coefficients (for a 50 000-vertex segment of 125 frames, 150 MB).
pub fn quantise_band(band: &[f64], step: f64, dead_zone: f64) -> Result<Vec<i64>> {
    if !(step.is_finite() && step > 0.0) {
        return Err(Error::Usage(format!(
            "temporal-DCT step {step} must be a positive number"
        )));
    }
    // Filled to its known length: collecting `Result`s cannot size the vector ahead, and its
    // doubling left a band's levels 1.7 times their bytes on average.
    let mut levels = Vec::with_capacity(band.len());
    for &c in band {
        let m = (c.abs() / step + 0.5 - dead_zone).floor().max(0.0);
        if m > MAX_LEVEL {
            return Err(Error::Usage(format!(
                "temporal-DCT step {step} is too fine for coefficient {c}"
            )));
        }
        levels.push(if c < 0.0 { -(m as i64) } else { m as i64 });
    }
    Ok(levels)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dead_zone_only_shrinks_levels() {
        let c = vec![vec![0.69, -0.71, 1.49, 0.3]];
        assert_eq!(quantise(&c, 1.0, 0.0).unwrap()[0], vec![1, -1, 1, 0]);
        assert_eq!(quantise(&c, 1.0, 0.2).unwrap()[0], vec![0, -1, 1, 0]);
        assert!(quantise(&c, 0.0, 0.2).is_err());
        assert!(quantise(&c, 1e-300, 0.2).is_err());
    }
}
