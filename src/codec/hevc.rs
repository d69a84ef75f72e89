//! HEVC (H.265) at 10 or 12 bits a sample: FFmpeg's `libx265` encoder and its native `hevc`
//! decoder, through `ffmpeg-next` (cargo feature `mpeg4`, which brings FFmpeg).
//!
//! The x | y | z picture is coded as the three planes of a 4:4:4 picture (`yuv444p10le`,
//! `yuv444p12le`), which shares block modes and motion vectors between the coordinates: measured
//! 3–9 % smaller at equal error than the three side by side in one monochrome (4:0:0) picture
//! (`gray10le`, `gray12le`; [`Planes::Mono`], which the decoder also reads) on CesiumMan and the
//! walking cat at quality 30/50/75 (docs/results.md).
//! The quantiser is a fixed QP (`qp=`, no rate control, `tune=psnr`: no psycho-visual tricks, which
//! spend bits on what looks sharp rather than on the error). No B-frames, no scene cuts, no open
//! GOPs: an IDR every `gop` frames (every frame with `gop` 1: all-intra), P-frames between, so each
//! frame gives exactly one packet, in order, and decoding can start at any IDR. Headers are
//! in-band (`repeat-headers`: VPS/SPS/PPS on every IDR). x265 runs without its thread pool and with
//! one frame thread, so its output does not depend on scheduling: the geometry-video coder runs
//! groups of pictures on several threads instead.
//!
//! The stream's codec set-up part holds the sample depth and the planes (one byte each), which the
//! decoder needs before any picture (the depth to read the residual ranges).

use super::geometry_video::{PictureCodec, PictureDecoder, PictureEncoder};
use super::libav;
use super::{Codec, Plane};
use crate::encoder::EncodeOptions;
use crate::geometry_image::{quantise, RangeMode};
use crate::stream::frame_index::FrameChunk;
use crate::{Error, Result};
use ffmpeg_next as ffmpeg;
use ffmpeg_next::{codec, decoder, encoder, format::Pixel, frame, Dictionary};

/// Sample depths the codec takes, in bits.
pub const DEPTHS: [u8; 2] = [10, 12];
/// The default depth: 10 bits, measured as good as 12 at every quality of the sweep
/// (docs/results.md) and the depth every hardware HEVC decoder (Main 10) takes.
pub const DEFAULT_DEPTH: u8 = 10;
/// The largest QP x265 takes.
pub const MAX_QP: u8 = 51;
/// How the geometry-video coder lays out x | y | z.
pub const DEFAULT_PLANES: Planes = Planes::Yuv444;
/// The time base only labels frames.
const TIME_BASE: (i32, i32) = (1, 25);

/// How the x | y | z residual images of a frame go into an HEVC picture.
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
pub struct HevcOptions {
    /// Fixed quantiser, 0 (finest) ..= 51; see [`super::hevc_law`].
    pub qp: u8,
    /// Frames per group of pictures: an IDR frame, then `gop − 1` P-frames (1: all-intra).
    pub gop: usize,
    /// Bits a sample: 10 or 12.
    pub depth: u8,
    /// Monochrome or 4:4:4.
    pub planes: Planes,
}

impl Default for HevcOptions {
    fn default() -> Self {
        HevcOptions {
            qp: 22,
            gop: 50,
            depth: DEFAULT_DEPTH,
            planes: DEFAULT_PLANES,
        }
    }
}

/// One coded frame.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Packet {
    /// The HEVC bitstream of the frame (Annex B, with VPS/SPS/PPS on IDR frames).
    pub data: Vec<u8>,
    /// True for an IDR frame: decoding may start here.
    pub key: bool,
}

const NAME: &str = "hevc";

fn ff_error(context: &str, e: ffmpeg::Error) -> Error {
    libav::error(NAME, context, e)
}

