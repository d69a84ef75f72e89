//! Baseline grayscale JPEG for intra-coded residual planes.
//!
//! Encoding: `jpeg-encoder` (IJG quality law, optimised Huffman tables since every byte counts).
//! Decoding: `zune-jpeg` — the decoder inside `image` — called directly rather than through `image` for
//! two reasons: strict mode, so a truncated or damaged scan is an error instead of a silently grey
//! block; and no platform intrinsics (`set_use_unsafe(false)`), so the scalar IDCT runs everywhere and
//! the same bytes decode to the same samples on every machine. JPEG decoders legitimately differ by ±1
//! (IDCT rounding); the encoder and decoder of mcgv must use this one function to agree exactly.

use super::{abbreviated, PictureCodec, PictureDecoder, PictureOptions, Plane};
#[cfg(feature = "encode")]
use super::PictureEncoder;
use super::{PicturePlan, PictureSetup, Resolved};
use crate::codec::rate::{anchor, ijg_scale_percent, read_law, Anchor, PictureLaw, Rate, RatePlan};
use crate::codec::Codec;
use super::AFFINE_PRECISION;
use crate::stream::bytes::{ByteReader, ByteWriter};
use crate::stream::frame_index::FrameChunk;
use crate::{Error, Result};
#[cfg(feature = "encode")]
use jpeg_encoder::{ColorType, Encoder, QuantizationTableType};
use zune_core::bytestream::ZCursor;
use zune_core::colorspace::ColorSpace;
use zune_core::options::DecoderOptions;
use zune_jpeg::JpegDecoder;

/// The largest width or height a baseline JPEG frame header can state.
pub const MAX_SIDE: u32 = u16::MAX as u32;
/// The quantisation table of every residual picture (scaled by the JPEG quality as libjpeg does):
/// flat, not Annex K's. A residual image is not a photograph: an error in a high frequency moves
/// vertices as far as one in a low frequency, so every coefficient gets the same step
/// (docs/design.md, "JPEG: flat quantisation table"). The table travels in the stream (the shared
/// header), so older streams still decode.
pub const TABLE: padding::JpegTable = padding::JpegTable::Flat;
/// The EOI marker every complete JPEG ends with.
const END_OF_IMAGE: [u8; 2] = [0xFF, 0xD9];

/// Codes `plane` as a baseline grayscale JPEG at `quality` (1..=100, higher = better).
#[cfg(feature = "encode")]
pub fn encode(plane: &Plane, quality: u8) -> Result<Vec<u8>> {
    plane.check()?;
    if !(1..=100).contains(&quality) {
        return Err(Error::Codec(format!(
            "jpeg quality {quality} outside 1..=100"
        )));
    }
    let (width, height) = side_u16(plane.width, plane.height)?;
    let mut out = Vec::with_capacity(plane.data.len() / 4);
    let mut encoder = Encoder::new(&mut out, quality);
    let table = match TABLE {
        padding::JpegTable::Flat => QuantizationTableType::Flat,
        padding::JpegTable::AnnexK => QuantizationTableType::Default,
    };
    encoder.set_quantization_tables(table.clone(), table);
    // Optimised tables travel with each frame (see `codec::abbreviated`); at low rates they more
    // than pay for themselves, since a flat block costs ~2 bits instead of 6 with the standard ones.
    encoder.set_optimized_huffman_tables(true);
    encoder
        .encode(&plane.data, width, height, ColorType::Luma)
        .map_err(|e| Error::Codec(format!("jpeg encode {}×{}: {e}", plane.width, plane.height)))?;
    Ok(out)
}

