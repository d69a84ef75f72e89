//! The frame index: where each frame's coded images lie in the images part, their checksum, and whether
//! the frame decodes on its own (a key frame), so one frame can be read without touching the others.

use crate::error::{Error, Result};
use crate::stream::bytes::{ByteReader, ByteWriter};

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

    /// Serialises the index.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = ByteWriter::new();
        w.u32(self.entries.len() as u32);
        for e in &self.entries {
            w.u32(e.len as u32).u32(e.crc).u8(e.key as u8);
        }
        w.into_bytes()
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
        if n.saturating_mul(9) != r.remaining() {
            return Err(Error::Stream("frame index has the wrong length".into()));
        }
        let mut offset = 0u64;
        let mut entries = Vec::with_capacity(n);
        for _ in 0..n {
            let len = r.u32()? as u64;
            let crc = r.u32()?;
            let key = match r.u8()? {
                0 => false,
                1 => true,
                k => return Err(Error::Stream(format!("frame index: bad key flag {k}"))),
            };
            entries.push(ChunkEntry {
                offset,
                len,
                crc,
                key,
            });
            offset += len;
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
        let back = FrameIndex::from_bytes(&index.to_bytes(), 4, 6).unwrap();
        assert_eq!(back, index);
        assert_eq!(back.entry(2).unwrap().offset, 4);
        assert_eq!(back.key_before(1), 0);
        assert_eq!(back.key_before(3), 2);
        assert!(back.entry(4).is_err());
        assert!(FrameIndex::from_bytes(&index.to_bytes(), 3, 6).is_err());
        assert!(FrameIndex::from_bytes(&index.to_bytes(), 4, 7).is_err());
    }
}