fn pixel_format(depth: u8, planes: Planes) -> Result<Pixel> {
    match (depth, planes) {
        (10, Planes::Mono) => Ok(Pixel::GRAY10LE),
        (12, Planes::Mono) => Ok(Pixel::GRAY12LE),
        (10, Planes::Yuv444) => Ok(Pixel::YUV444P10LE),
        (12, Planes::Yuv444) => Ok(Pixel::YUV444P12LE),
        _ => Err(Error::Codec(format!(
            "hevc sample depth {depth}: expected one of {DEPTHS:?}"
        ))),
    }
}

/// The FFmpeg picture size of a `width × height` x | y | z plane.
fn picture_size(width: u32, height: u32, planes: Planes) -> Result<(u32, u32)> {
    match planes {
        Planes::Mono => Ok((width, height)),
        Planes::Yuv444 if width % 3 == 0 => Ok((width / 3, height)),
        Planes::Yuv444 => Err(Error::Codec(format!(
            "hevc 4:4:4 plane width {width} is not three images wide"
        ))),
    }
}

/// The `x265-params` of a fixed-QP, deterministic encoding with IDR frames every `gop` frames.
fn x265_params(options: &HevcOptions, gop: u32) -> String {
    format!(
        "qp={qp}:keyint={gop}:min-keyint={gop}:scenecut=0:open-gop=0:bframes=0:\
         repeat-headers=1:info=0:pools=none:frame-threads=1:log-level=error",
        qp = options.qp
    )
}

/// A fixed-QP HEVC encoder for a sequence of same-size monochrome planes.
pub struct Encoder {
    inner: encoder::Video,
    width: u32,
    height: u32,
    depth: u8,
    planes: Planes,
    next_pts: i64,
}

impl Encoder {
    /// Opens an encoder for `width × height` planes whose first plane is frame `first_frame`.
    pub fn new(width: u32, height: u32, options: &HevcOptions, first_frame: usize) -> Result<Self> {
        libav::init()?;
        let format = pixel_format(options.depth, options.planes)?;
        if width < 16 || height < 16 || width % 2 != 0 || height % 2 != 0 {
            return Err(Error::Codec(format!(
                "hevc size {width}×{height}: sides must be even and at least 16"
            )));
        }
        if options.qp > MAX_QP {
            return Err(Error::Codec(format!(
                "hevc qp {} outside 0..={MAX_QP}",
                options.qp
            )));
        }
        let gop = libav::checked_gop(NAME, options.gop)?;
        let codec = encoder::find_by_name("libx265")
            .ok_or_else(|| Error::Codec("libx265 encoder missing from libavcodec".into()))?;
        let mut video = codec::Context::new_with_codec(codec)
            .encoder()
            .video()
            .map_err(|e| ff_error("encoder context", e))?;
        let (picture_width, picture_height) = picture_size(width, height, options.planes)?;
        video.set_width(picture_width);
        video.set_height(picture_height);
        video.set_format(format);
        video.set_time_base(TIME_BASE);
        video.set_gop(gop);
        video.set_max_b_frames(0);
        video.set_threading(libav::one_thread());
        let mut dict = Dictionary::new();
        dict.set("preset", "medium");
        dict.set("tune", "psnr");
        dict.set("x265-params", &x265_params(options, gop));
        let inner = video
            .open_as_with(codec, dict)
            .map_err(|e| ff_error(&format!("open libx265 {width}×{height}"), e))?;
        Ok(Encoder {
            inner,
            width,
            height,
            depth: options.depth,
            planes: options.planes,
            next_pts: i64::try_from(first_frame)
                .map_err(|_| Error::Codec(format!("hevc first frame {first_frame} too large")))?,
        })
    }

    /// Codes the next plane; returns the packets ready so far (x265 holds a few frames back).
    pub fn encode(&mut self, plane: &Plane<u16>) -> Result<Vec<Packet>> {
        plane.check()?;
        if (plane.width, plane.height) != (self.width, self.height) {
            return Err(Error::Codec(format!(
                "hevc plane {}×{} given to a {}×{} encoder",
                plane.width, plane.height, self.width, self.height
            )));
        }
        let top = quantise::max_level(self.depth) as u16;
        if plane.data.iter().any(|&v| v > top) {
            return Err(Error::Codec(format!(
                "hevc plane has samples above {top}, the largest at {} bits",
                self.depth
            )));
        }
        let (w, h) = picture_size(self.width, self.height, self.planes)?;
        let mut picture = frame::Video::new(pixel_format(self.depth, self.planes)?, w, h);
        for index in 0..self.planes.count() {
            fill_samples(&mut picture, index, plane, index * w as usize, w as usize)?;
        }
        picture.set_pts(Some(self.next_pts));
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
                key: packet.is_key(),
            });
        }
        Ok(packets)
    }
}

