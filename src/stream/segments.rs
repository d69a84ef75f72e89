//! Temporal segments: a long clip is coded as runs of frames, each with its own affine
//! maps and residual parts (its own temporal DCT or groups of pictures), behind the parts the
//! whole stream shares (header, first frame, partition, lattice, skinning weights).
//!
//! In the file a segment is a [`Tag::SEGMENT`] part — its first frame and frame count — followed
//! by the segment's own parts; the container files them under the segment
//! ([`ContainerReader::select`]). The segments must cover the header's frames in order, without a
//! gap: a decoder reads one segment's parts for a frame of it and no other segment's.

use crate::error::{Error, Result};
use crate::stream::bytes::{ByteReader, ByteWriter};
use crate::stream::container::{ContainerReader, Part, Tag};
use std::io::{Read, Seek};
use std::ops::Range;

/// The payload of a segment's start marker.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SegmentStart {
    /// The segment's first frame in the clip.
    pub first_frame: u32,
    /// Frames in the segment (at least one).
    pub frames: u32,
}

impl SegmentStart {
    /// The marker part of the segment of `frames` (a range of the clip's frames).
    pub fn part(frames: &Range<usize>) -> Result<Part> {
        let count = |n: usize| {
            u32::try_from(n).map_err(|_| Error::Usage(format!("frame {n} is past 2^32")))
        };
        let mut w = ByteWriter::new();
        w.u32(count(frames.start)?)
            .u32(count(frames.end - frames.start)?);
        Ok(Part::whole(Tag::SEGMENT, w.into_bytes()))
    }

    /// Parses a marker's payload.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self> {
        let mut r = ByteReader::new(bytes, "segment start");
        let start = Self {
            first_frame: r.u32()?,
            frames: r.u32()?,
        };
        r.finish()?;
        Ok(start)
    }
}

/// The frames of every segment of an opened stream of `frames` frames, checked to cover them in
/// order; a stream not cut into segments is one segment of all its frames.
pub fn read_ranges<R: Read + Seek>(
    reader: &mut ContainerReader<R>,
    frames: usize,
) -> Result<Vec<Range<usize>>> {
    let count = reader.segments();
    if count == 0 {
        return Ok(std::iter::once(0..frames).collect());
    }
    let mut ranges = Vec::with_capacity(count as usize);
    let mut next = 0usize;
    for s in 0..count {
        let bytes = reader.segment_start(s)?;
        let start = SegmentStart::from_bytes(&bytes)?;
        let (first, len) = (start.first_frame as usize, start.frames as usize);
        if first != next || len == 0 || first + len > frames {
            return Err(Error::Stream(format!(
                "segment {s} holds frames {first}..{} but should start at frame {next} and end \
                 by frame {frames} (damaged file, or segments joined out of order?)",
                first + len
            )));
        }
        ranges.push(first..first + len);
        next = first + len;
    }
    if next != frames {
        return Err(Error::Stream(format!(
            "the segments cover frames 0..{next}, the header says {frames} (a missing segment?)"
        )));
    }
    Ok(ranges)
}

/// The segment holding frame `f` among `ranges` (which cover the clip in order).
pub fn segment_of(ranges: &[Range<usize>], f: usize) -> Option<usize> {
    let s = ranges.partition_point(|r| r.end <= f);
    (s < ranges.len() && ranges[s].contains(&f)).then_some(s)
}

/// The clip's `frames` frames cut into runs of `length` (the last one shorter).
pub fn split(frames: usize, length: usize) -> Vec<Range<usize>> {
    let length = length.max(1);
    (0..frames)
        .step_by(length)
        .map(|start| start..(start + length).min(frames))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_and_find_frames() {
        let ranges = split(10, 4);
        assert_eq!(ranges, vec![0..4, 4..8, 8..10]);
        assert_eq!(segment_of(&ranges, 0), Some(0));
        assert_eq!(segment_of(&ranges, 7), Some(1));
        assert_eq!(segment_of(&ranges, 9), Some(2));
        assert_eq!(segment_of(&ranges, 10), None);
        assert_eq!(split(3, 8), vec![0..3]);
    }

    #[test]
    fn marker_round_trips() {
        let part = SegmentStart::part(&(12..20)).unwrap();
        let back = SegmentStart::from_bytes(&part.bytes).unwrap();
        assert_eq!(
            back,
            SegmentStart {
                first_frame: 12,
                frames: 8
            }
        );
        assert!(SegmentStart::from_bytes(&part.bytes[..7]).is_err());
    }
}
