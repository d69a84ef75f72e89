//! MPEG-4 Part 2 (FFmpeg's native `mpeg4` encoder and decoder through `ffmpeg-next`).
//!
//! The plane goes in the luma of a YUV 4:2:0 picture with flat chroma (128), which costs a few bits per
//! macroblock. The quantiser is fixed: FFmpeg only honours it when the context has the QSCALE flag and
//! `global_quality`, *and* every input frame carries the same value in its `quality` field — without
//! the latter the encoder silently runs at `qmin`. No B-frames, one thread and no scene-cut detection,
//! so each frame yields exactly one packet, in order, and I-frames fall exactly every `gop` frames.
//! Headers are in-band (no global header): each I-frame packet repeats the VOL header, so decoding can
//! start at any I-frame.

use super::{PictureOptions, Resolved, DEFAULT_GOP};
use crate::codec::rate::{anchor, read_law, Anchor, PictureLaw, Rate, RatePlan};
use crate::codec::Codec;
use crate::error::{Error, Result};

#[cfg(feature = "ffmpeg")]
pub(crate) use coder::Pictures;
#[cfg(all(feature = "ffmpeg", any(test, feature = "internals")))]
pub use coder::{Decoder, Encoder, Mpeg4Options, Packet};

/// MPEG-4 Part 2's options: its quantiser, its groups of pictures, their lattice and padding.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Mpeg4Config {
    /// The fixed quantiser (qscale) 1..=31, lower is finer; `None` takes the law's for the
    /// encoding's quality.
    pub qscale: Option<u8>,
    /// Frames per group of pictures: an I-frame, then `gop − 1` P-frames.
    pub gop: usize,
    /// The lattice and padding (default `biharmonic`).
    pub pictures: PictureOptions,
}

impl Default for Mpeg4Config {
    fn default() -> Self {
        Self {
            qscale: None,
            gop: DEFAULT_GOP,
            pictures: PictureOptions::default(),
        }
    }
}

impl Mpeg4Config {
    /// Fails, naming the option, when one is out of range.
    pub(crate) fn check(&self) -> Result<()> {
        if self.qscale.is_some_and(|q| !(1..=31).contains(&q)) {
            return Err(Error::option("qscale", "must be between 1 and 31"));
        }
        if self.gop == 0 {
            return Err(Error::option("gop", "must be at least 1"));
        }
        self.pictures.check(Codec::Mpeg4)
    }

    /// The plan of `rate` on a first frame of bounding-box diagonal `diagonal`: the law's pixel
    /// step and qscale, ranges per group, `biharmonic` padding, affine maps at
    /// [`super::p_frame_affine_precision`] (1/16 all-intra, as always, unmeasured).
    pub(crate) fn plan(&self, rate: &Rate, diagonal: f64) -> Result<RatePlan> {
        let law = mpeg4_law_at(rate.level());
        let resolved = Resolved {
            codec: Codec::Mpeg4,
            step_factor: law.step_factor,
            quantiser: self.qscale.unwrap_or(law.quantiser),
            gop: self.gop,
            depth: 8,
            padding: padding::Method::Biharmonic,
            affine_precision: match self.gop {
                1 => 1.0 / 16.0,
                _ => super::p_frame_affine_precision(rate),
            },
            deeper: Vec::new(),
        };
        super::plan(rate, diagonal, &self.pictures, resolved)
    }
}

/// MPEG-4's law, made as JPEG's over pixel step × qscale: qscales 1, 2 and 4 lie on one curve
/// (error about pixel step^0.6) where the 8-bit range allows; 2 is kept, and 1 from quality 90,
/// where finer steps meet the 8-bit floor on sequences with large residuals
/// (docs/design.md, "Quality laws (JPEG, MPEG-4, HEVC, AV1)").
const MPEG4_LAW: [Anchor; 4] = [
    anchor(1, 0.8, 2),
    anchor(50, 0.21, 2),
    anchor(75, 0.27, 2),
    anchor(90, 0.16, 1),
];

/// The step of MPEG-4's qscale `q`, relative: the qscale (its quantiser step is 2 × qscale).
pub(crate) fn mpeg4_quantiser_step(q: u8) -> f64 {
    f64::from(q.max(1))
}

/// MPEG-4's pixel step factor and qscale for a user quality 1..100.
#[cfg_attr(not(any(test, feature = "internals")), allow(dead_code))]
pub fn mpeg4_law(quality: u8) -> PictureLaw {
    mpeg4_law_at(f64::from(quality))
}

/// [`mpeg4_law`] at a quality between the integers too.
pub(crate) fn mpeg4_law_at(quality: f64) -> PictureLaw {
    read_law(&MPEG4_LAW, mpeg4_quantiser_step, quality)
}

