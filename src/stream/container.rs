//! The `.mcgv` container: a magic number, a version, and a table of tagged parts, each with a length
//! and a CRC-32 of its payload.
//!
//! The coded images are one part whose payload is a run of per-frame chunks; their offsets, lengths
//! and checksums live in the frame index, so a single frame can be read and verified without
//! touching (or trusting) any other frame's bytes.

use crate::error::{Error, Result};
use crate::stream::bytes::ByteWriter;
use crate::stream::part_table::{
    check_scopes, read_exact_or, read_file_header, read_part_entry, table_io,
};
use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::Path;

/// First bytes of every `.mcgv` file; the CR-LF and ^Z catch text-mode transfers, as PNG's magic does.
pub const MAGIC: [u8; 8] = *b"MCGV\r\n\x1a\n";

/// The container version this build writes and reads: 14, an affine trajectory may follow any of
/// the four nearest earlier clusters, named by rank, their innovation taken at its own order
/// (issue 35; 13: a missed partition label named among
/// the neighbours' other labels and its hit bit in contexts of their agreement; 12: the
/// frame index entropy-coded and a part's length in 4 bytes; 11: a translation's trajectory may follow
/// its reference cluster's whole map at its own centroid; 10: the first frame's version 4, a kept
/// vertex order names the free corners of the triangles last used, escapes by rank among the free
/// vertices; issue 35; 9: the first frame's version 3, a copy per corner said at once, seams cut
/// both ends of an edge, a smaller header, the vertex order coded in the input's order; 8: each affine
/// trajectory may add the innovation of a nearby cluster's; 7: the affine maps' linear part stored as a
/// rotation and a symmetric stretch; 6: per entry, quantised per column by the
/// cluster's extent along that axis, the temporal DCT's copies, the welded first frame; 5: the
/// header holds what every codec shares and each codec its own fields in its set-up part;
/// docs/history.md lists the versions).
/// A reader refuses any other version, so an older reader says "update" instead of misreading.
pub const VERSION: u16 = 14;

/// Bytes of a part header: tag (4), checksum kind (1), payload length (`u32`: 4), CRC (4). Until
/// container version 11 the length took 8 bytes; a part of 4 GiB or more is refused when added
/// (no stream of this tool comes near: a segment's pictures are one part).
pub const PART_HEADER_LEN: usize = 13;

/// Largest payload of one part.
pub const MAX_PART_LEN: usize = u32::MAX as usize;

/// Bytes of the file header: magic, version, reserved, part count.
pub const FILE_HEADER_LEN: usize = 16;

/// Largest number of parts a file may declare (a segmented stream has a few per segment); the
/// part table is also allocated no larger than the file's bytes can hold part headers.
pub(super) const MAX_PARTS: u32 = 1 << 20;

/// A part's four-character tag.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Tag(pub [u8; 4]);

impl Tag {
    /// Stream parameters (V, F, K, codec, quality, predictor).
    pub const HEADER: Tag = Tag(*b"HEAD");
    /// First frame: connectivity and geometry.
    pub const FIRST_FRAME: Tag = Tag(*b"MESH");
    /// Cluster label per vertex.
    pub const PARTITION: Tag = Tag(*b"PART");
    /// Texture coordinates and triangle materials (only for inputs that have them).
    pub const ATTRIBUTES: Tag = Tag(*b"ATTR");
    /// Lattice coordinate per vertex.
    pub const LATTICE: Tag = Tag(*b"LATC");
    /// Quantised affine coefficients per cluster and frame.
    pub const AFFINE: Tag = Tag(*b"AFFN");
    /// Quantised per-vertex skinning weights (only in skinning streams).
    pub const WEIGHTS: Tag = Tag(*b"SKIN");
    /// Residual quantisation ranges.
    pub const RANGES: Tag = Tag(*b"RANG");
    /// The residual codec's own set-up, shared by every segment and frame: its version and
    /// settings (e.g. the lattice, quantiser, GOP and JPEG tables of a picture codec).
    pub const CODEC_SETUP: Tag = Tag(*b"CSET");
    /// Offset, length, checksum and key flag of each frame chunk.
    pub const FRAME_INDEX: Tag = Tag(*b"INDX");
    /// The coded images, one chunk per frame.
    pub const FRAMES: Tag = Tag(*b"FRMS");
    /// Temporal-DCT index: quantiser step, and byte length and CRC of each frequency band.
    pub const TDCT_INDEX: Tag = Tag(*b"TDIX");
    /// Temporal-DCT coefficients, one chunk per frequency band, low to high.
    pub const TDCT: Tag = Tag(*b"TDCT");
    /// Start of a temporal segment: its first frame and frame count. The parts after it, up to
    /// the next, are the segment's own (see [`Tag::per_segment`]).
    pub const SEGMENT: Tag = Tag(*b"SEGM");

