//! Geometry video (MCGV §3.3–3.4): the residual coder shared by the picture codecs.
//!
//! Encoding builds the atlas on the decoded first frame, splats each frame's quantised residuals
//! onto it, pads the free pixels, tiles x | y | z into one picture and hands the pictures to a
//! [`PictureCodec`] (JPEG, MPEG-4). Its parts, in file order: the lattice coordinates (before the
//! predictor's), then the residual ranges (pixel step, per-frame shifts and offsets, the
//! correction list), the codec set-up, the frame index and the coded frames.
//! Decoding reads the frames from the last key frame before the one asked for.

use super::{Codec, StreamLayout};
use super::{CodecParams, CodedResiduals, Plane, ResidualDecoder, ResidualEncoder, ResidualInput};
use crate::encoder::EncodeOptions;
use crate::error::{Error, Result};
use crate::geometry_image::{
    lattice, quantise, tile, Corrections, FrameRanges, GeometryImages, RangeMode,
};
use crate::mesh::Point;
use crate::progress::Progress;
use crate::stream::bytes::{ByteReader, ByteWriter};
use crate::stream::container::{Checksum, ContainerReader, Part, Tag};
use crate::stream::frame_index::{FrameChunk, FrameIndex};
use crate::stream::side_info;
use rayon::prelude::*;
use std::io::{Read, Seek};
use std::time::Instant;

/// What a picture codec (one file per codec) tells the geometry-video coder. `Sync`: groups of
/// pictures are coded on several threads at once.
pub trait PictureCodec: Sync {
    /// The codec's stream id.
    fn codec(&self) -> Codec;
    /// How residual ranges are shared between frames.
    fn range_mode(&self, opts: &EncodeOptions) -> RangeMode;
    /// The padding this codec measured best with for an encoding with `opts` (its GOP).
    fn default_padding(&self, opts: &EncodeOptions) -> padding::Method;
    /// The pixel step as a multiple of the target step of `opts.quality`.
    fn step_factor(&self, opts: &EncodeOptions) -> f64;
    /// The picture codec's own quantiser (MPEG-4 qscale, JPEG quality, HEVC QP), recorded in the header.
    fn quantiser(&self, opts: &EncodeOptions) -> u8;
    /// Frames per group of pictures (1 for intra codecs).
    fn gop(&self, opts: &EncodeOptions) -> u32;
    /// Bits a sample of the pictures an encoding with `opts` makes (8 unless the codec codes deeper
    /// samples).
    fn depth(&self, _opts: &EncodeOptions) -> u8 {
        8
    }
    /// Bits a sample of a stream's pictures, read from its codec set-up part.
    fn depth_of_setup(&self, _setup: &[u8]) -> Result<u8> {
        Ok(8)
    }
    /// An encoder for `width`×`height` pictures whose first picture is frame `first_frame` of the
    /// sequence (a key frame: every group of pictures gets its own encoder).
    fn encoder(
        &self,
        width: u32,
        height: u32,
        first_frame: usize,
        opts: &EncodeOptions,
    ) -> Result<Box<dyn PictureEncoder>>;
    /// A decoder for `width`×`height` pictures; `setup` is the stream's codec set-up part.
    fn decoder(&self, width: u32, height: u32, setup: &[u8]) -> Result<Box<dyn PictureDecoder>>;
}

/// Codes pictures in frame order.
pub trait PictureEncoder {
    /// Codes the next frame's picture (samples of the codec's depth).
    fn push(&mut self, plane: &Plane<u16>) -> Result<()>;
    /// Ends the sequence: the codec set-up part and one chunk per frame.
    fn finish(self: Box<Self>) -> Result<(Vec<u8>, Vec<FrameChunk>)>;
}

/// Decodes pictures, starting at a key frame and continuing in order.
pub trait PictureDecoder {
    /// Decodes frame `f` from its chunk.
    fn decode(&mut self, f: usize, chunk: &[u8]) -> Result<Plane<u16>>;
}

/// The padding an encoding uses: the option's, else the picture codec's measured best.
pub fn padding_method(codec: &dyn PictureCodec, opts: &EncodeOptions) -> padding::Method {
    opts.padding.unwrap_or(codec.default_padding(opts))
}