/// Copies columns `x0..x0 + width` of the plane into FFmpeg plane `index` of `picture`, as 16-bit
/// little-endian samples, row by row (FFmpeg pads rows to its own stride, in bytes).
fn fill_samples(
    picture: &mut frame::Video,
    index: usize,
    plane: &Plane<u16>,
    x0: usize,
    width: usize,
) -> Result<()> {
    let stride = picture.stride(index);
    let buffer = picture.data_mut(index);
    for (y, row) in plane.data.chunks_exact(plane.width as usize).enumerate() {
        let src = &row[x0..x0 + width];
        let start = y * stride;
        let dst = buffer
            .get_mut(start..start + 2 * width)
            .ok_or_else(|| Error::Codec("hevc frame buffer smaller than the plane".into()))?;
        for (d, v) in dst.chunks_exact_mut(2).zip(src) {
            d.copy_from_slice(&v.to_le_bytes());
        }
    }
    Ok(())
}

/// An HEVC decoder giving back the planes of a stream made by [`Encoder`].
pub struct Decoder {
    inner: decoder::Video,
    width: u32,
    height: u32,
    depth: u8,
    planes: Planes,
    /// Whether an IDR frame has been decoded since the last reset: a P-frame without its
    /// reference must be an error, not a plausible but wrong picture.
    has_reference: bool,
}

impl Decoder {
    /// Opens a decoder that expects `width × height` x | y | z planes of `depth`-bit samples,
    /// coded as `planes` says.
    pub fn new(width: u32, height: u32, depth: u8, planes: Planes) -> Result<Self> {
        pixel_format(depth, planes)?;
        picture_size(width, height, planes)?;
        let inner = libav::open_decoder(NAME, codec::Id::HEVC)?;
        Ok(Decoder {
            inner,
            width,
            height,
            depth,
            planes,
            has_reference: false,
        })
    }

    /// Decodes one packet; returns the pictures it completes (one per packet for our streams).
    pub fn decode(&mut self, packet: &[u8]) -> Result<Vec<Plane<u16>>> {
        libav::send_packet(NAME, &mut self.inner, packet)?;
        self.receive()
    }

    /// Signals the end of the stream and returns the pictures still held by the decoder.
    pub fn flush(&mut self) -> Result<Vec<Plane<u16>>> {
        self.inner
            .send_eof()
            .map_err(|e| ff_error("flush decoder", e))?;
        let planes = self.receive()?;
        self.inner.flush();
        self.has_reference = false;
        Ok(planes)
    }

    fn receive(&mut self) -> Result<Vec<Plane<u16>>> {
        let mut planes = Vec::new();
        while let Some(picture) = libav::next_picture(NAME, &mut self.inner)? {
            planes.push(self.samples(&picture)?);
        }
        Ok(planes)
    }