    /// A human-readable name, for reports and errors.
    pub fn name(self) -> &'static str {
        match &self.0 {
            b"HEAD" => "header",
            b"MESH" => "first frame",
            b"PART" => "partition",
            b"ATTR" => "attributes",
            b"LATC" => "lattice coordinates",
            b"AFFN" => "affine coefficients",
            b"SKIN" => "skinning weights",
            b"RANG" => "residual ranges",
            b"CSET" => "codec set-up",
            b"INDX" => "frame index",
            b"FRMS" => "images",
            b"TDIX" => "temporal DCT index",
            b"TDCT" => "temporal DCT coefficients",
            b"SEGM" => "segment start",
            _ => "unknown part",
        }
    }

    /// Whether a part belongs to one temporal segment (its frames' predictor and residuals) rather
    /// than to the whole stream (header, first frame, partition, codec set-up, atlas, skinning
    /// weights).
    pub fn per_segment(self) -> bool {
        matches!(
            &self.0,
            b"AFFN" | b"RANG" | b"INDX" | b"FRMS" | b"TDIX" | b"TDCT"
        )
    }
}

impl std::fmt::Display for Tag {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} ({})", String::from_utf8_lossy(&self.0), self.name())
    }
}

/// Whether a part's CRC covers its whole payload, or its chunks carry their own (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Checksum {
    /// One CRC-32 over the payload.
    Whole,
    /// The payload's chunks are checked through the frame index.
    Chunked,
    /// Chunked, and any prefix of the chunks is useful: the one kind of part that may be cut short
    /// by the end of the file, and only when it is the last part (see [`ContainerReader::truncated`]).
    Progressive,
}

impl Checksum {
    fn id(self) -> u8 {
        match self {
            Checksum::Whole => 0,
            Checksum::Chunked => 1,
            Checksum::Progressive => 2,
        }
    }
}

/// One part as a coder hands it to the container: the container knows parts, not codecs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Part {
    /// What the part holds.
    pub tag: Tag,
    /// Its payload.
    pub bytes: Vec<u8>,
    /// How its integrity is checked.
    pub checksum: Checksum,
}

impl Part {
    /// A part whose payload one CRC covers.
    pub fn whole(tag: Tag, bytes: Vec<u8>) -> Self {
        Self {
            tag,
            bytes,
            checksum: Checksum::Whole,
        }
    }
}

/// Builds a container in memory; [`ContainerWriter::write_atomic`] puts it on disk.
#[derive(Debug, Default)]
pub struct ContainerWriter {
    parts: Vec<(Tag, Vec<u8>, Checksum)>,
}

impl ContainerWriter {
    /// An empty container.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a part; parts are written in the order added. A payload past [`MAX_PART_LEN`] is
    /// refused.
    pub fn add(&mut self, tag: Tag, payload: Vec<u8>, checksum: Checksum) -> Result<()> {
        if payload.len() > MAX_PART_LEN {
            return Err(Error::Usage(format!(
                "the {} part would be {} bytes, past the 4 GiB a part may hold: code shorter \
                 temporal segments (--segment-frames) or at a lower quality",
                tag.name(),
                payload.len()
            )));
        }
        self.parts.push((tag, payload, checksum));
        Ok(())
    }

