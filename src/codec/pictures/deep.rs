//! What the FFmpeg picture codecs at 10 or 12 bits a sample ([`super::hevc`], [`super::av1`])
//! share: the x | y | z picture layout ([`Planes`]), a fixed-quantiser encoder and a one-thread
//! decoder of 16-bit little-endian planes, the codec set-up part (sample depth and planes) and the
//! geometry-video glue (`Pictures`). What tells the codecs apart, the FFmpeg encoder and its
//! settings, the decoder and the quality law, is a `Flavour`.
//!
//! Each group of pictures has its own encoder (the geometry-video coder runs groups on several
//! threads), which makes one key frame, then P-frames, one packet per frame in order; headers are
//! in-band, so that decoding can start at any key frame.

#[cfg(any(test, feature = "internals"))]
pub use super::depth::auto_depth;
pub use super::depth::{deeper_from_quality, DEPTHS};
use super::depth::{auto_depth_at, DeepLaws};
use super::{PictureOptions, Resolved, DEFAULT_GOP};
use crate::codec::rate::{Rate, RatePlan};
use crate::codec::Codec;
use crate::error::{Error, Result};

#[cfg(all(feature = "ffmpeg", any(test, feature = "internals")))]
pub use coder::{Decoder, Encoder, Packet, Planes, DEFAULT_PLANES};
#[cfg(feature = "ffmpeg")]
pub(crate) use coder::{Flavour, Options, Pictures};

/// The options of HEVC and AV1: the codec's quantiser, the groups of pictures, the sample depth,
/// and the lattice and padding of the pictures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DeepConfig {
    /// The codec's own quantiser, lower is finer: HEVC's QP 0..=51 or libaom's constant-quality
    /// level (`crf`) 0..=63; `None` takes the law's for the encoding's quality.
    pub qp: Option<u8>,
    /// Frames per group of pictures: a key frame, then `gop − 1` P-frames (1: all-intra, every
    /// frame decodes alone).
    pub gop: usize,
    /// Bits a sample, 10 or 12; `None` picks it from the quality and the residuals (12 bits from
    /// quality 65 for HEVC, 90 for AV1, and below where 10 would widen a group's
    /// step; docs/design.md, "Sample depth").
    pub bit_depth: Option<u8>,
    /// The lattice and padding (default: `pushpull` all-intra, `biharmonic` with P-frames).
    pub pictures: PictureOptions,
}

impl Default for DeepConfig {
    fn default() -> Self {
        Self {
            qp: None,
            gop: DEFAULT_GOP,
            bit_depth: None,
            pictures: PictureOptions::default(),
        }
    }
}

impl DeepConfig {
    /// Fails, naming the option, when one is out of range for `codec`, whose quantiser goes up to
    /// `max_qp`.
    pub(crate) fn check(&self, codec: Codec, max_qp: u8) -> Result<()> {
        if self.qp.is_some_and(|q| q > max_qp) {
            return Err(Error::option(
                "qp",
                format!("must be between 0 and {max_qp} for {}", codec.name()),
            ));
        }
        if self.gop == 0 {
            return Err(Error::option("gop", "must be at least 1"));
        }
        if self.bit_depth.is_some_and(|d| !DEPTHS.contains(&d)) {
            return Err(Error::option("bit_depth", "must be 10 or 12"));
        }
        self.pictures.check(codec)
    }

    /// The bits a sample of `codec`'s encoding at `quality` (between the integers too):
    /// `bit_depth`, else [`auto_depth`]'s.
    pub(crate) fn depth_at(&self, codec: Codec, quality: f64) -> u8 {
        self.bit_depth
            .unwrap_or_else(|| auto_depth_at(codec, quality))
    }

