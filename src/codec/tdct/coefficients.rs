//! Temporal-DCT residual coding (`--codec tdct`, skinning paper §3.3, eq. 12).
//!
//! Each vertex's prediction residuals along x, y and z are three sequences over all F frames; each
//! is transformed by an orthonormal DCT-II (so that squared error in the coefficients equals squared
//! error in time), quantised with one uniform step, and coded frequency-major: band k holds
//! coefficient k of every vertex (x, y, z of each vertex, the vertices in the breadth-first order of
//! [`Neighbourhood`], each level possibly predicted from its neighbours: [`super::spatial`]). Every band is its own
//! byte-aligned chunk with its own range coder, while the adaptive models carry over from band to
//! band, so any prefix of the bands decodes to a coarser animation.
//!
//! The index part ([`super::index::BandIndex`]) holds the step and, per band, its byte length and CRC-32; a band
//! of length 0 is all zero and costs no coded bytes at all.

use super::spatial::{Around, Neighbourhood, Spatial};
use crate::error::{Error, Result};
use crate::stream::entropy::{self, BitModel, SignedModels, SymbolCoder, UIntModel};
use std::sync::Arc;

#[cfg(any(test, feature = "internals"))]
pub use super::transform::DEAD_ZONE;
#[cfg(any(test, feature = "internals"))]
pub use super::transform::quantise;
pub use super::transform::{basis, forward, quantise_band, Inverse};

/// Frequency classes of the context model: band k is in class min(⌊log2(k+1)⌋, CLASSES − 1).
const CLASSES: usize = 8;

/// Magnitude classes of the context model ([`magnitude_class`]): 0, 1, 2, 3–4, 5–8, 9+, both for
/// the same vertex/axis's level in the previous band and for the neighbours' magnitude: the mean
/// of the largest level and the largest coded value (level minus prediction) of the same axis among
/// the vertex's neighbours coded before it in this band (without a spatial predictor, the level).
const MAGNITUDES: usize = 6;

/// Magnitude contexts per frequency class: previous-band magnitude × whether an earlier axis of the
/// same vertex is non-zero in this band × the neighbours' magnitude.
const CONTEXTS: usize = MAGNITUDES * 2 * MAGNITUDES;

/// Sign contexts per frequency class: the sign (−, 0, +) of the sum of the signs of the values the
/// vertex's earlier neighbours coded for the same axis in this band ([`Around::sign_class`]).
const SIGNS: usize = 3;

/// Largest level magnitude the encoder writes: far above any sensible step, far below where the
/// f64 → i64 conversion or the decoder's dequantisation lose meaning.
pub(super) const MAX_LEVEL: f64 = (1u64 << 40) as f64;

/// Rate–distortion rounding of the levels (encoder only; the decoder reads levels as ever): each
/// level is chosen among the two integers nearest the coefficient and zero by the squared error
/// in steps plus `lambda` × the bits the adaptive model would spend on it now.
pub struct Rounding<'a> {
    /// Each coefficient of the band divided by the step (`[3v + a]`).
    pub scaled: &'a [f64],
    /// The price of one bit in squared steps.
    pub lambda: f64,
}

impl Rounding<'_> {
    fn choose(&self, i: usize, prediction: i64, model: &SignedModels) -> i64 {
        let x = self.scaled[i];
        let below = x.floor() as i64;
        let price = |l: i64| {
            let e = x - l as f64;
            e * e + self.lambda * model.cost(l.wrapping_sub(prediction))
        };
        let mut best = (price(0), 0);
        // Zero is priced already (and is one of the two when |x| < 1); a tie keeps the earlier.
        for l in [below, below + 1].into_iter().filter(|&l| l != 0) {
            let p = price(l);
            if p < best.0 {
                best = (p, l);
            }
        }
        best.1
    }
}

/// The class of a level's magnitude in the context model: 0, 1, 2, 3–4, 5–8, 9+.
fn magnitude_class(magnitude: u64) -> usize {
    match magnitude {
        0..=2 => magnitude as usize,
        3..=4 => 3,
        5..=8 => 4,
        _ => MAGNITUDES - 1,
    }
}