    /// Adds a part after those already added (see [`Self::add`]).
    pub fn push(&mut self, part: Part) -> Result<()> {
        self.add(part.tag, part.bytes, part.checksum)
    }

    /// The file's length in bytes, without serialising it.
    pub fn len(&self) -> u64 {
        FILE_HEADER_LEN as u64 + self.bytes_of(|_| true)
    }

    /// Whether the container holds no part.
    pub fn is_empty(&self) -> bool {
        self.parts.is_empty()
    }

    /// Bytes the parts of the tags `which` selects take in the file, part headers included.
    pub fn bytes_of(&self, which: impl Fn(Tag) -> bool) -> u64 {
        (self.parts.iter())
            .filter(|(tag, _, _)| which(*tag))
            .map(|(_, p, _)| (PART_HEADER_LEN + p.len()) as u64)
            .sum()
    }

    /// Bytes each part takes in the file (payload plus its part header), by part name, in the
    /// order of first appearance; a segmented stream's parts of one kind are summed.
    pub fn part_sizes(&self) -> Vec<(String, u64)> {
        let mut sizes: Vec<(String, u64)> = Vec::new();
        for (tag, payload, _) in &self.parts {
            let bytes = (PART_HEADER_LEN + payload.len()) as u64;
            match sizes.iter_mut().find(|(name, _)| name == tag.name()) {
                Some((_, total)) => *total += bytes,
                None => sizes.push((tag.name().to_string(), bytes)),
            }
        }
        sizes
    }

    /// Takes the parts out, in file order.
    pub fn into_parts(self) -> Vec<Part> {
        self.parts
            .into_iter()
            .map(|(tag, bytes, checksum)| Part {
                tag,
                bytes,
                checksum,
            })
            .collect()
    }

    /// The whole file as bytes.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = ByteWriter::new();
        w.raw(&MAGIC)
            .u16(VERSION)
            .u16(0)
            .u32(self.parts.len() as u32);
        for (tag, payload, checksum) in &self.parts {
            let crc = match checksum {
                Checksum::Whole => crc32fast::hash(payload),
                Checksum::Chunked | Checksum::Progressive => 0,
            };
            w.raw(&tag.0)
                .u8(checksum.id())
                // `add` refused anything longer.
                .u32(payload.len().min(MAX_PART_LEN) as u32)
                .u32(crc)
                .raw(payload);
        }
        w.into_bytes()
    }

    /// Writes the file to a temporary file beside `path` and renames it into place, so a failure
    /// never leaves a half-written file at `path`.
    #[cfg(feature = "encode")]
    pub fn write_atomic(&self, path: &Path) -> Result<u64> {
        let bytes = self.to_bytes();
        crate::output::write_atomic(path, &bytes)?;
        Ok(bytes.len() as u64)
    }
}

/// Where one part lies in the file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PartEntry {
    /// The part's tag.
    pub tag: Tag,
    /// Offset of the payload from the start of the file.
    pub offset: u64,
    /// Payload length in bytes (for a truncated progressive part, what the file still holds).
    pub len: u64,
    /// CRC-32 of the payload (unused for chunked parts).
    pub crc: u32,
    /// How the payload is checked.
    pub checksum: Checksum,
    /// The temporal segment the part belongs to (`None`: the whole stream's).
    pub segment: Option<u32>,
}

/// Reads a container lazily: the part table at open, payloads on request, verified against their CRC.
#[derive(Debug)]
pub struct ContainerReader<R> {
    source: R,
    parts: Vec<PartEntry>,
    file_len: u64,
    /// The last part cut short by the end of the file (progressive, or chunked in a partial
    /// file): its tag, segment and the length it declared.
    truncated: Option<(Tag, Option<u32>, u64)>,
    /// Temporal segments in the stream (0: not segmented).
    segments: u32,
    /// The segment whose parts [`ContainerReader::entry`] finds.
    selected: Option<u32>,
}

impl ContainerReader<BufReader<File>> {
    /// Opens a `.mcgv` file and reads its part table.
    pub fn open(path: &Path) -> Result<Self> {
        let file = File::open(path).map_err(|e| Error::io(path, e))?;
        Self::new(BufReader::new(file))
    }
}