    /// The plan of `rate` for `codec` on a first frame of bounding-box diagonal `diagonal`: the
    /// depth ([`auto_depth`] unless given), `laws`' pixel step and quantiser at that depth, ranges
    /// per group, [`deep_padding`], and the codec's affine precision unless asked otherwise.
    pub(crate) fn plan(
        &self,
        codec: Codec,
        laws: DeepLaws,
        rate: &Rate,
        diagonal: f64,
    ) -> Result<RatePlan> {
        let depth = self.depth_at(codec, rate.level());
        // Only the automatic depth may turn, and only at the law's quantiser: a quantiser the
        // caller gave means one thing at one depth. At 12 bits the residuals pick among the
        // codec's 12-bit laws where it has more than one, unless the caller gave the pixel step
        // (the laws' other steps would not be taken: a coarser quantiser over the same samples).
        let scale = rate.scale_percent();
        let laws_12 = || {
            let own = (laws.law)(scale, 12);
            let coarser = laws.coarser_12.filter(|_| rate.step.is_none());
            let coarser = coarser.map_or_else(Vec::new, |coarser| coarser(own));
            std::iter::once(own).chain(coarser).collect::<Vec<_>>()
        };
        let deeper = match (self.qp, depth) {
            (None, 12) => Some(laws_12()).filter(|laws| laws.len() > 1),
            (None, _) if self.bit_depth.is_none() => Some(laws_12()),
            _ => None,
        };
        let affine_precision = laws.affine_precision;
        let law = (laws.law)(scale, depth);
        let resolved = Resolved {
            codec,
            step_factor: law.step_factor,
            quantiser: self.qp.unwrap_or(law.quantiser),
            gop: self.gop,
            depth,
            padding: deep_padding(self.gop),
            affine_precision,
            deeper: deeper.unwrap_or_default(),
        };
        super::plan(rate, diagonal, &self.pictures, resolved)
    }
}

/// The padding of HEVC's and AV1's geometry images with a key frame every `gop` frames.
/// P-frame groups: `biharmonic`, smooth across chart borders, what a transform codec codes cheaply.
/// All-intra (`gop` 1): `pushpull`, which needs fewer bits there at equal error; in P-frame groups
/// no method beat `biharmonic` clearly (docs/design.md, "Padding per codec").
pub fn deep_padding(gop: usize) -> padding::Method {
    if gop <= 1 {
        padding::Method::PushPull
    } else {
        padding::Method::Biharmonic
    }
}

/// The FFmpeg encoder and decoder of HEVC and AV1, and their geometry-video glue.
#[cfg(feature = "ffmpeg")]
mod coder {
    use super::super::PictureSetup;
    use super::super::{libav, PictureCodec, PictureDecoder, PictureEncoder, PicturePlan, Plane};
    use super::DEPTHS;
    use crate::geometry_image::quantise;
    use crate::stream::frame_index::FrameChunk;
    use crate::{Error, Result};
    use ffmpeg_next::{codec, decoder, encoder, format::Pixel, frame, Dictionary};

    /// How the geometry-video coder lays out x | y | z.
    pub const DEFAULT_PLANES: Planes = Planes::Yuv444;
    /// The time base only labels frames.
    const TIME_BASE: (i32, i32) = (1, 25);

    /// What one deep-sample codec is: its names, its FFmpeg encoder and settings, its decoder, its
    /// quantiser's range and the law mapping `quality` onto it.
    pub trait Flavour: Sync {
        /// The codec's name in errors and on the command line ("hevc", "av1").
        fn name(&self) -> &'static str;
        /// The FFmpeg encoder's name.
        fn encoder_name(&self) -> &'static str;
        /// The FFmpeg decoder's codec id (FFmpeg picks its preferred decoder for it).
        fn decoder_id(&self) -> codec::Id;
        /// The largest quantiser the encoder takes (0 is the finest).
        fn max_qp(&self) -> u8;
        /// The encoder's private options (FFmpeg's dictionary) for a fixed quantiser, deterministic
        /// output and a key frame every `gop` frames (size, format, GOP, no B-frames and one thread
        /// are set on the context already); `size` is the picture's width and height.
        fn settings(&self, options: &Options, gop: u32, size: (u32, u32)) -> Dictionary<'static>;
    }

    /// How the x | y | z residual images of a frame go into a picture.
    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    pub enum Planes {
        /// The three side by side in one monochrome (4:0:0) picture.
        Mono,
        /// Each in one plane (Y, Cb, Cr) of a 4:4:4 picture a third as wide.
        Yuv444,
    }

    impl Planes {
        fn id(self) -> u8 {
            match self {
                Planes::Mono => 0,
                Planes::Yuv444 => 1,
            }
        }

        /// The planes of an FFmpeg picture (1 or 3).
        fn count(self) -> usize {
            match self {
                Planes::Mono => 1,
                Planes::Yuv444 => 3,
            }
        }
    }

    /// Encoder settings.
    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    pub struct Options {
        /// Fixed quantiser, 0 (finest) ..= the flavour's [`Flavour::max_qp`].
        pub qp: u8,
        /// Frames per group of pictures: a key frame, then `gop − 1` P-frames (1: all-intra).
        pub gop: usize,
        /// Bits a sample: 10 or 12.
        pub depth: u8,
        /// Monochrome or 4:4:4.
        pub planes: Planes,
    }

    /// One coded frame.
    #[derive(Debug, Clone, PartialEq, Eq)]
    pub struct Packet {
        /// The coded frame, with the sequence headers on key frames.
        pub data: Vec<u8>,
        /// True for a key frame: decoding may start here.
        pub key: bool,
    }