    fn samples(&mut self, picture: &frame::Video) -> Result<Plane<u16>> {
        if picture.is_corrupt() || picture.has_decode_errors() {
            return Err(Error::Codec("hevc picture decoded with errors".into()));
        }
        if picture.is_key() {
            self.has_reference = true;
        } else if !self.has_reference {
            return Err(Error::Codec(
                "hevc P-frame before any IDR frame: decoding must start at an IDR frame".into(),
            ));
        }
        let format = pixel_format(self.depth, self.planes)?;
        let (w, h) = picture_size(self.width, self.height, self.planes)?;
        if picture.format() != format || (picture.width(), picture.height()) != (w, h) {
            return Err(Error::Codec(format!(
                "hevc picture is {:?} {}×{}, expected {format:?} {}×{}",
                picture.format(),
                picture.width(),
                picture.height(),
                w,
                h
            )));
        }
        let (w, h) = (w as usize, h as usize);
        let mut data = vec![0u16; self.width as usize * h];
        for index in 0..self.planes.count() {
            let (stride, bytes) = (picture.stride(index), picture.data(index));
            for (y, out) in data.chunks_exact_mut(self.width as usize).enumerate() {
                let row = bytes.get(y * stride..y * stride + 2 * w).ok_or_else(|| {
                    Error::Codec("hevc picture buffer shorter than its size".into())
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

/// HEVC as the geometry-video picture codec: an IDR frame every `gop` frames, P-frames between,
/// residual ranges shared by a group so that P-frames predict like from like.
pub struct Pictures;

impl Pictures {
    fn options(&self, opts: &EncodeOptions) -> HevcOptions {
        HevcOptions {
            qp: self.quantiser(opts),
            gop: opts.gop,
            depth: self.depth(opts),
            planes: DEFAULT_PLANES,
        }
    }
}

impl PictureCodec for Pictures {
    fn codec(&self) -> Codec {
        Codec::Hevc
    }

    fn range_mode(&self, opts: &EncodeOptions) -> RangeMode {
        RangeMode::PerGroup(opts.gop)
    }

    /// `biharmonic`: smooth across chart borders, what a transform codec codes cheaply; measured
    /// against the other methods at HEVC's QPs in docs/results.md.
    fn default_padding(&self) -> padding::Method {
        padding::Method::Biharmonic
    }

    fn step_factor(&self, opts: &EncodeOptions) -> f64 {
        super::hevc_law(opts.quality, self.depth(opts)).step_factor
    }

    fn quantiser(&self, opts: &EncodeOptions) -> u8 {
        opts.qscale
            .unwrap_or_else(|| super::hevc_law(opts.quality, self.depth(opts)).quantiser)
    }

    fn gop(&self, opts: &EncodeOptions) -> u32 {
        opts.gop as u32
    }

    fn depth(&self, opts: &EncodeOptions) -> u8 {
        opts.bit_depth.unwrap_or(DEFAULT_DEPTH)
    }

    fn depth_of_setup(&self, setup: &[u8]) -> Result<u8> {
        read_setup(setup).map(|(depth, _)| depth)
    }

    fn encoder(
        &self,
        width: u32,
        height: u32,
        first_frame: usize,
        opts: &EncodeOptions,
    ) -> Result<Box<dyn PictureEncoder>> {
        let options = self.options(opts);
        Ok(Box::new(PacketEncoder {
            encoder: Encoder::new(width, height, &options, first_frame)?,
            depth: options.depth,
            packets: Vec::new(),
        }))
    }

    fn decoder(&self, width: u32, height: u32, setup: &[u8]) -> Result<Box<dyn PictureDecoder>> {
        let (depth, planes) = read_setup(setup)?;
        Ok(Box::new(PacketDecoder(Decoder::new(
            width, height, depth, planes,
        )?)))
    }
}

/// The sample depth and planes of a set-up part.
fn read_setup(setup: &[u8]) -> Result<(u8, Planes)> {
    let planes = [Planes::Mono, Planes::Yuv444];
    match setup {
        [depth, id] if DEPTHS.contains(depth) => planes
            .into_iter()
            .find(|p| p.id() == *id)
            .map(|p| (*depth, p))
            .ok_or_else(|| Error::Stream(format!("hevc set-up: unknown planes {id}"))),
        _ => Err(Error::Stream(format!(
            "hevc set-up {setup:?}: expected the sample depth ({DEPTHS:?}) and the planes"
        ))),
    }
}

struct PacketEncoder {
    encoder: Encoder,
    depth: u8,
    packets: Vec<Packet>,
}

impl PictureEncoder for PacketEncoder {
    fn push(&mut self, plane: &Plane<u16>) -> Result<()> {
        self.packets.extend(self.encoder.encode(plane)?);
        Ok(())
    }

    fn finish(self: Box<Self>) -> Result<(Vec<u8>, Vec<FrameChunk>)> {
        let setup = vec![self.depth, self.encoder.planes.id()];
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
            Error::Stream(format!("frame {f}: the HEVC packet decoded to no picture"))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp(width: u32, height: u32, t: u32, depth: u8) -> Plane<u16> {
        let top = f64::from(quantise::max_level(depth));
        let data = (0..width * height)
            .map(|i| {
                let (x, y) = (f64::from(i % width), f64::from(i / width));
                let v = 0.5 + 0.3 * ((x + 2.0 * f64::from(t)) / 9.0).sin() * (y / 7.0).cos();
                (v * top).round() as u16
            })
            .collect();
        Plane::new(width, height, data).unwrap()
    }

    fn code(planes: &[Plane<u16>], options: &HevcOptions) -> Vec<Packet> {
        let (w, h) = (planes[0].width, planes[0].height);
        let mut encoder = Encoder::new(w, h, options, 0).unwrap();
        let mut packets = Vec::new();
        for p in planes {
            packets.extend(encoder.encode(p).unwrap());
        }
        packets.extend(encoder.finish().unwrap());
        packets
    }

    #[test]
    fn deep_planes_round_trip_with_idr_frames_every_gop() {
        for (depth, layout) in [(10, Planes::Mono), (12, Planes::Mono), (10, Planes::Yuv444)] {
            let (w, h) = (96, 48);
            let planes: Vec<_> = (0..5).map(|t| ramp(w, h, t, depth)).collect();
            let options = HevcOptions {
                qp: 4,
                gop: 2,
                depth,
                planes: layout,
            };
            let packets = code(&planes, &options);
            let keys: Vec<bool> = packets.iter().map(|p| p.key).collect();
            assert_eq!(keys, [true, false, true, false, true], "{depth} bits");
            assert_eq!(packets, code(&planes, &options), "not deterministic");
            let mut decoder = Decoder::new(w, h, depth, layout).unwrap();
            for (plane, packet) in planes.iter().zip(&packets) {
                let back = decoder.decode(&packet.data).unwrap();
                let worst = back[0]
                    .data
                    .iter()
                    .zip(&plane.data)
                    .map(|(a, b)| a.abs_diff(*b))
                    .max()
                    .unwrap();
                // QP 4 is a step of about one level of an 8-bit picture: 4 levels at 10 bits, 16
                // at 12.
                assert!(
                    worst <= 1 << (depth - 6),
                    "{depth} bits {layout:?}: {worst}"
                );
            }
            // A P-frame without its IDR frame gives no picture.
            let mut cold = Decoder::new(w, h, depth, layout).unwrap();
            let first = cold.decode(&packets[1].data);
            assert!(first.map_or(true, |p| p.is_empty()));
        }
    }

    #[test]
    fn bad_settings_are_errors() {
        let options = HevcOptions::default();
        assert!(Encoder::new(15, 32, &options, 0).is_err());
        assert!(Encoder::new(32, 32, &HevcOptions { qp: 52, ..options }, 0).is_err());
        assert!(Encoder::new(
            32,
            32,
            &HevcOptions {
                depth: 8,
                ..options
            },
            0
        )
        .is_err());
        let yuv = HevcOptions {
            planes: Planes::Yuv444,
            ..options
        };
        assert!(
            Encoder::new(64, 32, &yuv, 0).is_err(),
            "not three images wide"
        );
        let mut encoder = Encoder::new(96, 32, &options, 0).unwrap();
        assert!(encoder.encode(&Plane::filled(96, 32, 1024)).is_err());
        assert!(encoder.encode(&Plane::filled(48, 32, 0)).is_err());
        assert!(Pictures.depth_of_setup(&[]).is_err());
        assert!(Pictures.depth_of_setup(&[10]).is_err());
        assert!(Pictures.depth_of_setup(&[9, 0]).is_err());
        assert!(Pictures.depth_of_setup(&[10, 2]).is_err());
        assert_eq!(read_setup(&[12, 1]).unwrap(), (12, Planes::Yuv444));
    }
}