impl<R: Read + Seek> ContainerReader<R> {
    /// Reads the part table of a container from any seekable source.
    pub fn new(source: R) -> Result<Self> {
        Self::read(source, false)
    }

    /// Reads the part table of a container still arriving (the prefix of a download): the parts
    /// whose bytes have all arrived, and the one the file ends in when its chunks are checked one
    /// by one (progressive or chunked: a picture codec's frames), so that the chunks present
    /// decode; a chunk past the end, or a part not there yet, is an error when asked for.
    pub fn partial(source: R) -> Result<Self> {
        Self::read(source, true)
    }

    fn read(mut source: R, partial: bool) -> Result<Self> {
        let file_len = source.seek(SeekFrom::End(0)).map_err(table_io)?;
        source.seek(SeekFrom::Start(0)).map_err(table_io)?;
        let count = read_file_header(&mut source)?;
        let fit = file_len.saturating_sub(FILE_HEADER_LEN as u64) / PART_HEADER_LEN as u64;
        let mut parts = Vec::with_capacity((count as u64).min(fit) as usize);
        let mut pos = 16u64;
        let mut truncated = None;
        let mut segments = 0u32;
        for i in 0..count {
            // A file still arriving ends where it ends: the parts after are to come.
            if partial && pos + PART_HEADER_LEN as u64 > file_len {
                break;
            }
            let mut part = read_part_entry(&mut source, (i, count), pos, file_len, partial)?;
            if part.entry.tag == Tag::SEGMENT {
                segments += 1;
            }
            part.entry.segment = segments.checked_sub(1);
            if let Some((tag, declared)) = part.truncated {
                // A part whose one CRC covers it whole is of no use until it has all arrived.
                if part.entry.checksum == Checksum::Whole {
                    break;
                }
                truncated = Some((tag, part.entry.segment, declared));
            }
            parts.push(part.entry);
            pos = part.end;
            source.seek(SeekFrom::Start(pos)).map_err(table_io)?;
        }
        check_scopes(&parts)?;
        if pos != file_len && !partial {
            return Err(Error::Stream(format!(
                "{} bytes after the last part (file damaged or concatenated?)",
                file_len - pos
            )));
        }
        Ok(Self {
            source,
            parts,
            file_len,
            truncated,
            segments,
            selected: segments.checked_sub(1).map(|_| 0),
        })
    }

    /// The length a part declared, when it is the progressive last part and the file ends inside
    /// it (its entry then holds only the bytes present); `None` for a complete part.
    pub fn truncated(&self, tag: Tag) -> Option<u64> {
        self.truncated
            .filter(|&(t, segment, _)| t == tag && segment == self.scope(tag))
            .map(|(.., declared)| declared)
    }

    /// Whether the file ends inside its last part (progressive, or chunked in a partial file).
    pub fn cut_short(&self) -> bool {
        self.truncated.is_some()
    }

    /// Temporal segments in the stream (0 for a stream that is not cut into segments).
    pub fn segments(&self) -> u32 {
        self.segments
    }

    /// Makes [`ContainerReader::entry`] (and every read by tag) find segment `segment`'s own
    /// parts; the whole stream's parts are found whatever the segment.
    pub fn select(&mut self, segment: u32) -> Result<()> {
        if segment >= self.segments.max(1) {
            return Err(Error::Stream(format!(
                "segment {segment}: the stream has {} segments",
                self.segments.max(1)
            )));
        }
        self.selected = (self.segments > 0).then_some(segment);
        Ok(())
    }

    /// The payload of segment `segment`'s start marker (a segmented stream's), verified.
    pub fn segment_start(&mut self, segment: u32) -> Result<Vec<u8>> {
        let e = self
            .parts
            .iter()
            .find(|p| p.tag == Tag::SEGMENT && p.segment == Some(segment))
            .copied()
            .ok_or_else(|| Error::Stream(format!("missing start of segment {segment}")))?;
        self.payload(&e)
    }

    /// The part table.
    pub fn parts(&self) -> &[PartEntry] {
        &self.parts
    }