/// The residual images an encoding with `codec` makes of `input`'s residuals.
pub fn images(codec: &dyn PictureCodec, input: &ResidualInput) -> Result<GeometryImages> {
    let step = pixel_step(codec, input.diagonal, input.options)?;
    let (reference, triangles) = (input.reference, input.mesh.triangles());
    let build =
        || lattice::build_atlas(reference, triangles, input.partition, input.options.lattice);
    let atlas = match input.atlas {
        Some(cache) => cache.get_or_build(build)?,
        None => build()?,
    };
    Ok(images_on(
        codec,
        atlas,
        input.residuals,
        input.options,
        step,
    ))
}

/// One grey level of an encoding in model units: `opts.step` (a fraction of the first frame's
/// bounding-box diagonal `diagonal`) or the law's for `opts.quality`, rounded to the `f32` the
/// stream stores.
pub fn pixel_step(codec: &dyn PictureCodec, diagonal: f64, opts: &EncodeOptions) -> Result<f32> {
    super::quality::stored_step("pixel step", diagonal, opts, codec.step_factor(opts))
}

/// The residual images an encoding with `codec` and `opts` makes of `residuals` on the atlas of
/// `reference`, `triangles` and `partition`, at `pixel_step`.
pub fn images_of(
    codec: &dyn PictureCodec,
    reference: &[Point],
    triangles: &[[u32; 3]],
    partition: &crate::motion::Partition,
    residuals: &[Vec<[f32; 3]>],
    opts: &EncodeOptions,
    pixel_step: f32,
) -> Result<GeometryImages> {
    let atlas = lattice::build_atlas(reference, triangles, partition, opts.lattice)?;
    Ok(images_on(codec, atlas, residuals, opts, pixel_step))
}

/// The residual images of `residuals` on a built atlas (lattice size and atlas).
fn images_on(
    codec: &dyn PictureCodec,
    (size, atlas): ((u16, u16), atlas::Atlas),
    residuals: &[Vec<[f32; 3]>],
    opts: &EncodeOptions,
    pixel_step: f32,
) -> GeometryImages {
    GeometryImages::new(
        size,
        atlas,
        residuals,
        (codec.range_mode(opts), codec.depth(opts)),
        pixel_step,
        padding::PaddingOptions {
            method: padding_method(codec, opts),
            jpeg_quality: match codec.codec() {
                Codec::Jpeg => codec.quantiser(opts),
                _ => opts.quality,
            },
            jpeg_table: super::jpeg::TABLE,
            ..padding::PaddingOptions::default()
        },
    )
}

/// The geometry-video residual encoder over one picture codec.
pub struct Encoder<P>(P);

impl<P: PictureCodec> Encoder<P> {
    /// The encoder for picture codec `codec`.
    pub fn new(codec: P) -> Self {
        Self(codec)
    }
}

impl<P: PictureCodec> ResidualEncoder for Encoder<P> {
    fn encode(&self, input: &ResidualInput) -> Result<CodedResiduals> {
        let clock = Instant::now();
        let images = images(&self.0, input)?;
        let atlas_seconds = clock.elapsed().as_secs_f64();
        let clock = Instant::now();
        input.progress.stage("images");
        let (setup, chunks) = code_pictures(&self.0, &images, input)?;
        let images_seconds = clock.elapsed().as_secs_f64();
        let mut ranges = ByteWriter::new();
        quantise::write_ranges(images.pixel_step, &images.ranges, &mut ranges);
        images.corrections.write(&mut ranges);
        let (index, payload) = FrameIndex::build(chunks);
        let lattice_part = side_info::encode_lattice(
            images.atlas.vertex_pixels(),
            images.lattice,
            input.mesh.triangles(),
        )?;
        let opts = input.options;
        Ok(CodedResiduals {
            params: CodecParams {
                lattice: images.lattice,
                qscale: self.0.quantiser(opts),
                gop: self.0.gop(opts),
                padding: images.padding.method.to_string(),
            },
            atlas: Some(images.atlas.stats().clone()),
            before_predictor: vec![Part::whole(Tag::LATTICE, lattice_part)],
            after_predictor: vec![
                Part::whole(Tag::RANGES, ranges.into_bytes()),
                Part::whole(Tag::CODEC_SETUP, setup),
                Part::whole(Tag::FRAME_INDEX, index.to_bytes()),
                Part {
                    tag: Tag::FRAMES,
                    bytes: payload,
                    checksum: Checksum::Chunked,
                },
            ],
            stage_seconds: vec![
                ("atlas".into(), atlas_seconds),
                ("images".into(), images_seconds),
            ],
        })
    }
}

