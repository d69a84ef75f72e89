//! Temporal-DCT residual coding (`tdct`, skinning paper §3.3, eq. 12): no atlas, no images.
//!
//! Each vertex's residual trajectory along x, y and z is transformed over all frames, quantised
//! with one step that `quality` sets as a fraction of the bounding-box diagonal, and coded band by
//! band from low to high frequency ([`coefficients`]). Its parts come after the predictor's: the
//! band index, then the bands, last in the file so that a stream cut inside them still decodes
//! every complete band (a coarser animation).

pub mod coefficients;
pub mod copies;
pub mod index;
pub mod spatial;
pub mod transform;

use super::rate::{Rate, RatePlan};
use super::StreamLayout;
use super::{BandsDescription, Codec, Description};
use super::ResidualDecoder;
#[cfg(feature = "encode")]
use super::{CodedResiduals, Estimate, Limit, ResidualEncoder, ResidualInput};
use crate::error::{Error, Result};
use crate::mesh::{Point, Triangle};
use crate::progress::Progress;
use crate::stream::container::{Checksum, ContainerReader, Part, Tag};
use coefficients::{BandCoder, Rounding};
use copies::Copies;
use index::BandIndex;
use spatial::{Neighbourhood, Spatial};
use std::io::{Read, Seek};
use std::sync::Arc;
use std::time::Instant;

#[cfg(any(test, feature = "internals"))]
pub use coefficients::DEAD_ZONE;

/// The price of a bit, in squared steps, of the encoder's rate–distortion rounding
/// ([`Rounding`]): of the prices swept against the dead-zone quantiser ([`DEAD_ZONE`]), the one
/// that saves most and is worse nowhere (`measure_rounding` in `tests/it/tdct.rs`;
/// docs/design.md, "Temporal-DCT coder (rounding, contexts, spatial prediction)").
pub const ROUNDING_LAMBDA: f64 = 0.1;

/// The affine step over the temporal DCT's step: 3/16, finer than the picture codecs' quarter.
/// The maps' rounding error is white in time, so the dead zone drops most of it into the output
/// instead of coding it; finer maps cost fewer bytes at equal vertex RMSE on 7 of 10 clips
/// measured (BrainStem −15 %, pdance −1.5 … −4.6 %, pcow and Parrot +0.7 … +1.7 %;
/// docs/design.md, "Affine precision per codec").
pub const AFFINE_PRECISION: f64 = 3.0 / 16.0;

/// The version of the temporal DCT's set-up part (its only byte: the step, the bands and the copy
/// bits are a segment's own, in its band index). Version 2: the copies ([`copies`]).
const SETUP_VERSION: u8 = 2;

/// The temporal DCT's options: none of its own yet (the step is every codec's).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub struct TdctConfig {}

impl TdctConfig {
    /// The plan of `rate` on a first frame of bounding-box diagonal `diagonal`: the quality's
    /// target step is the quantiser step; affine maps at [`AFFINE_PRECISION`] of it.
    pub(crate) fn plan(&self, rate: &Rate, diagonal: f64) -> Result<RatePlan> {
        let step = rate.stored_step("temporal-DCT step", diagonal, 1.0)?;
        Ok(rate.plan(step, AFFINE_PRECISION, Codec::Tdct, None))
    }
}

/// The temporal-DCT residual encoder at one quantiser step (model units, as stored).
#[cfg(feature = "encode")]
pub(crate) struct Encoder {
    /// The quantiser step.
    pub step: f32,
}

#[cfg(feature = "encode")]
impl ResidualEncoder for Encoder {
    fn encode(&self, input: &ResidualInput) -> Result<CodedResiduals> {
        let clock = Instant::now();
        input.progress.stage("temporal DCT");
        let step = self.step;
        let kept = Kept::of(input)?;
        let coefficients = coefficients::forward(&kept.residuals)?;
        let step64 = f64::from(step);
        // Plain rounding here only decides which bands are empty; the levels coded are chosen by
        // rate and distortion as each band is coded.
        let mut coder = BandCoder::new(Arc::new(kept.neighbourhood));
        let chunks = (coefficients.iter().enumerate())
            .map(|(k, values)| {
                let band = coefficients::quantise_band(values, step64, 0.0)?;
                let scaled: Vec<f64> = values.iter().map(|c| c / step64).collect();
                let rounding = Rounding {
                    scaled: &scaled,
                    lambda: ROUNDING_LAMBDA,
                };
                Ok(coder.encode_rounded(k, &band, &rounding, &Spatial::ALL)?.0)
            })
            .collect::<Result<Vec<_>>>()?;
        let (mut index, payload) = BandIndex::build(step, chunks);
        index.copies = kept.bits;
        input.progress.frames(input.residuals.len() as u64);
        Ok(CodedResiduals {
            setup: vec![SETUP_VERSION],
            atlas: None,
            residual_spread: None,
            picture_depth: None,
            before_predictor: Vec::new(),
            after_predictor: vec![
                Part::whole(Tag::TDCT_INDEX, index.to_bytes()?),
                // Last, so that a stream cut inside it still decodes the bands before the cut.
                Part {
                    tag: Tag::TDCT,
                    bytes: payload,
                    checksum: Checksum::Progressive,
                },
            ],
            stage_seconds: vec![("temporal DCT".into(), clock.elapsed().as_secs_f64())],
        })
    }