/// Decodes a JPEG made by [`encode`]; fails unless it is a valid grayscale image of `width × height`.
pub fn decode(bytes: &[u8], width: u32, height: u32) -> Result<Plane> {
    side_u16(width, height)?;
    // A scan cut right after its last MCU still decodes; the missing end marker betrays it.
    if !bytes.ends_with(&END_OF_IMAGE) {
        return Err(Error::Codec(format!(
            "jpeg of {} bytes does not end with the end-of-image marker (truncated?)",
            bytes.len()
        )));
    }
    let options = DecoderOptions::default()
        .set_strict_mode(true)
        .set_use_unsafe(false)
        .set_max_width(width as usize)
        .set_max_height(height as usize)
        .jpeg_set_out_colorspace(ColorSpace::Luma);
    let mut decoder = JpegDecoder::new_with_options(ZCursor::new(bytes), options);
    decoder
        .decode_headers()
        .map_err(|e| Error::Codec(format!("jpeg headers: {e:?}")))?;
    let info = decoder
        .info()
        .ok_or_else(|| Error::Codec("jpeg headers missing".into()))?;
    if (u32::from(info.width), u32::from(info.height)) != (width, height) {
        return Err(Error::Codec(format!(
            "jpeg is {}×{}, expected {width}×{height}",
            info.width, info.height
        )));
    }
    if decoder.input_colorspace() != Some(ColorSpace::Luma) {
        return Err(Error::Codec(format!(
            "jpeg colour space {:?}, expected grayscale",
            decoder.input_colorspace()
        )));
    }
    let data = decoder
        .decode()
        .map_err(|e| Error::Codec(format!("jpeg decode {width}×{height}: {e:?}")))?;
    Plane::new(width, height, data)
}

fn side_u16(width: u32, height: u32) -> Result<(u16, u16)> {
    match (u16::try_from(width), u16::try_from(height)) {
        (Ok(w), Ok(h)) if w > 0 && h > 0 => Ok((w, h)),
        _ => Err(Error::Codec(format!(
            "jpeg size {width}×{height} outside 1..={MAX_SIDE}"
        ))),
    }
}

/// JPEG's options: its own quality, and the lattice and padding of its pictures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct JpegConfig {
    /// JPEG's own quality 1..=100 for the residual pictures; `None` takes the law's for the
    /// encoding's quality.
    pub quality: Option<u8>,
    /// The lattice and padding (default `snap`).
    pub pictures: PictureOptions,
}

impl JpegConfig {
    /// Fails, naming the option, when one is out of range.
    pub(crate) fn check(&self) -> Result<()> {
        if self.quality.is_some_and(|q| !(1..=100).contains(&q)) {
            return Err(Error::option("jpeg_quality", "must be between 1 and 100"));
        }
        self.pictures.check(Codec::Jpeg)
    }

    /// The plan of `rate` on a first frame of bounding-box diagonal `diagonal`: the law's pixel
    /// step, every frame its own key frame and ranges, `snap` padding at the JPEG quality.
    pub(crate) fn plan(&self, rate: &Rate, diagonal: f64) -> Result<RatePlan> {
        let law = jpeg_law_at(rate.level());
        let resolved = Resolved {
            codec: Codec::Jpeg,
            step_factor: law.step_factor,
            quantiser: self.quality.unwrap_or(law.quantiser),
            gop: 1,
            depth: 8,
            padding: padding::Method::Snap,
            affine_precision: AFFINE_PRECISION,
            deeper: Vec::new(),
        };
        super::plan(rate, diagonal, &self.pictures, resolved)
    }
}

/// JPEG's law, read off the lower hull of (bpvf, vertex RMSE) over pixel step × JPEG quality on
/// the smallest lattice the charts fit: the error follows about the square root of the pixel
/// step, so the factor falls as the quality rises; JPEG quality 90 from quality 75 on
/// (docs/design.md, "Quality laws (JPEG, MPEG-4, HEVC, AV1)").
const JPEG_LAW: [Anchor; 4] = [
    anchor(1, 1.25, 75),
    anchor(50, 0.25, 75),
    anchor(75, 0.4, 90),
    anchor(90, 0.2, 90),
];

/// The step of JPEG quality `q`'s (flat) table, relative: IJG's scale of it.
pub(crate) fn jpeg_quantiser_step(q: u8) -> f64 {
    f64::from(ijg_scale_percent(q).max(1))
}