/// The FFmpeg encoder and decoder, and their geometry-video glue.
#[cfg(feature = "ffmpeg")]
mod coder {
    use super::super::PictureSetup;
    use super::super::{libav, PictureCodec, PictureDecoder, PictureEncoder, PicturePlan, Plane};
    use crate::stream::frame_index::FrameChunk;
    use crate::{Error, Result};
    use ffmpeg_next as ffmpeg;
    use ffmpeg_next::util::picture;
    use ffmpeg_next::{codec, decoder, encoder, format::Pixel, frame, Dictionary};

    /// Chroma value of a neutral (grey) picture: the planes carry no information.
    const NEUTRAL_CHROMA: u8 = 128;
    /// MPEG-4 video object layer width and height are 13-bit fields.
    const MAX_SIDE: u32 = 8191;
    /// The time base only labels frames; 1/25 keeps `vop_time_increment` short.
    const TIME_BASE: (i32, i32) = (1, 25);
    /// `sc_threshold` at this value switches scene-cut detection off (FFmpeg's own "never").
    const NO_SCENE_CUT: &str = "1000000000";

    /// Encoder settings.
    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    pub struct Mpeg4Options {
        /// Fixed quantiser, 1 (best) ..= 31 (coarsest); see [`super::mpeg4_law`].
        pub qscale: u8,
        /// Frames per group of pictures: an I-frame, then `gop − 1` P-frames.
        pub gop: usize,
    }

    impl Default for Mpeg4Options {
        fn default() -> Self {
            Mpeg4Options { qscale: 4, gop: 30 }
        }
    }

    /// One coded frame.
    #[derive(Debug, Clone, PartialEq, Eq)]
    pub struct Packet {
        /// The MPEG-4 bitstream of the frame (with VOS/VOL headers on I-frames).
        pub data: Vec<u8>,
        /// Index of the frame in the sequence given to [`Encoder::encode`], from 0.
        pub pts: i64,
        /// True for an I-frame: decoding may start here.
        pub key: bool,
    }

    const NAME: &str = "mpeg4";

    fn ff_error(context: &str, e: ffmpeg::Error) -> Error {
        libav::error(NAME, context, e)
    }

    /// The sizes the encoder takes: 4:2:0 chroma needs even sides, the VOL header 13 bits.
    fn check_size(width: u32, height: u32) -> Result<()> {
        let ok = |side: u32| (2..=MAX_SIDE).contains(&side) && side % 2 == 0;
        if ok(width) && ok(height) {
            Ok(())
        } else {
            Err(Error::Codec(format!(
                "mpeg4 size {width}×{height}: sides must be even and within 2..={MAX_SIDE}"
            )))
        }
    }

    /// A fixed-quantiser MPEG-4 Part 2 encoder for a sequence of same-size planes.
    pub struct Encoder {
        inner: encoder::Video,
        width: u32,
        height: u32,
        /// Lambda of the fixed quantiser, set on every frame.
        lambda: i32,
        next_pts: i64,
    }

    impl Encoder {
        #[cfg(any(test, feature = "internals"))]
        /// Opens an encoder for `width × height` planes (sides even, at most 8191).
        pub fn new(width: u32, height: u32, options: &Mpeg4Options) -> Result<Self> {
            Self::starting_at(width, height, options, 0)
        }

        /// [`Encoder::new`] for a sequence whose first plane is frame `first_frame` of a longer one:
        /// its time stamps continue there, so a group of pictures coded alone carries the same time
        /// code (and so the same bytes) as when one encoder codes the whole sequence.
        pub fn starting_at(
            width: u32,
            height: u32,
            options: &Mpeg4Options,
            first_frame: usize,
        ) -> Result<Self> {
            libav::init()?;
            check_size(width, height)?;
            if !(1..=31).contains(&options.qscale) {
                return Err(Error::Codec(format!(
                    "mpeg4 qscale {} outside 1..=31",
                    options.qscale
                )));
            }
            let gop = libav::checked_gop(NAME, options.gop)?;
            let codec = encoder::find(codec::Id::MPEG4)
                .ok_or_else(|| Error::Codec("mpeg4 encoder missing from libavcodec".into()))?;
            let mut video = codec::Context::new_with_codec(codec)
                .encoder()
                .video()
                .map_err(|e| ff_error("encoder context", e))?;
            let lambda = i32::from(options.qscale) * ffmpeg::ffi::FF_QP2LAMBDA;
            video.set_width(width);
            video.set_height(height);
            video.set_format(Pixel::YUV420P);
            video.set_time_base(TIME_BASE);
            video.set_gop(gop);
            video.set_max_b_frames(0);
            video.set_qmin(1);
            video.set_qmax(31);
            video.set_global_quality(lambda);
            // BITEXACT drops the "Lavc…" user-data string from every I-frame and pins the output across
            // FFmpeg builds.
            video.set_flags(codec::Flags::QSCALE | codec::Flags::BITEXACT);
            video.set_threading(libav::one_thread());
            let mut dict = Dictionary::new();
            dict.set("sc_threshold", NO_SCENE_CUT);
            // Trellis quantisation: a lower error per byte, for encoding time the residual pictures
            // can afford (docs/design.md, "MPEG-4 encoder settings").
            dict.set("trellis", "1");
            // Rate-distortion decisions: macroblock mode by rate-distortion (`mbd` rd), SATD for
            // motion search (`cmp`, `subcmp`), the coded-block pattern chosen by rate-distortion and
            // the zero motion vector always tried (`mpv_flags` cbp_rd, mv0: a chart stays in place
            // from frame to frame); fewer bits at equal error for a little more encoding time
            // (docs/design.md, "MPEG-4 encoder settings").
            dict.set("mbd", "2");
            dict.set("cmp", "2");
            dict.set("subcmp", "2");
            dict.set("mpv_flags", "+cbp_rd+mv0");
            let inner = video
                .open_as_with(codec, dict)
                .map_err(|e| ff_error(&format!("open encoder {width}×{height}"), e))?;
            Ok(Encoder {
                inner,
                width,
                height,
                lambda,
                next_pts: i64::try_from(first_frame).map_err(|_| {
                    Error::Codec(format!("mpeg4 first frame {first_frame} too large"))
                })?,
            })
        }