    /// The bands coded once, with the dead-zone quantiser instead of the rate–distortion
    /// rounding and the mean spatial predictor only: about a third of [`Self::encode`]'s work.
    /// Over the candidates of the media's automatic choices it kept streams 0.1 % larger on
    /// average, 1 % at most, than coding each candidate in full (docs/design.md, "Speed of the
    /// automatic choice").
    ///
    /// With a limit, the bands stop once the set-up's byte and the bands so far pass it: the
    /// index, still to come, only adds to them.
    fn estimate_bytes(&self, input: &ResidualInput, limit: &Limit) -> Result<Option<Estimate>> {
        let step = f64::from(self.step);
        let kept = Kept::of(input)?;
        let coefficients = coefficients::forward(&kept.residuals)?;
        let mut coder = BandCoder::new(Arc::new(kept.neighbourhood));
        let mut chunks = Vec::with_capacity(coefficients.len());
        let (mut so_far, mut stopped) = (1, false);
        for (k, values) in coefficients.iter().enumerate() {
            let band = coefficients::quantise_band(values, step, transform::DEAD_ZONE)?;
            let chunk = coder.encode_among(k, &band, &[Spatial::Mean])?;
            so_far += chunk.len() as u64;
            chunks.push(chunk);
            stopped = limit.passed(so_far);
            if stopped {
                break;
            }
        }
        input.progress.frames(input.residuals.len() as u64);
        if stopped {
            return Ok(Some(Estimate {
                bytes: so_far,
                stopped,
            }));
        }
        let (mut index, payload) = BandIndex::build(self.step, chunks);
        index.copies = kept.bits;
        let setup = 1 + index.to_bytes()?.len() as u64;
        let bytes = setup + payload.len() as u64;
        Ok(Some(Estimate { bytes, stopped: false }))
    }
}

/// What the bands of an encoder's input hold: the residuals of the vertices that are not copies
/// ([`copies`]), their neighbourhood, and the copy bits of the band index.
#[cfg(feature = "encode")]
struct Kept<'a> {
    residuals: std::borrow::Cow<'a, [Vec<[f32; 3]>]>,
    neighbourhood: Neighbourhood,
    bits: Vec<bool>,
}

#[cfg(feature = "encode")]
impl<'a> Kept<'a> {
    fn of(input: &ResidualInput<'a>) -> Result<Self> {
        let candidates = copies::candidates(input.reference);
        let bits = copies::equal_trajectories(&candidates, input.mesh.frames());
        let copies = Copies::new(input.mesh.vertex_count(), &candidates, &bits);
        let residuals = match copies.any() {
            true => copies.keep_residuals(input.residuals).into(),
            false => input.residuals.into(),
        };
        let neighbourhood = kept_neighbourhood(&copies, input.mesh.triangles())?;
        Ok(Self {
            residuals,
            neighbourhood,
            bits,
        })
    }
}

/// The neighbourhood the bands are coded over: of the merged connectivity when there are copies,
/// else of the mesh's own (so a stream without copies codes its bands as version 1 did).
fn kept_neighbourhood(copies: &Copies, triangles: &[Triangle]) -> Result<Neighbourhood> {
    match copies.any() {
        true => Neighbourhood::new(copies.kept_count(), &copies.merged_triangles(triangles)),
        false => Neighbourhood::new(copies.kept_count(), triangles),
    }
}

/// The decoded temporal-DCT coefficients of a stream, read once at open.
pub(crate) struct Bands {
    /// Byte length of every band in the stream, decoded or not.
    pub lengths: Vec<u64>,
    /// Dequantised coefficients of the decoded bands (`[3v + a]`); `None` for an all-zero band.
    /// Bands past the decoded ones are missing (truncated stream, or a preview) and count as zero.
    pub decoded: Vec<Option<Vec<f32>>>,
    /// The quantiser step.
    pub step: f32,
}

/// The temporal-DCT residual decoder.
pub(crate) struct Decoder {
    bands: Bands,
    frames: usize,
    /// The vertices the bands hold, and the copies of them.
    copies: Copies,
}