    fn pixel_format(name: &str, depth: u8, planes: Planes) -> Result<Pixel> {
        match (depth, planes) {
            (10, Planes::Mono) => Ok(Pixel::GRAY10LE),
            (12, Planes::Mono) => Ok(Pixel::GRAY12LE),
            (10, Planes::Yuv444) => Ok(Pixel::YUV444P10LE),
            (12, Planes::Yuv444) => Ok(Pixel::YUV444P12LE),
            _ => Err(Error::Codec(format!(
                "{name} sample depth {depth}: expected one of {DEPTHS:?}"
            ))),
        }
    }

    /// The FFmpeg picture size of a `width × height` x | y | z plane.
    fn picture_size(name: &str, width: u32, height: u32, planes: Planes) -> Result<(u32, u32)> {
        match planes {
            Planes::Mono => Ok((width, height)),
            Planes::Yuv444 if width % 3 == 0 => Ok((width / 3, height)),
            Planes::Yuv444 => Err(Error::Codec(format!(
                "{name} 4:4:4 plane width {width} is not three images wide"
            ))),
        }
    }

    /// A fixed-quantiser encoder for a sequence of same-size monochrome planes.
    pub struct Encoder {
        inner: encoder::Video,
        name: &'static str,
        width: u32,
        height: u32,
        depth: u8,
        planes: Planes,
        next_pts: i64,
    }

    impl Encoder {
        /// Opens `flavour`'s encoder for `width × height` planes whose first plane is frame
        /// `first_frame`.
        pub fn new(
            flavour: &dyn Flavour,
            width: u32,
            height: u32,
            options: &Options,
            first_frame: usize,
        ) -> Result<Self> {
            libav::init()?;
            let name = flavour.name();
            let format = pixel_format(name, options.depth, options.planes)?;
            if width < 16 || height < 16 || width % 2 != 0 || height % 2 != 0 {
                return Err(Error::Codec(format!(
                    "{name} size {width}×{height}: sides must be even and at least 16"
                )));
            }
            if options.qp > flavour.max_qp() {
                return Err(Error::Codec(format!(
                    "{name} qp {} outside 0..={}",
                    options.qp,
                    flavour.max_qp()
                )));
            }
            let gop = libav::checked_gop(name, options.gop)?;
            let codec = encoder::find_by_name(flavour.encoder_name()).ok_or_else(|| {
                Error::Codec(format!(
                    "{} encoder missing from libavcodec",
                    flavour.encoder_name()
                ))
            })?;
            let mut video = codec::Context::new_with_codec(codec)
                .encoder()
                .video()
                .map_err(|e| libav::error(name, "encoder context", e))?;
            let (picture_width, picture_height) =
                picture_size(name, width, height, options.planes)?;
            video.set_width(picture_width);
            video.set_height(picture_height);
            video.set_format(format);
            video.set_time_base(TIME_BASE);
            video.set_gop(gop);
            video.set_max_b_frames(0);
            video.set_threading(libav::one_thread());
            let inner = video
                .open_as_with(
                    codec,
                    flavour.settings(options, gop, (picture_width, picture_height)),
                )
                .map_err(|e| {
                    let context = format!("open {} {width}×{height}", flavour.encoder_name());
                    libav::error(name, &context, e)
                })?;
            Ok(Encoder {
                inner,
                name,
                width,
                height,
                depth: options.depth,
                planes: options.planes,
                next_pts: i64::try_from(first_frame).map_err(|_| {
                    Error::Codec(format!("{name} first frame {first_frame} too large"))
                })?,
            })
        }

        /// Codes the next plane; returns the packets ready so far (an encoder may hold frames back).
        pub fn encode(&mut self, plane: &Plane<u16>) -> Result<Vec<Packet>> {
            let name = self.name;
            plane.check()?;
            if (plane.width, plane.height) != (self.width, self.height) {
                return Err(Error::Codec(format!(
                    "{name} plane {}×{} given to a {}×{} encoder",
                    plane.width, plane.height, self.width, self.height
                )));
            }
            let top = quantise::max_level(self.depth) as u16;
            if plane.data.iter().any(|&v| v > top) {
                return Err(Error::Codec(format!(
                    "{name} plane has samples above {top}, the largest at {} bits",
                    self.depth
                )));
            }
            let (w, h) = picture_size(name, self.width, self.height, self.planes)?;
            let mut picture = frame::Video::new(pixel_format(name, self.depth, self.planes)?, w, h);
            for index in 0..self.planes.count() {
                fill_samples(&mut picture, index, plane, index * w as usize, w as usize)?;
            }
            picture.set_pts(Some(self.next_pts));
            self.inner
                .send_frame(&picture)
                .map_err(|e| libav::error(name, &format!("encode frame {}", self.next_pts), e))?;
            self.next_pts += 1;
            self.receive()
        }