        /// Codes the next plane; returns the packets ready so far (one per frame with these settings).
        pub fn encode(&mut self, plane: &Plane) -> Result<Vec<Packet>> {
            plane.check()?;
            if (plane.width, plane.height) != (self.width, self.height) {
                return Err(Error::Codec(format!(
                    "mpeg4 plane {}×{} given to a {}×{} encoder",
                    plane.width, plane.height, self.width, self.height
                )));
            }
            let mut picture = frame::Video::new(Pixel::YUV420P, self.width, self.height);
            fill_luma(&mut picture, plane)?;
            picture.data_mut(1).fill(NEUTRAL_CHROMA);
            picture.data_mut(2).fill(NEUTRAL_CHROMA);
            picture.set_pts(Some(self.next_pts));
            // SAFETY: `picture` owns a valid AVFrame; `quality` is a plain int field that ffmpeg-next
            // exposes only for reading.
            unsafe {
                (*picture.as_mut_ptr()).quality = self.lambda;
            }
            self.inner
                .send_frame(&picture)
                .map_err(|e| ff_error(&format!("encode frame {}", self.next_pts), e))?;
            self.next_pts += 1;
            self.receive()
        }

        /// Ends the sequence and returns the packets still held by the encoder.
        pub fn finish(mut self) -> Result<Vec<Packet>> {
            self.inner
                .send_eof()
                .map_err(|e| ff_error("flush encoder", e))?;
            self.receive()
        }

        fn receive(&mut self) -> Result<Vec<Packet>> {
            let mut packets = Vec::new();
            while let Some(packet) = libav::next_packet(NAME, &mut self.inner)? {
                packets.push(Packet {
                    data: packet.data().unwrap_or_default().to_vec(),
                    pts: packet.pts().unwrap_or(self.next_pts - 1),
                    key: packet.is_key(),
                });
            }
            Ok(packets)
        }
    }

    /// Copies the plane into the luma of `picture`, row by row (FFmpeg pads rows to its own stride);
    /// the padding, which FFmpeg leaves as the allocator gave it, is zeroed first, so that no byte
    /// the encoder may read differs from one run to the next.
    fn fill_luma(picture: &mut frame::Video, plane: &Plane) -> Result<()> {
        let stride = picture.stride(0);
        let width = plane.width as usize;
        let luma = picture.data_mut(0);
        luma.fill(0);
        for (y, src) in plane.data.chunks_exact(width).enumerate() {
            let start = y * stride;
            let dst = luma
                .get_mut(start..start + width)
                .ok_or_else(|| Error::Codec("mpeg4 frame buffer smaller than the plane".into()))?;
            dst.copy_from_slice(src);
        }
        Ok(())
    }

    /// An MPEG-4 Part 2 decoder giving back the luma planes of a stream made by [`Encoder`].
    pub struct Decoder {
        inner: decoder::Video,
        width: u32,
        height: u32,
        /// Whether an I-frame has been decoded since the last reset: FFmpeg would otherwise predict a
        /// leading P-frame from nothing and return a plausible but wrong picture.
        has_reference: bool,
    }

    impl Decoder {
        /// Opens a decoder that expects `width × height` pictures.
        pub fn new(width: u32, height: u32) -> Result<Self> {
            check_size(width, height)?;
            let inner = libav::open_decoder(NAME, codec::Id::MPEG4)?;
            Ok(Decoder {
                inner,
                width,
                height,
                has_reference: false,
            })
        }

