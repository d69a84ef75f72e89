//! Reading a container's part table: the file header, each part header, and where the parts lie
//! (the whole stream's, or a temporal segment's). [`super::container::ContainerReader`] does this
//! at open, before any payload is read.

use super::container::{Checksum, PartEntry, Tag, MAGIC, MAX_PARTS, PART_HEADER_LEN, VERSION};
use crate::error::{Error, Result};
use crate::stream::bytes::ByteReader;
use std::io::Read;

/// An I/O failure while reading the part table.
pub(super) fn table_io(e: std::io::Error) -> Error {
    Error::Stream(format!("reading the part table: {e}"))
}

/// Checks where each part lies: a segmented stream has its segments' parts after their start
/// markers and the whole stream's before the first; no part appears twice in one place (a damaged
/// tag could otherwise shadow another part).
pub(super) fn check_scopes(parts: &[PartEntry]) -> Result<()> {
    let segmented = parts.iter().any(|p| p.tag == Tag::SEGMENT);
    let mut seen = rustc_hash::FxHashSet::default();
    for p in parts {
        if segmented && p.tag != Tag::SEGMENT && p.tag.per_segment() != p.segment.is_some() {
            return Err(Error::Stream(format!(
                "part {} lies {} (damaged file?)",
                p.tag,
                if p.segment.is_some() {
                    "inside a segment but belongs to the whole stream"
                } else {
                    "before the first segment but belongs to one"
                }
            )));
        }
        if !seen.insert((p.tag, p.segment)) {
            return Err(Error::Stream(format!(
                "part {} appears twice{} (damaged file?)",
                p.tag,
                p.segment
                    .map_or(String::new(), |s| format!(" in segment {s}"))
            )));
        }
    }
    Ok(())
}

/// Reads and checks the 16-byte file header (magic, version); returns the part count.
pub(super) fn read_file_header<R: Read>(source: &mut R) -> Result<u32> {
    let mut head = [0u8; 16];
    read_exact_or(source, &mut head, "the file header")?;
    let mut r = ByteReader::new(&head, "file header");
    if r.take(8)? != MAGIC {
        return Err(Error::Stream(
            "not a .mcgv file (wrong magic number)".into(),
        ));
    }
    let version = r.u16()?;
    if version < VERSION {
        return Err(Error::Stream(format!(
            "this file was written by an older mcgv-video (stream version {version}); this build \
             reads stream version {VERSION} only: re-encode the animation from its source"
        )));
    }
    if version > VERSION {
        return Err(Error::Stream(format!(
            "stream version {version} is newer than this build reads (version {VERSION}): update \
             mcgv-video"
        )));
    }
    let _reserved = r.u16()?;
    let count = r.u32()?;
    if count > MAX_PARTS {
        return Err(Error::Stream(format!(
            "header claims {count} parts (at most {MAX_PARTS})"
        )));
    }
    Ok(count)
}

/// One part header as read by [`read_part_entry`].
pub(super) struct PartRead {
    pub entry: PartEntry,
    /// Where its payload ends in the file.
    pub end: u64,
    /// Its tag and declared length when it is the progressive last part cut by the end of the file.
    pub truncated: Option<(Tag, u64)>,
}

/// Reads part `i` of `count`, whose header (`PART_HEADER_LEN` bytes) starts at `pos`. `partial`: the file is still
/// arriving, so any part may be cut short by its end (the caller decides what is of use).
pub(super) fn read_part_entry<R: Read>(
    source: &mut R,
    (i, count): (u32, u32),
    pos: u64,
    file_len: u64,
    partial: bool,
) -> Result<PartRead> {
    let mut ph = [0u8; PART_HEADER_LEN];
    read_exact_or(source, &mut ph, "a part header")?;
    let mut r = ByteReader::new(&ph, "part header");
    let mut tag = [0u8; 4];
    tag.copy_from_slice(r.take(4)?);
    // Part tags are outside every CRC: a damaged tag would otherwise drop an optional part
    // (the attributes) silently. Every part of this version is known, so any other is refused.
    if Tag(tag).name() == "unknown part" {
        return Err(Error::Stream(format!(
            "part {i}: unknown tag {} (damaged file?)",
            Tag(tag)
        )));
    }
    let checksum = match r.u8()? {
        0 => Checksum::Whole,
        1 => Checksum::Chunked,
        2 => Checksum::Progressive,
        other => {
            return Err(Error::Stream(format!(
                "part {i}: unknown checksum kind {other}"
            )))
        }
    };
    let len = u64::from(r.u32()?);
    let crc = r.u32()?;
    let offset = pos + PART_HEADER_LEN as u64;
    let declared_end = offset.checked_add(len);
    let mut truncated = None;
    // A progressive last part may be cut by the end of the file: its prefix still decodes. So may
    // any part of a file still arriving (the caller keeps the ones whose chunks are checked alone).
    let cut_allowed = partial || (checksum == Checksum::Progressive && i + 1 == count);
    let (len, declared_end) = match declared_end {
        Some(e)
            if e > file_len
                && cut_allowed
                && offset <= file_len =>
        {
            truncated = Some((Tag(tag), len));
            (file_len - offset, Some(file_len))
        }
        other => (len, other),
    };
    let end = declared_end.filter(|&e| e <= file_len).ok_or_else(|| {
        Error::Stream(format!(
            "part {} claims {len} bytes but the file ends first (truncated file?)",
            Tag(tag)
        ))
    })?;
    let entry = PartEntry {
        tag: Tag(tag),
        offset,
        len,
        crc,
        checksum,
        segment: None,
    };
    Ok(PartRead {
        entry,
        end,
        truncated,
    })
}

pub(super) fn read_exact_or<R: Read>(source: &mut R, buf: &mut [u8], what: &str) -> Result<()> {
    source.read_exact(buf).map_err(|e| match e.kind() {
        std::io::ErrorKind::UnexpectedEof => {
            Error::Stream(format!("file ends inside {what} (truncated)"))
        }
        _ => Error::Stream(format!("reading {what}: {e}")),
    })
}