/// The adaptive models of the coefficient coder, carried from band to band.
///
/// A level (minus its spatial prediction) is coded as a magnitude with one of `CONTEXTS` models
/// per frequency class and, when non-zero, a sign with one of `SIGNS`, chosen by what the decoder
/// already has: the same vertex/axis's level in the previous band, whether an earlier axis of the
/// same vertex is non-zero in this band, and the neighbours' magnitude (six classes each), and for
/// the sign, the signs the neighbours coded. The frequency class costs nothing and separates the DC
/// band, whose statistics differ. The contexts, the spatial predictor and its per-band choice are
/// each kept for the bytes they save at equal error (`measure_dead_zone` in `tests/it/tdct.rs`,
/// `measure_spatial` in `tests/it/tdct_spatial.rs`;
/// docs/design.md, "Temporal-DCT coder (rounding, contexts, spatial prediction)").
#[derive(Clone)]
pub struct BandCoder {
    /// Magnitude models, [`CONTEXTS`] per frequency class.
    magnitudes: Vec<UIntModel>,
    /// Sign models, [`SIGNS`] per frequency class.
    signs: Vec<BitModel>,
    /// min(|level|, 255) of each vertex/axis in the previous band: the decoder has it too.
    previous: Vec<u8>,
    /// The value each vertex/axis coded in the current band (its level minus the prediction);
    /// only the earlier neighbours' entries, written in this band, are ever read.
    coded: Vec<i64>,
    /// The coding order and the neighbours the spatial predictor reads.
    neighbourhood: Arc<Neighbourhood>,
    /// The band's spatial predictor.
    mode: BitModel,
}

impl BandCoder {
    /// Fresh models for the vertices of `neighbourhood`.
    pub fn new(neighbourhood: Arc<Neighbourhood>) -> Self {
        Self {
            magnitudes: vec![UIntModel::default(); CLASSES * CONTEXTS],
            signs: vec![BitModel::default(); CLASSES * SIGNS],
            previous: vec![0; 3 * neighbourhood.vertex_count()],
            coded: vec![0; 3 * neighbourhood.vertex_count()],
            neighbourhood,
            mode: BitModel::default(),
        }
    }

    /// Codes band `k` in either direction: `levels` is read by an encoder, filled by a decoder. An
    /// encoder given `rounding` first sets each level to the one it prices lowest.
    fn code<C: SymbolCoder>(
        &mut self,
        coder: &mut C,
        k: usize,
        spatial: Spatial,
        levels: &mut [i64],
        rounding: Option<&Rounding>,
    ) -> Result<()> {
        let class = ((k + 1).ilog2() as usize).min(CLASSES - 1);
        let magnitudes = &mut self.magnitudes[class * CONTEXTS..(class + 1) * CONTEXTS];
        let signs = &mut self.signs[class * SIGNS..(class + 1) * SIGNS];
        let spatial = Spatial::from_bit(u64::from(
            coder.bit(spatial == Spatial::Mean, &mut self.mode)?,
        ));
        for (v, earlier) in self.neighbourhood.visit() {
            let around = Around::of(levels, &self.coded, earlier);
            let mut sibling = 0;
            for a in 0..3 {
                let i = 3 * v + a;
                let prediction = match spatial {
                    Spatial::None => 0,
                    Spatial::Mean => around.mean(a),
                };
                let prev = magnitude_class(u64::from(self.previous[i]));
                // With the mean predictor the neighbours' coded values tell how well it predicts,
                // their levels how large the coefficients are; both help (see the struct's doc).
                let near = magnitude_class(around.magnitude(a));
                let model = SignedModels {
                    magnitude: &mut magnitudes[(prev * 2 + sibling) * MAGNITUDES + near],
                    sign: &mut signs[around.sign_class(a)],
                };
                if let Some(r) = rounding {
                    levels[i] = r.choose(i, prediction, &model);
                }
                let value = coder.signed_with(levels[i].wrapping_sub(prediction), model)?;
                self.coded[i] = value;
                levels[i] = value.wrapping_add(prediction);
                self.previous[i] = levels[i].unsigned_abs().min(255) as u8;
                sibling |= usize::from(levels[i] != 0);
            }
        }
        Ok(())
    }