    /// Total file length in bytes.
    pub fn file_len(&self) -> u64 {
        self.file_len
    }

    /// The entry of a part that must be present (of the selected segment, for a segment's part).
    pub fn entry(&self, tag: Tag) -> Result<PartEntry> {
        self.find(tag).ok_or_else(|| match self.selected {
            Some(s) if tag.per_segment() => {
                Error::Stream(format!("missing part {tag} in segment {s}"))
            }
            _ => Error::Stream(format!("missing part {tag}")),
        })
    }

    /// Whether a part is present (in the selected segment, for a segment's part).
    pub fn has(&self, tag: Tag) -> bool {
        self.find(tag).is_some()
    }

    /// Where a part of `tag` is looked for: the selected segment for a segment's part, else the
    /// whole stream's parts.
    fn scope(&self, tag: Tag) -> Option<u32> {
        if tag.per_segment() {
            self.selected
        } else {
            None
        }
    }

    fn find(&self, tag: Tag) -> Option<PartEntry> {
        let scope = self.scope(tag);
        self.parts
            .iter()
            .find(|p| p.tag == tag && p.segment == scope)
            .copied()
    }

    /// A whole part's payload, verified against its CRC.
    pub fn part(&mut self, tag: Tag) -> Result<Vec<u8>> {
        let e = self.entry(tag)?;
        self.payload(&e)
    }

    /// The payload of an entry of [`ContainerReader::parts`], verified against its CRC when one
    /// covers it whole.
    pub fn payload(&mut self, e: &PartEntry) -> Result<Vec<u8>> {
        let bytes = self.read_at(e.offset, e.len, e.tag)?;
        if e.checksum == Checksum::Whole && crc32fast::hash(&bytes) != e.crc {
            return Err(Error::Stream(format!(
                "part {} fails its checksum (damaged file)",
                e.tag
            )));
        }
        Ok(bytes)
    }

    /// A chunk `[offset, offset+len)` of a chunked part, verified against `crc`.
    pub fn chunk(
        &mut self,
        tag: Tag,
        offset: u64,
        len: u64,
        crc: u32,
        what: &str,
    ) -> Result<Vec<u8>> {
        self.chunk_if_intact(tag, offset, len, crc, what)?
            .ok_or_else(|| Error::Stream(format!("{what} fails its checksum (damaged file)")))
    }

    /// [`Self::chunk`], but a chunk that fails its checksum is `None` rather than an error: for
    /// chunks a decoder can do without (a temporal-DCT band and those after it).
    pub fn chunk_if_intact(
        &mut self,
        tag: Tag,
        offset: u64,
        len: u64,
        crc: u32,
        what: &str,
    ) -> Result<Option<Vec<u8>>> {
        let e = self.entry(tag)?;
        let end = offset.checked_add(len);
        if end.is_none_or(|end| end > e.len) {
            let declared = self.truncated(tag);
            if end.zip(declared).is_some_and(|(end, d)| end <= d) {
                return Err(Error::Stream(format!(
                    "{what} is past the end of the file (cut short, or still arriving)"
                )));
            }
            return Err(Error::Stream(format!("{what} lies outside part {tag}")));
        }
        let bytes = self.read_at(e.offset + offset, len, tag)?;
        Ok((crc32fast::hash(&bytes) == crc).then_some(bytes))
    }

