//! Geometry video (MCGV §3.3–3.4): the residual coder shared by the picture codecs.
//!
//! Encoding builds the atlas on the decoded first frame, splats each frame's quantised residuals
//! onto it, pads the free pixels, tiles x | y | z into one picture and hands the pictures to a
//! `PictureCodec`. Its parts, in file order: the set-up (`PictureSetup`) and the lattice
//! coordinates (the whole stream's, before the predictor's), then a segment's residual ranges
//! (pixel step, per-frame shifts and offsets, the correction list), frame index and coded frames.
//! Decoding reads the frames from the last key frame before the one asked for.

use super::setup::PictureSetup;
use super::{PictureCodec, PictureDecoder, PicturePlan, Plane};
use crate::codec::{BandsDescription, Codec, Description, PicturesDescription};
use crate::codec::{ResidualDecoder, StreamLayout};
#[cfg(feature = "encode")]
use crate::codec::{CodedResiduals, ResidualEncoder, ResidualInput};
use crate::error::{Error, Result};
#[cfg(feature = "encode")]
use crate::geometry_image::lattice::AtlasCache;
use crate::geometry_image::{lattice, quantise, range_coding, tile, Corrections, FrameRanges};
#[cfg(feature = "encode")]
use crate::geometry_image::GeometryImages;
use crate::mesh::Point;
use crate::motion::Partition;
use crate::progress::Progress;
use crate::stream::container::{Checksum, ContainerReader, Part, Tag};
use crate::stream::frame_index::{FrameChunk, FrameIndex};
use crate::stream::side_info;
#[cfg(feature = "encode")]
use rayon::prelude::*;
use std::io::{Read, Seek};
use std::time::Instant;

/// The residual images `plan` makes of `residuals` at pixel step `pixel_step` on the atlas of
/// `reference`, `triangles` and `partition`, built afresh or taken from `atlas`.
#[cfg(feature = "encode")]
pub(crate) fn images(
    (codec, plan): (&dyn PictureCodec, &PicturePlan),
    pixel_step: f32,
    (reference, triangles, partition): (&[Point], &[[u32; 3]], &Partition),
    residuals: &[Vec<[f32; 3]>],
    atlas: Option<&AtlasCache>,
) -> Result<GeometryImages> {
    let build = || lattice::build_atlas(reference, triangles, partition, plan.lattice);
    let (size, atlas) = match atlas {
        Some(cache) => cache.get_or_build(build)?,
        None => build()?,
    };
    GeometryImages::new(
        size,
        atlas,
        residuals,
        (plan.ranges(), plan.depth),
        pixel_step,
        codec.padding(plan),
    )
}

/// The geometry-video residual encoder over one picture codec, with the plan's settings.
#[cfg(feature = "encode")]
pub(crate) struct Encoder {
    codec: &'static dyn PictureCodec,
    plan: PicturePlan,
    pixel_step: f32,
}

#[cfg(feature = "encode")]
impl Encoder {
    /// The encoder of `plan` on `codec` at `pixel_step`.
    pub fn new(codec: &'static dyn PictureCodec, plan: PicturePlan, pixel_step: f32) -> Self {
        Self {
            codec,
            plan,
            pixel_step,
        }
    }
}

#[cfg(feature = "encode")]
impl ResidualEncoder for Encoder {
    fn encode(&self, input: &ResidualInput) -> Result<CodedResiduals> {
        let clock = Instant::now();
        let shape = (input.reference, input.mesh.triangles(), input.partition);
        let images = images(
            (self.codec, &self.plan),
            self.pixel_step,
            shape,
            input.residuals,
            input.atlas,
        )?;
        let atlas_seconds = clock.elapsed().as_secs_f64();
        let clock = Instant::now();
        input.progress.stage("images");
        let (codec_data, chunks) = code_pictures(self, &images, input)?;
        let images_seconds = clock.elapsed().as_secs_f64();
        let ranges = range_coding::encode_ranges(
            images.pixel_step,
            &images.ranges,
            &images.corrections,
            input.mesh.vertex_count(),
        )?;
        let (index, payload) = FrameIndex::build(chunks);
        let lattice_part = side_info::encode_lattice(
            images.atlas.vertex_pixels(),
            images.lattice,
            input.mesh.triangles(),
        )?;
        let stats = images.atlas.stats();
        let setup = PictureSetup {
            lattice: images.lattice,
            quantiser: self.plan.quantiser,
            gop: u32::try_from(self.plan.gop).unwrap_or(u32::MAX),
            depth: self.plan.depth,
            padding: images.padding.options().method,
            charts: stats.charts as u32,
            chart_pixels: stats.chart_pixels as u32,
            codec_data,
        };
        Ok(CodedResiduals {
            setup: setup.to_bytes(),
            residual_spread: Some(images.spread),
            picture_depth: Some(self.plan.depth),
            atlas: Some((images.lattice, images.atlas)),
            before_predictor: vec![Part::whole(Tag::LATTICE, lattice_part)],
            after_predictor: vec![
                Part::whole(Tag::RANGES, ranges),
                Part::whole(Tag::FRAME_INDEX, index.to_bytes()?),
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
#[cfg(feature = "encode")]
fn code_pictures(
    coder: &Encoder,
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
        .map(|group| code_group(coder, images, input, group))
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
                    coder.plan.codec.name()
                )))
            }
            Some(_) => {}
        }
        chunks.extend(group_chunks);
    }
    if chunks.len() != frames {
        return Err(Error::Codec(format!(
            "the {} encoder gave {} pictures for {} frames",
            coder.plan.codec.name(),
            chunks.len(),
            frames
        )));
    }
    Ok((setup.unwrap_or_default(), chunks))
}

