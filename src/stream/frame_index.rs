//! The frame index: where each frame's coded images lie in the images part, their checksum, and whether
//! the frame decodes on its own (a key frame), so one frame can be read without touching the others.
//!
//! Entropy-coded since container version 12: per frame the key flag (adaptive), the length
//! (adaptive Exp-Golomb, one model for key frames and one for the others) and the CRC-32 (raw), about
//! 5 bytes a frame against the 9 of fixed-width fields (docs/design.md, "Frame index").

use crate::error::{Error, Result};
use crate::stream::bytes::{ByteReader, ByteWriter};
use crate::stream::entropy::{self, BitModel, SymbolCoder, UIntModel};

/// One frame's coded bytes, as the encoder produces them.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FrameChunk {
    /// The coded picture (JPEG scan or MPEG-4 packet).
    pub data: Vec<u8>,
    /// Whether it decodes without earlier frames.
    pub key: bool,
}

/// Where one frame's chunk lies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ChunkEntry {
    /// Offset in the images part.
    pub offset: u64,
    /// Length in bytes.
    pub len: u64,
    /// CRC-32 of the chunk.
    pub crc: u32,
    /// Whether the frame decodes without earlier frames.
    pub key: bool,
}

/// The index of all frames.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FrameIndex {
    entries: Vec<ChunkEntry>,
}

impl FrameIndex {
    /// Lays the chunks end to end: the index and the images part's payload.
    pub fn build(chunks: Vec<FrameChunk>) -> (Self, Vec<u8>) {
        let mut payload = Vec::with_capacity(chunks.iter().map(|c| c.data.len()).sum());
        let entries = chunks
            .into_iter()
            .map(|c| {
                let e = ChunkEntry {
                    offset: payload.len() as u64,
                    len: c.data.len() as u64,
                    crc: crc32fast::hash(&c.data),
                    key: c.key,
                };
                payload.extend_from_slice(&c.data);
                e
            })
            .collect();
        (Self { entries }, payload)
    }

    /// Serialises the index: the frame count, then the entries entropy-coded.
    pub fn to_bytes(&self) -> Result<Vec<u8>> {
        let mut enc = entropy::Encoder::new();
        let mut entries = self.entries.clone();
        code_entries(&mut enc, &mut entries)?;
        let mut w = ByteWriter::new();
        w.u32(self.entries.len() as u32).raw(&enc.finish()?);
        Ok(w.into_bytes())
    }

    /// Parses an index for `frames` frames whose chunks fill an images part of `payload_len` bytes.
    pub fn from_bytes(bytes: &[u8], frames: usize, payload_len: u64) -> Result<Self> {
        let mut r = ByteReader::new(bytes, "frame index");
        let n = r.u32()? as usize;
        if n != frames {
            return Err(Error::Stream(format!(
                "frame index lists {n} frames, header says {frames}"
            )));
        }
        // Each entry is at least a key decision: a count no payload could hold is refused before
        // anything is allocated.
        entropy::check_capacity(n as u64, r.remaining(), "frame index")?;
        let mut dec = entropy::Decoder::new(r.take(r.remaining())?)?;
        let empty = ChunkEntry {
            offset: 0,
            len: 0,
            crc: 0,
            key: false,
        };
        let mut entries = vec![empty; n];
        code_entries(&mut dec, &mut entries)?;
        let mut offset = 0u64;
        for (f, e) in entries.iter_mut().enumerate() {
            e.offset = offset;
            offset = offset
                .checked_add(e.len)
                .filter(|&end| end <= payload_len)
                .ok_or_else(|| {
                    Error::Stream(format!(
                        "frame {f} runs past the {payload_len}-byte images part"
                    ))
                })?;
        }
        if offset != payload_len {
            return Err(Error::Stream(format!(
                "frame index covers {offset} bytes, the images part has {payload_len}"
            )));
        }
        if entries.first().is_some_and(|e| !e.key) {
            return Err(Error::Stream("the first frame is not a key frame".into()));
        }
        Ok(Self { entries })
    }

    /// Every frame's entry, to rewrite (the fuzz harness repairs the CRCs of mutated chunks).
    #[cfg(any(test, feature = "internals"))]
    pub fn entries_mut(&mut self) -> &mut [ChunkEntry] {
        &mut self.entries
    }

    /// The entry of frame `f`.
    pub fn entry(&self, f: usize) -> Result<ChunkEntry> {
        self.entries.get(f).copied().ok_or_else(|| {
            Error::Usage(format!(
                "frame {f} does not exist (the stream has {})",
                self.entries.len()
            ))
        })
    }

    /// The last key frame at or before `f`.
    pub fn key_before(&self, f: usize) -> usize {
        (0..=f.min(self.entries.len().saturating_sub(1)))
            .rev()
            .find(|&i| self.entries[i].key)
            .unwrap_or(0)
    }
}

/// Codes each entry's key flag, length and CRC (offsets follow from the lengths), one traversal
/// for the encoder and the decoder; an empty chunk has no CRC.
fn code_entries<C: SymbolCoder>(c: &mut C, entries: &mut [ChunkEntry]) -> Result<()> {
    let mut key = BitModel::default();
    let mut lengths: [UIntModel; 2] = Default::default();
    for e in entries.iter_mut() {
        e.key = c.bit(e.key, &mut key)?;
        e.len = c.unsigned(e.len, &mut lengths[usize::from(e.key)])?;
        e.crc = match e.len {
            0 => 0,
            _ => c.raw_bits(u64::from(e.crc), 32)? as u32,
        };
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn build_serialise_parse() {
        let chunks = vec![
            FrameChunk {
                data: vec![1, 2, 3],
                key: true,
            },
            FrameChunk {
                data: vec![4],
                key: false,
            },
            FrameChunk {
                data: vec![5, 6],
                key: true,
            },
            FrameChunk {
                data: vec![],
                key: false,
            },
        ];
        let (index, payload) = FrameIndex::build(chunks);
        assert_eq!(payload, vec![1, 2, 3, 4, 5, 6]);
        let bytes = index.to_bytes().unwrap();
        let back = FrameIndex::from_bytes(&bytes, 4, 6).unwrap();
        assert_eq!(back, index);
        assert_eq!(back.entry(2).unwrap().offset, 4);
        assert_eq!(back.key_before(1), 0);
        assert_eq!(back.key_before(3), 2);
        assert!(back.entry(4).is_err());
        assert!(FrameIndex::from_bytes(&bytes, 3, 6).is_err());
        assert!(FrameIndex::from_bytes(&bytes, 4, 7).is_err());
        assert!(FrameIndex::from_bytes(&bytes, 4, 5).is_err());
    }
}