    fn read_at(&mut self, offset: u64, len: u64, tag: Tag) -> Result<Vec<u8>> {
        // Lengths were checked against the file size at open, so this allocation is bounded by it.
        let io = |e: std::io::Error| Error::Stream(format!("reading part {tag}: {e}"));
        self.source.seek(SeekFrom::Start(offset)).map_err(io)?;
        let mut buf = vec![0u8; len as usize];
        read_exact_or(&mut self.source, &mut buf, "a part")?;
        Ok(buf)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Cursor;

    fn sample() -> Vec<u8> {
        let mut w = ContainerWriter::new();
        w.add(Tag::HEADER, b"hello".to_vec(), Checksum::Whole).unwrap();
        w.add(Tag::FRAMES, b"0123456789".to_vec(), Checksum::Chunked).unwrap();
        w.to_bytes()
    }

    #[test]
    fn length_without_serialising_is_the_files() {
        let mut w = ContainerWriter::new();
        assert!(w.is_empty());
        assert_eq!(w.len(), w.to_bytes().len() as u64);
        w.add(Tag::HEADER, b"hello".to_vec(), Checksum::Whole).unwrap();
        w.add(Tag::FRAMES, b"0123456789".to_vec(), Checksum::Chunked).unwrap();
        assert_eq!(w.len(), w.to_bytes().len() as u64);
    }

    #[test]
    fn round_trip_parts_and_chunks() {
        let bytes = sample();
        let mut r = ContainerReader::new(Cursor::new(bytes)).unwrap();
        assert_eq!(r.part(Tag::HEADER).unwrap(), b"hello");
        let crc = crc32fast::hash(b"345");
        assert_eq!(r.chunk(Tag::FRAMES, 3, 3, crc, "frame 1").unwrap(), b"345");
        assert!(r.chunk(Tag::FRAMES, 3, 3, crc ^ 1, "frame 1").is_err());
        assert!(r.chunk(Tag::FRAMES, 8, 3, crc, "frame 1").is_err());
        assert!(r.part(Tag::AFFINE).is_err());
    }

    #[test]
    fn every_truncation_and_a_flipped_bit_are_errors() {
        let bytes = sample();
        for cut in 0..bytes.len() {
            assert!(
                ContainerReader::new(Cursor::new(bytes[..cut].to_vec())).is_err(),
                "cut {cut}"
            );
        }
        let mut flipped = bytes.clone();
        flipped[FILE_HEADER_LEN + PART_HEADER_LEN + 1] ^= 0x10; // inside the header payload
        let mut r = ContainerReader::new(Cursor::new(flipped)).unwrap();
        assert!(r.part(Tag::HEADER).is_err());
        let mut extra = bytes;
        extra.push(0);
        assert!(ContainerReader::new(Cursor::new(extra)).is_err());
    }

    fn progressive(last: bool) -> Vec<u8> {
        let mut w = ContainerWriter::new();
        w.add(Tag::HEADER, b"hello".to_vec(), Checksum::Whole).unwrap();
        w.add(Tag::TDCT, b"0123456789".to_vec(), Checksum::Progressive).unwrap();
        if !last {
            w.add(Tag::AFFINE, b"abc".to_vec(), Checksum::Whole).unwrap();
        }
        w.to_bytes()
    }

    #[test]
    fn only_a_progressive_last_part_may_be_cut_short() {
        let bytes = progressive(true);
        let r = ContainerReader::new(Cursor::new(bytes.clone())).unwrap();
        assert_eq!(r.entry(Tag::TDCT).unwrap().len, 10);
        assert_eq!(r.truncated(Tag::TDCT), None);
        let payload = bytes.len() - 10;
        for cut in payload..bytes.len() {
            let mut r = ContainerReader::new(Cursor::new(bytes[..cut].to_vec()))
                .unwrap_or_else(|e| panic!("cut {cut}: {e}"));
            assert_eq!(r.entry(Tag::TDCT).unwrap().len, (cut - payload) as u64);
            assert_eq!(r.truncated(Tag::TDCT), Some(10));
            assert_eq!(r.part(Tag::HEADER).unwrap(), b"hello");
            let crc = crc32fast::hash(b"01");
            let whole = r.chunk(Tag::TDCT, 0, 2, crc, "band 0");
            assert_eq!(whole.is_ok(), cut >= payload + 2, "cut {cut}");
        }
        // Inside the part's own header, or before it: still an error.
        for cut in 0..payload {
            assert!(ContainerReader::new(Cursor::new(bytes[..cut].to_vec())).is_err());
        }
        // Not the last part: a cut is an error like any other.
        let bytes = progressive(false);
        for cut in 0..bytes.len() {
            assert!(ContainerReader::new(Cursor::new(bytes[..cut].to_vec())).is_err());
        }
    }
}