        /// Ends the sequence and returns the packets still held by the encoder.
        pub fn finish(mut self) -> Result<Vec<Packet>> {
            self.inner
                .send_eof()
                .map_err(|e| libav::error(self.name, "flush encoder", e))?;
            self.receive()
        }

        fn receive(&mut self) -> Result<Vec<Packet>> {
            let mut packets = Vec::new();
            while let Some(packet) = libav::next_packet(self.name, &mut self.inner)? {
                packets.push(Packet {
                    data: packet.data().unwrap_or_default().to_vec(),
                    key: packet.is_key(),
                });
            }
            Ok(packets)
        }
    }

    /// Copies columns `x0..x0 + width` of the plane into FFmpeg plane `index` of `picture`, as 16-bit
    /// little-endian samples, row by row (FFmpeg pads rows to its own stride, in bytes). The rest
    /// of FFmpeg's buffer, which it leaves as the allocator gave it, is zeroed first: no byte an
    /// encoder may read can differ from one run to the next.
    fn fill_samples(
        picture: &mut frame::Video,
        index: usize,
        plane: &Plane<u16>,
        x0: usize,
        width: usize,
    ) -> Result<()> {
        let stride = picture.stride(index);
        let buffer = picture.data_mut(index);
        buffer.fill(0);
        for (y, row) in plane.data.chunks_exact(plane.width as usize).enumerate() {
            let src = &row[x0..x0 + width];
            let start = y * stride;
            let dst = buffer
                .get_mut(start..start + 2 * width)
                .ok_or_else(|| Error::Codec("frame buffer smaller than the plane".into()))?;
            for (d, v) in dst.chunks_exact_mut(2).zip(src) {
                d.copy_from_slice(&v.to_le_bytes());
            }
        }
        Ok(())
    }

    /// A decoder giving back the planes of a stream made by [`Encoder`].
    pub struct Decoder {
        inner: decoder::Video,
        name: &'static str,
        width: u32,
        height: u32,
        depth: u8,
        planes: Planes,
        /// Whether a key frame has been decoded since the last reset: a P-frame without its
        /// reference must be an error, not a plausible but wrong picture.
        has_reference: bool,
    }

    impl Decoder {
        /// Opens `flavour`'s decoder for `width × height` x | y | z planes of `depth`-bit samples,
        /// coded as `planes` says.
        pub fn new(
            flavour: &dyn Flavour,
            width: u32,
            height: u32,
            depth: u8,
            planes: Planes,
        ) -> Result<Self> {
            let name = flavour.name();
            pixel_format(name, depth, planes)?;
            picture_size(name, width, height, planes)?;
            let inner = libav::open_decoder(name, flavour.decoder_id())?;
            Ok(Decoder {
                inner,
                name,
                width,
                height,
                depth,
                planes,
                has_reference: false,
            })
        }

        /// Decodes one packet; returns the pictures it completes (one per packet for our streams).
        pub fn decode(&mut self, packet: &[u8]) -> Result<Vec<Plane<u16>>> {
            libav::send_packet(self.name, &mut self.inner, packet)?;
            self.receive()
        }

        /// Signals the end of the stream and returns the pictures still held by the decoder.
        pub fn flush(&mut self) -> Result<Vec<Plane<u16>>> {
            self.inner
                .send_eof()
                .map_err(|e| libav::error(self.name, "flush decoder", e))?;
            let planes = self.receive()?;
            self.inner.flush();
            self.has_reference = false;
            Ok(planes)
        }

        fn receive(&mut self) -> Result<Vec<Plane<u16>>> {
            let mut planes = Vec::new();
            while let Some(picture) = libav::next_picture(self.name, &mut self.inner)? {
                planes.push(self.samples(&picture)?);
            }
            Ok(planes)
        }

