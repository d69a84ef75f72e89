//! The temporal-DCT index part: the quantiser step and, per band, where its bytes lie in the
//! coefficients part and their CRC-32, so that a reader can stop at any band and check each one;
//! then the copy bit of each candidate vertex ([`super::copies`]).

use crate::error::{Error, Result};
use crate::stream::bytes::{ByteReader, ByteWriter};
use crate::stream::entropy::{self, BitModel, UIntModel};

/// One band's place in the coefficients part.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BandEntry {
    /// Offset from the start of the coefficients part.
    pub offset: u64,
    /// Bytes; 0 for an all-zero band.
    pub len: u64,
    /// CRC-32 of the band's bytes (0 for an empty band).
    pub crc: u32,
}

/// The temporal-DCT index part: the step and where each band lies.
#[derive(Debug, Clone, PartialEq)]
pub struct BandIndex {
    /// The quantiser step Δ in the mesh's units.
    pub step: f32,
    /// One entry per band, low to high frequency.
    pub bands: Vec<BandEntry>,
    /// Per candidate vertex ([`super::copies::candidates`]): whether it is a copy.
    pub copies: Vec<bool>,
}

impl BandIndex {
    /// The index of `chunks` (one per band, in order) and their concatenation.
    pub fn build(step: f32, chunks: Vec<Vec<u8>>) -> (Self, Vec<u8>) {
        let mut payload = Vec::new();
        let bands = chunks
            .into_iter()
            .map(|c| {
                let e = BandEntry {
                    offset: payload.len() as u64,
                    len: c.len() as u64,
                    crc: if c.is_empty() { 0 } else { crc32fast::hash(&c) },
                };
                payload.extend_from_slice(&c);
                e
            })
            .collect();
        let copies = Vec::new();
        (
            Self {
                step,
                bands,
                copies,
            },
            payload,
        )
    }

    /// Serialises the index: step, band count, then lengths and CRCs entropy-coded (most lengths
    /// are small and many bands are empty, which then cost a fraction of a byte).
    pub fn to_bytes(&self) -> Result<Vec<u8>> {
        let mut enc = entropy::Encoder::new();
        let mut lengths = UIntModel::default();
        for b in &self.bands {
            enc.unsigned(b.len, &mut lengths);
            if b.len > 0 {
                enc.raw_bits(u64::from(b.crc), 32);
            }
        }
        // The candidate count is the decoder's to check: stated here, an index parses alone.
        enc.unsigned(self.copies.len() as u64, &mut UIntModel::default());
        let mut copy = BitModel::default();
        for &c in &self.copies {
            enc.bit(c, &mut copy);
        }
        let mut w = ByteWriter::new();
        w.f32(self.step)
            .u32(self.bands.len() as u32)
            .raw(&enc.finish()?);
        Ok(w.into_bytes())
    }

    /// Parses an index that must describe `frames` bands filling exactly `payload_len` bytes.
    pub fn from_bytes(bytes: &[u8], frames: usize, payload_len: u64) -> Result<Self> {
        let mut r = ByteReader::new(bytes, "temporal-DCT index");
        let step = r.f32()?;
        if !(step > 0.0 && step.is_normal()) {
            return Err(Error::Stream(format!(
                "temporal-DCT index: step {step} is not a positive number"
            )));
        }
        let count = r.u32()? as usize;
        if count != frames {
            return Err(Error::Stream(format!(
                "temporal-DCT index lists {count} bands for {frames} frames"
            )));
        }
        let mut dec = entropy::Decoder::new(r.take(r.remaining())?)?;
        let mut lengths = UIntModel::default();
        let mut bands = Vec::new();
        let mut offset = 0u64;
        for k in 0..count {
            let len = dec.unsigned(&mut lengths)?;
            let crc = if len > 0 { dec.raw_bits(32)? as u32 } else { 0 };
            let end = offset
                .checked_add(len)
                .filter(|&e| e <= payload_len)
                .ok_or_else(|| {
                    Error::Stream(format!(
                        "temporal-DCT band {k} runs past the {payload_len}-byte coefficients part"
                    ))
                })?;
            bands.push(BandEntry { offset, len, crc });
            offset = end;
        }
        if offset != payload_len {
            return Err(Error::Stream(format!(
                "temporal-DCT bands cover {offset} of the coefficients part's {payload_len} bytes"
            )));
        }
        let candidates = dec.unsigned(&mut UIntModel::default())?;
        entropy::check_capacity(candidates, bytes.len(), "temporal-DCT index, copy bits")?;
        let mut copy = BitModel::default();
        let copies = (0..candidates)
            .map(|_| dec.bit(&mut copy))
            .collect::<Result<Vec<bool>>>()?;
        Ok(Self {
            step,
            bands,
            copies,
        })
    }
}