/// Pads, tiles and codes every frame's images, one group of pictures per task.
///
/// Groups are independent by construction (a group starts at a key frame and its padding starts
/// afresh), so they run on rayon's threads; each gets its own picture encoder and the chunks are
/// joined in frame order. The encoders' set-up parts must agree, as one encoder's frames do.
fn code_pictures(
    codec: &dyn PictureCodec,
    images: &GeometryImages,
    input: &ResidualInput,
) -> Result<(Vec<u8>, Vec<FrameChunk>)> {
    let frames = input.residuals.len();
    let gop = images.gop.max(1);
    let groups: Vec<std::ops::Range<usize>> = (0..frames)
        .step_by(gop)
        .map(|start| start..(start + gop).min(frames))
        .collect();
    let coded: Vec<Result<(Vec<u8>, Vec<FrameChunk>)>> = groups
        .into_par_iter()
        .map(|group| code_group(codec, images, input, group))
        .collect();
    let mut setup: Option<Vec<u8>> = None;
    let mut chunks = Vec::with_capacity(frames);
    for group in coded {
        let (group_setup, group_chunks) = group?;
        match &setup {
            None => setup = Some(group_setup),
            Some(s) if *s != group_setup => {
                return Err(Error::Codec(format!(
                    "the {} encoders of two groups of pictures gave different set-ups",
                    codec.codec().name()
                )))
            }
            Some(_) => {}
        }
        chunks.extend(group_chunks);
    }
    if chunks.len() != frames {
        return Err(Error::Codec(format!(
            "the {} encoder gave {} pictures for {} frames",
            codec.codec().name(),
            chunks.len(),
            frames
        )));
    }
    Ok((setup.unwrap_or_default(), chunks))
}

/// Pads, tiles and codes the frames of one group of pictures in order, from its key frame.
fn code_group(
    codec: &dyn PictureCodec,
    images: &GeometryImages,
    input: &ResidualInput,
    group: std::ops::Range<usize>,
) -> Result<(Vec<u8>, Vec<FrameChunk>)> {
    let (w, h) = (images.lattice.0 as usize, images.lattice.1 as usize);
    let mut encoder = codec.encoder((3 * w) as u32, h as u32, group.start, input.options)?;
    let mut previous: Option<[Vec<f32>; 3]> = None;
    for f in group {
        let prev = previous.as_ref().filter(|_| images.continues(f));
        let padded = images.padded(&input.residuals[f], f, prev)?;
        encoder.push(&tile::compose(
            [&padded[0], &padded[1], &padded[2]],
            w,
            h,
            images.depth,
        ))?;
        previous = Some(padded);
        input.progress.frames(1);
    }
    encoder.finish()
}

/// The geometry-image side of a stream: what the decoder reads before any picture.
pub struct ImageLayout {
    /// Lattice pixel of every vertex.
    pub pixels: Vec<[u16; 2]>,
    /// One grey level in model units, before any frame's shift.
    pub pixel_step: f32,
    /// Residual range (shift, offset) per frame and coordinate.
    pub ranges: Vec<FrameRanges>,
    /// The residuals the ranges clip.
    pub corrections: Corrections,
    /// Where each frame's picture lies.
    pub index: FrameIndex,
    /// The codec set-up part.
    pub setup: Vec<u8>,
    /// Lattice width and height.
    pub lattice: (u16, u16),
    /// Bits a sample of the pictures.
    pub depth: u8,
}

/// The geometry-video residual decoder over one picture codec.
pub struct Decoder<P> {
    codec: P,
    layout: ImageLayout,
}