    /// Notes an all-zero band, which is not coded, for the next band's contexts.
    fn skip(&mut self) {
        self.previous.fill(0);
    }

    /// Encodes band `k` with `spatial`: its chunk and the levels it holds.
    fn encode_with(
        &mut self,
        k: usize,
        spatial: Spatial,
        levels: &[i64],
        rounding: Option<&Rounding>,
    ) -> Result<(Vec<u8>, Vec<i64>)> {
        let mut enc = entropy::Encoder::new();
        let mut copy = levels.to_vec();
        self.code(&mut enc, k, spatial, &mut copy, rounding)?;
        Ok((enc.finish()?, copy))
    }

    #[cfg(any(test, feature = "internals"))]
    /// Encodes band `k` with the spatial predictor that codes it smallest: its chunk, empty when
    /// every level is zero.
    pub fn encode(&mut self, k: usize, levels: &[i64]) -> Result<Vec<u8>> {
        self.encode_among(k, levels, &Spatial::ALL)
    }

    /// Encodes band `k` with the spatial predictor of `candidates` that codes it smallest (the
    /// automatic choice's estimates and measurements).
    pub fn encode_among(
        &mut self,
        k: usize,
        levels: &[i64],
        candidates: &[Spatial],
    ) -> Result<Vec<u8>> {
        Ok(self.encode_band(k, levels, None, candidates)?.0)
    }

    /// Encodes band `k` choosing each level by rate and distortion (see [`Rounding`]), starting
    /// from `levels` (the band quantised without it, which only decides whether the band is empty):
    /// its chunk and the levels it holds, which the decoder will read.
    pub fn encode_rounded(
        &mut self,
        k: usize,
        levels: &[i64],
        rounding: &Rounding,
        candidates: &[Spatial],
    ) -> Result<(Vec<u8>, Vec<i64>)> {
        if rounding.scaled.len() != levels.len() {
            return Err(Error::Codec(format!(
                "band {k}: {} coefficients for {} levels",
                rounding.scaled.len(),
                levels.len()
            )));
        }
        self.encode_band(k, levels, Some(rounding), candidates)
    }

    fn encode_band(
        &mut self,
        k: usize,
        levels: &[i64],
        rounding: Option<&Rounding>,
        candidates: &[Spatial],
    ) -> Result<(Vec<u8>, Vec<i64>)> {
        if levels.len() != self.previous.len() {
            return Err(Error::Codec(format!(
                "band {k} has {} levels for {} coefficients",
                levels.len(),
                self.previous.len()
            )));
        }
        if levels.iter().all(|&l| l == 0) {
            self.skip();
            return Ok((Vec::new(), levels.to_vec()));
        }
        let mut best: Option<(Vec<u8>, Vec<i64>, BandCoder)> = None;
        for &spatial in candidates {
            let mut trial = self.clone();
            let (chunk, coded) = trial.encode_with(k, spatial, levels, rounding)?;
            if best.as_ref().is_none_or(|(b, _, _)| chunk.len() < b.len()) {
                best = Some((chunk, coded, trial));
            }
        }
        let (chunk, coded, coder) =
            best.ok_or_else(|| Error::Codec("no spatial predictor to try".into()))?;
        if coded.iter().all(|&l| l == 0) {
            // Rounding emptied the band: it is not coded at all, as the decoder expects.
            self.skip();
            return Ok((Vec::new(), coded));
        }
        *self = coder;
        Ok((chunk, coded))
    }

