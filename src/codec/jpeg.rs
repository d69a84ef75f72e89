//! Baseline grayscale JPEG for intra-coded residual planes.
//!
//! Encoding: `jpeg-encoder` (IJG quality law, optimised Huffman tables since every byte counts).
//! Decoding: `zune-jpeg` — the decoder inside `image` — called directly rather than through `image` for
//! two reasons: strict mode, so a truncated or damaged scan is an error instead of a silently grey
//! block; and no platform intrinsics (`set_use_unsafe(false)`), so the scalar IDCT runs everywhere and
//! the same bytes decode to the same samples on every machine. JPEG decoders legitimately differ by ±1
//! (IDCT rounding); the encoder and decoder of mcgv must use this one function to agree exactly.

use super::Plane;
use crate::{Error, Result};
use jpeg_encoder::{ColorType, Encoder};
use zune_core::bytestream::ZCursor;
use zune_core::colorspace::ColorSpace;
use zune_core::options::DecoderOptions;
use zune_jpeg::JpegDecoder;

/// The largest width or height a baseline JPEG frame header can state.
pub const MAX_SIDE: u32 = u16::MAX as u32;
/// The EOI marker every complete JPEG ends with.
const END_OF_IMAGE: [u8; 2] = [0xFF, 0xD9];

/// Codes `plane` as a baseline grayscale JPEG at `quality` (1..=100, higher = better).
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

/// JPEG marker codes (the byte after 0xFF) that the compact form needs to find.
mod marker {
    /// Start of a baseline frame: carries the picture size.
    pub const SOF0: u8 = 0xC0;
    /// Huffman tables.
    pub const DHT: u8 = 0xC4;
    /// Start of scan: entropy-coded data follows its header.
    pub const SOS: u8 = 0xDA;
}
/// The SOI marker every JPEG starts with.
const START_OF_IMAGE: [u8; 2] = [0xFF, 0xD8];

/// A marker segment `[start, end)` of a JPEG, `start` at its 0xFF.
#[derive(Debug, Clone, Copy)]
struct Segment {
    marker: u8,
    start: usize,
    end: usize,
}

/// The marker segments from SOI up to and including SOS; the scan data starts at the last one's end.
fn header_segments(bytes: &[u8]) -> Result<Vec<Segment>> {
    if !bytes.starts_with(&START_OF_IMAGE) {
        return Err(Error::Codec("jpeg does not start with SOI".into()));
    }
    let mut segments = Vec::new();
    let mut at = START_OF_IMAGE.len();
    loop {
        let segment = segment_at(bytes, at)?;
        segments.push(segment);
        if segment.marker == marker::SOS {
            return Ok(segments);
        }
        at = segment.end;
    }
}

fn segment_at(bytes: &[u8], at: usize) -> Result<Segment> {
    match bytes.get(at..at + 4) {
        Some(&[0xFF, marker, hi, lo]) => {
            let end = at + 2 + (usize::from(hi) << 8 | usize::from(lo));
            if end > bytes.len() {
                return Err(Error::Codec(format!(
                    "jpeg segment {marker:#04x} at byte {at} runs past the end"
                )));
            }
            Ok(Segment {
                marker,
                start: at,
                end,
            })
        }
        _ => Err(Error::Codec(format!(
            "jpeg: no marker segment at byte {at}"
        ))),
    }
}

/// The header bytes that only depend on (width, height, quality), as `jpeg-encoder` writes them.
struct Template {
    /// SOI and every segment before the Huffman tables (JFIF, frame header, quantisation tables).
    prefix: Vec<u8>,
    /// The start-of-scan header.
    sos: Vec<u8>,
}

