//! A trivial residual codec that exists only for the interface's tests: each frame's residuals
//! rounded to the plan's step and stored as 64-bit integers, one chunk a frame (any frame decodes
//! alone). It shows what a codec is — this one file (its options, its plan, its encoder and
//! decoder, its set-up) and one variant of [`super::Codec`] and [`super::CodecConfig`], whose
//! match arms in `codec/mod.rs` are the only other lines it needs.

use super::rate::{Rate, RatePlan};
use super::{BandsDescription, Codec, Description, PicturesDescription, StreamLayout};
use super::{CodedResiduals, ResidualDecoder, ResidualEncoder, ResidualInput};
use crate::error::{Error, Result};
use crate::mesh::Point;
use crate::motion::DEFAULT_AFFINE_PRECISION;
use crate::stream::bytes::{ByteReader, ByteWriter};
use crate::stream::container::{Checksum, ContainerReader, Part, Tag};
use crate::stream::frame_index::{FrameChunk, FrameIndex};
use std::io::{Read, Seek};

/// The set-up part: the version, then the step.
const VERSION: u8 = 1;

/// The raw codec's options: none.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RawConfig;

impl RawConfig {
    /// The plan: the quality's target step, affine maps at a quarter of it.
    pub(crate) fn plan(&self, rate: &Rate, diagonal: f64) -> Result<RatePlan> {
        let step = rate.stored_step("raw step", diagonal, 1.0)?;
        Ok(rate.plan(step, DEFAULT_AFFINE_PRECISION, Codec::Raw, None))
    }
}

/// Rounds each residual to `step`.
pub(crate) struct Encoder {
    /// The step, in model units.
    pub step: f32,
}

impl ResidualEncoder for Encoder {
    fn encode(&self, input: &ResidualInput) -> Result<CodedResiduals> {
        let step = f64::from(self.step);
        let chunks = input
            .residuals
            .iter()
            .map(|frame| {
                let mut w = ByteWriter::new();
                for value in frame.iter().flatten() {
                    w.u64((f64::from(*value) / step).round() as i64 as u64);
                }
                FrameChunk {
                    data: w.into_bytes(),
                    key: true,
                }
            })
            .collect();
        input.progress.frames(input.residuals.len() as u64);
        let (index, payload) = FrameIndex::build(chunks);
        let mut setup = ByteWriter::new();
        setup.u8(VERSION).f32(self.step);
        Ok(CodedResiduals {
            setup: setup.into_bytes(),
            atlas: None,
            residual_spread: None,
            picture_depth: None,
            before_predictor: Vec::new(),
            after_predictor: vec![
                Part::whole(Tag::FRAME_INDEX, index.to_bytes()?),
                Part {
                    tag: Tag::FRAMES,
                    bytes: payload,
                    checksum: Checksum::Chunked,
                },
            ],
            stage_seconds: Vec::new(),
        })
    }
}

/// Reads a frame's chunk and adds its levels times the step.
pub(crate) struct Decoder {
    step: f32,
    index: FrameIndex,
}

impl Decoder {
    /// Reads the set-up and the frame index.
    pub fn open<R: Read + Seek>(
        setup: &[u8],
        stream: &StreamLayout,
        reader: &mut ContainerReader<R>,
    ) -> Result<Self> {
        let mut r = ByteReader::new(setup, "raw set-up");
        if r.u8()? != VERSION {
            return Err(Error::Stream("raw set-up: unknown version".into()));
        }
        let step = r.f32()?;
        r.finish()?;
        let frames = stream.header.frames as usize;
        let len = reader.entry(Tag::FRAMES)?.len;
        let index = FrameIndex::from_bytes(&reader.part(Tag::FRAME_INDEX)?, frames, len)?;
        Ok(Self { step, index })
    }
}

impl<R: Read + Seek> ResidualDecoder<R> for Decoder {
    fn add_frame(
        &mut self,
        reader: &mut ContainerReader<R>,
        f: usize,
        frame: &mut [Point],
    ) -> Result<()> {
        let e = self.index.entry(f)?;
        let chunk = reader.chunk(Tag::FRAMES, e.offset, e.len, e.crc, "raw frame")?;
        let mut r = ByteReader::new(&chunk, "raw frame");
        for value in frame.iter_mut().flatten() {
            let level = r.u64()? as i64;
            *value += (level as f64 * f64::from(self.step)) as f32;
        }
        r.finish()
    }

    fn describe(&self) -> Description {
        Description {
            codec: Codec::Raw,
            settings: Vec::new(),
            pictures: None::<PicturesDescription>,
            bands: None::<BandsDescription>,
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::codec::{Codec, CodecConfig};
    use crate::encoder::{encode, EncodeOptions};
    use crate::mesh::AnimatedMesh;
    use crate::Decoder;

    /// A bending strip: 40 vertices, 30 frames.
    fn strip() -> AnimatedMesh {
        let triangles = (0..19u32)
            .flat_map(|i| {
                [
                    [2 * i, 2 * i + 1, 2 * i + 2],
                    [2 * i + 1, 2 * i + 3, 2 * i + 2],
                ]
            })
            .collect();
        let frames = (0..30)
            .map(|f| {
                let t = f as f32 / 29.0;
                (0..40)
                    .map(|v| {
                        let x = (v / 2) as f32 * 0.1;
                        [x, (v % 2) as f32 * 0.1, (3.0 * x * t).sin() * 0.3]
                    })
                    .collect()
            })
            .collect();
        AnimatedMesh::new(triangles, frames).expect("a valid animation")
    }

    #[test]
    fn a_codec_plugged_in_as_one_file_and_one_variant_codes_and_decodes() {
        let mesh = strip();
        for segment_frames in [None, Some(8)] {
            let opts = EncodeOptions {
                codec: CodecConfig::Raw(super::RawConfig),
                quality: 80,
                clusters: 2,
                segment_frames,
                ..EncodeOptions::default()
            };
            let encoded = encode(&mesh, &opts).expect("encodes");
            let step = opts.plan(mesh.bbox_diagonal()).unwrap().step;
            let bytes = encoded.to_bytes();
            let mut decoder = Decoder::new(&bytes).expect("opens");
            assert_eq!(decoder.codec(), Codec::Raw);
            let all = decoder.decode_all().expect("decodes");
            assert_eq!(decoder.describe().map(|d| d.codec), Some(Codec::Raw));
            for f in 0..mesh.frame_count() {
                let alone = decoder.decode_frame(f).expect("a frame alone");
                assert_eq!(alone, all.frame(f), "frame {f}");
                for (a, b) in all.frame(f).iter().zip(mesh.frame(f)) {
                    for i in 0..3 {
                        // Rounded to the step (a half), plus the f32 arithmetic of the predictor.
                        assert!((a[i] - b[i]).abs() <= 0.5 * step + 1e-5, "frame {f}");
                    }
                }
            }
            let parts: Vec<String> = decoder.part_bytes().into_iter().map(|p| p.0).collect();
            assert!(parts.contains(&"codec set-up".to_string()), "{parts:?}");
        }
    }
}