        /// Decodes one packet; returns the pictures it completes (one per packet for our streams).
        ///
        /// The first packet after [`Decoder::new`] or [`Decoder::reset`] must be an I-frame.
        pub fn decode(&mut self, packet: &[u8]) -> Result<Vec<Plane>> {
            libav::send_packet(NAME, &mut self.inner, packet)?;
            self.receive()
        }

        /// Signals the end of the stream and returns the pictures still held by the decoder.
        pub fn flush(&mut self) -> Result<Vec<Plane>> {
            self.inner
                .send_eof()
                .map_err(|e| ff_error("flush decoder", e))?;
            let planes = self.receive()?;
            self.reset();
            Ok(planes)
        }

        /// Forgets all reference pictures, so decoding can restart at another I-frame.
        pub fn reset(&mut self) {
            self.inner.flush();
            self.has_reference = false;
        }

        fn receive(&mut self) -> Result<Vec<Plane>> {
            let mut planes = Vec::new();
            while let Some(picture) = libav::next_picture(NAME, &mut self.inner)? {
                planes.push(self.luma(&picture)?);
            }
            Ok(planes)
        }

        fn luma(&mut self, picture: &frame::Video) -> Result<Plane> {
            if picture.is_corrupt() || picture.has_decode_errors() {
                return Err(Error::Codec("mpeg4 picture decoded with errors".into()));
            }
            if picture.kind() == picture::Type::I {
                self.has_reference = true;
            } else if !self.has_reference {
                return Err(Error::Codec(format!(
                    "mpeg4 {:?}-frame before any I-frame: decoding must start at an I-frame",
                    picture.kind()
                )));
            }
            if picture.format() != Pixel::YUV420P
                || (picture.width(), picture.height()) != (self.width, self.height)
            {
                return Err(Error::Codec(format!(
                    "mpeg4 picture is {:?} {}×{}, expected YUV420P {}×{}",
                    picture.format(),
                    picture.width(),
                    picture.height(),
                    self.width,
                    self.height
                )));
            }
            let (width, height) = (self.width as usize, self.height as usize);
            let stride = picture.stride(0);
            let luma = picture.data(0);
            let mut data = Vec::with_capacity(width * height);
            for y in 0..height {
                let row = luma.get(y * stride..y * stride + width).ok_or_else(|| {
                    Error::Codec("mpeg4 picture buffer shorter than its size".into())
                })?;
                data.extend_from_slice(row);
            }
            Plane::new(self.width, self.height, data)
        }
    }

    /// MPEG-4 Part 2 as the geometry-video picture codec: an I-frame every `gop` frames, P-frames
    /// between, residual ranges shared by a group so that P-frames predict like from like.
    pub(crate) struct Pictures;

    impl PictureCodec for Pictures {
        fn encoder(
            &self,
            width: u32,
            height: u32,
            first_frame: usize,
            plan: &PicturePlan,
        ) -> Result<Box<dyn PictureEncoder>> {
            let options = Mpeg4Options {
                qscale: plan.quantiser,
                gop: plan.gop,
            };
            Ok(Box::new(PacketEncoder {
                encoder: Encoder::starting_at(width, height, &options, first_frame)?,
                packets: Vec::new(),
            }))
        }

        fn settings(&self, quantiser: u8, gop: u32, _depth: u8) -> Vec<(&'static str, u32)> {
            vec![("qscale", quantiser.into()), ("gop", gop)]
        }

        fn decoder(
            &self,
            width: u32,
            height: u32,
            _setup: &PictureSetup,
        ) -> Result<Box<dyn PictureDecoder>> {
            Ok(Box::new(PacketDecoder(Decoder::new(width, height)?)))
        }
    }

    struct PacketEncoder {
        encoder: Encoder,
        packets: Vec<Packet>,
    }

    impl PictureEncoder for PacketEncoder {
        fn push(&mut self, plane: &Plane<u16>) -> Result<()> {
            self.packets.extend(self.encoder.encode(&plane.to_8bit()?)?);
            Ok(())
        }

        fn finish(self: Box<Self>) -> Result<(Vec<u8>, Vec<FrameChunk>)> {
            let mut packets = self.packets;
            packets.extend(self.encoder.finish()?);
            let chunks = packets
                .into_iter()
                .map(|p| FrameChunk {
                    data: p.data,
                    key: p.key,
                })
                .collect();
            Ok((Vec::new(), chunks))
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
            planes.pop().map(|p| p.widen()).ok_or_else(|| {
                Error::Stream(format!(
                    "frame {f}: the MPEG-4 packet decoded to no picture"
                ))
            })
        }
    }
}