        fn samples(&mut self, picture: &frame::Video) -> Result<Plane<u16>> {
            let name = self.name;
            if picture.is_corrupt() || picture.has_decode_errors() {
                return Err(Error::Codec(format!("{name} picture decoded with errors")));
            }
            if picture.is_key() {
                self.has_reference = true;
            } else if !self.has_reference {
                return Err(Error::Codec(format!(
                    "{name} P-frame before any key frame: decoding must start at a key frame"
                )));
            }
            let format = pixel_format(name, self.depth, self.planes)?;
            let (w, h) = picture_size(name, self.width, self.height, self.planes)?;
            if picture.format() != format || (picture.width(), picture.height()) != (w, h) {
                return Err(Error::Codec(format!(
                    "{name} picture is {:?} {}×{}, expected {format:?} {w}×{h}",
                    picture.format(),
                    picture.width(),
                    picture.height(),
                )));
            }
            let (w, h) = (w as usize, h as usize);
            let mut data = vec![0u16; self.width as usize * h];
            for index in 0..self.planes.count() {
                let (stride, bytes) = (picture.stride(index), picture.data(index));
                for (y, out) in data.chunks_exact_mut(self.width as usize).enumerate() {
                    let row = bytes.get(y * stride..y * stride + 2 * w).ok_or_else(|| {
                        Error::Codec(format!("{name} picture buffer shorter than its size"))
                    })?;
                    let dst = &mut out[index * w..(index + 1) * w];
                    for (d, b) in dst.iter_mut().zip(row.chunks_exact(2)) {
                        *d = u16::from_le_bytes([b[0], b[1]]);
                    }
                }
            }
            Plane::new(self.width, self.height, data)
        }
    }

    /// A deep-sample codec as the geometry-video picture codec: a key frame every `gop` frames,
    /// P-frames between, the planes of [`DEFAULT_PLANES`].
    pub(crate) struct Pictures<F>(pub F);

    impl<F: Flavour> PictureCodec for Pictures<F> {
        fn settings(&self, quantiser: u8, gop: u32, depth: u8) -> Vec<(&'static str, u32)> {
            vec![
                ("qp", quantiser.into()),
                ("gop", gop),
                ("bit_depth", depth.into()),
            ]
        }

        fn encoder(
            &self,
            width: u32,
            height: u32,
            first_frame: usize,
            plan: &PicturePlan,
        ) -> Result<Box<dyn PictureEncoder>> {
            let options = Options {
                qp: plan.quantiser,
                gop: plan.gop,
                depth: plan.depth,
                planes: DEFAULT_PLANES,
            };
            Ok(Box::new(PacketEncoder {
                encoder: Encoder::new(&self.0, width, height, &options, first_frame)?,
                packets: Vec::new(),
            }))
        }

        fn decoder(
            &self,
            width: u32,
            height: u32,
            setup: &PictureSetup,
        ) -> Result<Box<dyn PictureDecoder>> {
            let planes = read_planes(self.0.name(), &setup.codec_data)?;
            let decoder = Decoder::new(&self.0, width, height, setup.depth, planes)?;
            Ok(Box::new(PacketDecoder(decoder)))
        }
    }

    /// The planes of the codec's bytes of a set-up part.
    pub(super) fn read_planes(name: &str, codec_data: &[u8]) -> Result<Planes> {
        let planes = [Planes::Mono, Planes::Yuv444];
        match codec_data {
            [id] => planes
                .into_iter()
                .find(|p| p.id() == *id)
                .ok_or_else(|| Error::Stream(format!("{name} set-up: unknown planes {id}"))),
            _ => Err(Error::Stream(format!(
                "{name} set-up {codec_data:?}: expected the planes"
            ))),
        }
    }

    struct PacketEncoder {
        encoder: Encoder,
        packets: Vec<Packet>,
    }

    impl PictureEncoder for PacketEncoder {
        fn push(&mut self, plane: &Plane<u16>) -> Result<()> {
            self.packets.extend(self.encoder.encode(plane)?);
            Ok(())
        }

        fn finish(self: Box<Self>) -> Result<(Vec<u8>, Vec<FrameChunk>)> {
            let setup = vec![self.encoder.planes.id()];
            let mut packets = self.packets;
            packets.extend(self.encoder.finish()?);
            let chunks = packets
                .into_iter()
                .map(|p| FrameChunk {
                    data: p.data,
                    key: p.key,
                })
                .collect();
            Ok((setup, chunks))
        }
    }

    /// One packet per frame and no B-frames: no reordering.
    struct PacketDecoder(Decoder);

    impl PictureDecoder for PacketDecoder {
        fn decode(&mut self, f: usize, packet: &[u8]) -> Result<Plane<u16>> {
            let mut planes = self.0.decode(packet)?;
            if planes.is_empty() {
                planes = self.0.flush()?;
            }
            planes.pop().ok_or_else(|| {
                Error::Stream(format!(
                    "frame {f}: the {} packet decoded to no picture",
                    self.0.name
                ))
            })
        }
    }
}

/// What hevc's and av1's unit tests share.
#[cfg(all(test, feature = "ffmpeg"))]
#[path = "deep_testing.rs"]
pub(crate) mod testing;
