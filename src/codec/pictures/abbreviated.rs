//! Abbreviated JPEG (ISO 10918-1, B.5): what every picture of a stream shares — the quantisation
//! table, frame header and scan header, fixed by the picture size and quality — is stored once; each
//! frame keeps only its own Huffman tables (optimised per picture) and its entropy-coded scan.
//!
//! A 768×256 grayscale JPEG carries ~300 bytes of headers, of which the optimised Huffman tables are
//! ~100. Optimised tables matter most at low rates: with the standard tables an all-flat 8×8 block
//! still costs 6 bits (DC difference 0 and end-of-block), with optimised ones about 2.

use crate::error::{Error, Result};

/// Marker of a Huffman table segment.
const DHT: u8 = 0xC4;
/// Marker of the start-of-scan segment.
const SOS: u8 = 0xDA;

/// A JPEG taken apart.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Parts<'a> {
    /// SOI and every segment up to and including the scan header, except the Huffman tables.
    pub shared: Vec<u8>,
    /// The Huffman table segments.
    pub tables: Vec<u8>,
    /// Entropy-coded data and EOI.
    pub scan: &'a [u8],
}

/// Walks the marker segments after SOI, calling `each(marker, segment_bytes)` up to and including SOS;
/// returns the offset just past the SOS segment.
fn walk(jpeg: &[u8], mut each: impl FnMut(u8, &[u8])) -> Result<usize> {
    let bad = |why: &str| Error::Codec(format!("malformed JPEG: {why}"));
    if jpeg.len() < 4 || jpeg[0] != 0xFF || jpeg[1] != 0xD8 {
        return Err(bad("no start-of-image marker"));
    }
    let mut pos = 2;
    loop {
        if pos + 4 > jpeg.len() || jpeg[pos] != 0xFF {
            return Err(bad("segment expected"));
        }
        let marker = jpeg[pos + 1];
        let len = u16::from_be_bytes([jpeg[pos + 2], jpeg[pos + 3]]) as usize;
        let end = pos + 2 + len;
        if len < 2 || end > jpeg.len() {
            return Err(bad("segment runs past the end"));
        }
        each(marker, &jpeg[pos..end]);
        if marker == SOS {
            return Ok(end);
        }
        pos = end;
    }
}

/// Splits a baseline JPEG into what a stream shares, its Huffman tables and its scan.
pub fn split(jpeg: &[u8]) -> Result<Parts<'_>> {
    let mut shared = jpeg[..2.min(jpeg.len())].to_vec();
    let mut tables = Vec::new();
    let end = walk(jpeg, |marker, segment| {
        if marker == DHT {
            tables.extend_from_slice(segment);
        } else {
            shared.extend_from_slice(segment);
        }
    })?;
    Ok(Parts {
        shared,
        tables,
        scan: &jpeg[end..],
    })
}

/// Rebuilds a full JPEG: the shared segments, the frame's tables just before the scan header, the scan.
pub fn join(shared: &[u8], tables: &[u8], scan: &[u8]) -> Result<Vec<u8>> {
    let mut sos_start = None;
    let mut pos = 2;
    let end = walk(shared, |marker, segment| {
        if marker == SOS {
            sos_start = Some(pos);
        }
        pos += segment.len();
    })?;
    let sos =
        sos_start.ok_or_else(|| Error::Codec("shared JPEG header has no scan header".into()))?;
    let mut out = Vec::with_capacity(end + tables.len() + scan.len());
    out.extend_from_slice(&shared[..sos]);
    out.extend_from_slice(tables);
    out.extend_from_slice(&shared[sos..end]);
    out.extend_from_slice(scan);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::codec::pictures::{jpeg, Plane};

    #[test]
    fn split_and_join_restore_a_real_jpeg() {
        let data = (0..64 * 32).map(|i| ((i * 7) % 251) as u8).collect();
        let plane = Plane::new(64, 32, data).unwrap();
        let bytes = jpeg::encode(&plane, 60).unwrap();
        let parts = split(&bytes).unwrap();
        assert!(!parts.tables.is_empty() && parts.tables[1] == DHT);
        assert_eq!(
            join(&parts.shared, &parts.tables, parts.scan).unwrap(),
            bytes
        );
        // Another picture of the same size and quality shares the same header.
        let other = jpeg::encode(&Plane::filled(64, 32, 9), 60).unwrap();
        assert_eq!(split(&other).unwrap().shared, parts.shared);
    }

    #[test]
    fn malformed_input_is_an_error() {
        assert!(split(b"not a jpeg").is_err());
        assert!(split(&[0xFF, 0xD8, 0xFF, 0xC4, 0, 40, 1]).is_err());
        assert!(join(b"\xFF\xD8", b"", b"").is_err());
    }
}