/// Pads, tiles and codes the frames of one group of pictures in order, from its key frame.
#[cfg(feature = "encode")]
fn code_group(
    coder: &Encoder,
    images: &GeometryImages,
    input: &ResidualInput,
    group: std::ops::Range<usize>,
) -> Result<(Vec<u8>, Vec<FrameChunk>)> {
    let (w, h) = (images.lattice.0 as usize, images.lattice.1 as usize);
    let (width, height) = ((3 * w) as u32, h as u32);
    let mut encoder = coder
        .codec
        .encoder(width, height, group.start, &coder.plan)?;
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
pub(crate) struct ImageLayout {
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
    /// The stream's set-up: lattice, quantiser, groups, depth, padding, the codec's own bytes.
    pub setup: PictureSetup,
}

impl ImageLayout {
    /// Lattice width and height.
    pub fn lattice(&self) -> (u16, u16) {
        self.setup.lattice
    }

    /// Bits a sample of the pictures.
    pub fn depth(&self) -> u8 {
        self.setup.depth
    }
}

/// The geometry-video residual decoder over one picture codec.
pub(crate) struct Decoder {
    codec: Codec,
    pictures: &'static dyn PictureCodec,
    layout: ImageLayout,
}

impl Decoder {
    /// Reads the set-up (`setup`, the payload of its part), lattice coordinates, ranges and frame
    /// index of `codec`'s stream, whose pictures `pictures` decodes.
    pub fn open<R: Read + Seek>(
        (codec, pictures): (Codec, &'static dyn PictureCodec),
        setup: &[u8],
        stream: &StreamLayout,
        reader: &mut ContainerReader<R>,
    ) -> Result<Self> {
        let h = stream.header;
        let (v, frames) = (h.vertices as usize, h.frames as usize);
        let setup = PictureSetup::from_bytes(setup, h.vertices)?;
        let lattice = setup.lattice;
        let pixels =
            side_info::decode_lattice(&reader.part(Tag::LATTICE)?, v, lattice, stream.triangles)?;
        let depth = setup.depth;
        let ranges_bytes = reader.part(Tag::RANGES)?;
        let (pixel_step, ranges, corrections) =
            range_coding::decode_ranges(&ranges_bytes, frames, v, depth)?;
        // A partial stream's images part may be cut short: the index covers the declared length.
        let images_len = match reader.truncated(Tag::FRAMES) {
            Some(declared) => declared,
            None => reader.entry(Tag::FRAMES)?.len,
        };
        let index = FrameIndex::from_bytes(&reader.part(Tag::FRAME_INDEX)?, frames, images_len)?;
        Ok(Self {
            codec,
            pictures,
            layout: ImageLayout {
                pixels,
                pixel_step,
                ranges,
                corrections,
                index,
                setup,
            },
        })
    }

    fn picture_size(&self) -> (u32, u32) {
        let (w, h) = self.layout.lattice();
        (3 * u32::from(w), u32::from(h))
    }

    fn picture_decoder(&self) -> Result<Box<dyn PictureDecoder>> {
        let (w, h) = self.picture_size();
        self.pictures.decoder(w, h, &self.layout.setup)
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
        let lw = self.layout.lattice().0 as usize;
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

impl<R: Read + Seek> ResidualDecoder<R> for Decoder {
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

    fn describe(&self) -> Description {
        let setup = &self.layout.setup;
        let settings = self
            .pictures
            .settings(setup.quantiser, setup.gop, setup.depth);
        Description {
            codec: self.codec,
            settings,
            pictures: Some(PicturesDescription {
                lattice: setup.lattice,
                bit_depth: setup.depth,
                charts: setup.charts,
                packing_efficiency: setup.packing_efficiency(),
                padding: setup.padding.name(),
                corrections: (0..self.layout.ranges.len())
                    .map(|f| self.layout.corrections.frame(f).len() as u32)
                    .collect(),
            }),
            bands: None::<BandsDescription>,
        }
    }

    fn images(&self) -> Option<&ImageLayout> {
        Some(&self.layout)
    }

    fn add_picture(&self, f: usize, plane: &Plane<u16>, frame: &mut [Point]) -> Result<()> {
        self.layout.index.entry(f)?;
        let top = quantise::max_level(self.layout.depth());
        if plane.data.iter().any(|&s| u32::from(s) > top as u32) {
            return Err(Error::Usage(format!(
                "frame {f}: a picture sample is above {top}, the largest at {} bits",
                self.layout.depth()
            )));
        }
        self.add(f, plane, frame)
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