    /// Decodes band `k` from its chunk (empty: all zero); `None` for an all-zero band.
    pub fn decode(&mut self, k: usize, bytes: &[u8]) -> Result<Option<Vec<i64>>> {
        if bytes.is_empty() {
            self.skip();
            return Ok(None);
        }
        let n = self.previous.len();
        // Refuse before allocating: a band holds one coded symbol or more per coefficient.
        entropy::check_capacity(n as u64, bytes.len(), &format!("temporal-DCT band {k}"))?;
        let mut dec = entropy::Decoder::new(bytes)?;
        let mut levels = vec![0i64; n];
        self.code(&mut dec, k, Spatial::None, &mut levels, None)
            .map_err(|e| Error::Stream(format!("temporal-DCT band {k}: {e}")))?;
        // The encoder never writes more: a larger level would dequantise to a meaningless (even
        // infinite) coordinate.
        if levels.iter().any(|l| l.unsigned_abs() as f64 > MAX_LEVEL) {
            return Err(Error::Stream(format!(
                "temporal-DCT band {k} holds a level beyond ±2^40"
            )));
        }
        Ok(Some(levels))
    }
}

#[cfg(test)]
mod tests {
    use super::super::index::BandIndex;
    use super::*;

    fn residuals(frames: usize, vertices: usize) -> Vec<Vec<[f32; 3]>> {
        (0..frames)
            .map(|f| {
                (0..vertices)
                    .map(|v| {
                        let t = f as f32 * 0.1 + v as f32;
                        [t.sin(), (2.0 * t).cos() * 0.5, 0.01 * f as f32]
                    })
                    .collect()
            })
            .collect()
    }

    #[test]
    fn transform_is_orthonormal_and_inverts() {
        let r = residuals(13, 4);
        let c = forward(&r).unwrap();
        let energy_t: f64 = r
            .iter()
            .flatten()
            .flatten()
            .map(|&x| f64::from(x).powi(2))
            .sum();
        let energy_c: f64 = c.iter().flatten().map(|x| x * x).sum();
        assert!((energy_t - energy_c).abs() < 1e-9 * energy_t);
        let mut inv = Inverse::new(13);
        for v in 0..4 {
            for a in 0..3 {
                let x = inv.run(|k| c[k][3 * v + a]).to_vec();
                for (n, &xn) in x.iter().enumerate() {
                    assert!((xn - f64::from(r[n][v][a])).abs() < 1e-6);
                    let direct: f64 = (0..13).map(|k| c[k][3 * v + a] * basis(k, n, 13)).sum();
                    assert!((direct - xn).abs() < 1e-9);
                }
            }
        }
    }