impl<P: PictureCodec> Decoder<P> {
    /// Reads the lattice coordinates, ranges, codec set-up and frame index.
    pub fn open<R: Read + Seek>(
        codec: P,
        stream: &StreamLayout,
        reader: &mut ContainerReader<R>,
    ) -> Result<Self> {
        let h = stream.header;
        let (v, frames) = (h.vertices as usize, h.frames as usize);
        let lattice = (h.lattice_width, h.lattice_height);
        let pixels =
            side_info::decode_lattice(&reader.part(Tag::LATTICE)?, v, lattice, stream.triangles)?;
        let setup = reader.part(Tag::CODEC_SETUP)?;
        let depth = codec.depth_of_setup(&setup)?;
        let ranges_bytes = reader.part(Tag::RANGES)?;
        let mut r = ByteReader::new(&ranges_bytes, "residual ranges");
        let (pixel_step, ranges) = quantise::read_ranges(&mut r, frames, depth)?;
        let corrections = Corrections::read(&mut r, frames, v)?;
        r.finish()?;
        let images_len = reader.entry(Tag::FRAMES)?.len;
        let index = FrameIndex::from_bytes(&reader.part(Tag::FRAME_INDEX)?, frames, images_len)?;
        Ok(Self {
            codec,
            layout: ImageLayout {
                pixels,
                pixel_step,
                ranges,
                corrections,
                index,
                setup,
                lattice,
                depth,
            },
        })
    }

    fn picture_size(&self) -> (u32, u32) {
        (
            3 * u32::from(self.layout.lattice.0),
            u32::from(self.layout.lattice.1),
        )
    }

    fn picture_decoder(&self) -> Result<Box<dyn PictureDecoder>> {
        let (w, h) = self.picture_size();
        self.codec.decoder(w, h, &self.layout.setup)
    }

    fn next_picture<R: Read + Seek>(
        &self,
        decoder: &mut dyn PictureDecoder,
        reader: &mut ContainerReader<R>,
        f: usize,
    ) -> Result<Plane<u16>> {
        let e = self.layout.index.entry(f)?;
        let chunk = reader.chunk(Tag::FRAMES, e.offset, e.len, e.crc, &format!("frame {f}"))?;
        decoder.decode(f, &chunk)
    }

    /// Adds frame `f`'s residuals, read from `plane`, to `frame`.
    fn add(&self, f: usize, plane: &Plane<u16>, frame: &mut [Point]) -> Result<()> {
        let (w, h) = self.picture_size();
        if plane.width != w || plane.height != h {
            return Err(Error::Stream(format!(
                "frame {f}: picture is {}x{}, expected {w}x{h}",
                plane.width, plane.height
            )));
        }
        let lw = self.layout.lattice.0 as usize;
        let mut residuals = vec![[0.0f32; 3]; frame.len()];
        for a in 0..3 {
            let levels = tile::sample(plane, a, lw, &self.layout.pixels);
            let range = self.layout.ranges[f][a];
            for (r, l) in residuals.iter_mut().zip(levels) {
                r[a] = range.dequantise(l);
            }
        }
        for c in self.layout.corrections.frame(f) {
            if let Some(r) = residuals.get_mut(c.vertex as usize) {
                r[usize::from(c.axis)] = c.residual(self.layout.pixel_step);
            }
        }
        for (p, r) in frame.iter_mut().zip(&residuals) {
            for a in 0..3 {
                p[a] += r[a];
            }
        }
        Ok(())
    }
}

impl<P: PictureCodec, R: Read + Seek> ResidualDecoder<R> for Decoder<P> {
    fn add_frame(
        &mut self,
        reader: &mut ContainerReader<R>,
        f: usize,
        frame: &mut [Point],
    ) -> Result<()> {
        let plane = ResidualDecoder::picture(self, reader, f)?;
        self.add(f, &plane, frame)
    }

    fn add_all(
        &mut self,
        reader: &mut ContainerReader<R>,
        frames: &mut [Vec<Point>],
        progress: &dyn Progress,
    ) -> Result<()> {
        let mut decoder = self.picture_decoder()?;
        for (f, frame) in frames.iter_mut().enumerate() {
            let plane = self.next_picture(decoder.as_mut(), reader, f)?;
            self.add(f, &plane, frame)?;
            progress.frames(1);
        }
        Ok(())
    }

    fn images(&self) -> Option<&ImageLayout> {
        Some(&self.layout)
    }

    fn picture(&mut self, reader: &mut ContainerReader<R>, f: usize) -> Result<Plane<u16>> {
        self.layout.index.entry(f)?;
        let key = self.layout.index.key_before(f);
        let mut decoder = self.picture_decoder()?;
        let mut last = None;
        for g in key..=f {
            last = Some(self.next_picture(decoder.as_mut(), reader, g)?);
        }
        last.ok_or_else(|| Error::Stream("no frame decoded".into()))
    }
}