/// JPEG's pixel step factor and JPEG quality for a user quality 1..100.
#[cfg_attr(not(any(test, feature = "internals")), allow(dead_code))]
pub fn jpeg_law(quality: u8) -> PictureLaw {
    jpeg_law_at(f64::from(quality))
}

/// [`jpeg_law`] at a quality between the integers too.
pub(crate) fn jpeg_law_at(quality: f64) -> PictureLaw {
    read_law(&JPEG_LAW, jpeg_quantiser_step, quality)
}

/// JPEG as the geometry-video picture codec: every frame a key frame, the tables every frame
/// shares stored once in the codec set-up part ([`super::abbreviated`]).
pub(crate) struct Pictures;

impl PictureCodec for Pictures {
    /// `snap` quantises as JPEG will: at the picture's JPEG quality, with its table.
    fn padding(&self, plan: &PicturePlan) -> padding::PaddingOptions {
        padding::PaddingOptions {
            method: plan.padding,
            jpeg_quality: plan.quantiser,
            jpeg_table: TABLE,
            ..padding::PaddingOptions::default()
        }
    }

    #[cfg(feature = "encode")]
    fn encoder(
        &self,
        _width: u32,
        _height: u32,
        _first_frame: usize,
        plan: &PicturePlan,
    ) -> Result<Box<dyn PictureEncoder>> {
        Ok(Box::new(FrameEncoder {
            quality: plan.quantiser,
            shared: None,
            chunks: Vec::new(),
        }))
    }

    fn settings(&self, quantiser: u8, _gop: u32, _depth: u8) -> Vec<(&'static str, u32)> {
        vec![("jpeg_quality", quantiser.into())]
    }

    fn decoder(
        &self,
        width: u32,
        height: u32,
        setup: &PictureSetup,
    ) -> Result<Box<dyn PictureDecoder>> {
        Ok(Box::new(FrameDecoder {
            width,
            height,
            setup: setup.codec_data.clone(),
        }))
    }
}

#[cfg(feature = "encode")]
struct FrameEncoder {
    quality: u8,
    /// The header every frame shares (tables aside), from the first frame.
    shared: Option<Vec<u8>>,
    chunks: Vec<FrameChunk>,
}

#[cfg(feature = "encode")]
impl PictureEncoder for FrameEncoder {
    fn push(&mut self, plane: &Plane<u16>) -> Result<()> {
        let jpeg = encode(&plane.to_8bit()?, self.quality)?;
        let parts = abbreviated::split(&jpeg)?;
        match &self.shared {
            None => self.shared = Some(parts.shared.clone()),
            Some(s) if *s != parts.shared => {
                return Err(Error::Codec("JPEG headers differ between frames".into()))
            }
            Some(_) => {}
        }
        let mut data = ByteWriter::new();
        data.blob(&parts.tables).raw(parts.scan);
        self.chunks.push(FrameChunk {
            data: data.into_bytes(),
            key: true,
        });
        Ok(())
    }

    fn finish(self: Box<Self>) -> Result<(Vec<u8>, Vec<FrameChunk>)> {
        Ok((self.shared.unwrap_or_default(), self.chunks))
    }
}

struct FrameDecoder {
    width: u32,
    height: u32,
    setup: Vec<u8>,
}

impl PictureDecoder for FrameDecoder {
    fn decode(&mut self, f: usize, chunk: &[u8]) -> Result<Plane<u16>> {
        let mut r = ByteReader::new(chunk, "JPEG frame");
        let tables = r.blob()?;
        let scan = r.take(r.remaining())?;
        let bytes = abbreviated::join(&self.setup, tables, scan)
            .map_err(|e| Error::Stream(format!("frame {f}: {e}")))?;
        decode(&bytes, self.width, self.height)
            .map(|p| p.widen())
            .map_err(|e| Error::Stream(format!("frame {f}: {e}")))
    }
}