    #[test]
    fn bands_round_trip_with_carried_models() {
        let r = residuals(9, 30);
        let levels = quantise(&forward(&r).unwrap(), 0.01, DEAD_ZONE).unwrap();
        let strip: Vec<[u32; 3]> = (0..28).map(|i| [i, i + 1, i + 2]).collect();
        let neighbourhood = Arc::new(Neighbourhood::new(30, &strip).unwrap());
        let mut enc = BandCoder::new(neighbourhood.clone());
        let chunks: Vec<Vec<u8>> = levels
            .iter()
            .enumerate()
            .map(|(k, l)| enc.encode(k, l).unwrap())
            .collect();
        let (index, payload) = BandIndex::build(0.01, chunks);
        let index =
            BandIndex::from_bytes(&index.to_bytes().unwrap(), 9, payload.len() as u64).unwrap();
        let mut dec = BandCoder::new(neighbourhood.clone());
        for (k, e) in index.bands.iter().enumerate() {
            let bytes = &payload[e.offset as usize..(e.offset + e.len) as usize];
            let got = dec.decode(k, bytes).unwrap().unwrap_or_else(|| vec![0; 90]);
            assert_eq!(got, levels[k], "band {k}");
        }
        // Rounded by rate and distortion, each level is one of the two integers nearest its
        // coefficient or zero, some differ from plain rounding, fewer bytes are spent, and the
        // decoder reads exactly the levels the encoder reports.
        let c = forward(&r).unwrap();
        let plain = quantise(&c, 0.01, 0.0).unwrap();
        let (mut rounded, mut plain_bytes, mut rounded_bytes) = (Vec::new(), 0, 0);
        let (mut enc, mut plain_enc) = (
            BandCoder::new(neighbourhood.clone()),
            BandCoder::new(neighbourhood.clone()),
        );
        for (k, band) in plain.iter().enumerate() {
            let scaled: Vec<f64> = c[k].iter().map(|x| x / 0.01).collect();
            let rounding = Rounding {
                scaled: &scaled,
                lambda: 0.1,
            };
            let (chunk, coded) = enc
                .encode_rounded(k, band, &rounding, &Spatial::ALL)
                .unwrap();
            for (&x, &l) in scaled.iter().zip(&coded) {
                assert!(l == 0 || (x - l as f64).abs() < 1.0, "{x} → {l}");
            }
            plain_bytes += plain_enc.encode(k, band).unwrap().len();
            rounded_bytes += chunk.len();
            rounded.push((chunk, coded));
        }
        assert!(rounded.iter().zip(&plain).any(|((_, r), p)| r != p));
        assert!(
            rounded_bytes < plain_bytes,
            "{rounded_bytes} ≥ {plain_bytes}"
        );
        let mut dec = BandCoder::new(neighbourhood);
        for (k, (chunk, coded)) in rounded.iter().enumerate() {
            let got = dec.decode(k, chunk).unwrap().unwrap_or_else(|| vec![0; 90]);
            assert_eq!(&got, coded, "band {k}");
        }
        // Levels the encoder never writes are refused; so are more coefficients than bytes can hold.
        let huge = BandCoder::new(Arc::new(Neighbourhood::isolated(1)))
            .encode(1, &[1 << 50, 0, 0])
            .unwrap();
        assert!(BandCoder::new(Arc::new(Neighbourhood::isolated(1)))
            .decode(1, &huge)
            .is_err());
        assert!(BandCoder::new(Arc::new(Neighbourhood::isolated(100_000)))
            .decode(0, &[0; 4])
            .is_err());
        assert!(
            BandIndex::from_bytes(&index.to_bytes().unwrap(), 8, payload.len() as u64).is_err()
        );
        assert!(
            BandIndex::from_bytes(&index.to_bytes().unwrap(), 9, payload.len() as u64 + 1).is_err()
        );
    }

    #[test]
    fn neighbours_sharing_a_sign_make_the_signs_cheap() {
        // 300 vertices along a strip, levels of magnitude 1..=3: each axis's signs in runs of 20
        // vertices (y's shifted by 10, z's opposite to x's), against the same magnitudes with
        // pseudo-random signs. Interleaved, x, y, z look random to one sign model; with the same
        // axis's signs of the neighbours as context most signs cost a fraction of a bit.
        let strip: Vec<[u32; 3]> = (0..298).map(|i| [i, i + 1, i + 2]).collect();
        let neighbourhood = Arc::new(Neighbourhood::new(300, &strip).unwrap());
        let magnitude = |i: usize| (i * 7 % 3) as i64 + 1;
        let runs: Vec<i64> = (0..900)
            .map(|i| {
                if (i / 3 / 20) % 2 == 0 {
                    magnitude(i)
                } else {
                    -magnitude(i)
                }
            })
            .collect();
        let mut seed = 12345u64;
        let random: Vec<i64> = (0..900)
            .map(|i| {
                seed = seed
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                if seed >> 63 == 0 {
                    magnitude(i)
                } else {
                    -magnitude(i)
                }
            })
            .collect();
        let bytes = |levels: &[i64]| {
            let mut coder = BandCoder::new(neighbourhood.clone());
            coder
                .encode_among(1, levels, &[Spatial::None])
                .unwrap()
                .len()
        };
        let (runs, random) = (bytes(&runs), bytes(&random));
        assert!(
            (runs as f64) < 0.75 * random as f64,
            "signs in runs {runs} bytes, random signs {random} bytes"
        );
    }
}