impl Decoder {
    /// Checks the set-up (`setup`, the payload of its part), reads the band index and decodes the
    /// bands, low to high, up to `max_bands`, the end of a truncated file, a damaged band or the
    /// last band. A band cut by the end of the file or failing its CRC ends decoding (it and the
    /// rest count as zero): the bands before it still give a coarser animation, and the caller
    /// sees how many were decoded ([`Description`](crate::codec::Description)'s bands).
    pub fn open<R: Read + Seek>(
        setup: &[u8],
        stream: &StreamLayout,
        reader: &mut ContainerReader<R>,
        max_bands: Option<usize>,
    ) -> Result<Self> {
        if setup != [SETUP_VERSION] {
            return Err(Error::Stream(format!(
                "temporal-DCT set-up {setup:?}: this build reads version {SETUP_VERSION}"
            )));
        }
        let (vertices, frames) = (
            stream.header.vertices as usize,
            stream.header.frames as usize,
        );
        let entry = reader.entry(Tag::TDCT)?;
        let declared = reader.truncated(Tag::TDCT);
        if stream.reference.len() != vertices {
            return Err(Error::Stream(format!(
                "the first frame has {} vertices, the header {vertices}",
                stream.reference.len()
            )));
        }
        let candidates = copies::candidates(stream.reference);
        let index = BandIndex::from_bytes(
            &reader.part(Tag::TDCT_INDEX)?,
            frames,
            declared.unwrap_or(entry.len),
        )?;
        if index.copies.len() != candidates.len() {
            return Err(Error::Stream(format!(
                "temporal-DCT index: {} copy bits for {} vertices that share a first-frame position",
                index.copies.len(),
                candidates.len()
            )));
        }
        let copies = Copies::new(vertices, &candidates, &index.copies);
        let step = index.step;
        let limit = max_bands.unwrap_or(frames).min(frames);
        let neighbourhood = kept_neighbourhood(&copies, stream.triangles)?;
        let mut coder = BandCoder::new(Arc::new(neighbourhood));
        let mut decoded = Vec::new();
        for (k, band) in index.bands.iter().enumerate().take(limit) {
            if band.offset + band.len > entry.len {
                break;
            }
            let bytes = if band.len == 0 {
                Vec::new()
            } else {
                let what = format!("temporal-DCT band {k}");
                match reader.chunk_if_intact(Tag::TDCT, band.offset, band.len, band.crc, &what)? {
                    Some(bytes) => bytes,
                    None => break,
                }
            };
            decoded.push(dequantise(k, coder.decode(k, &bytes)?, step)?);
        }
        Ok(Self {
            bands: Bands {
                lengths: index.bands.iter().map(|b| b.len).collect(),
                decoded,
                step,
            },
            frames,
            copies,
        })
    }
}

/// Band `k`'s coefficients from its levels.
fn dequantise(k: usize, levels: Option<Vec<i64>>, step: f32) -> Result<Option<Vec<f32>>> {
    let coefficients = levels.map(|l| -> Vec<f32> {
        l.iter()
            .map(|&q| (q as f64 * f64::from(step)) as f32)
            .collect()
    });
    // Levels are bounded but the step is any positive f32: their product can overflow, and an
    // infinite coefficient would turn every frame's coordinates into infinities or NaN.
    if coefficients
        .as_ref()
        .is_some_and(|c| c.iter().any(|x| !x.is_finite()))
    {
        return Err(Error::Stream(format!(
            "temporal-DCT band {k}: a level times the step {step:e} is not a finite number"
        )));
    }
    Ok(coefficients)
}

impl<R: Read + Seek> ResidualDecoder<R> for Decoder {
    /// Sums the decoded bands' basis functions at `f`: O(V · bands).
    fn add_frame(
        &mut self,
        _reader: &mut ContainerReader<R>,
        f: usize,
        frame: &mut [Point],
    ) -> Result<()> {
        let mut sum = vec![0.0f64; 3 * self.copies.kept_count()];
        for (k, band) in self.bands.decoded.iter().enumerate() {
            if let Some(c) = band {
                let b = coefficients::basis(k, f, self.frames);
                for (s, &c) in sum.iter_mut().zip(c) {
                    *s += f64::from(c) * b;
                }
            }
        }
        self.copies.add_to_frame(frame, &sum);
        Ok(())
    }

    /// The inverse DCT of each vertex/axis sequence (rustdct's DCT-III over all frames).
    fn add_all(
        &mut self,
        _reader: &mut ContainerReader<R>,
        frames: &mut [Vec<Point>],
        progress: &dyn Progress,
    ) -> Result<()> {
        let mut inverse = coefficients::Inverse::new(self.frames);
        for slot in 0..self.copies.kept_count() {
            let v = self.copies.kept_vertex(slot);
            for a in 0..3 {
                let x = inverse.run(|k| match self.bands.decoded.get(k) {
                    Some(Some(c)) => f64::from(c[3 * slot + a]),
                    _ => 0.0,
                });
                for (frame, &x) in frames.iter_mut().zip(x) {
                    if let Some(p) = frame.get_mut(v) {
                        p[a] += x as f32;
                    }
                }
            }
        }
        for frame in frames.iter_mut() {
            self.copies.copy_into(frame);
        }
        progress.frames(frames.len() as u64);
        Ok(())
    }

    fn describe(&self) -> Description {
        Description {
            codec: Codec::Tdct,
            settings: Vec::new(),
            pictures: None,
            bands: Some(BandsDescription {
                step: self.bands.step,
                lengths: self.bands.lengths.clone(),
                decoded: self.bands.decoded.len(),
            }),
        }
    }
}