impl Template {
    /// Built by coding an 8×8 picture at `quality`, then writing the real size into its frame header,
    /// so the tables are exactly the encoder's.
    fn new(width: u32, height: u32, quality: u8) -> Result<Self> {
        let (w, h) = side_u16(width, height)?;
        let tiny = encode(&Plane::filled(8, 8, 128), quality)?;
        let segments = header_segments(&tiny)?;
        let (first_dht, sos) = layout(&segments)?;
        let mut prefix = tiny.get(..first_dht.start).unwrap_or_default().to_vec();
        let sof = segments
            .iter()
            .find(|s| s.marker == marker::SOF0 && s.end <= first_dht.start)
            .ok_or_else(|| Error::Codec("jpeg-encoder wrote no baseline frame header".into()))?;
        // SOF0: FF C0, length (2), precision (1), height (2), width (2), …
        let size = prefix
            .get_mut(sof.start + 5..sof.start + 9)
            .ok_or_else(|| Error::Codec("jpeg frame header too short".into()))?;
        size.copy_from_slice(&[h.to_be_bytes(), w.to_be_bytes()].concat());
        let sos = tiny.get(sos.start..sos.end).unwrap_or_default().to_vec();
        Ok(Template { prefix, sos })
    }
}

/// The first Huffman-table segment and the SOS segment, checking that only Huffman tables lie between.
fn layout(segments: &[Segment]) -> Result<(Segment, Segment)> {
    let first_dht = segments
        .iter()
        .position(|s| s.marker == marker::DHT)
        .ok_or_else(|| Error::Codec("jpeg without Huffman tables".into()))?;
    let tail = segments.get(first_dht..).unwrap_or_default();
    match (tail.first(), tail.split_last()) {
        (Some(first), Some((sos, tables)))
            if sos.marker == marker::SOS && tables.iter().all(|s| s.marker == marker::DHT) =>
        {
            Ok((*first, *sos))
        }
        _ => Err(Error::Codec(
            "jpeg layout is not …, Huffman tables, start of scan".into(),
        )),
    }
}

/// [`encode`] without the ≈ 180 header bytes that `(width, height, quality)` determine: only the
/// image's own Huffman tables and its entropy-coded scan remain. On a 64×64 plane that is ≈ 40 % of
/// the file; [`decode_compact`] rebuilds the rest.
pub fn encode_compact(plane: &Plane, quality: u8) -> Result<Vec<u8>> {
    let full = encode(plane, quality)?;
    let segments = header_segments(&full)?;
    let (first_dht, sos) = layout(&segments)?;
    let template = Template::new(plane.width, plane.height, quality)?;
    let fixed_prefix = full.get(..first_dht.start) == Some(template.prefix.as_slice());
    let fixed_sos = full.get(sos.start..sos.end) == Some(template.sos.as_slice());
    if !fixed_prefix || !fixed_sos || !full.ends_with(&END_OF_IMAGE) {
        return Err(Error::Codec(
            "jpeg-encoder wrote headers that do not match the compact template".into(),
        ));
    }
    let tables = full.get(first_dht.start..sos.start).unwrap_or_default();
    // The scan keeps its EOI: a truncated scan with an EOI appended would decode without complaint.
    let scan = full.get(sos.end..).unwrap_or_default();
    Ok([tables, scan].concat())
}

/// Decodes bytes from [`encode_compact`]; `width`, `height` and `quality` must be the encoder's
/// (a wrong quality decodes with the wrong tables: the caller must store it).
pub fn decode_compact(bytes: &[u8], width: u32, height: u32, quality: u8) -> Result<Plane> {
    if !(1..=100).contains(&quality) {
        return Err(Error::Codec(format!(
            "jpeg quality {quality} outside 1..=100"
        )));
    }
    let template = Template::new(width, height, quality)?;
    let mut tables_end = 0;
    while bytes.get(tables_end..tables_end + 2) == Some(&[0xFF, marker::DHT]) {
        tables_end = segment_at(bytes, tables_end)?.end;
    }
    if tables_end == 0 {
        return Err(Error::Codec(
            "compact jpeg does not start with Huffman tables".into(),
        ));
    }
    let (tables, scan) = bytes.split_at(tables_end);
    let full = [template.prefix.as_slice(), tables, &template.sos, scan].concat();
    decode(&full, width, height)
}
