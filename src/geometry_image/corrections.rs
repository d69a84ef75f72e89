//! The sparse correction list: residuals that fell outside their frame's 256 levels (see
//! [`super::quantise`]), sent as (vertex, axis, residual in pixel steps) so that a clipped vertex
//! still decodes within half a pixel step. The picture keeps the clipped level there; the decoder
//! replaces what it reads at that vertex by the correction.
//!
//! Stored per frame: a count, then each entry as LEB128 varints (vertex gap since the previous
//! entry, axis, zigzag residual), a few bytes each.

use super::quantise::FrameRanges;
use crate::error::{Error, Result};
use crate::stream::bytes::{ByteReader, ByteWriter};

/// One clipped coordinate of one vertex.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Correction {
    /// The vertex.
    pub vertex: u32,
    /// The coordinate: 0, 1, 2 for x, y, z.
    pub axis: u8,
    /// Its residual in pixel steps, rounded.
    pub value: i64,
}

impl Correction {
    /// The residual it stands for at pixel step `step`.
    pub fn residual(&self, step: f32) -> f32 {
        (self.value as f64 * f64::from(step)) as f32
    }
}

/// Every frame's corrections, sorted by vertex then axis.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Corrections(Vec<Vec<Correction>>);

impl Corrections {
    /// How many corrections in all.
    #[cfg(any(test, feature = "internals"))]
    pub fn len(&self) -> usize {
        self.0.iter().map(Vec::len).sum()
    }

    /// Whether there are none.
    #[cfg(any(test, feature = "internals"))]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The corrections of every residual that does not fit its frame's range.
    pub fn of_clipped(residuals: &[Vec<[f32; 3]>], ranges: &[FrameRanges], step: f32) -> Self {
        let frames = residuals
            .iter()
            .zip(ranges)
            .map(|(frame, range)| {
                let mut list = Vec::new();
                for (v, r) in frame.iter().enumerate() {
                    for a in 0..3 {
                        if !range[a].fits(r[a]) {
                            let value = (f64::from(r[a]) / f64::from(step)).round();
                            list.push(Correction {
                                vertex: v as u32,
                                axis: a as u8,
                                // Saturating: a residual beyond ±2^63 steps is not a motion.
                                value: value as i64,
                            });
                        }
                    }
                }
                list
            })
            .collect();
        Self(frames)
    }

    /// Frame `f`'s corrections (none past the last frame).
    pub fn frame(&self, f: usize) -> &[Correction] {
        self.0.get(f).map_or(&[], Vec::as_slice)
    }

    /// Appends the list to `w`.
    pub fn write(&self, w: &mut ByteWriter) {
        for frame in &self.0 {
            varint(w, frame.len() as u64);
            let mut last = 0u32;
            for c in frame {
                varint(w, u64::from(c.vertex - last));
                w.u8(c.axis);
                varint(w, zigzag(c.value));
                last = c.vertex;
            }
        }
    }

    /// Reads a list written by [`Self::write`] for `frames` frames of `vertices` vertices.
    pub fn read(r: &mut ByteReader, frames: usize, vertices: usize) -> Result<Self> {
        let mut out = Vec::with_capacity(frames.min(r.remaining()));
        for f in 0..frames {
            let count = read_varint(r)?;
            if count > r.remaining() as u64 {
                return Err(Error::Stream(format!(
                    "frame {f} claims {count} corrections, more than the part holds"
                )));
            }
            let mut list = Vec::with_capacity(count as usize);
            let mut vertex = 0u64;
            for _ in 0..count {
                vertex += read_varint(r)?;
                let axis = r.u8()?;
                let value = unzigzag(read_varint(r)?);
                if vertex >= vertices as u64 || axis > 2 {
                    return Err(Error::Stream(format!(
                        "frame {f}: a correction of vertex {vertex} axis {axis} \
                         ({vertices} vertices, axes 0..2)"
                    )));
                }
                list.push(Correction {
                    vertex: vertex as u32,
                    axis,
                    value,
                });
            }
            out.push(list);
        }
        Ok(Self(out))
    }
}

fn zigzag(v: i64) -> u64 {
    ((v << 1) ^ (v >> 63)) as u64
}

fn unzigzag(u: u64) -> i64 {
    ((u >> 1) as i64) ^ -((u & 1) as i64)
}

/// LEB128; hand-written since the stream's byte helpers are fixed-width and a crate for ten lines
/// is not worth its dependency.
fn varint(w: &mut ByteWriter, mut v: u64) {
    while v >= 0x80 {
        w.u8((v as u8 & 0x7f) | 0x80);
        v >>= 7;
    }
    w.u8(v as u8);
}

fn read_varint(r: &mut ByteReader) -> Result<u64> {
    let mut v = 0u64;
    for shift in (0..64).step_by(7) {
        let b = r.u8()?;
        v |= u64::from(b & 0x7f) << shift;
        if b < 0x80 {
            return Ok(v);
        }
    }
    Err(Error::Stream(
        "a correction number runs past 64 bits".into(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn corrections_round_trip_and_bad_ones_are_refused() {
        let list = Corrections(vec![
            vec![],
            vec![
                Correction {
                    vertex: 2,
                    axis: 1,
                    value: -70_000,
                },
                Correction {
                    vertex: 2,
                    axis: 2,
                    value: i64::MAX,
                },
                Correction {
                    vertex: 9,
                    axis: 0,
                    value: 300,
                },
            ],
        ]);
        let mut w = ByteWriter::new();
        list.write(&mut w);
        let bytes = w.into_bytes();
        let back = Corrections::read(&mut ByteReader::new(&bytes, "c"), 2, 10).unwrap();
        assert_eq!(back, list);
        assert_eq!(back.len(), 3);
        let few_vertices = Corrections::read(&mut ByteReader::new(&bytes, "c"), 2, 9);
        assert!(few_vertices.unwrap_err().to_string().contains("vertex 9"));
        assert!(Corrections::read(&mut ByteReader::new(&bytes[..5], "c"), 2, 10).is_err());
    }
}
