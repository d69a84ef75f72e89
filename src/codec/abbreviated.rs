//! Abbreviated JPEG (ISO 10918-1, B.5): the tables and frame/scan headers, identical for every picture
//! of a stream at one quality and size, are stored once; each frame keeps only its entropy-coded scan.
//!
//! Without this, a 256×256 grayscale JPEG carries ~600 bytes of headers: more than a whole frame of
//! residuals at low rates (for a 3000-vertex mesh, 1.6 bits per vertex per frame of pure overhead).

use crate::error::{Error, Result};

/// Splits a baseline JPEG into its header (SOI up to the end of the SOS segment) and its scan
/// (entropy-coded data and EOI).
pub fn split(jpeg: &[u8]) -> Result<(&[u8], &[u8])> {
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
        if marker == 0xDA {
            return Ok(jpeg.split_at(end));
        }
        pos = end;
    }
}

/// Rebuilds a full JPEG from a stored header and a frame's scan.
pub fn join(header: &[u8], scan: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(header.len() + scan.len());
    out.extend_from_slice(header);
    out.extend_from_slice(scan);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_finds_the_scan_and_join_restores() {
        // SOI, a COM segment (len 4: "hi"), SOS (len 8), scan bytes, EOI.
        let jpeg = [
            0xFF, 0xD8, 0xFF, 0xFE, 0, 4, b'h', b'i', 0xFF, 0xDA, 0, 8, 1, 1, 0, 0, 63, 0, 0x12,
            0x34, 0xFF, 0xD9,
        ];
        let (head, scan) = split(&jpeg).unwrap();
        assert_eq!(scan, &[0x12, 0x34, 0xFF, 0xD9]);
        assert_eq!(join(head, scan), jpeg);
        assert!(split(&jpeg[..10]).is_err());
        assert!(split(b"not a jpeg").is_err());
    }
}
